"""Benchmark area ``webapp``: the web application timed from the browser.

The application serves the real head CT on this machine (127.0.0.1); Debian's
Chromium, driven by Playwright, opens it with the 3D view at 1024 x 768 CSS
pixels (device scale 1) and measures, in the page:

* start-up: from launching the server process to the page saying Ready, to
  the first image of the CT in the 3D view (and from Ready to it), and to
  the first full-resolution one;
* drilling: press and drag across the bone in Drill mode, one mouse event
  every 16 ms (a 60 Hz mouse); for every mouse event, the time from the
  browser dispatching it to the page showing the first 3D frame that
  includes it (first, median, p95, max);
* navigation: a camera drag the same way (interactive frames: the preview
  window at the navigation scale, the ray caster casting as many rays as
  fit in the navigation frame rate), the server's cost of those frames and
  of the still full-resolution frame the view rests on, and the time from
  releasing the mouse to the full-resolution image.

A frame includes a mouse event when the server began drawing it after it had
applied that event: the server logs when it applied each event and when
each window began to draw; the page logs when each frame arrived, was
decoded and could be shown, with the server's encoding time, on the same
clock. The browser's mouse events are matched to the server's by position
(trame-rca sends one event at a time and merges the moves that wait, so one
server event can stand for several).

Baseline (same run, right after): hovering with the drill, which moves the
tool's glyph over the bone without cutting (the same path through the
server, the renderer's cached image, the encoder and the page, without
the ray casting a cut needs).
"""

from __future__ import annotations

import bisect
import json
import os
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from ..webapp.browser import AppPage, AppServer, launch_chromium
from .harness import machine_description, measurement

VIEW_SIZE = (1024, 768)
MOUSE_PERIOD_MS = 16.0
DRILL_EVENTS = 120


def _stats(values) -> dict:
    values = [float(v) for v in values]
    if not values:
        return {"count": 0}
    return {"count": len(values), "first": round(values[0], 1), "median": round(statistics.median(values), 1),
            "p95": round(float(np.percentile(values, 95)), 1), "max": round(max(values), 1)}


def event_latencies(mouse, server_events, renders, frames, box, start_ms: float) -> list[float]:
    """Milliseconds from each browser mouse event after ``start_ms`` (pressed: drag) to the frame showing it.

    ``mouse``: the page's mouse events; ``server_events``: (type, received,
    applied, x, y) of the 3D view's events as the server handled them;
    ``renders``: when the server began drawing a window; ``frames``: the
    3D view's frames in the page (``st``, ``shown``).
    """
    moves = [m for m in mouse if m["t"] >= start_ms and m["type"] in ("mousedown", "mousemove") and m["buttons"] & 1]
    applied = [e for e in server_events if e[1] >= start_ms and e[0] in ("LeftButtonPress", "MouseMove")
               and e[3] is not None]

    def browser_index(event) -> int | None:
        # The page's position of the server's event (trame-rca: x from the left, y from the bottom).
        x, y = event[3] + box["x"], box["y"] + box["height"] - event[4]
        for index, move in enumerate(moves):
            if abs(move["x"] - x) < 0.75 and abs(move["y"] - y) < 0.75:
                return index
        return None

    matched = sorted((index, event[2]) for event in applied if (index := browser_index(event)) is not None)
    renders = sorted(renders)
    shown = []
    for frame in frames:
        if frame.get("shown") and frame["shown"] > 0:
            position = bisect.bisect_right(renders, frame["st"]) - 1
            if position >= 0:
                shown.append((renders[position], frame["shown"]))
    latencies = []
    for index, move in enumerate(moves):
        covering = [applied_at for (m, applied_at) in matched if m >= index]
        if not covering:
            continue
        done = covering[0]
        showing = [shown_at for (render_start, shown_at) in shown if render_start >= done]
        if showing:
            latencies.append(min(showing) - move["t"])
    return latencies


