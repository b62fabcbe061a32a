"""The web application in a real browser: Debian's Chromium driven by Playwright, as a surgeon would use it.

One application server on 127.0.0.1 (the temporal-bone phantom, a 1 MB
upload limit, one allowed server folder) is started and stopped by the
module; the tests run in file order on its page, each wait time-limited:

1. the phantom loads and shows in the 3D view and the slice views;
2. a segment is made protected in the segments table;
3. a drag across the 3D view drills: the removed volume in the table grows
   and the pixels under the drag change;
4. drilling deeper reaches the protected segment: the warning appears and
   its removed volume stays 0;
5. undo gives back the previous image and volumes;
6. each export downloads a file that Slicer Core reads back (closed STL,
   segment, drilled CT, a bundle with the same cut);
7. Restore mode adds bone back into the groove, and undo takes it away;
8. bad input: a file that is not an image, a file over the limit, a server
   path outside the allowed folder, the page lost in the middle of a
   stroke, and a second tab on the session: a clear message, nothing lost;
   then a scan of the user's own by its server path, without segmentation:
   the bone is segmented automatically (with progress) and drilled;
9. SoftCut on the example head CT: a click in the SoftCut outline mode
   places a point on the skin, the example cheek outline is planned,
   previewed in the 3D view, carved (one undo step) and measured;
10. several users through wslink's launcher (a process and a scene each).

Screenshots of the steps go to ``$VOLUMECUTTING_SCREENSHOTS`` (Docs/webapp
holds the committed ones), else into pytest's temporary folder.
"""

import os
import signal
from pathlib import Path

import numpy as np
import pytest
from playwright.sync_api import TimeoutError as PlaywrightTimeoutError

from VolumeCuttingLib.webapp.browser import AppPage, AppServer, opened_app_page, screenshot_folder

pytestmark = pytest.mark.browser

# What the tests hand on to the next one (they run in file order on one page).
shared = {}
PROTECTED = "MastoidBone"  # under the 1.5-2 mm mastoid cortex, which the drill may cut
VIEWPORT = {"width": 1440, "height": 900}


@pytest.fixture(scope="module")
def shots(tmp_path_factory):
    return screenshot_folder(tmp_path_factory, "webapp-screenshots")


@pytest.fixture(scope="module")
def data_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("allowed-scans")


@pytest.fixture(scope="module")
def server(tmp_path_factory, data_dir):
    log = tmp_path_factory.mktemp("webapp-server") / "server.log"
    with AppServer("--phantom", "--max-upload-mb", "1", "--data-dir", data_dir, log_path=log) as running:
        yield running


@pytest.fixture(scope="module")
def app(server, browser):
    with opened_app_page(browser, server.url, timing=True, still_ms=1500, downloads=True) as application:
        yield application


def view_point(app, fx, fy):
    box = app.three_d_box()
    return box["x"] + fx * box["width"], box["y"] + fy * box["height"]


def rest(app):
    """The pointer off the bone (the glyph hides) and the view refined and still."""
    box = app.three_d_box()
    app.page.mouse.move(box["x"] + 8, box["y"] + box["height"] - 8)
    app.wait_refined(1000, 300)


def region(pixels, app, points, margin=12):
    """The pixels of the 3D view around a list of page points."""
    box = app.three_d_box()
    xs = [int(x - box["x"]) for x, _ in points]
    ys = [int(y - box["y"]) for _, y in points]
    return pixels[max(min(ys) - margin, 0):max(ys) + margin, max(min(xs) - margin, 0):max(xs) + margin].astype(int)


def set_role(app, segment_id, role):
    app.page.locator(f'[data-role-of="{segment_id}"]').click()
    app.page.locator(".v-overlay--active .v-list-item", has_text=role).first.click()
    app.wait_for(f"""() => [...document.querySelectorAll('[data-role-of="{segment_id}"]')]
                     .some(e => e.textContent.includes('{role}'))""", 30, f"the role of {segment_id} to read {role}")


