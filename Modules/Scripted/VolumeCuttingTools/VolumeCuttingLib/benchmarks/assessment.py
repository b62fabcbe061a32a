"""Benchmark area ``assessment``: what recording a session costs the haptic loop, grading it, and storing it.

Recording per haptic tick: a haptic session is recorded inside the loop by
a ``vtkHapticRecorder`` given to ``vtkHapticLoop.SetRecorder`` (each tick
copies its device sample, force, proxy and drill state into a slot
reserved beforehand; ``hapticsjob`` turns those ticks into the complete
recording, ``haptic_session.json``, after the session, off the loop). It is
switched by giving the loop a recorder or none, so the figure is the tick
with the recorder against the tick without it, same run: the haptics
area's bone ball (``haptics._ball_scene``) and the main job's drilling
session (``hapticsjob.write_recording``, 4.5 s at 1 kHz) replayed through
the loop without rendering, alternately without and with the recorder
(without, with, with, without, ...), the cut cleared before each replay.
Tick durations are the loop's own (wall and the haptic thread's processor
time); each condition's figure is the median over its replays of their
p50, p99 and max, and every replay's figures are kept in the rows. On this
shared machine one replay's p50 and p99 move by tens of microseconds from
one replay to the next (other jobs' load, the caches they empty), far more
than a recorder's tick can cost, so the on-off difference is noise-bound
here; what recording adds is then measured exactly as well: the recorder's
per-tick call (``AppendInput``: a tick filled and ``Record``, the loop's
call, a copy of 130 bytes into a reserved slot) timed over 200,000 calls
from Python against a wrapped call of the same recorder doing nothing, an
upper bound of the loop's own call (Python's argument conversion included).

Grading on one core: the shipped 86-stroke head-CT mastoidectomy, timed as
``assessment.sessions.careful`` makes it (5 mm/s, tools, camera), graded
by ``assessment.metrics.assess`` in a child process held to one processor
(its affinity, and OMP/BLAS/VTK thread counts of 1). The first call
includes building the scan from the head CT (as ``vc assess`` does in a
fresh process); the repeats reuse it. Baseline, in the same child: the
product's own replay of the same recording through the logic
(``cutting.recording.replay``: the head CT, its bone segmentation, a 5 mm
cutting and a 3 mm diamond burr), the cut cleared before each repeat.
Both wall time and the child's processor time are given (this machine is
shared: wall time carries the other jobs' preemption).

Storing a session: the ``records`` area's measurements (one assessed
session of 60 metrics stored in an SQLite file and in a PostgreSQL server,
and a learning curve), run from here so that the figures stand beside
these; the graded head-CT session has as many metrics as the row says.
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import slicer
import vtk

from ..cutting import recording
from ..jobs import hapticsjob
from . import records as records_area
from .harness import machine_description, measurement
from .haptics import _ball_scene

#: Replays of the haptic session with the recorder and without it (each).
RECORDING_REPLAYS = 4
VOLUME_SPREAD_LIMIT = 0.005  # of the largest removed volume, between replays of one recording
#: Threads a one-core child is held to, by every library that reads one of these.
ONE_CORE_ENVIRONMENT = {name: "1" for name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                                               "VTK_SMP_MAX_THREADS", "NUMEXPR_NUM_THREADS")}


def _haptic_replay(application, cut_node, plan, recording_path: Path, ticks: int, record: bool) -> dict:
    """One replay of the recorded session through the haptic loop, with a recorder in the loop or none; its tick statistics."""
    logic = application.volume_cutting_logic
    logic.ClearCut(cut_node)
    surface, direction, _ = hapticsjob.target_beside(cut_node, plan)
    tool, _ = hapticsjob.active_burr(application.scene, cut_node)
    pose = vtk.vtkMatrix4x4()
    rotation = recording.frame_along(direction)
    start = surface - hapticsjob.STANDOFF_MM * direction
    for row in range(3):
        for column in range(3):
            pose.SetElement(row, column, float(rotation[row, column]))
        pose.SetElement(row, 3, float(start[row]))
    tool.GetParentTransformNode().SetMatrixTransformToParent(pose)
    replay = slicer.vtkReplayHapticDevice()
    if not replay.ReadFile(str(recording_path)):
        raise RuntimeError(f"the haptic recording {recording_path} could not be read back (see the log)")
    session = slicer.vtkSlicerVolumeCuttingHapticSession()
    session.SetLogic(logic)
    loop = session.GetLoop()
    loop.SetRate(hapticsjob.RATE_HZ)
    recorder = None
    if record:
        recorder = slicer.vtkHapticRecorder()
        recorder.SetCapacity(ticks + 1000)
        loop.SetRecorder(recorder)
    if not session.Start(cut_node, replay):
        raise RuntimeError("the haptic session could not start (see the log)")
    try:
        while not replay.IsFinished():
            time.sleep(hapticsjob.DISPLAY_PERIOD_S)
            session.Update()
    finally:
        session.Stop()
    return {
        "ticks": int(loop.GetNumberOfTicks()),
        "recorded": recorder.GetNumberOfTicks() if recorder is not None else 0,
        "removed_mm3": logic.GetRemovedVolume(cut_node),
        "p50": loop.GetTickDurationPercentile(50.0), "p99": loop.GetTickDurationPercentile(99.0),
        "max": loop.GetMaximumTickDuration(),
        "cpu_p50": loop.GetTickProcessorTimePercentile(50.0), "cpu_p99": loop.GetTickProcessorTimePercentile(99.0),
        "cpu_max": loop.GetTickProcessorTimePercentile(100.0),
    }


def _recorder_call_us(calls: int = 200_000, repeats: int = 5) -> tuple[float, float]:
    """The recorder's per-tick call from Python (AppendInput: a tick filled and Record), and a wrapped call doing nothing (us)."""
    recorder = slicer.vtkHapticRecorder()
    recorder.SetCapacity(calls)
    position, orientation = [1.0, 2.0, 3.0], [1.0, 0.0, 0.0, 0.0]
    appends, getters = [], []
    for _ in range(repeats):
        recorder.Clear()
        start = time.perf_counter()
        for _ in range(calls):
            recorder.AppendInput(position, orientation, 0, 1, True)
        appends.append(time.perf_counter() - start)
        start = time.perf_counter()
        for _ in range(calls):
            recorder.GetTickPresent(0)
        getters.append(time.perf_counter() - start)
    if recorder.GetNumberOfTicks() != calls or recorder.GetNumberOfDroppedTicks():
        raise RuntimeError("the recorder did not keep every tick")
    return 1e6 * statistics.median(appends) / calls, 1e6 * statistics.median(getters) / calls


