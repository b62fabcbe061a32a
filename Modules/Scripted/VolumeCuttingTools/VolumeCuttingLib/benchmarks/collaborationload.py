"""Part of the benchmark area ``collaboration``: several sessions at once through the launcher (issue 27, part 4).

wslink's launcher (``VolumeCuttingLib.webapp.launcher``, one application
process per user) serves the temporal-bone phantom on 127.0.0.1. Debian's
Chromium (Playwright) opens one trainee page first; it drills alone (the
baseline, same run). Then five more trainee pages open through the
launcher (six session processes) and two instructor pages join two of
them with the link their trainee's page shows. All six trainees drill at
once: the same scripted drag in every page, the mouse moved in each page
in turn, one move per page every 16 ms.

Drilling latency is *mouse to image*: from each mouse event in the page to
the first 3D frame shown in that page that the server began drawing after
it had applied that event (``benchmarks.webapp.event_latencies``; p95 per
session). Memory is each session process's resident set (``VmRSS`` in
``/proc/PID/status``) after the drilling, the baseline the lone session's
after its own.
"""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from ..webapp.browser import AppPage, BrowserTestError, free_port, launch_chromium
from .harness import machine_description, measurement
from .webapp import MOUSE_PERIOD_MS, _stats, drag_path, event_latencies

TRAINEES = 6
INSTRUCTORS = 2
VIEWPORT = {"width": 1280, "height": 800}
DRILL_EVENTS = 40  # short: six sessions share two cores here


def resident_mb(pid: int) -> float:
    """Resident set of process ``pid`` (MB), from /proc."""
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024.0
    raise RuntimeError(f"/proc/{pid}/status has no VmRSS")


def session_processes(launcher_pid: int) -> dict[int, int]:
    """The launcher's application processes by the port they serve: {port: pid}."""
    found = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            parent = int(stat.read_text().rsplit(")", 1)[1].split()[1])
            command = (stat.parent / "cmdline").read_bytes().split(b"\0")
        except (OSError, ValueError, IndexError):
            continue
        if parent == launcher_pid and b"--port" in command:
            found[int(command[command.index(b"--port") + 1])] = int(stat.parent.name)
    return found


class Launcher:
    """``python -m VolumeCuttingLib.webapp.launcher`` on a free port, serving ``sessions`` users on the phantom."""

    def __init__(self, sessions: int, folder: Path):
        self.port = free_port()  # the sessions take the next ports; hoped free, as in the browser test
        self.folder = folder
        library = str(Path(__file__).resolve().parents[2])
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in (library, os.environ.get("PYTHONPATH", "")) if p))
        env.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
        self.log = open(folder / "launcher.log", "w")
        self.process = subprocess.Popen([sys.executable, "-m", "VolumeCuttingLib.webapp.launcher", "--port", str(self.port),
                                         "--sessions", str(sessions), "--start-timeout", "600", "--folder", str(folder / "launcher"), "--", "--phantom"],
                                        stdout=self.log, stderr=subprocess.STDOUT, env=env)
        deadline = time.monotonic() + 120
        while True:
            try:
                socket.create_connection(("127.0.0.1", self.port), timeout=0.5).close()
                return
            except OSError:
                if self.process.poll() is not None or time.monotonic() > deadline:
                    self.stop()
                    raise BrowserTestError(f"The launcher did not start; see {folder / 'launcher.log'}")
                time.sleep(0.2)

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.port}/"

    def stop(self) -> None:
        sessions = list(session_processes(self.process.pid).values())
        self.process.terminate()
        try:
            self.process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.process.kill()
        for pid in sessions:  # they would end at their own timeout once their page is gone
            try:
                os.kill(pid, signal.SIGTERM)
            except ProcessLookupError:
                pass
        self.log.close()


def open_page(browser, url: str) -> AppPage:
    page = browser.new_context(viewport=VIEWPORT, device_scale_factor=1).new_page()
    page.set_default_timeout(300000)
    app = AppPage(page, timing=True)
    app.open(url, 300)
    return app


def session_port(app: AppPage) -> int:
    url = app.page.evaluate("() => window.trame.client.getConfig().sessionURL")
    return int(url.split("://", 1)[1].split("/", 1)[0].rsplit(":", 1)[1])


def drill_together(trainees: list[AppPage], run_index: int) -> list[list[float]]:
    """The same drag in every page at once (one mouse move per page in turn, every 16 ms); mouse-to-image latencies."""
    paths, boxes, areas, starts = [], [], [], []
    for app in trainees:
        box = app.three_d_box()
        boxes.append(box)
        areas.append(app.three_d_area())
        paths.append(drag_path(box, DRILL_EVENTS, start=(0.38, 0.30 + 0.12 * (run_index % 4)), step=(1.6, 0.2)))
        app.page.mouse.move(*paths[-1][0])
    for app in trainees:
        app.wait_refined(1000, 600)
    for app, path in zip(trainees, paths):
        starts.append(app.page.evaluate("() => Date.now()"))
        app.page.mouse.down()
    for step in range(1, DRILL_EVENTS):
        trainees[0].page.wait_for_timeout(MOUSE_PERIOD_MS)
        for app, path in zip(trainees, paths):
            app.page.mouse.move(*path[step])
    for app in trainees:
        app.page.mouse.up()
    latencies = []
    for app, box, area, start in zip(trainees, boxes, areas, starts):
        app.wait_refined(1500, 600)
        server = app.server_timing()
        page = app.timing()
        frames = [f for f in page["frames"] if f["name"] == area]
        events = [e for e in server["events"] if len(e) == 5]
        latencies.append(event_latencies(page["mouse"], events, server["renders"], frames, box, start))
    return latencies


