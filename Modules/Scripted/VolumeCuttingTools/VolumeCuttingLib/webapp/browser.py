"""Driving the web application from a real browser (Playwright with Debian's Chromium), as a person would.

Shared by the browser tests and the ``webapp`` benchmark area:

* ``AppServer``: the application in a process of its own on 127.0.0.1 and a
  free port, started and stopped with time limits;
* ``launch_chromium``: Debian's Chromium through Playwright (no browser
  download);
* ``AppPage``: the page: wait until the CT is shown, switch modes, drag in
  the 3D view, read the segments table and the 3D view's pixels, download
  exports; and, for timing, the time each frame of the 3D view reached the
  page (``TIMING_HOOK``);
* ``SoundPage``: the page's drill sound (AudioWorklet) alone, rendered
  offline or timed live;
* ``opened_app_page`` and ``screenshot_folder``: the set-up every browser
  test shares (a desktop-sized page, ready; where its pictures go).

Every wait has a time limit and says what it waited for when it runs out.
"""

from __future__ import annotations

import io
import os
import shutil
import socket
import subprocess
import sys
import time
from contextlib import closing, contextmanager
from pathlib import Path

import numpy as np

CHROMIUM_CANDIDATES = ("/usr/bin/chromium", "/usr/bin/chromium-browser")
DESKTOP_VIEWPORT = {"width": 1440, "height": 900}

# Records, in the page, when each frame of each view arrived and was ready to
# show (decoded, at the next animation frame), with the server's encoding
# time (meta.st, ms since the epoch), and every mouse event with its time
# (also ms since the epoch: same clock as the server's on this machine).
TIMING_HOOK = """
(() => {
  const vc = (window.__vcTiming = { frames: [], mouse: [] });
  const now = () => performance.timeOrigin + performance.now();
  const pending = new Map(); // object URL of a frame's image -> its record
  let lastUrl = null;
  const createObjectURL = URL.createObjectURL.bind(URL);
  URL.createObjectURL = (blob) => { lastUrl = createObjectURL(blob); return lastUrl; };
  for (const type of ["mousedown", "mousemove", "mouseup", "wheel"]) {
    document.addEventListener(type, (e) => vc.mouse.push({ type, t: performance.timeOrigin + e.timeStamp,
      x: e.clientX, y: e.clientY, buttons: e.buttons }), true);
  }
  // A frame is shown when an image element takes its URL (the viewer swaps images once one has loaded).
  const displayed = new Map(); // object URL -> time it was ready on screen
  function showing(url, time) {
    const record = pending.get(url);
    if (record) { record.shown = time; pending.delete(url); } else { displayed.set(url, time); }
  }
  new MutationObserver((mutations) => {
    for (const m of mutations) {
      if (m.target.tagName !== "IMG") continue;
      const url = m.target.getAttribute("src");
      const done = () => requestAnimationFrame(() => showing(url, now()));
      m.target.decode().then(done, done);
    }
  }).observe(document, { subtree: true, attributes: true, attributeFilter: ["src"] });
  function hook() {
    const t = window.trame;
    const connection = t && t.client && t.client.getConnection && t.client.getConnection();
    const session = connection && connection.getSession && connection.getSession();
    if (!session) { setTimeout(hook, 20); return; }
    session.subscribe("trame.rca.topic.stream", ([message]) => {
      const record = { name: message.name, st: message.meta.st, w: message.meta.w, h: message.meta.h,
                       arrived: now(), shown: null };
      vc.frames.push(record);
      const before = lastUrl;
      // The viewer's own handler makes the image's object URL in the same dispatch, before or after this one.
      queueMicrotask(() => {
        if (!lastUrl || lastUrl === before) return;
        if (displayed.has(lastUrl)) { record.shown = displayed.get(lastUrl); displayed.delete(lastUrl); }
        else pending.set(lastUrl, record);
      });
    });
  }
  hook();
})();
"""


class BrowserTestError(RuntimeError):
    """A wait in the page ran out or the application did not start; the message says what was awaited."""