def _recording_cost(machine) -> list[dict]:
    application, cut_node, plan = _ball_scene()
    runs = {True: [], False: []}
    with tempfile.TemporaryDirectory(prefix="volumecutting-assessment-bench-") as folder:
        recording_path = Path(folder) / "haptic_session.vchr"
        _, direction, _ = hapticsjob.target_beside(cut_node, plan)
        ticks = hapticsjob.write_recording(recording_path, direction, slicer.vtkVirtualHapticDevice().GetCapabilities())
        # Without, with, with, without, ...: a drift of the machine's load falls on both alike.
        order = [bool(n % 4 in (1, 2)) for n in range(2 * RECORDING_REPLAYS)]
        for record in order:
            runs[record].append(_haptic_replay(application, cut_node, plan, recording_path, ticks, record))
    with_recorder, without = runs[True], runs[False]
    if any(run["recorded"] < run["ticks"] for run in with_recorder):
        raise RuntimeError("the recorder kept fewer ticks than the loop ran")
    # The loop's cutter thread cuts a few milliseconds behind the ticks, so the force (and with it the proxy's path)
    # reads a field that differs slightly from run to run: the same input cuts the same volume within a fraction of
    # a percent, not bit for bit. A larger spread means the replays were not the same input.
    volumes = sorted(run["removed_mm3"] for run in with_recorder + without)
    if volumes[-1] - volumes[0] > VOLUME_SPREAD_LIMIT * volumes[-1]:
        raise RuntimeError(f"the replays cut different volumes ({volumes} mm^3): not the same input")

    def median(runs_, key):
        return statistics.median(run[key] for run in runs_)

    ticks_each = with_recorder[0]["ticks"]
    where = (f"one haptic tick at 1 kHz on the haptics area's bone ball, the main job's drilling session replayed "
             f"({ticks_each} ticks, no rendering; median of {RECORDING_REPLAYS} replays each way, alternated)")
    baseline = "the same tick without a recorder in the loop, same replays interleaved"
    results = []
    for label in ("p50", "p99", "max"):
        results.append(measurement(f"{where}, recorder in the loop: {label}", median(with_recorder, label), "us",
                                   f"{baseline}: {label}", median(without, label), ticks_each * RECORDING_REPLAYS,
                                   machine))
    for label in ("p50", "p99", "max"):
        results.append(measurement(f"the same tick, processor time of the haptic thread, recorder in the loop: {label}",
                                   median(with_recorder, f"cpu_{label}"), "us",
                                   f"{baseline}, processor time: {label}", median(without, f"cpu_{label}"),
                                   ticks_each * RECORDING_REPLAYS, machine))
    difference = median(with_recorder, "p99") - median(without, "p99")
    cpu_difference = median(with_recorder, "cpu_p99") - median(without, "cpu_p99")
    results.append(measurement("recording cost per haptic tick: p99 with the recorder less p99 without (target <= 5 us)",
                               difference, "us", "p99 without the recorder", median(without, "p99"),
                               ticks_each * RECORDING_REPLAYS, machine))
    results.append(measurement("recording cost per haptic tick, processor time: p99 with less p99 without "
                               "(target <= 5 us)", cpu_difference, "us", "processor-time p99 without the recorder",
                               median(without, "cpu_p99"), ticks_each * RECORDING_REPLAYS, machine))
    for row in results:
        row["replays"] = {"with_recorder": with_recorder, "without": without}
    append_us, getter_us = _recorder_call_us()
    results.append(measurement("the recorder's per-tick call from Python (vtkHapticRecorder.AppendInput: a tick filled "
                               "and recorded, as the loop's Record; an upper bound of what the loop's call adds)",
                               append_us, "us", "a wrapped call of the same recorder doing no work (GetTickPresent)",
                               getter_us, 200_000, machine))
    return results


