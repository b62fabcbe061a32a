"""Turning the head in the browser (issue 28, findings 5 and 2): quick frames while the camera moves, the full
picture on release, and a picture as soon as the page says Ready.

The application serves the example head CT; Debian's Chromium, driven by
Playwright, gives the 3D view 1024 x 768 CSS pixels (as the ``webapp``
benchmark does) and:

1. watches the start: from the moment the page says Ready, the 3D view
   shows a picture of the CT within ``FIRST_PICTURE_S`` and is never the
   black placeholder again;
2. drags the camera across the view, a mouse event every 16 ms (a 60 Hz
   mouse), and times each event to the first frame in the page that shows
   it (the benchmark's matching of browser and server events). The target
   on a quiet 2-core machine is p95 <= 150 ms (``TARGET_P95_MS``); on a
   machine shared with other jobs the wall clock says little, so the test
   asserts what does not depend on the load: the frames drawn while the
   camera moves are interactive ones (the ray caster casts fewer rays than
   pixels), each costs the server a fraction of a still frame, and the drag
   is answered as quickly as the cheapest path through the application
   (the drill's glyph hovering over the bone, measured right before) within
   ``HOVER_FACTOR``. The absolute p95 is printed, and asserted against a
   loaded machine's bound (``LOADED_P95_MS``);
3. after the release the view comes to rest on a full-resolution still
   frame, and that image is the one a still render of the same camera gives
   (the main window redrawn from nothing after a resize there and back).

Screenshots of an interactive frame and the release frame go to
``$VOLUMECUTTING_SCREENSHOTS``, else into pytest's temporary folder.
"""

import os
import statistics
import time

import numpy as np
import pytest

from VolumeCuttingLib.benchmarks.webapp import MOUSE_PERIOD_MS, VIEW_SIZE, drag_path, event_latencies
from VolumeCuttingLib.webapp.browser import AppPage, AppServer, screenshot_folder

pytestmark = [pytest.mark.browser, pytest.mark.realdata]

TARGET_P95_MS = 150.0
# What a 2-core machine with a load average of 10-17 (other builds and browsers beside) gave after the fix:
# p95 190-430 ms (before it: 1,400-4,000 ms there, and 540 ms on a quiet machine).
LOADED_P95_MS = 500.0
HOVER_FACTOR = 3.0
# An interactive frame costs the server at most this share of a still frame of the whole view.
INTERACTIVE_SHARE = 0.25
# From Ready to the picture: the page says Ready once the first frame is sent, so the first look (a screenshot
# takes 0.3-1.4 s on a loaded machine) must find it; a second look within 1 s covers an image still decoding.
FIRST_PICTURE_S = 1.0
# A pixel of the placeholder: black.
BLACK = 12


@pytest.fixture(scope="module")
def shots(tmp_path_factory):
    return screenshot_folder(tmp_path_factory, "camera-drag-screenshots")


def black_share(pixels: np.ndarray) -> float:
    return float(np.mean(pixels.max(axis=2) < BLACK))


@pytest.fixture(scope="module")
def started(browser, tmp_path_factory):
    """The head CT's page from the server's start, with what the 3D view showed from Ready on."""
    log = tmp_path_factory.mktemp("camera-drag-server") / "server.log"
    with AppServer(log_path=log) as server:
        page = browser.new_page(viewport={"width": 1745, "height": 856}, device_scale_factor=1)
        page.set_default_timeout(60000)
        app = AppPage(page, timing=True)
        app.open(server.url)
        app.wait_for("() => (document.querySelector('[data-testid=status]')?.textContent || '').includes('Ready')",
                     300, "the page to say Ready")
        ready = time.monotonic()
        # From Ready on: (seconds after Ready, share of black pixels in the 3D view).
        seen = []
        while time.monotonic() - ready < FIRST_PICTURE_S + 2.0:
            seen.append((time.monotonic() - ready, black_share(app.three_d_pixels())))
        yield app, seen, server
        page.close()


def test_a_picture_shows_as_soon_as_the_page_says_ready(started):
    _, seen, _ = started
    pictures = [t for t, black in seen if black < 0.5]
    assert pictures, f"the 3D view stayed black for {seen[-1][0]:.1f} s after Ready"
    first = pictures[0]
    print(f"\nfirst picture {first:.2f} s after Ready; the view from Ready on (s, share of black): "
          + ", ".join(f"{t:.2f} {black:.2f}" for t, black in seen))
    assert first <= FIRST_PICTURE_S
    assert all(black < 0.5 for t, black in seen if t >= first), "the view went black again after its first picture"