def free_port() -> int:
    with closing(socket.socket(socket.AF_INET, socket.SOCK_STREAM)) as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def chromium_executable() -> str:
    """Debian's Chromium (``apt-get install chromium``; Utilities/vc setup installs it)."""
    explicit = os.environ.get("VOLUMECUTTING_CHROMIUM")
    for candidate in ([explicit] if explicit else []) + list(CHROMIUM_CANDIDATES):
        if candidate and Path(candidate).is_file():
            return candidate
    found = shutil.which("chromium")
    if found:
        return found
    raise BrowserTestError("Chromium is not installed: run Utilities/vc setup (it installs Debian's chromium), "
                           "or set VOLUMECUTTING_CHROMIUM to a Chromium executable")


def launch_chromium(playwright, **options):
    return playwright.chromium.launch(executable_path=chromium_executable(), args=["--no-sandbox"], **options)


class AppServer:
    """``python -m VolumeCuttingLib.webapp`` on 127.0.0.1 and a free port, as a context manager.

    ``args`` are the application's options (``--phantom``, ...); its output
    goes to ``log_path``. ``started_at`` is the ``time.time()`` of the
    launch, for start-up timings.
    """

    def __init__(self, *args, log_path: str | Path, port: int | None = None, start_timeout_s: float = 90.0, env=None):
        self.args = [str(a) for a in args]
        self.port = port or free_port()
        self.log_path = Path(log_path)
        self.start_timeout_s = start_timeout_s
        self.env = dict(os.environ, **(env or {}))
        self.env.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
        # The server runs the same VolumeCuttingLib as the caller (the installed one, or a source tree).
        library_root = str(Path(__file__).resolve().parents[2])
        self.env["PYTHONPATH"] = os.pathsep.join(p for p in (library_root, self.env.get("PYTHONPATH", "")) if p)
        self.process = None
        self.started_at = None

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.port}/"

    def __enter__(self) -> AppServer:
        self.start()
        return self

    def __exit__(self, *exc) -> None:
        self.stop()

    def start(self) -> None:
        self.log_path.parent.mkdir(parents=True, exist_ok=True)
        log = open(self.log_path, "w")
        self.started_at = time.time()
        self.process = subprocess.Popen(
            [sys.executable, "-m", "VolumeCuttingLib.webapp", "--host", "127.0.0.1", "--port", str(self.port), "--server",
             *self.args], stdout=log, stderr=subprocess.STDOUT, env=self.env)
        log.close()
        deadline = time.monotonic() + self.start_timeout_s
        while time.monotonic() < deadline:
            if self.process.poll() is not None:
                raise BrowserTestError(f"The application exited with {self.process.returncode} while starting; "
                                       f"its log:\n{self.log_tail()}")
            try:
                with socket.create_connection(("127.0.0.1", self.port), timeout=0.5):
                    return
            except OSError:
                time.sleep(0.1)
        self.stop()
        raise BrowserTestError(f"The application did not listen on port {self.port} within {self.start_timeout_s:.0f} s; "
                               f"its log:\n{self.log_tail()}")

    def stop(self) -> None:
        if self.process is None or self.process.poll() is not None:
            return
        self.process.terminate()
        try:
            self.process.wait(timeout=15)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait(timeout=120)  # a loaded machine takes a while to unmap a large scan

    def log_tail(self, lines: int = 40) -> str:
        try:
            return "\n".join(self.log_path.read_text(errors="replace").splitlines()[-lines:])
        except OSError:
            return "(no log)"