def drag_path(box, count, start=(0.42, 0.40), step=(1.4, 0.45)):
    x0, y0 = box["x"] + start[0] * box["width"], box["y"] + start[1] * box["height"]
    return [(x0 + step[0] * i, y0 + step[1] * i) for i in range(count)]


def run(out_dir: Path | None = None, drill_scale: float | None = None) -> dict:
    """Open the application on the head CT in Chromium and time start-up, drilling and navigation."""
    from playwright.sync_api import sync_playwright

    out_dir = Path(out_dir or tempfile.mkdtemp(prefix="volumecutting-webapp-bench-"))
    args = ["--drill-scale", str(drill_scale)] if drill_scale else []
    results = {}
    with AppServer(*args, log_path=out_dir / "server.log") as server, sync_playwright() as playwright:
        browser = launch_chromium(playwright)
        # Room for the 3D view at 1024 x 768 beside the panels and the slice views.
        page = browser.new_page(viewport={"width": 1745, "height": 856}, device_scale_factor=1)
        app = AppPage(page, timing=True)
        app.open(server.url)
        app.wait_for("() => (document.querySelector('[data-testid=status]')?.textContent || '').includes('Ready')",
                     300, "the page to say Ready")
        ready_in_page = time.time()
        app.wait_ready(300)
        first_image = time.time()
        box = app.fit_three_d_view(*VIEW_SIZE)
        area = app.three_d_area()
        app.wait_refined(2000, 300)
        timing = app.timing()
        frames = [f for f in timing["frames"] if f["name"] == area and f.get("shown")]
        full = [f for f in frames if f["w"] >= VIEW_SIZE[0] - 8 and (f["shown"] or 0) > 0]
        # The size the 3D view really had (the window is resized until it fits VIEW_SIZE).
        results["view_css_px"] = [round(box["width"]), round(box["height"])]
        results["startup"] = {
            "ready_in_page_s": round(ready_in_page - server.started_at, 2),
            "ready_to_first_picture_s": round(max(0.0, first_image - ready_in_page), 2),
            "first_frame_s": round(min(f["shown"] for f in frames if f["shown"] > 0) / 1000.0 - server.started_at, 2)
            if frames else None,
            "first_full_resolution_frame_s": round(min(f["shown"] for f in full) / 1000.0 - server.started_at, 2) if full else None,
        }

        app.set_mode("drill")
        path = drag_path(box, DRILL_EVENTS)
        page.mouse.move(*path[0])
        app.wait_refined(1500, 120)

        def timed_drag(points, hover=False):
            start = time.time() * 1000.0
            if hover:
                for x, y in points:
                    page.mouse.move(x, y)
                    page.wait_for_timeout(MOUSE_PERIOD_MS)
            else:
                app.drag(points, MOUSE_PERIOD_MS)
            app.wait_refined(2000, 300)
            server_log = app.server_timing()
            page_log = app.timing()
            frames = [f for f in page_log["frames"] if f["name"] == area]
            mouse = page_log["mouse"]
            if hover:
                # Hover latencies: every move counts, no button.
                mouse = [dict(m, buttons=1, type="mousemove") for m in mouse if m["type"] == "mousemove"]
            events = [e for e in server_log["events"] if len(e) == 5]
            if hover:
                events = [("MouseMove",) + tuple(e[1:]) for e in events if e[0] == "MouseMove"]
            return event_latencies(mouse, events, server_log["renders"], frames, box, start), events, start

        drill, events, start = timed_drag(path)
        applied = [e for e in events if e[1] >= start]
        removed = app.total_removed()
        hover_path = drag_path(box, DRILL_EVENTS, start=(0.30, 0.62), step=(1.4, -0.45))
        hover, _, _ = timed_drag(hover_path, hover=True)
        results["drilling"] = {"latency_ms": _stats(drill), "browser_events": len(drill), "server_events": len(applied),
                               "removed_mm3": removed}
        results["hover"] = {"latency_ms": _stats(hover)}

        app.set_mode("navigate")
        rotate = drag_path(box, 40, start=(0.5, 0.5), step=(3.0, 0.0))
        navigation, _, nav_start = timed_drag(rotate)
        page_log = app.timing()
        release = max(m["t"] for m in page_log["mouse"] if m["type"] == "mouseup")
        full_after = [f["shown"] for f in page_log["frames"] if f["name"] == area and f["w"] >= VIEW_SIZE[0] - 8
                      and (f.get("shown") or 0) > release]
        server_frames = [f for f in app.server_timing().get("frames", []) if f[1] >= nav_start]
        results["navigation"] = {"latency_ms": _stats(navigation),
                                 "server_frame_ms": {
                                     "interactive": _stats([f[2] for f in server_frames if f[0] == "preview" and f[5] > 1]),
                                     "still_full_view": _stats([f[2] for f in server_frames if f[0] == "main"])},
                                 "release_to_full_resolution_ms": round(min(full_after) - release, 1) if full_after else None}
        app.screenshot(out_dir / "benchmark.png")
        # Everything measured, for a closer look.
        (out_dir / "timing.json").write_text(json.dumps({"page": app.timing(), "server": app.server_timing(),
                                                         "box": box, "area": area}))
        browser.close()
    results["out_dir"] = str(out_dir)
    return results


