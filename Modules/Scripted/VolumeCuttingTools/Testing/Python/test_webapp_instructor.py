"""The instructor link in Chromium: a trainee page and an instructor page on one session (the phantom).

One journey, in the order an instructor lives it: a guessed link and a
page with a wrong secret are refused; the instructor joins with the link
the trainee's page shows and sees the same frames of the 3D view, the
segment table and the nerve monitor; trying to drill or to change the
trainee's settings is refused with a message and leaves the cut untouched
(its checksum); the instructor points (the trainee's 3D view shows the
marker), draws a guide axis (the trainee's next stroke stays on it),
freezes the drill (the trainee's stroke is refused with a message) and
undoes the guided stroke (the cut comes back bit for bit); control passes
only when the trainee accepts, and comes back when they take it; renewing
the link drops the instructor and the old link is refused.
"""

import os
import time
import urllib.error
import urllib.request
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from VolumeCuttingLib.webapp.browser import AppPage, AppServer

pytestmark = pytest.mark.browser

VIEWPORT = {"width": 1280, "height": 800}


def side_by_side(left, right, path):
    """The trainee's page (left) and the instructor's (right) in one picture, a grey band between them."""
    images = [Image.open(left).convert("RGB"), Image.open(right).convert("RGB")]
    band = 16
    picture = Image.new("RGB", (sum(i.width for i in images) + band, max(i.height for i in images)), (96, 96, 96))
    picture.paste(images[0], (0, 0))
    picture.paste(images[1], (images[0].width + band, 0))
    picture.save(path)


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    with AppServer("--phantom", "--test-hooks", log_path=tmp_path_factory.mktemp("webapp-instructor") / "server.log") as running:
        yield running


def open_page(browser, url, timing=True):
    context = browser.new_context(viewport=VIEWPORT, device_scale_factor=1)
    page = context.new_page()
    page.set_default_timeout(60000)
    application = AppPage(page, timing=timing)
    application.open(url)
    return application


def state(page, key):
    return page.page.evaluate(f"() => window.trame.state.get('{key}')")


def checksum(page):
    answer = page.page.evaluate("() => window.trame.trigger('vc_co_checksum')")
    assert answer.get("ok"), answer
    return answer["result"]


def point_in_view(page, fx, fy):
    box = page.three_d_box()
    return box["x"] + fx * box["width"], box["y"] + fy * box["height"]


def stroke(page, fy=0.5):
    page.drag([point_in_view(page, 0.44 + 0.004 * i, fy) for i in range(20)], 15)


def wait_notice(page, text):
    page.wait_for(f"() => (window.trame.state.get('vc_notice') || '').includes({text!r})", 20, f"the notice '{text}'")
    page.page.evaluate("() => window.trame.state.set('vc_notice', '')")


def yellow_pixels(page):
    pixels = page.three_d_pixels().astype(int)
    return int(((pixels[..., 0] > 200) & (pixels[..., 1] > 170) & (pixels[..., 2] < 90)).sum())