class AppPage:
    """The application's page in a Playwright ``page``."""

    def __init__(self, page, timing: bool = False):
        self.page = page
        if timing:
            page.add_init_script(TIMING_HOOK)

    def open(self, url: str, timeout_s: float = 60.0) -> None:
        self.page.goto(url, timeout=timeout_s * 1000)

    def testid(self, name: str):
        return self.page.locator(f'[data-testid="{name}"]')

    def wait_ready(self, timeout_s: float = 60.0) -> None:
        """Until data is loaded (nothing loading) and the 3D view shows an image."""
        self.wait_for("() => { const s = window.trame?.state; return !!s && !s.get('vc_busy') && !!s.get('vc_description'); }",
                      timeout_s, "the data to be loaded")
        self.wait_for_view_image(timeout_s)

    def wait_for_view_image(self, timeout_s: float = 60.0) -> None:
        box = self.three_d_box()
        script = """([x, y]) => { const image = document.elementsFromPoint(x, y).find(e => e.tagName === 'IMG');
                                   return image && image.complete && image.naturalWidth > 16; }"""
        self.page.wait_for_function(script, arg=[box["x"] + box["width"] / 2, box["y"] + box["height"] / 2],
                                    timeout=timeout_s * 1000)

    def three_d_box(self) -> dict:
        box = self.testid("three-d-view").bounding_box()
        if box is None:
            raise BrowserTestError("The 3D view is not on the page")
        return box

    def set_mode(self, mode: str, timeout_s: float = 60.0) -> None:
        """Click a mode button and wait until the server drills (or navigates) in that mode."""
        self.testid(f"mode-{mode}").click()
        self.wait_for(f"async () => (await window.trame.trigger('vc_diagnostics')).mode === '{mode}'", timeout_s,
                      f"the server to switch to {mode} mode")

    def drag(self, points, step_delay_ms: float = 16.0, shift: bool = False) -> None:
        """Press at the first point (page pixels), move through the others, release at the last."""
        mouse = self.page.mouse
        mouse.move(*points[0])
        if shift:
            self.page.keyboard.down("Shift")
        mouse.down()
        for x, y in points[1:]:
            self.page.wait_for_timeout(step_delay_ms)
            mouse.move(x, y)
        mouse.up()
        if shift:
            self.page.keyboard.up("Shift")

    def removed_volume(self, segment_id: str) -> float:
        return float(self.page.locator(f'[data-removed-of="{segment_id}"]').inner_text())

    def total_removed(self) -> float:
        text = self.testid("total-removed").inner_text()
        return float(text.split(":")[1].split()[0])

    def wait_for(self, script: str, timeout_s: float = 30.0, what: str = "", arg=None):
        """Until the function ``script`` returns a truthy value; a function that returns a promise is awaited.

        Playwright's wait_for_function takes a pending promise for a truthy answer, so an ``async`` predicate
        (a trigger asking the server) returned at once: polled here with evaluate, which awaits it.
        """
        deadline = time.monotonic() + timeout_s
        while True:
            try:
                # Only truthiness crosses back: a predicate may return a DOM element, which does not serialize.
                value = self.page.evaluate(f"async (arg) => !!(await ({script})(arg))", arg)
            except Exception as error:  # the page navigating, a script error: report it with what was awaited
                raise BrowserTestError(f"Waiting for {what or script}: {error}") from error
            if value:
                return value
            if time.monotonic() > deadline:
                raise BrowserTestError(f"Waited {timeout_s:.0f} s for {what or script}")
            self.page.wait_for_timeout(50)

    def wait_for_total_removed(self, predicate: str, timeout_s: float = 30.0) -> float:
        """Until the total removed volume (mm3, a number ``v``) satisfies ``predicate`` (JavaScript, e.g. 'v > 0')."""
        script = f"""() => {{ const t = document.querySelector('[data-testid=total-removed]')?.textContent;
                             if (!t) return false; const v = parseFloat(t.split(':')[1]); return {predicate}; }}"""
        self.wait_for(script, timeout_s, f"the total removed volume to satisfy {predicate}")
        return self.total_removed()

    def wait_still(self, quiet_ms: float = 800.0, timeout_s: float = 30.0) -> None:
        """Until the server is idle and no frame arrived for ``quiet_ms`` (needs the timing hook).

        A trigger is answered only between two frames, so answering one means
        the server is not in the middle of drawing.
        """
        deadline = time.monotonic() + timeout_s
        script = f"""async () => {{ await window.trame.trigger('vc_diagnostics');
                             const f = (window.__vcTiming?.frames || []);
                             const last = f.length ? f[f.length - 1].arrived : 0;
                             return performance.timeOrigin + performance.now() - last > {quiet_ms}; }}"""
        while time.monotonic() < deadline:
            if self.page.evaluate(script):
                return
            self.page.wait_for_timeout(min(quiet_ms, 500))
        raise BrowserTestError(f"The 3D view kept changing for {timeout_s:.0f} s")

    def wait_refined(self, quiet_ms: float = 1000.0, timeout_s: float = 60.0) -> None:
        """Until the 3D view shows a full-resolution frame and stays still (needs the timing hook)."""
        area = self.three_d_area()
        width = self.three_d_box()["width"]
        deadline = time.monotonic() + timeout_s
        script = f"""async () => {{ await window.trame.trigger('vc_diagnostics');
                             const f = (window.__vcTiming?.frames || []).filter(f => f.name === '{area}');
                             const last = f.length ? f[f.length - 1] : null;
                             return !!last && last.w >= {0.9 * width} && last.shown > 0 &&
                                    performance.timeOrigin + performance.now() - last.arrived > {quiet_ms}; }}"""
        while time.monotonic() < deadline:
            if self.page.evaluate(script):
                return
            self.page.wait_for_timeout(200)
        raise BrowserTestError(f"The 3D view did not come to rest at full resolution within {timeout_s:.0f} s")

    def settle(self, quiet_ms: float = 1000.0, timeout_s: float = 30.0) -> None:
        """Until the 3D view's image stayed the same for ``quiet_ms`` (no timing hook needed)."""
        deadline = time.monotonic() + timeout_s
        previous = None
        stable_since = time.monotonic()
        while time.monotonic() < deadline:
            pixels = self.three_d_pixels()
            if previous is None or pixels.shape != previous.shape or np.any(pixels != previous):
                previous = pixels
                stable_since = time.monotonic()
            elif (time.monotonic() - stable_since) * 1000.0 >= quiet_ms:
                return
            self.page.wait_for_timeout(150)
        raise BrowserTestError(f"The 3D view kept changing for {timeout_s:.0f} s")

    def three_d_pixels(self) -> np.ndarray:
        """The 3D view as the page shows it: (height, width, 3) uint8."""
        from PIL import Image

        box = self.three_d_box()
        png = self.page.screenshot(clip=box)
        return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"))

    def screenshot(self, path: str | Path) -> Path:
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        self.page.screenshot(path=str(path))
        return path

    def download(self, testid: str, folder: str | Path, timeout_s: float = 60.0) -> Path:
        """Click an export button and save the file the browser downloads."""
        with self.page.expect_download(timeout=timeout_s * 1000) as info:
            self.testid(testid).click()
        download = info.value
        target = Path(folder) / download.suggested_filename
        download.save_as(str(target))
        return target

    def timing(self) -> dict:
        return self.page.evaluate("() => window.__vcTiming")

    def server_timing(self) -> dict:
        return self.page.evaluate("() => window.trame.trigger('vc_diagnostics')")

    def three_d_area(self) -> str:
        return self.page.evaluate("() => window.trame.state.get('vc_three_d_area')")

    def fit_three_d_view(self, width: int, height: int, attempts: int = 4) -> dict:
        """Resize the browser window until the 3D view is ``width`` x ``height`` CSS pixels (device scale 1).

        The 3D view takes 3/4 of the width beside the panels and its full height below the toolbar.
        """
        box = self.three_d_box()
        for _ in range(attempts):
            if round(box["width"]) == width and round(box["height"]) == height:
                break
            viewport = self.page.viewport_size
            self.page.set_viewport_size({"width": viewport["width"] + round((width - box["width"]) * 4 / 3),
                                         "height": viewport["height"] + round(height - box["height"])})
            self.page.wait_for_timeout(500)
            box = self.three_d_box()
        return box