def test_turning_the_head_is_answered_with_interactive_frames(started, shots):
    app, _, _ = started
    page = app.page
    box = app.fit_three_d_view(*VIEW_SIZE)
    app.wait_refined(2000, 300)
    area = app.three_d_area()

    def timed(points, hover=False):
        start = time.time() * 1000.0
        interactive = None
        if hover:
            for x, y in points:
                page.mouse.move(x, y)
                page.wait_for_timeout(MOUSE_PERIOD_MS)
        else:
            page.mouse.move(*points[0])
            page.mouse.down()
            for x, y in points[1:]:
                page.wait_for_timeout(MOUSE_PERIOD_MS)
                page.mouse.move(x, y)
            # Still holding the button: what the user sees while turning.
            page.wait_for_timeout(400)
            interactive = app.three_d_pixels()
            page.mouse.up()
        app.wait_refined(2000, 300)
        server, page_log = app.server_timing(), app.timing()
        mouse = page_log["mouse"]
        events = [e for e in server["events"] if len(e) == 5]
        if hover:
            mouse = [dict(m, buttons=1, type="mousemove") for m in mouse if m["type"] == "mousemove"]
            events = [("MouseMove",) + tuple(e[1:]) for e in events if e[0] == "MouseMove"]
        frames = [f for f in page_log["frames"] if f["name"] == area]
        return event_latencies(mouse, events, server["renders"], frames, box, start), start, interactive

    # The floor: the drill's glyph moved over the bone (a cached image, the glyph, the encoder, the page).
    app.set_mode("drill")
    hover_path = drag_path(box, 60, start=(0.30, 0.62), step=(1.4, -0.45))
    hover, _, _ = timed(hover_path, hover=True)
    app.set_mode("navigate")
    app.page.mouse.move(box["x"] + 8, box["y"] + box["height"] - 8)
    app.wait_refined(1000, 300)
    drag, drag_start, interactive = timed(drag_path(box, 40, start=(0.5, 0.5), step=(3.0, 0.0)))
    release = app.three_d_pixels()
    _save(interactive, shots / "camera-drag-interactive.png")
    _save(release, shots / "camera-drag-release.png")

    p95 = float(np.percentile(drag, 95))
    hover_p95 = float(np.percentile(hover, 95))
    print(f"\ncamera drag: {len(drag)} events, median {statistics.median(drag):.0f} ms, p95 {p95:.0f} ms, "
          f"max {max(drag):.0f} ms (target p95 {TARGET_P95_MS:.0f} ms on a quiet machine); hover p95 {hover_p95:.0f} ms; "
          f"load average {os.getloadavg()[0]:.1f}")
    assert len(drag) >= 30, "most mouse events of the drag were matched to a frame"
    assert p95 <= LOADED_P95_MS
    assert p95 <= HOVER_FACTOR * hover_p95
    frames = [f for f in app.server_timing()["frames"] if f[1] >= drag_start]
    moving = [f for f in frames if f[0] == "preview" and f[5] > 1]
    still = [f for f in frames if f[0] == "main"]
    print(f"server: {len(moving)} interactive frames, median {statistics.median(f[2] for f in moving):.0f} ms "
          f"(a ray per {statistics.median(f[5] for f in moving):.0f} px each way), still frame of the view "
          f"{statistics.median(f[2] for f in still):.0f} ms")
    # Interactive frames, each a fraction of a still frame's cost; the view rests on a still full-resolution frame.
    assert len(moving) >= 5
    assert statistics.median(f[2] for f in moving) <= INTERACTIVE_SHARE * statistics.median(f[2] for f in still)
    assert frames[-1][0] == "main" and frames[-1][5] == 1 and frames[-1][3] >= VIEW_SIZE[0] - 8


def wait_for_full_frame(app, width, quiet_ms=1500, timeout_s=300):
    """Until a frame of the whole view at ``width`` CSS pixels, drawn after this call, is shown and the view is still."""
    area = app.three_d_area()
    since = app.page.evaluate("() => performance.timeOrigin + performance.now()")
    app.wait_for(f"""async () => {{ await window.trame.trigger('vc_diagnostics');
                     const f = (window.__vcTiming?.frames || []).filter(f => f.name === '{area}');
                     const last = f.length ? f[f.length - 1] : null;
                     return !!last && Math.abs(last.w - {width}) <= 8 && last.arrived > {since} && last.shown > 0 &&
                            performance.timeOrigin + performance.now() - last.arrived > {quiet_ms}; }}""",
                 timeout_s, f"a still frame of the whole view at {width:.0f} px")


def _save(pixels, path):
    from PIL import Image

    Image.fromarray(pixels).save(path)


def test_the_release_frame_is_the_still_render(started, shots):
    """The image the view rests on after the drag is a still render: the same camera redrawn from nothing gives it."""
    app, _, _ = started
    rested = app.three_d_pixels()
    viewport = app.page.viewport_size
    # Another size, then back: the main window casts every pixel again at the same camera.
    for width in (viewport["width"] - 400, viewport["width"]):
        app.page.set_viewport_size({"width": width, "height": viewport["height"]})
        wait_for_full_frame(app, app.three_d_box()["width"])
    redrawn = app.three_d_pixels()
    _save(redrawn, shots / "camera-drag-still-render.png")
    assert redrawn.shape == rested.shape
    difference = np.abs(redrawn.astype(int) - rested.astype(int)).max(axis=2)
    print(f"\nrelease frame against the still render: mean {difference.mean():.3f}, "
          f"{np.mean(difference > 6) * 100:.2f} % of pixels off by more than 6")
    assert difference.mean() < 0.5 and np.mean(difference > 6) < 0.002
    # Not a blank image that would match anything: the CT fills a good part of the view.
    assert black_share(rested) < 0.5 and rested.std() > 20