def test_the_phantom_loads_into_all_views(app, shots):
    assert "Temporal-bone phantom" in app.testid("status").inner_text()
    pixels = app.three_d_pixels()
    assert pixels.shape[0] > 600 and pixels.shape[1] > 600
    # Bone in the middle of the 3D view, the dark background at its corner.
    middle = pixels[pixels.shape[0] // 2 - 20:pixels.shape[0] // 2 + 20, pixels.shape[1] // 2 - 20:pixels.shape[1] // 2 + 20]
    assert middle.mean() > pixels[:30, -30:].mean() + 60
    assert app.page.locator("[data-removed-of]").count() == 14
    app.screenshot(shots / "01-phantom-loaded.png")


def test_a_segment_is_made_protected(app, shots):
    set_role(app, PROTECTED, "protected")
    assert app.removed_volume(PROTECTED) == 0.0
    app.screenshot(shots / "02-protected-segment.png")


def test_drilling_across_the_view_removes_bone(app, shots):
    app.set_mode("drill")
    path = [view_point(app, 0.40 + 0.004 * i, 0.45 + 0.001 * i) for i in range(40)]
    rest(app)
    before = app.three_d_pixels()
    removed_before = app.total_removed()
    app.drag(path, 20)
    removed = app.wait_for_total_removed(f"v > {removed_before + 1.0}", 60)
    assert app.removed_volume("MastoidCortex") > 1.0
    assert app.removed_volume(PROTECTED) == 0.0
    rest(app)
    after = app.three_d_pixels()
    changed = np.abs(region(after, app, path) - region(before, app, path)).sum(axis=2) > 30
    assert changed.mean() > 0.2, f"only {changed.mean():.0%} of the pixels under the drag changed"
    far = [view_point(app, 0.2, 0.2)]
    assert np.abs(region(after, app, far) - region(before, app, far)).max() < 40  # elsewhere the view stays
    assert app.testid("contact-warning").is_hidden()
    app.screenshot(shots / "03-drilled.png")
    assert removed > 1.0


def test_drilling_into_the_protected_segment_warns_and_spares_it(app, shots):
    rest(app)
    shared["image"] = app.three_d_pixels()
    shared["cortex"] = app.removed_volume("MastoidCortex")
    # Shift drills twice as deep: with the depth at 2 mm, 4 mm, through the cortex into the bone.
    slider = app.page.locator('[data-testid="depth"] [role="slider"]')
    slider.focus()
    for _ in range(4):
        slider.press("ArrowRight")
    app.wait_for("() => window.trame.state.get('vc_depth') === 2", 20, "the depth to read 2 mm")
    path = [view_point(app, 0.55, 0.35 + 0.004 * i) for i in range(25)]
    app.drag(path, 25, shift=True)
    warning = app.testid("contact-warning")
    warning.wait_for(state="visible", timeout=60000)
    assert PROTECTED in warning.inner_text() and "protected" in warning.inner_text()
    app.wait_for("() => document.querySelector('[data-testid=contacts]')", 30, "the contact list")
    app.page.wait_for_timeout(500)
    app.screenshot(shots / "04-protected-contact.png")
    assert app.removed_volume(PROTECTED) == 0.0
    assert app.removed_volume("MastoidCortex") > shared["cortex"]


def test_undo_restores_the_previous_image_and_volumes(app, shots):
    app.testid("undo").click()
    cortex = shared["cortex"]
    app.wait_for(f"""() => Math.abs(parseFloat(document.querySelector('[data-removed-of="MastoidCortex"]').textContent)
                     - {cortex}) < 0.005""", 30, "the cortex's removed volume to come back")
    rest(app)
    after = app.three_d_pixels()
    before = shared["image"]
    # The bottom line of the view is the mode hint, which names the depth (changed since).
    # Frames are JPEG: the same image encoded twice differs by up to ~70 (summed over RGB) in the bone's texture;
    # the undone stroke differs by hundreds over about 1 % of the view.
    difference = np.abs(after.astype(int) - before.astype(int)).sum(axis=2)[:-36]
    if (difference > 100).mean() >= 0.001:
        from PIL import Image

        Image.fromarray(before).save(shots / "undo-before.png")
        Image.fromarray(after).save(shots / "undo-after.png")
    assert (difference > 100).mean() < 0.001, f"{(difference > 100).mean():.2%} of the view differs after undo"
    app.screenshot(shots / "05-undone.png")
    app.testid("redo").click()
    app.wait_for(f"""() => parseFloat(document.querySelector('[data-removed-of="MastoidCortex"]').textContent)
                     > {cortex} + 0.005""", 30, "redo")
    app.testid("undo").click()
    app.wait_for(f"""() => Math.abs(parseFloat(document.querySelector('[data-removed-of="MastoidCortex"]').textContent)
                     - {cortex}) < 0.005""", 30, "undo again")


def test_each_export_downloads_a_file_slicer_reads(app, tmp_path, shots):
    from test_webapp_session import check_exports

    app.page.locator('[data-testid="export-stl"]').scroll_into_view_if_needed()
    paths = {kind: app.download(f"export-{kind}", tmp_path) for kind in ("stl", "segmentation", "drilled_ct", "scene")}
    assert paths["stl"].name.endswith("removed.stl") and paths["scene"].suffix == ".mrb"
    app.screenshot(shots / "06-exports.png")
    check_exports(paths, app.total_removed(), tmp_path, tolerance_mm3=0.006)  # the page rounds to 0.01 mm3
    shared["drilled_ct"] = paths["drilled_ct"]


def test_restore_mode_adds_bone_back_into_the_groove(app):
    total = app.total_removed()
    app.set_mode("restore")
    # Along the groove of the drilling test: the tool rests in it and fills it.
    app.drag([view_point(app, 0.40 + 0.004 * i, 0.45 + 0.001 * i) for i in range(40)], 20)
    restored = app.wait_for_total_removed(f"v < {total - 1.0}", 60)
    assert app.removed_volume(PROTECTED) == 0.0
    app.testid("undo").click()
    app.wait_for_total_removed(f"Math.abs(v - {total}) < 0.01", 60)
    app.set_mode("drill")
    assert 0.0 <= restored < total


def test_an_upload_that_is_not_an_image_is_refused_and_nothing_is_lost(app, tmp_path, shots):
    total = app.total_removed()
    app.page.locator('[data-testid="source"]').click()
    app.page.locator(".v-overlay--active .v-list-item", has_text="My own scan").click()
    notes = tmp_path / "notes.nrrd"
    notes.write_text("Operative notes, not a CT.\n")
    app.page.locator('[data-testid="upload-ct"] input[type=file]').set_input_files(str(notes))
    app.wait_for("() => (window.trame.state.get('vc_uploaded') || {}).ct", 30, "the upload to arrive")
    app.testid("load").click()
    error = app.testid("data-error")
    error.wait_for(state="visible", timeout=60000)
    assert "notes.nrrd" in error.inner_text()
    assert "previous data stays" in app.testid("status").inner_text()
    assert app.total_removed() == total
    app.screenshot(shots / "07-not-an-image.png")


def test_an_upload_over_the_limit_is_refused_at_once(app, tmp_path):
    big = tmp_path / "big.nii.gz"
    big.write_bytes(os.urandom(2 * 2**20))
    app.page.locator('[data-testid="upload-ct"] input[type=file]').set_input_files(str(big))
    message = app.testid("upload-message")
    message.wait_for(state="visible", timeout=10000)
    assert "big.nii.gz" in message.inner_text() and "1.0 MB" in message.inner_text()


def test_a_server_path_outside_the_allowed_folders_is_refused(app, data_dir):
    uploaded = app.page.evaluate("() => window.trame.state.get('vc_uploaded')")
    app.page.evaluate("() => window.trame.state.set('vc_uploaded', {ct: '', segmentation: ''})")
    app.testid("ct-path").locator("input").fill("/etc/passwd")
    app.testid("load").click()
    error = app.testid("data-error")
    app.wait_for("() => document.querySelector('[data-testid=data-error]')?.textContent.includes('/etc/passwd')", 30,
                 "the message about /etc/passwd")
    assert str(data_dir) in error.inner_text()
    app.page.evaluate("(uploaded) => window.trame.state.set('vc_uploaded', uploaded)", uploaded)


def test_a_second_tab_is_told_and_can_take_over(app, browser, server, shots):
    total = app.total_removed()
    context = browser.new_context(viewport=VIEWPORT, device_scale_factor=1)
    second = AppPage(context.new_page())
    second.open(server.url)
    second.testid("take-over").wait_for(state="visible", timeout=60000)
    assert "open in another tab" in second.testid("tab-overlay").inner_text()
    assert app.testid("take-over").is_hidden()
    # The views here follow the session: the 3D view and the three slice views get their images.
    second.wait_for("() => [...document.querySelectorAll('img')].filter(i => i.complete && i.naturalWidth > 100).length >= 4",
                    60, "the second tab's views to show the session")
    second.page.wait_for_timeout(500)
    second.screenshot(shots / "08-second-tab.png")
    second.testid("take-over").click()
    app.testid("take-over").wait_for(state="visible", timeout=30000)
    assert second.total_removed() == total
    app.testid("take-over").click()
    second.testid("take-over").wait_for(state="visible", timeout=30000)
    context.close()
    app.wait_for("() => !document.querySelector('[data-testid=take-over]')", 30, "the first tab to own the session")


def test_a_page_lost_in_the_middle_of_a_stroke_keeps_the_cut(app, browser, server):
    undo_before = app.page.evaluate("() => window.trame.state.get('vc_undo_count')")
    total = app.total_removed()
    app.page.context.close()
    context = browser.new_context(viewport=VIEWPORT, device_scale_factor=1)
    page = AppPage(context.new_page(), timing=True)
    page.open(server.url)
    page.wait_ready(120)
    page.wait_still(1500, 120)
    page.set_mode("drill")
    mouse = page.page.mouse
    start = view_point(page, 0.45, 0.6)
    mouse.move(*start)
    page.page.wait_for_timeout(300)
    mouse.down()
    for i in range(25):
        mouse.move(start[0] + 3 * i, start[1])
        page.page.wait_for_timeout(25)
    page.wait_for("async () => { await window.trame.trigger('vc_diagnostics'); return true; }", 60, "the server to take the moves")
    context.close()  # the page goes away with the button down

    context = browser.new_context(viewport=VIEWPORT, device_scale_factor=1)
    again = AppPage(context.new_page())
    again.open(server.url)
    again.wait_ready(120)
    assert again.total_removed() > total
    assert again.page.evaluate("() => window.trame.state.get('vc_undo_count')") == undo_before + 1
    # The stroke was closed: undo takes exactly it back.
    again.testid("undo").click()
    again.wait_for_total_removed(f"Math.abs(v - {total}) < 0.01", 60)
    context.close()


def test_an_own_scan_by_its_server_path_is_segmented_automatically_and_drilled(browser, server, data_dir, shots):
    """The drilled CT just exported, as a scan of the user's own in the allowed folder, without a segmentation."""
    scan = data_dir / "my-temporal-bone.nrrd"
    scan.write_bytes(shared["drilled_ct"].read_bytes())
    context = browser.new_context(viewport=VIEWPORT, device_scale_factor=1)
    page = AppPage(context.new_page(), timing=True)
    page.open(server.url)
    page.wait_ready(120)
    page.page.evaluate("() => window.trame.state.set('vc_uploaded', {ct: '', segmentation: ''})")
    page.page.locator('[data-testid="source"]').click()
    page.page.locator(".v-overlay--active .v-list-item", has_text="My own scan").click()
    page.testid("ct-path").locator("input").fill(str(scan))
    # The progress the page shows while loading: every step's fraction, as the state carried it.
    page.page.evaluate("""() => { window.__vcProgress = [];
        const watch = () => { window.__vcProgress.push([window.trame.state.get('vc_busy'), window.trame.state.get('vc_progress'),
                                                         window.trame.state.get('vc_status')]);
                              if (window.__vcProgress.length < 3000) setTimeout(watch, 10); };
        watch(); }""")
    page.testid("load").click()
    page.wait_for("() => (document.querySelector('[data-testid=status]')?.textContent || '').includes('Ready: my-temporal-bone.nrrd')",
                  120, "the own scan to be ready")
    progress = page.page.evaluate("() => window.__vcProgress")
    assert any(busy and "Segmenting bone automatically" in (status or "") for busy, _, status in progress)
    assert page.page.locator("[data-removed-of]").count() == 2  # cortical and trabecular bone
    assert page.total_removed() == 0.0
    assert page.testid("upload-message").is_hidden()  # the earlier refused upload's message went with the old data
    page.wait_still(1500, 180)
    page.screenshot(shots / "09-own-scan-segmented.png")
    page.set_mode("drill")
    page.drag([view_point(page, 0.40 + 0.004 * i, 0.50) for i in range(30)], 20)
    page.wait_for_total_removed("v > 1", 60)
    context.close()


def test_softcut_plans_previews_and_carves_the_cheek_on_the_head_ct(browser, server, shots):
    # A page of its own: the first page was lost on purpose above.
    context = browser.new_context(viewport=VIEWPORT, device_scale_factor=1)
    app = AppPage(context.new_page(), timing=True)
    app.open(server.url)
    app.wait_ready(120)
    page = app.page
    page.set_default_timeout(60000)
    take_over = app.testid("take-over")
    if take_over.is_visible():
        # The first page's tab was closed: the server may hand this page the drill while the button is pressed.
        try:
            take_over.click(timeout=10000)
        except PlaywrightTimeoutError:
            assert take_over.is_hidden(), "the take-over button stayed but could not be pressed"
    page.locator('[data-testid="source"]').click()
    page.locator(".v-overlay--active .v-list-item", has_text="Example head CT").click()
    app.testid("load").click()
    app.wait_for("() => (document.querySelector('[data-testid=status]')?.textContent || '').includes('Ready: Example head CT')",
                 120, "the head CT to be ready")
    app.wait_still(1000, 120)
    # A click on the head in the outline mode: a point on the skin (the view turns to the skin).
    app.set_mode("outline")
    app.wait_still(1000, 120)
    page.mouse.click(*view_point(app, 0.5, 0.5))
    app.wait_for("() => window.trame.state.get('vc_sc_points') === 1", 30, "a point of the outline")
    app.testid("softcut-clear").click()
    app.testid("softcut-example").click()
    app.wait_for("() => window.trame.state.get('vc_sc_points') === 20", 60, "the example cheek outline")
    app.set_mode("navigate")
    # The right cheek, from the patient's right front (the main job's view).
    page.evaluate("() => window.trame.state.set('vc_sc_depth', 8)")
    app.wait_still(800, 120)
    before = app.three_d_pixels()
    app.testid("softcut-preview").click()
    app.wait_for("() => (document.querySelector('[data-testid=softcut-status]')?.textContent || '').includes('Preview at 8 mm')",
                 60, "the preview")
    app.wait_still(1000, 120)
    previewed = app.three_d_pixels()
    app.screenshot(shots / "10-softcut-preview.png")
    assert app.total_removed() == 0.0  # a preview cuts nothing
    changed = np.abs(previewed.astype(int) - before.astype(int)).max(axis=2) > 40
    assert changed.mean() > 0.002, f"the preview changed {100 * changed.mean():.2f} % of the view"
    app.testid("softcut-carve").click()
    removed = app.wait_for_total_removed("v > 3000", 120)
    app.wait_for("() => !!document.querySelector('[data-measurement=\"Resected volume\"]')", 60, "the measurements")
    volume = float(page.locator('[data-measurement="Resected volume"] td').nth(1).inner_text().split()[0])
    assert 4000.0 < volume < 8000.0 and removed > 0.9 * volume
    for name in ("Surface area", "Length", "Width", "Thickness"):
        assert page.locator(f'[data-measurement="{name}"]').count() == 1
    assert app.testid("softcut-error").count() == 0
    assert page.evaluate("() => window.trame.state.get('vc_undo_count')") == 1
    app.testid("softcut-panel").scroll_into_view_if_needed()
    app.wait_still(1500, 120)
    app.screenshot(shots / "11-softcut-carved.png")
    context.close()


def test_the_launcher_gives_each_user_a_scene_of_their_own(browser, tmp_path):
    """Two browsers through wslink's launcher: two application processes (on the phantom), nothing shared."""
    import socket
    import subprocess
    import sys
    import time

    from VolumeCuttingLib.webapp.browser import free_port

    port = free_port()
    library = str(Path(__import__("VolumeCuttingLib").__file__).resolve().parents[1])
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in (library, os.environ.get("PYTHONPATH", "")) if p),
               VTK_DEFAULT_OPENGL_WINDOW="vtkEGLRenderWindow")
    log = open(tmp_path / "launcher.log", "w")
    # The session ports follow the page's: the test takes a free port and hopes the next three are free too.
    launcher = subprocess.Popen([sys.executable, "-m", "VolumeCuttingLib.webapp.launcher", "--port", str(port),
                                 "--sessions", "2", "--folder", str(tmp_path / "launcher"), "--", "--phantom"],
                                stdout=log, stderr=subprocess.STDOUT, env=env)
    users = []
    try:
        deadline = time.monotonic() + 60
        while True:
            try:
                socket.create_connection(("127.0.0.1", port), timeout=0.5).close()
                break
            except OSError:
                assert launcher.poll() is None and time.monotonic() < deadline, (tmp_path / "launcher.log").read_text()
                time.sleep(0.2)
        for _ in range(2):
            context = browser.new_context(viewport=VIEWPORT, device_scale_factor=1)
            user = AppPage(context.new_page())
            user.open(f"http://127.0.0.1:{port}/")
            users.append(user)
        for user in users:
            user.wait_ready(300)
        sessions = [user.page.evaluate("() => window.trame.client.getConfig().sessionURL") for user in users]
        assert len(set(sessions)) == 2 and all(str(port) not in url for url in sessions)
        for user in users:
            # Each owns its session. The server publishes the owner as it handles connections coming and going;
            # in some full-suite runs the take-over prompt was still shown at the instant both pages were ready
            # (cause not pinned down), so the test asks that it goes within 15 s, not that it never showed.
            user.testid("take-over").wait_for(state="hidden", timeout=15000)
        users[0].set_mode("drill")
        users[0].drag([view_point(users[0], 0.40 + 0.004 * i, 0.45) for i in range(30)], 20)
        users[0].wait_for_total_removed("v > 1", 120)
        assert users[1].total_removed() == 0.0
        assert users[1].page.evaluate("() => window.trame.state.get('vc_mode')") == "navigate"
    finally:
        for user in users:
            user.page.context.close()
        sessions_started = children_of(launcher.pid)
        launcher.terminate()
        launcher.wait(timeout=30)
        # The sessions would end at their own timeout once their page is gone; end them now.
        for pid in sessions_started:
            try:
                os.kill(pid, signal.SIGTERM)
            except ProcessLookupError:
                pass
        log.close()


def children_of(pid: int) -> list[int]:
    """Process IDs whose parent is ``pid`` (from /proc)."""
    children = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            children.append(int(stat.parent.name))
    return children