def webapp(repeats: int) -> list[dict]:
    """The ``webapp`` area of ``VolumeCuttingLib.benchmarks``: one run with the drill preview at half the view's
    resolution (the application's default) and one drilling at full resolution, for comparison (each takes
    about a minute; ``repeats`` is not used: every mouse event of a run is a sample)."""
    machine = machine_description("llvmpipe (server-side, offscreen EGL)")
    # These machines' cores are shared with other jobs: the load averages are in the details.
    machine["cores_shared"] = True
    load_before = os.getloadavg()
    preview = run(drill_scale=0.5)
    full = run(drill_scale=1.0)
    load_after = os.getloadavg()
    drilling, hover = preview["drilling"]["latency_ms"], preview["hover"]["latency_ms"]
    navigation, full_drilling = preview["navigation"]["latency_ms"], full["drilling"]["latency_ms"]
    entries = []
    for statistic in ("first", "median", "p95", "max"):
        entries.append(measurement(f"drill: mouse-move to image in page, {statistic} (ms; preview at 0.5)",
                                   drilling[statistic], "ms", f"hover: mouse-move to image in page, {statistic} (ms)",
                                   hover[statistic], drilling["count"], machine))
    for statistic in ("first", "median", "p95", "max"):
        entries.append(measurement(f"drill at full resolution: mouse-move to image in page, {statistic} (ms)",
                                   full_drilling[statistic], "ms", f"drill with the 0.5 preview, {statistic} (ms)",
                                   drilling[statistic], full_drilling["count"], machine))
    for statistic in ("first", "median", "p95", "max"):
        entries.append(measurement(f"camera drag: mouse-move to image in page, {statistic} (ms; interactive frames at 0.5)",
                                   navigation[statistic], "ms", f"hover: mouse-move to image in page, {statistic} (ms)",
                                   hover[statistic], navigation["count"], machine))
    startup = preview["startup"]
    entries.append(measurement("server start to the CT shown in the 3D view (s)", startup["first_frame_s"], "s",
                               "server start to the page loaded with its data (s)", startup["ready_in_page_s"], 1, machine))
    entries.append(measurement("page says Ready to the CT shown in the 3D view (s)", startup["ready_to_first_picture_s"], "s",
                               "server start to the page saying Ready (s)", startup["ready_in_page_s"], 1, machine))
    entries.append(measurement("server start to the CT at full resolution (s)", startup["first_full_resolution_frame_s"],
                               "s", "server start to the CT shown in the 3D view (s)", startup["first_frame_s"], 1, machine))
    keys = ("view_css_px", "startup", "drilling", "hover", "navigation")
    details = {"preview_0.5": {k: preview[k] for k in keys}, "full_resolution": {k: full[k] for k in keys},
               "load_average_before_after": [round(v, 2) for v in load_before + load_after]}
    for entry in entries:
        entry["details"] = details
    return entries