def test_the_instructor_journey(server, browser, tmp_path):
    # Docs/webapp/15-instructor-link.png: both pages side by side, written when VOLUMECUTTING_SCREENSHOTS names a folder.
    shots = os.environ.get("VOLUMECUTTING_SCREENSHOTS")
    trainee = open_page(browser, server.url)
    trainee.wait_ready(300)
    trainee.wait_still(1000, 120)
    link = trainee.page.locator('[data-testid="instructor-link"] input').input_value()
    assert link.startswith(server.url + "instructor?key=vc-"), link
    key = link.split("key=")[1]
    untouched = checksum(trainee)

    # A guessed link, an empty one and a page connecting with a wrong secret get nothing.
    for wrong in (server.url + "instructor?key=vc-" + "A" * 43, server.url + "instructor", link[:-1]):
        with pytest.raises(urllib.error.HTTPError) as refused:
            urllib.request.urlopen(wrong, timeout=10)
        assert refused.value.code == 403 and "not valid" in refused.value.read().decode()
    intruder = open_page(browser, server.url + "?secret=vc-guessed", timing=False)
    intruder.page.wait_for_timeout(1500)
    assert not intruder.page.evaluate("() => !!window.trame?.state?.get('vc_description')")
    assert intruder.page.locator("img").count() == 0
    intruder.page.context.close()

    # The instructor joins with the link: the same session, views, table and meter.
    instructor = open_page(browser, link)
    instructor.wait_ready(120)
    assert state(instructor, "vc_role") == "instructor" and state(trainee, "vc_role") == "trainee"
    assert "secret" not in instructor.page.url  # the key does not stay in the address bar
    assert instructor.testid("instructor-panel").is_visible()
    assert instructor.testid("mode").count() == 0 and instructor.testid("load").count() == 0
    trainee.wait_for("() => document.querySelector('[data-testid=instructor-presence]').textContent.includes('connected')"
                     " && window.trame.state.get('vc_instructor_present')", 20, "the trainee to see the instructor")
    assert instructor.page.locator("[data-removed-of]").count() == trainee.page.locator("[data-removed-of]").count() == 14
    instructor.wait_for("() => document.querySelectorAll('[data-monitor-of]').length > 0", 60, "the monitor meter")

    # The trainee drills: the instructor gets the same 3D frames and the same table.
    trainee.set_mode("drill")
    removed = trainee.total_removed()
    started = trainee.page.evaluate("() => Date.now()")
    stroke(trainee)
    trainee.wait_for_total_removed(f"v > {removed + 0.5}", 60)
    trainee.wait_still(500, 60)
    instructor.wait_for_total_removed(f"v == {trainee.total_removed()}", 20)
    area = trainee.three_d_area()
    sent = {f["st"] for f in trainee.timing()["frames"] if f["name"] == area and f["st"] > started}
    seen = {f["st"] for f in instructor.timing()["frames"] if f["name"] == area}
    assert len(sent) > 3 and sent <= seen, f"{len(sent - seen)} of the trainee's {len(sent)} frames did not reach the instructor"

    # The instructor cannot drill, nor change the trainee's mode, depth or cut: refused, with a message.
    after_stroke = checksum(trainee)
    stroke(instructor)
    wait_notice(instructor, "You are watching")
    instructor.page.evaluate("""async (area) => { await window.trame.trigger('vc_set_mode', ['restore']);
        await window.trame.trigger('vc_undo'); window.trame.state.set('vc_depth', 7.5);
        // Below the page: wslink's and trame's own calls (reload the data, stop the server, drop the frames).
        const session = window.trame.client.getConnection().getSession();
        await session.call('trame.lifecycle.update', ['server_ready']);
        await session.call('application.exit.later', [1]);
        await session.call('trame.rca.drop', [area, 0]); }""", trainee.three_d_area())
    wait_notice(instructor, "You are watching")
    trainee.page.wait_for_timeout(1500)  # the server would stop 1 s after an exit it took
    trainee.page.wait_for_timeout(300)
    diagnostics = trainee.server_timing()
    assert diagnostics["mode"] == "drill" and state(trainee, "vc_depth") != 7.5
    assert min(diagnostics["refused"].values()) > 0, diagnostics["refused"]
    assert checksum(trainee) == after_stroke and trainee.total_removed() == instructor.total_removed()

    # Point: the trainee's view shows the yellow marker.
    yellow_before = yellow_pixels(trainee)
    instructor.testid("tool-point").click()
    instructor.page.mouse.click(*point_in_view(instructor, 0.3, 0.5))
    trainee.wait_for("() => !!window.trame.state.get('vc_pointer')", 20, "the marker")
    deadline = time.monotonic() + 30
    while yellow_pixels(trainee) <= yellow_before + 30:
        assert time.monotonic() < deadline, "the trainee's 3D view does not show the instructor's marker"
        trainee.page.wait_for_timeout(150)

    # Guide axis: 6 mm into the bone where the instructor clicks; the trainee's stroke stays on it.
    instructor.testid("tool-axis").click()
    instructor.page.evaluate("() => window.trame.state.set('vc_ins_axis_depth', 6)")
    instructor.page.mouse.click(*point_in_view(instructor, 0.5, 0.6))
    trainee.wait_for("() => !!window.trame.state.get('vc_guide')", 20, "the guide axis")
    guide = state(trainee, "vc_guide")
    assert guide["length"] == pytest.approx(6.0)
    assert "6.0 mm" in instructor.testid("guide-status").inner_text()
    if shots:
        trainee.wait_still(500, 60)
        instructor.page.evaluate("() => window.trame.state.set('vc_notice', '')")
        Path(shots).mkdir(parents=True, exist_ok=True)
        side_by_side(trainee.screenshot(tmp_path / "trainee.png"), instructor.screenshot(tmp_path / "instructor.png"),
                     Path(shots) / "15-instructor-link.png")
    before_guided, removed = checksum(trainee), trainee.total_removed()
    stroke(trainee, 0.6)
    trainee.wait_for_total_removed(f"v > {removed + 0.2}", 60)
    entry, target = np.array(guide["entry"]), np.array(guide["target"])
    centre = np.array(trainee.server_timing()["tool"])
    along = np.clip(np.dot(centre - entry, target - entry) / 36.0, 0.0, 1.0)
    assert np.linalg.norm(centre - (entry + along * (target - entry))) < 1e-3, "the burr left the guide axis"

    # Freeze: the trainee's stroke is refused with a message, nothing is cut.
    instructor.testid("freeze").click()
    trainee.testid("frozen-banner").wait_for(state="visible", timeout=20000)
    frozen_cut = checksum(trainee)
    stroke(trainee, 0.6)
    wait_notice(trainee, "frozen")
    assert checksum(trainee) == frozen_cut
    instructor.testid("freeze").click()
    trainee.testid("frozen-banner").wait_for(state="hidden", timeout=20000)

    # Undo: the guided stroke goes, the cut is what it was before it, bit for bit.
    instructor.testid("instructor-undo").click()
    trainee.wait_for_total_removed(f"v < {trainee.total_removed()}", 30)
    assert checksum(trainee) == before_guided
    instructor.testid("clear-marks").click()
    trainee.wait_for("() => !window.trame.state.get('vc_guide') && !window.trame.state.get('vc_pointer')", 20, "no marks")

    # Control: declined, then accepted; the instructor drills; the trainee takes it back.
    instructor.testid("request-control").click()
    trainee.testid("decline").click()
    trainee.testid("consent-dialog").wait_for(state="hidden", timeout=20000)
    assert state(trainee, "vc_owner") != state(instructor, "vc_client_id")
    instructor.testid("request-control").click()
    trainee.testid("accept").click()
    instructor.testid("give-back").wait_for(state="visible", timeout=20000)
    trainee.testid("take-back").wait_for(state="visible", timeout=20000)
    instructor.wait_for("() => window.trame.state.get('vc_owner') === window.trame.state.get('vc_client_id')", 20,
                        "the instructor to hold control")
    instructor.set_mode("drill")
    removed = instructor.total_removed()
    stroke(instructor, 0.4)
    instructor.wait_for_total_removed(f"v > {removed + 0.2}", 60)
    instructor.wait_still(500, 60)  # the server has applied the whole stroke
    held = checksum(trainee)
    stroke(trainee, 0.45)
    trainee.page.wait_for_timeout(500)
    assert checksum(trainee) == held  # while the instructor holds control the trainee's mouse does nothing
    trainee.testid("take-back").click()
    instructor.testid("request-control").wait_for(state="visible", timeout=20000)

    # A new link: the instructor's page leaves the session and the old link is refused.
    final = checksum(trainee)
    trainee.testid("renew-link").click()
    trainee.wait_for(f"() => !document.querySelector('[data-testid=instructor-link] input').value.includes({key!r})",
                     20, "the new link")
    trainee.wait_for("() => !window.trame.state.get('vc_instructor_present')", 20, "the instructor to be gone")
    with pytest.raises(urllib.error.HTTPError) as refused:
        urllib.request.urlopen(link, timeout=10)
    assert refused.value.code == 403
    assert checksum(trainee) == final
    instructor.page.context.close()
    trainee.page.context.close()