def run(repeats: int, out_dir: Path | None = None) -> dict:
    from playwright.sync_api import sync_playwright

    out_dir = Path(out_dir or tempfile.mkdtemp(prefix="volumecutting-load-bench-"))
    result = {"out_dir": str(out_dir)}
    launcher = Launcher(TRAINEES, out_dir)
    try:
        with sync_playwright() as playwright:
            browser = launch_chromium(playwright)
            alone = open_page(browser, launcher.url)
            alone.wait_ready(600)
            alone.set_mode("drill", 120)
            lone = []
            for run_index in range(repeats):
                lone += drill_together([alone], run_index)[0]
            processes = session_processes(launcher.process.pid)
            result["alone"] = {"latency_ms": lone, "rss_mb": resident_mb(processes[session_port(alone)]),
                               "removed_mm3": alone.total_removed()}

            # One after the other: six loading the phantom at once on two cores outlast any sensible start time.
            trainees = [alone]
            for _ in range(TRAINEES - 1):
                trainees.append(open_page(browser, launcher.url))
                trainees[-1].wait_ready(600)
            ports = [session_port(app) for app in trainees]
            if len(set(ports)) != TRAINEES:
                raise RuntimeError(f"The launcher gave {len(set(ports))} sessions to {TRAINEES} pages: {ports}")
            instructors = []
            for app in trainees[:INSTRUCTORS]:
                link = app.page.locator('[data-testid="instructor-link"] input').input_value()
                instructors.append(open_page(browser, link))
            for app in instructors:
                app.wait_ready(600)
            for app in trainees[1:]:
                app.set_mode("drill", 300)
            together = [[] for _ in trainees]
            for run_index in range(repeats):
                for pooled, latencies in zip(together, drill_together(trainees, run_index + 1)):
                    pooled += latencies
            for app in instructors:
                app.wait_still(1000, 300)
            processes = session_processes(launcher.process.pid)
            result["sessions"] = [{"port": port, "pid": processes[port], "rss_mb": resident_mb(processes[port]),
                                   "latency_ms": latencies, "instructor": index < INSTRUCTORS,
                                   "removed_mm3": app.total_removed()}
                                  for index, (app, port, latencies) in enumerate(zip(trainees, ports, together))]
            result["instructor_removed_mm3"] = [app.total_removed() for app in instructors]
            result["processes_under_launcher"] = len(processes)
            trainees[0].screenshot(out_dir / "trainee-1.png")
            instructors[0].screenshot(out_dir / "instructor-1.png")
            trainees[-1].screenshot(out_dir / f"trainee-{TRAINEES}.png")
            browser.close()
    finally:
        launcher.stop()
    return result


def load_measurements(repeats: int) -> list[dict]:
    """The load test's part of the ``collaboration`` area: per session, drilling p95 (mouse to image) and memory."""
    machine = machine_description("llvmpipe (server-side, offscreen EGL) in each of 6 session processes; "
                                  "8 Chromium pages on this machine")
    machine["cores_shared"] = True
    repeats = max(1, repeats)
    load_before = os.getloadavg()
    started = time.time()
    result = run(repeats)
    alone = result["alone"]
    alone_p95 = _stats(alone["latency_ms"]).get("p95")
    if alone_p95 is None:
        raise RuntimeError(f"The lone session's drilling showed no frame; see {result['out_dir']}")
    entries = []
    for number, session in enumerate(result["sessions"], 1):
        watched = ", instructor watching" if session["instructor"] else ""
        stats = _stats(session["latency_ms"])
        entries.append(measurement(
            f"load: session {number} of {TRAINEES}{watched}, drilling mouse to image p95, "
            f"{TRAINEES} trainees + {INSTRUCTORS} instructors (ms)",
            stats.get("p95"), "ms", "one session alone, drilling mouse to image p95 (ms)", alone_p95,
            stats["count"], machine))
        entries.append(measurement(
            f"load: session {number} of {TRAINEES}{watched}, process resident memory after drilling (MB)",
            round(session["rss_mb"], 1), "MB", "one session alone, resident memory after its drilling (MB)",
            round(alone["rss_mb"], 1), repeats, machine))
    details = {"latency": "mouse to image: each mouse event in the page to the first 3D frame shown there that the server "
                          "began drawing after applying the event",
               "alone_latency_ms": _stats(alone["latency_ms"]),
               "sessions": [{"port": s["port"], "instructor": s["instructor"], "latency_ms": _stats(s["latency_ms"]),
                             "rss_mb": round(s["rss_mb"], 1), "removed_mm3": s["removed_mm3"]} for s in result["sessions"]],
               "alone_removed_mm3": alone["removed_mm3"], "instructor_pages_removed_mm3": result["instructor_removed_mm3"],
               "drilling_runs": repeats, "mouse_events_per_run": DRILL_EVENTS,
               "wall_s": round(time.time() - started, 1),
               "load_average_before_after": [round(v, 2) for v in load_before + os.getloadavg()]}
    for entry in entries:
        entry["details"] = details
    return entries