def one_core_figures(repeats: int) -> dict:
    """Grading the head-CT mastoidectomy and the logic's replay of it (seconds, wall and processor); run on one core."""
    from ..assessment import metrics, scans, sessions
    from ..config import toolconfig
    from ..data import headct
    from ..scene.application import HeadlessSlicer

    figures = {"cpus": sorted(os.sched_getaffinity(0))}
    wall, cpu = time.perf_counter(), time.process_time()
    untimed = recording.load(recording.head_ct_mastoidectomy_path())
    session = sessions.careful(scans.head_ct_scan())
    figures["scan_and_recording_s"] = [time.perf_counter() - wall, time.process_time() - cpu]
    # The first call as a fresh `vc assess` makes it: the scan built from the head CT inside it.
    scans._head_ct.cache_clear()

    def graded(reference=None):
        wall_, cpu_ = time.perf_counter(), time.process_time()
        result = metrics.assess(session, None, reference)
        return [time.perf_counter() - wall_, time.process_time() - cpu_], result

    figures["assess_first"], first = graded()
    figures["assess_repeats"] = [graded()[0] for _ in range(repeats)]
    figures["assess_with_reference_repeats"] = [graded(session)[0] for _ in range(repeats)]
    figures["strokes"] = len(session["strokes"])
    figures["poses"] = sum(len(stroke["positions"]) for stroke in session["strokes"])
    figures["score"] = first.score
    figures["metrics"] = len(first.metrics)

    application = HeadlessSlicer()
    logic = application.volume_cutting_logic
    volume = headct.load_volume_node(application.scene, name="HeadCT")
    bone = logic.CreateBoneSegmentation(volume, 700.0, 200.0, 0.5)
    cut = logic.AddVolumeCutNode(volume, bone)
    cut.SetCuttableSegmentIDs([logic.GetCorticalBoneSegmentID(), logic.GetTrabecularBoneSegmentID()])
    presets = {preset.name: preset for preset in toolconfig.load_presets()}
    tools = {key: toolconfig.create_tool_node(application.scene, toolconfig.from_preset(presets[name]), name)
             for key, name in (("cutting", "Cutting burr 5 mm"), ("diamond", "Diamond burr 3 mm"))}

    def replayed():
        logic.ClearCut(cut)
        wall_, cpu_ = time.perf_counter(), time.process_time()
        counts = recording.replay(logic, cut, untimed, tools)
        return [time.perf_counter() - wall_, time.process_time() - cpu_], counts

    figures["replay_first"], counts = replayed()
    figures["replay_repeats"] = [replayed()[0] for _ in range(repeats)]
    figures["replay_refused_poses"] = counts["refused_poses"]
    figures["replay_removed_mm3"] = logic.GetRemovedVolume(cut)
    return figures


