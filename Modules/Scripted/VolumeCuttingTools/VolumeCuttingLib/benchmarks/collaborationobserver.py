"""Part of the benchmark area ``collaboration``: how long after the trainee's page the instructor's page shows a frame.

The application serves the temporal-bone phantom on 127.0.0.1; Debian's
Chromium (Playwright) opens the trainee's page and, with the instructor
link the trainee's page shows, the instructor's, each in its own browser
context, both views the same size. The trainee drills (press and drag
across the bone in Drill mode, a mouse event every 16 ms) ``repeats`` times.
Every frame of the 3D view carries the server's encoding time (``st``); both
pages log when each frame arrived and when it could be shown (decoded, at
the next animation frame), on the same clock (one browser on one machine).
For every 3D frame the trainee's page showed during the drilling, the
observer delay is the time the instructor's page showed the same frame
(same view, same ``st``) minus the time the trainee's page did (p50, p95,
max), with the frames the instructor's page never got counted apart.

Baseline (same runs): the trainee's own delay from the server's encoding of
a frame to its page showing it.
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

from ..webapp.browser import AppPage, AppServer, launch_chromium
from .harness import machine_description, measurement
from .webapp import MOUSE_PERIOD_MS, _stats, drag_path

VIEWPORT = {"width": 1280, "height": 800}
DRILL_EVENTS = 90


def observer_delays(trainee_frames, observer_frames, area: str, since_ms: float) -> dict:
    """Delays (ms) of the observer's frames after the trainee's, matched by view and server time."""
    seen = {(f["name"], f["st"]): f for f in observer_frames}
    shown, arrived, own, missed = [], [], [], 0
    for frame in trainee_frames:
        if frame["name"] != area or frame["st"] < since_ms or not frame.get("shown"):
            continue
        own.append(frame["shown"] - frame["st"])
        match = seen.get((frame["name"], frame["st"]))
        if match is None or not match.get("shown"):
            missed += 1
            continue
        shown.append(match["shown"] - frame["shown"])
        arrived.append(match["arrived"] - frame["arrived"])
    return {"shown": shown, "arrived": arrived, "trainee_own": own, "missed": missed}


def run(repeats: int, out_dir: Path | None = None) -> dict:
    from playwright.sync_api import sync_playwright

    out_dir = Path(out_dir or tempfile.mkdtemp(prefix="volumecutting-observer-bench-"))
    pooled = {"shown": [], "arrived": [], "trainee_own": [], "missed": 0}
    with AppServer("--phantom", log_path=out_dir / "server.log") as server, sync_playwright() as playwright:
        browser = launch_chromium(playwright)
        pages = []
        for _ in range(2):
            context = browser.new_context(viewport=VIEWPORT, device_scale_factor=1)
            page = context.new_page()
            page.set_default_timeout(120000)
            pages.append(AppPage(page, timing=True))
        trainee, instructor = pages
        trainee.open(server.url)
        trainee.wait_ready(300)
        link = trainee.page.locator('[data-testid="instructor-link"] input').input_value()
        instructor.open(link)
        instructor.wait_ready(120)
        trainee.set_mode("drill")
        area = trainee.three_d_area()
        box = trainee.three_d_box()
        for run_index in range(repeats):
            path = drag_path(box, DRILL_EVENTS, start=(0.38, 0.30 + 0.12 * (run_index % 4)), step=(1.6, 0.2))
            trainee.page.mouse.move(*path[0])
            trainee.wait_refined(1000, 300)
            start = trainee.page.evaluate("() => Date.now()")
            trainee.drag(path, MOUSE_PERIOD_MS)
            trainee.wait_refined(1500, 300)
            instructor.wait_still(1000, 120)
            delays = observer_delays(trainee.timing()["frames"], instructor.timing()["frames"], area, start)
            for key in ("shown", "arrived", "trainee_own"):
                pooled[key] += delays[key]
            pooled["missed"] += delays["missed"]
        pooled["removed_mm3"] = trainee.total_removed()
        pooled["instructor_removed_mm3"] = instructor.total_removed()
        trainee.screenshot(out_dir / "trainee.png")
        instructor.screenshot(out_dir / "instructor.png")
        browser.close()
    pooled["out_dir"] = str(out_dir)
    return pooled


def observer_measurements(repeats: int) -> list[dict]:
    """The instructor link's part of the ``collaboration`` area: ``repeats`` drilling runs (at least one), every 3D frame a sample."""
    machine = machine_description("llvmpipe (server-side, offscreen EGL); two Chromium pages on this machine")
    machine["cores_shared"] = True
    load_before = os.getloadavg()
    started = time.time()
    result = run(max(1, repeats))
    load_after = os.getloadavg()
    if not result["shown"]:
        raise RuntimeError(f"The instructor's page showed none of the trainee's 3D frames ({result['missed']} missed); "
                           f"see {result['out_dir']}/server.log")
    shown, arrived, own = _stats(result["shown"]), _stats(result["arrived"]), _stats(result["trainee_own"])
    entries = []
    for statistic in ("median", "p95", "max"):
        entries.append(measurement(f"observer: instructor's page shows a 3D frame after the trainee's, {statistic} (ms)",
                                   shown.get(statistic), "ms",
                                   f"trainee: server encoding to the frame shown in the page, {statistic} (ms)",
                                   own.get(statistic), shown["count"], machine))
    details = {"observer_shown_after_trainee_ms": shown, "observer_arrived_after_trainee_ms": arrived,
               "trainee_encoding_to_shown_ms": own, "frames_missed_by_observer": result["missed"],
               "drilling_runs": max(1, repeats), "mouse_events_per_run": DRILL_EVENTS,
               "removed_mm3": {"trainee_page": result["removed_mm3"], "instructor_page": result["instructor_removed_mm3"]},
               "wall_s": round(time.time() - started, 1),
               "load_average_before_after": [round(v, 2) for v in load_before + load_after]}
    for entry in entries:
        entry["details"] = details
    return entries