class SoundPage:
    """The page's drill sound alone: the application's ``www`` folder served over HTTP on 127.0.0.1 (the
    same files the application serves) and a page with nothing but ``drillsound.js`` in ``browser``.

    ``render`` renders the AudioWorklet in an OfflineAudioContext; ``measure_latency`` times parameter
    changes to the changed sound in a live AudioContext, started by a click (the user's gesture).
    """

    PAGE = b'<html><body><button id="start">start</button><script src="drillsound.js"></script></body></html>'

    def __init__(self, browser):
        self.browser = browser
        self.server = None
        self.context = None
        self.page = None

    def __enter__(self) -> SoundPage:
        import functools
        import http.server
        import threading

        page_html = self.PAGE

        class Handler(http.server.SimpleHTTPRequestHandler):
            def do_GET(self):
                if self.path.startswith("/sound-test.html"):
                    self.send_response(200)
                    self.send_header("Content-Type", "text/html")
                    self.send_header("Content-Length", str(len(page_html)))
                    self.end_headers()
                    self.wfile.write(page_html)
                else:
                    super().do_GET()

            def log_message(self, *args):
                pass

        www = Path(__file__).with_name("www")
        self.server = http.server.ThreadingHTTPServer(("127.0.0.1", free_port()), functools.partial(Handler, directory=str(www)))
        threading.Thread(target=self.server.serve_forever, daemon=True).start()
        self.context = self.browser.new_context()
        self.page = self.context.new_page()
        self.page.goto(f"http://127.0.0.1:{self.server.server_address[1]}/sound-test.html")
        self.page.wait_for_function("() => !!window.vcDrillSound", timeout=30000)
        return self

    def __exit__(self, *exc) -> None:
        if self.context is not None:
            self.context.close()
        if self.server is not None:
            self.server.shutdown()
            self.server.server_close()

    def render(self, schedule, seconds: float, config: dict | None = None) -> np.ndarray:
        """Samples of the worklet for ``schedule`` ([(time_s, parameters dict)]) from a steady start."""
        samples = self.page.evaluate("([s, n, c]) => window.vcDrillSound.renderOffline(s, n, c)",
                                     [[[t, p] for t, p in schedule], seconds, config])
        return np.array(samples)

    def start(self, volume: float = 1.0) -> bool:
        self.page.evaluate("""(volume) => { document.getElementById('start').onclick = () => {
            window.soundStarted = window.vcDrillSound.start(volume); }; }""", volume)
        self.page.click("#start")
        return bool(self.page.evaluate("() => window.soundStarted"))

    def measure_latency(self, before: dict, after: dict, trials: int = 20) -> list[dict]:
        """Per change: latencyMs (page change to the changed sound at the output), outputLatencyMs, viaTimestamp."""
        if not self.start():
            raise BrowserTestError(f"The page's sound did not start: {self.page.evaluate('() => window.vcDrillSound.message')}")
        try:
            return self.page.evaluate("([a, b, n]) => window.vcDrillSound.measureLatency(a, b, n)", [before, after, trials])
        finally:
            self.page.evaluate("() => window.vcDrillSound.stop()")