def _one_core_child(repeats: int) -> dict:
    """``one_core_figures`` in a child process held to one processor (the first this process may use)."""
    environment = dict(os.environ, **ONE_CORE_ENVIRONMENT, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    processor = min(os.sched_getaffinity(0))
    code = ("import json, sys; from VolumeCuttingLib.benchmarks.assessment import one_core_figures; "
            f"print('FIGURES ' + json.dumps(one_core_figures({int(repeats)})))")
    completed = subprocess.run([sys.executable, "-c", code], env=environment, capture_output=True, text=True,
                               preexec_fn=lambda: os.sched_setaffinity(0, {processor}), check=False)
    lines = [line for line in completed.stdout.splitlines() if line.startswith("FIGURES ")]
    if completed.returncode != 0 or not lines:
        raise RuntimeError(f"the one-core grading run failed ({completed.returncode}): {completed.stderr[-2000:]}")
    return json.loads(lines[-1][len("FIGURES "):])


def _grading(repeats: int, machine) -> list[dict]:
    figures = _one_core_child(max(repeats, 3))
    one_core = dict(machine, cores=1, note=f"child process held to processor {figures['cpus']}, "
                                           f"{', '.join(ONE_CORE_ENVIRONMENT)} = 1; " + machine.get("note", ""))
    what = (f"grading the shipped head-CT mastoidectomy ({figures['strokes']} strokes, {figures['poses']} poses, "
            f"score {figures['score']:.1f}, {figures['metrics']} metrics) on one core, no reference")
    baseline = "the product's replay of the same recording through the logic (cutting.recording.replay), same process"
    results = []
    for index, clock in ((0, "wall"), (1, "processor")):
        def median(key):
            return statistics.median(run[index] for run in figures[key])

        results += [
            measurement(f"{what}, first call (the scan built from the head CT in it), {clock} time",
                        figures["assess_first"][index], "s", f"{baseline}, first call, {clock} time",
                        figures["replay_first"][index], 1, one_core),
            measurement(f"{what}, median of repeats (target <= 5 s), {clock} time", median("assess_repeats"), "s",
                        f"{baseline}, median of repeats, {clock} time", median("replay_repeats"),
                        len(figures["assess_repeats"]), one_core),
            measurement(f"the same grading against a reference (the same session: final product too), median of "
                        f"repeats, {clock} time", median("assess_with_reference_repeats"), "s",
                        f"{baseline}, median of repeats, {clock} time", median("replay_repeats"),
                        len(figures["assess_with_reference_repeats"]), one_core),
        ]
    for row in results:
        row["figures"] = figures
    return results


def assessment(repeats: int) -> list[dict]:
    machine = machine_description()
    machine["note"] = "shared machine: its cores shared with other jobs (compilers, tests); no GPU"
    results = _recording_cost(machine)
    results += _grading(repeats, machine)
    results += records_area.records(repeats)
    return results