def screenshot_folder(tmp_path_factory, name: str) -> Path:
    """Where a browser test's screenshots go: ``$VOLUMECUTTING_SCREENSHOTS`` (Docs/webapp's pictures) or a new
    temporary folder ``name`` from pytest's ``tmp_path_factory``."""
    folder = os.environ.get("VOLUMECUTTING_SCREENSHOTS")
    path = Path(folder) if folder else tmp_path_factory.mktemp(name)
    path.mkdir(parents=True, exist_ok=True)
    return path


@contextmanager
def opened_app_page(browser, url: str, timing: bool = False, still_ms: float | None = None, downloads: bool = False,
                    viewport: dict | None = None, timeout_s: float = 300.0):
    """A page of the application at ``url`` in a browser context of its own, once its data is shown (and, with
    ``still_ms``, the 3D view stayed still that long); the context is closed on leaving."""
    context = browser.new_context(viewport=viewport or DESKTOP_VIEWPORT, device_scale_factor=1,
                                  accept_downloads=downloads)
    try:
        page = context.new_page()
        page.set_default_timeout(60000)
        app = AppPage(page, timing=timing)
        app.open(url, timeout_s)  # a large scan is read before the page is served
        app.wait_ready(timeout_s)
        if still_ms is not None:
            app.wait_still(still_ms, timeout_s)
        yield app
    finally:
        context.close()
