"""Benchmark area ``haptics``: what one tick of the haptic loop costs, and how regular the loop is.

Strokes: on the cut-field area's grid (512^3 voxels of 0.33 mm, factor 2),
the first 500 poses of its helix (steps of 0.5 mm) swept by a 2.5 x 5 mm
cylindrical burr and by a 20 mm disk saw 0.5 mm thick (a cylinder as long as
its blade is thick, as the logic builds it), each against the 5 mm spherical
burr's capsule strokes over the same poses in the same run, one core.

Haptic update: a CT of 200 x 200 x 160 voxels of 0.4 mm holding a bone ball
(1200 HU, 25 mm radius) in air, a cut node on it with a 4 mm cutting burr as
its active tool, and the main job's recorded drilling session (hapticsjob:
4.5 s, 2.5 s of it with the drill pushing into the bone) replayed through
the haptic loop at 1 kHz. Once while the product's 3D view (the volume-cut
ray caster, 600 x 600, llvmpipe) renders continuously on the main thread, and
once, as the baseline, with the main thread only updating the scene at 60 Hz.
A tick (device read, 82-point contact against the CT's iso-surface minus the
cut field, force, proxy, cut stroke, recording) is timed by the loop itself;
its period jitter too, and the processor time the haptic thread spent in
each tick (its own CPU clock), which separates a tick's compute from the
preemption a shared machine adds to its wall time. The first call is the first force-model step after
Prepare at a pose in contact, timed from Python. The whole-voxel baseline is
vtkHapticForceModel.CountWholeVoxelContacts (the nearest voxel's CT value and
a whole-voxel cutter's removal for each shell point) at the replay's proxy
positions, timed from Python per call, against ComputeContactForce (the same
points against the sub-voxel fields) timed the same way.

Real data with protected structures: the temporal-bone case
(``data.temporalbone``: 288^3 voxels of 0.15 mm, a labelmap drawn slice by
slice, loaded through ``owndata`` as a user's files, 11 structures
protected), the same recorded session drilled along the floor of the ear
canal, without rendering, with the loop's cutter thread cutting the segments
the ticks queue while the force model counts those it has not cut yet as
removed (the default) against the same replay cutting in the ticks (both
with the shield preparer), in alternating rounds; the cut and the
shield are forgotten before each replay, so every replay starts from none.
Before each pair the same loop runs with ticks that do nothing (a virtual
device in the air of a 4-voxel CT, ``hapticsjob.idle_loop``): its longest
tick and its overruns are this machine's own scheduling noise, against which
the replays' figures are read. The slowest ticks' profiles (force model,
cut, monitor, page faults, preemptions) are kept with the rows.

Real-time priority: the temporal-bone replay and a replay on the example
head CT (no segmentation, beside the main job's right mastoidectomy), each
with the loop's threads at real-time priority (SCHED_FIFO, the default where
the system grants it) and at normal priority, alternating in the same
minutes, with the do-nothing loop at both priorities before each pair: once
on the machine as it is (other jobs share it) and once with busy processes
added. The processor time the host took from this virtual machine meanwhile
(/proc/stat's steal) is kept with the do-nothing rows: no priority inside
the machine wins that back.
"""

from __future__ import annotations

import contextlib
import subprocess
import tempfile
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import slicer
import vtk

from ..cutting import drilling
from ..data import headct, temporalbone
from ..jobs import hapticsjob
from ..scene import nodes
from ..scene.application import HeadlessSlicer, opengl_renderer_name
from .harness import grid_matrix, machine_description, measurement

STROKE_POSES = 500
CT_DIMENSIONS = (200, 200, 160)
CT_SPACING = 0.4
BALL_RADIUS = 25.0
VIEW_SIZE = 600


def _helix():
    """The cut-field area's helix: 20 mm radius through the middle of a 512^3 CT, steps of 0.5 mm."""
    center_mm = np.array([84.0, 84.0, 84.0])
    angles = np.arange(STROKE_POSES + 1) * 0.5 / 20.0
    return [center_mm + np.array([20.0 * np.cos(t), 20.0 * np.sin(t), 0.2 * t]) for t in angles]


def _percentiles_ms(times_s):
    return {q: 1000.0 * float(np.percentile(times_s, q)) for q in (50, 99)}


def _strokes(machine) -> list[dict]:
    dims = [512, 512, 512]
    poses = _helix()
    matrices = []
    for pose in poses:
        matrix = vtk.vtkMatrix4x4()
        for axis in range(3):
            matrix.SetElement(axis, 3, float(pose[axis]))
        matrices.append(matrix)

    def sphere_times():
        field = slicer.vtkVolumeCutField()
        field.Initialize(dims, grid_matrix(0.33, dims), 2)
        times, cpu = [], []
        field.BeginStroke()
        for p0, p1 in zip(poses[:-1], poses[1:]):
            start, start_cpu = time.perf_counter(), time.thread_time()
            field.CutCapsule(p0, p1, 2.5)
            times.append(time.perf_counter() - start)
            cpu.append(time.thread_time() - start_cpu)
        field.EndStroke()
        return times, cpu

    def tool_times(tool):
        field = slicer.vtkVolumeCutField()
        field.Initialize(dims, grid_matrix(0.33, dims), 2)
        times, cpu = [], []
        field.BeginStroke()
        for m0, m1 in zip(matrices[:-1], matrices[1:]):
            start, start_cpu = time.perf_counter(), time.thread_time()
            field.CutToolSweep(tool, m0, m1)
            times.append(time.perf_counter() - start)
            cpu.append(time.thread_time() - start_cpu)
        field.EndStroke()
        return times, cpu

    cylinder = slicer.vtkVolumeCutCylinderTool()
    cylinder.SetRadius(2.5)
    cylinder.SetLength(5.0)
    disk = slicer.vtkVolumeCutCylinderTool()
    disk.SetRadius(10.0)
    disk.SetLength(0.5)
    # Wall time, and the calling thread's processor time (what the stroke
    # costs when the shared machine's other jobs do not preempt it).
    sphere_wall, sphere_cpu = (_percentiles_ms(t) for t in sphere_times())
    results = []
    for name, tool in (("2.5 x 5 mm cylindrical burr", cylinder), ("20 mm disk saw 0.5 mm thick", disk)):
        wall, cpu = (_percentiles_ms(t) for t in tool_times(tool))
        for q in (50, 99):
            results.append(measurement(
                f"stroke of a {name} moving 0.5 mm, 0.33 mm voxels, factor 2, one core, wall time: p{q}", wall[q], "ms",
                "the 5 mm spherical burr's stroke over the same poses, same run", sphere_wall[q], STROKE_POSES, machine))
            results.append(measurement(
                f"the same stroke, processor time of the calling thread: p{q}", cpu[q], "ms",
                "the spherical burr's stroke, processor time, same run", sphere_cpu[q], STROKE_POSES, machine))
    return results


def _ball_scene():
    application = HeadlessSlicer()
    k, j, i = np.ogrid[: CT_DIMENSIONS[2], : CT_DIMENSIONS[1], : CT_DIMENSIONS[0]]
    half = [(n - 1) / 2.0 for n in CT_DIMENSIONS]
    r2 = ((i - half[0]) ** 2 + (j - half[1]) ** 2 + (k - half[2]) ** 2) * CT_SPACING**2
    ct = np.where(r2 < BALL_RADIUS**2, 1200, -1000).astype(np.int16)
    ijk_to_ras = np.diag([CT_SPACING, CT_SPACING, CT_SPACING, 1.0])
    ijk_to_ras[:3, 3] = [-h * CT_SPACING for h in half]
    volume = nodes.create_scalar_volume_node(application.scene, ct, ijk_to_ras, "BoneBall")
    logic = application.volume_cutting_logic
    cut_node = logic.AddVolumeCutNode(volume, None)
    cut_node.SetSurfaceIsoValue(300.0)
    # The ball's left pole, drilled along +x: the session works beside it.
    plan = SimpleNamespace(entry=np.array([-BALL_RADIUS, 0.0, 0.0]), direction=np.array([1.0, 0.0, 0.0]),
                           surface_radius=2.0)
    return application, cut_node, plan


def _replay(application, cut_node, plan, out_dir, frame):
    application.volume_cutting_logic.ClearCut(cut_node)
    return hapticsjob.run(application, cut_node, plan, out_dir, frame=frame, check_machine=False)


#: The temporal-bone replay's plan: along -x (medially) 6 mm below this entry,
#: which runs the burr along the floor of the ear canal, beside its shield.
TEMPORAL_BONE_PLAN = dict(entry=(20.0, 5.0, -2.5), direction=(-1.0, 0.0, 0.0), surface_radius=0.0)


#: Alternating rounds of temporal-bone replays, one of each mode a round (see ``REPLAY_MODES``).
TEMPORAL_BONE_ROUNDS = 3

#: The loop's ways of cutting, replayed in turn: the cutter thread with the force model counting the
#: segments it has not cut yet as removed (the default), the cutter thread without that (the force model
#: meets the bone the cutter has not reached yet), and cutting in the ticks.
REPLAY_MODES = {
    "cutter": dict(asynchronous_cutting=True, feel_pending_cuts=True),
    "cutter_unfelt": dict(asynchronous_cutting=True, feel_pending_cuts=False),
    "in_ticks": dict(asynchronous_cutting=False),
}


def _replayed_forces(folder: Path) -> np.ndarray:
    """The force the replay sent at each tick (N), from its recording."""
    recorder = slicer.vtkHapticRecorder()
    if not recorder.ReadFile(str(folder / "haptic_replay.vchr")):
        raise RuntimeError(f"the replay's recording in {folder} could not be read back (see the log)")
    forces = np.zeros((recorder.GetNumberOfTicks(), 3))
    force = [0.0, 0.0, 0.0]
    for n in range(len(forces)):
        recorder.GetTickForce(n, force)
        forces[n] = force
    return forces


#: A tick whose force differs from the replay cutting in the ticks by more than this (N) felt another bone.
FELT_DIFFERENCE_N = 0.05


def _force_difference(forces: np.ndarray, reference: np.ndarray) -> tuple[int, float]:
    """Ticks whose force differs from the reference replay's at the same tick by more than
    ``FELT_DIFFERENCE_N``, and the median difference over the ticks (N). Replays cutting in the ticks
    give the same forces bit for bit, so every difference is the cutter's."""
    count = min(len(forces), len(reference))
    differences = np.linalg.norm(forces[:count] - reference[:count], axis=1)
    return int(np.sum(differences > FELT_DIFFERENCE_N)), float(np.median(differences)) if count else 0.0


def _temporal_bone_scene():
    """The temporal-bone case loaded as a user's files, its 11 structures protected: (application, cut node, plan)."""
    application = HeadlessSlicer()
    files = temporalbone.cached_case_files()
    volume, segmentation, cuttable, protected = temporalbone.load_case(application.scene, files)
    cut_node = application.volume_cutting_logic.AddVolumeCutNode(volume, segmentation)
    cut_node.SetCuttableSegmentIDs(cuttable)
    cut_node.SetProtectedSegmentIDs(protected)
    cut_node.SetSurfaceIsoValue(300.0)
    plan = SimpleNamespace(**{key: np.asarray(value) if isinstance(value, tuple) else value
                              for key, value in TEMPORAL_BONE_PLAN.items()})
    return application, cut_node, plan


def _head_ct_scene():
    """The example head CT without segmentation, drilled beside the main job's right mastoidectomy."""
    application = HeadlessSlicer()
    volume = headct.load_volume_node(application.scene, name="HeadCT")
    cut_node = application.volume_cutting_logic.AddVolumeCutNode(volume, None)
    cut_node.SetSurfaceIsoValue(300.0)
    return application, cut_node, drilling.MastoidectomyPlan(entry=drilling.lateral_entry(volume, *headct.RIGHT_MASTOID_YZ))


def _temporal_bone_replays(scene, out_dir: Path, machine) -> list[dict]:
    """Replays on the temporal-bone case in each of ``REPLAY_MODES``, in alternating rounds."""

    application, cut_node, plan = scene
    logic = application.volume_cutting_logic
    protection = logic.GetCutField(cut_node).GetProtection()
    runs = {mode: [] for mode in REPLAY_MODES}
    # Per round, each mode's forces against the same round's replay cutting in the ticks.
    force_differences = {mode: [] for mode in REPLAY_MODES}
    idle = []
    modes = list(REPLAY_MODES)
    for round_index in range(TEMPORAL_BONE_ROUNDS):
        idle.append(hapticsjob.idle_loop())
        forces = {}
        # Each round starts with another mode: none always follows the idle loop or the same neighbour.
        for mode in modes[round_index % len(modes):] + modes[:round_index % len(modes)]:
            logic.ClearCut(cut_node)
            protection.ClearBricks()
            folder = out_dir / f"temporalbone-{round_index}-{mode}"
            folder.mkdir()
            runs[mode].append(hapticsjob.run(application, cut_node, plan, folder, check_machine=False,
                                             **REPLAY_MODES[mode]))
            forces[mode] = _replayed_forces(folder)
        for mode in REPLAY_MODES:
            force_differences[mode].append(_force_difference(forces[mode], forces["in_ticks"]))

    def worst(replays, key):
        return max(replay[key] for replay in replays)

    def median(replays, key):
        return float(np.median([replay[key] for replay in replays]))

    def work(replays, statistic, field):
        """The force model's work over the replays' ticks (the profile's p99 or max of a field), median of the replays."""
        return float(np.median([replay["tick_profile"][statistic][field] for replay in replays]))

    after, unfelt, before = runs["cutter"], runs["cutter_unfelt"], runs["in_ticks"]
    ticks = sum(replay["ticks_run"] for replay in after)
    where = (f"temporal-bone case ({'x'.join(str(n) for n in temporalbone.DIMENSIONS)} voxels of "
             f"{temporalbone.SPACING} mm, {after[0]['protected_segments']} protected structures, via owndata), "
             f"replayed drilling along the ear canal ({TEMPORAL_BONE_ROUNDS} replays of {after[0]['ticks_run']} ticks, "
             f"no rendering), cutter thread, pending cuts felt")
    baseline = (f"the same replays cutting in the ticks, alternating with them in the same run "
                f"(shield preparer on in both)")
    results = []
    for label, key in (("p50", "tick_us_p50"), ("p99", "tick_us_p99")):
        results.append(measurement(f"one haptic tick on the {where}: {label} (median of the replays)", median(after, key),
                                   "us", f"{baseline}: {label}", median(before, key), ticks, machine))
    results.append(measurement(f"one haptic tick on the {where}: max (over the replays)", worst(after, "tick_us_max"),
                               "us", f"{baseline}: max", worst(before, "tick_us_max"), ticks, machine))
    results.append(measurement(f"the same tick, processor time of the haptic thread: max (over the replays)",
                               worst(after, "tick_cpu_us_max"), "us", f"{baseline}, processor time: max",
                               worst(before, "tick_cpu_us_max"), ticks, machine))
    results.append(measurement(f"haptic loop overruns on the {where} (all replays)",
                               sum(replay["overruns"] for replay in after), "ticks", baseline,
                               sum(replay["overruns"] for replay in before), 1, machine))
    unfelt_name = "the same replays with the cutter thread, pending cuts not felt (the force model meets uncut bone)"
    for label, key in (("p99", "tick_us_p99"), ("max", "tick_us_max")):
        results.append(measurement(f"one haptic tick on the {where}: {label} (median of the replays)", median(after, key),
                                   "us", f"{unfelt_name}: {label}", median(unfelt, key), ticks, machine))
    results.append(measurement(f"haptic loop overruns on the {where} (all replays)",
                               sum(replay["overruns"] for replay in after), "ticks", unfelt_name,
                               sum(replay["overruns"] for replay in unfelt), 1, machine))
    # What the force model does in a tick: the anatomy's points its contact tests look up (traces
    # included) and its time, the same in every mode if the cutter being behind does not change its work.
    for statistic in ("p99", "max"):
        results.append(measurement(
            f"points of the anatomy the force model looked up in a tick on the {where}: {statistic} (median of the replays)",
            work(after, f"{statistic}_us", "samples"), "lookups", f"{baseline}: {statistic}",
            work(before, f"{statistic}_us", "samples"), ticks, machine))
    results.append(measurement(
        f"the force model's part of a tick on the {where}: p99 (median of the replays)",
        work(after, "p99_us", "force_model_us"), "us", f"{baseline}: p99", work(before, "p99_us", "force_model_us"),
        ticks, machine))
    results.append(measurement(
        f"ticks whose force differs by more than {FELT_DIFFERENCE_N} N from the same round's replay cutting in the ticks, "
        f"on the {where} (all rounds)", sum(count for count, _ in force_differences["cutter"]), "ticks",
        f"{unfelt_name}, the same count", sum(count for count, _ in force_differences["cutter_unfelt"]), ticks, machine))
    results.append(measurement(
        f"difference of the force sent at the same tick from the same round's replay cutting in the ticks, on the "
        f"{where} (median over the ticks, median of the rounds)",
        float(np.median([median for _, median in force_differences["cutter"]])), "N", f"{unfelt_name}, the same difference",
        float(np.median([median for _, median in force_differences["cutter_unfelt"]])), ticks, machine))
    results.append(measurement(
        f"mean force while drilling on the {where} (median of the replays)", median(after, "force_mean_while_drilling_n"),
        "N", f"{baseline} (the same feel: ratio about 1)", median(before, "force_mean_while_drilling_n"), ticks, machine))
    results.append(measurement(f"shield bricks the haptic thread built in its ticks on the {where} (all replays)",
                               sum(replay["shield_bricks_built_in_ticks"] for replay in after), "bricks", baseline,
                               sum(replay["shield_bricks_built_in_ticks"] for replay in before), 1, machine))
    results.append(measurement(f"the cut's part of a tick on the {where} (queueing the segment): max",
                               worst(after, "cut_us_max"), "us", f"{baseline}: the cut stroke's part, max",
                               worst(before, "cut_us_max"), ticks, machine))
    results.append(measurement(f"one segment cut by the cutter thread on the {where}: p99 (median of the replays)",
                               median(after, "cutter_us_p99"), "us", f"{baseline}: the cut stroke's part of a tick, p99",
                               median(before, "cut_us_p99"), ticks, machine))
    results.append(measurement(f"longest time from a tick to its segment cut by the cutter on the {where}",
                               worst(after, "cut_latency_us_max"), "us", "one period of the 1 kHz loop", 1000.0, 1,
                               machine))
    results.append(measurement(f"cut volume of the replay on the {where} (mm^3, first replay)",
                               after[0]["removed_volume_mm3"], "mm^3", f"{baseline} (the same strokes: ratio about 1)",
                               before[0]["removed_volume_mm3"], 1, machine))
    results.append(measurement(
        "the machine's own noise: longest tick of the same 1 kHz loop with ticks that do nothing, before each round "
        f"({TEMPORAL_BONE_ROUNDS} runs of 4.5 s, max)", max(run["tick_us_max"] for run in idle), "us",
        "the cutter thread's replays: max tick (above)", worst(after, "tick_us_max"),
        sum(run["ticks_run"] for run in idle), machine))
    results.append(measurement(
        "the machine's own noise: overruns of the do-nothing loop (all runs)", sum(run["overruns"] for run in idle),
        "ticks", "the cutter thread's replays: overruns (above)", sum(replay["overruns"] for replay in after), 1,
        machine))
    profiles = {mode: [replay["tick_profile"] for replay in replays] for mode, replays in runs.items()}
    profiles["idle"] = [run["profile"] for run in idle]
    for row in results:
        row["real_time_priority"] = after[0]["real_time_priority"]
    results[2]["slowest_ticks"] = {name: [tick for profile in group for tick in profile["slowest"][:2]]
                                   for name, group in profiles.items()}
    return results


def _contact_ratio(cut_node, out_dir, machine) -> list[dict]:
    """Sub-voxel contact (82 points) against whole-voxel contact at the replay's proxy positions, same calls."""
    model = hapticsjob.force_model(cut_node, sphere_radius=2.0)
    if model is None:
        raise RuntimeError("the force model could not be prepared (see the log)")
    anatomy = cut_node.GetAnatomyVolumeNode()
    ijk_to_ras = vtk.vtkMatrix4x4()
    anatomy.GetIJKToRASMatrix(ijk_to_ras)
    cutter = slicer.vtkBinaryVoxelCutter()
    cutter.Initialize(list(anatomy.GetImageData().GetDimensions()), ijk_to_ras)
    recording = slicer.vtkHapticRecorder()
    if not recording.ReadFile(str(out_dir / "haptic_replay.vchr")):
        raise RuntimeError("the replayed session could not be read back (see the log)")
    positions = []
    for n in range(recording.GetNumberOfTicks()):
        if recording.GetTickDrilling(n):
            proxy = [0.0, 0.0, 0.0]
            recording.GetTickProxy(n, proxy)
            cutter.CutCapsule(proxy, proxy, 2.0)
            positions.append(proxy)
    force = [0.0, 0.0, 0.0]
    sub_voxel, whole_voxel = [], []
    contacts = 0
    for _ in range(3):
        for position in positions:
            start = time.perf_counter()
            contacts += model.ComputeContactForce(position, force) > 0
            middle = time.perf_counter()
            model.CountWholeVoxelContacts(position, cutter)
            whole_voxel.append(time.perf_counter() - middle)
            sub_voxel.append(middle - start)
    sub = {q: 1e6 * float(np.percentile(sub_voxel, q)) for q in (50, 99)}
    whole = {q: 1e6 * float(np.percentile(whole_voxel, q)) for q in (50, 99)}
    return [measurement(
        f"contact of the burr's 82 shell points against the CT iso-surface minus the cut field, "
        f"at the {len(positions)} drilling proxy positions of the replay ({contacts // 3} in contact), from Python: p{q}",
        sub[q], "us", "whole-voxel contact test of the same points (nearest voxel, whole-voxel removal), same calls",
        whole[q], len(sub_voxel), machine) for q in (50, 99)], whole_voxel


def _first_call(cut_node, position) -> float:
    """The first force-model step after Prepare at a pose in contact, drill on (s)."""
    model = hapticsjob.force_model(cut_node, sphere_radius=2.0)
    model.Reset([position[0] - 3.0, position[1], position[2]])
    start = time.perf_counter()
    model.Step(position, 0.001, True)
    return time.perf_counter() - start


def haptics(repeats: int) -> list[dict]:
    del repeats  # every stroke and tick is one repeat
    results = []
    application, cut_node, plan = _ball_scene()
    view = application.create_3d_view(VIEW_SIZE, VIEW_SIZE)
    view.look_at([0.0, 0.0, 0.0], direction=(-1.0, 0.0, 0.0), distance=4.0 * BALL_RADIUS)
    view.render()
    machine = machine_description(opengl_renderer_name(view.render_window))
    machine["note"] = ("shared machine: 2 cores shared with other jobs (compilers, tests) and no GPU; "
                       "rendering by Mesa llvmpipe on the CPU")
    results += _strokes(machine)

    with tempfile.TemporaryDirectory() as directory:
        out_dir = Path(directory)
        frames = {"n": 0}

        def render():
            view.render()
            frames["n"] += 1

        rendering = _replay(application, cut_node, plan, out_dir, render)
        quiet = _replay(application, cut_node, plan, out_dir, None)
        contact_rows, whole_voxel_s = _contact_ratio(cut_node, out_dir, machine)
        surface = np.array(quiet["surface_ras_mm"])
        first_s = _first_call(cut_node, surface + 1.0 * plan.direction)
        temporal_bone = _temporal_bone_scene()
        temporal_bone_rows = _temporal_bone_replays(temporal_bone, out_dir, machine)
        priority_rows = _priority_replays({"temporal-bone case": temporal_bone, "head CT": _head_ct_scene()}, out_dir,
                                          machine)

    what = (f"one haptic tick at 1 kHz (device read, 82-point contact, force, proxy, cut stroke of a 4 mm burr, "
            f"recording) while the 3D view renders continuously in the main thread "
            f"({rendering['display_frames']} frames in {rendering['wall_s']} s)")
    baseline = "the same tick with the main thread only updating the scene at 60 Hz, same run"
    for label, key in (("p50", "tick_us_p50"), ("p99", "tick_us_p99"), ("max", "tick_us_max")):
        results.append(measurement(f"{what}: {label}", rendering[key], "us", f"{baseline}: {label}", quiet[key],
                                   rendering["ticks_run"], machine))
    # The haptic thread's own CPU clock over the same ticks: the tick's
    # compute without the preemption that this shared machine adds to its wall time.
    for label, key in (("p50", "tick_cpu_us_p50"), ("p99", "tick_cpu_us_p99"), ("max", "tick_cpu_us_max")):
        results.append(measurement(
            f"the same tick, processor time of the haptic thread while rendering: {label}", rendering[key], "us",
            f"{baseline}, processor time: {label}", quiet[key], rendering["ticks_run"], machine))
    results.append(measurement(
        "the first force-model step after Prepare, at a pose in contact, drill on (from Python)", 1e6 * first_s, "us",
        "the loop's tick p50 without rendering (above)", quiet["tick_us_p50"], 1, machine))
    results.append(measurement(
        "haptic loop period jitter at 1 kHz while the 3D view renders continuously: p99",
        rendering["period_jitter_us_p99"], "us", "the same without rendering, same run: p99",
        quiet["period_jitter_us_p99"], rendering["ticks_run"], machine))
    results.append(measurement(
        f"haptic loop overruns (ticks ending after their deadline) of {rendering['ticks_run']} while rendering",
        rendering["overruns"], "ticks", "the same without rendering, same run", quiet["overruns"], 1, machine))
    results.append(measurement(
        "one haptic tick (loop-timed p50, without rendering) against one whole-voxel contact test of the same "
        "82 points (Python-timed p50)", quiet["tick_us_p50"], "us",
        "whole-voxel contact test p50 (below)", 1e6 * float(np.percentile(whole_voxel_s, 50)), quiet["ticks_run"],
        machine))
    results += contact_rows
    for row in results:
        row["real_time_priority"] = rendering["real_time_priority"]
    results.append(measurement(
        "cut volume of the replayed session while rendering (mm^3)", rendering["removed_volume_mm3"], "mm^3",
        "the same session without rendering (determinism: ratio 1)", quiet["removed_volume_mm3"], 1, machine))
    return results + temporal_bone_rows + priority_rows


#: Rounds of the real-time priority A/B: per round and load, the do-nothing loop and each case's replay with and
#: without real-time priority, the order alternating between rounds.
PRIORITY_ROUNDS = 2
#: Busy processes (``yes``) started for the loaded half of the A/B, on top of the machine's own other work.
BUSY_PROCESSES = 3


@contextlib.contextmanager
def _busy(count: int):
    """``count`` processes that keep a processor busy each (writing to /dev/null) while the block runs."""
    processes = [subprocess.Popen(["yes"], stdout=subprocess.DEVNULL) for _ in range(count)]
    try:
        yield
    finally:
        for process in processes:
            process.kill()
            process.wait()


def _stolen_ms() -> float:
    """Processor time the host took from this virtual machine's processors so far (ms; 0 where not reported)."""
    try:
        fields = Path("/proc/stat").read_text().split("\n", 1)[0].split()
        return 10.0 * float(fields[8])  # USER_HZ 100: the "steal" column of the "cpu" line
    except (OSError, IndexError, ValueError):
        return 0.0


def _priority_replays(scenes: dict, out_dir: Path, machine) -> list[dict]:
    """The same replays with and without real-time priority, alternating, on a quiet and a loaded machine.

    For each load (the machine as it is, then with ``BUSY_PROCESSES`` busy
    processes more) and round: the do-nothing loop, then each scene's replay
    (cutter thread, pending cuts felt, shield preparer: the defaults), first
    with real-time priority and then without (the other way round in odd
    rounds). The cut and the shield are forgotten before each replay.
    """
    runs, idle, stolen = {}, {}, {}
    for busy in (0, BUSY_PROCESSES):
        with _busy(busy):
            for round_index in range(PRIORITY_ROUNDS):
                for real_time in ((True, False) if round_index % 2 == 0 else (False, True)):
                    before = _stolen_ms()
                    idle.setdefault((busy, real_time), []).append(hapticsjob.idle_loop(real_time_priority=real_time))
                    for case, (application, cut_node, plan) in scenes.items():
                        application.volume_cutting_logic.ClearCut(cut_node)
                        application.volume_cutting_logic.GetCutField(cut_node).GetProtection().ClearBricks()
                        folder = out_dir / f"priority-{busy}-{round_index}-{real_time}-{case.split()[0]}"
                        folder.mkdir()
                        runs.setdefault((case, busy, real_time), []).append(
                            hapticsjob.run(application, cut_node, plan, folder, real_time_priority=real_time,
                                           check_machine=False))
                    stolen[(busy, real_time)] = stolen.get((busy, real_time), 0.0) + _stolen_ms() - before
    granted = runs[(next(iter(scenes)), 0, True)][0]["real_time_priority_status"]
    results = []
    for busy in (0, BUSY_PROCESSES):
        load = "the machine as it is" if not busy else f"{busy} busy processes ('yes') added"
        for case in scenes:
            fast, slow = runs[(case, busy, True)], runs[(case, busy, False)]
            ticks = sum(replay["ticks_run"] for replay in fast)
            protected = fast[0]["protected_segments"]
            where = (f"{case} ({protected} protected structures), replayed drilling, {load}, "
                     f"real-time priority ({granted})")
            baseline = "the same replays at normal priority, alternating with them in the same run"
            for label, key, combine in (("p50", "tick_us_p50", np.median), ("p99", "tick_us_p99", np.median),
                                        ("max", "tick_us_max", np.max)):
                results.append(measurement(
                    f"one haptic tick on the {where}: {label} ({'median' if label != 'max' else 'max'} of "
                    f"{PRIORITY_ROUNDS} replays)", float(combine([replay[key] for replay in fast])), "us",
                    f"{baseline}: {label}", float(combine([replay[key] for replay in slow])), ticks, machine))
            row = measurement(f"haptic loop overruns on the {where} (all replays)",
                              sum(replay["overruns"] for replay in fast), "ticks", baseline,
                              sum(replay["overruns"] for replay in slow), 1, machine)
            # Where the slowest ticks' time went: the tick's own processor time against the wall time it took.
            row["slowest_ticks"] = {"real_time": [tick for replay in fast for tick in replay["tick_profile"]["slowest"][:3]],
                                    "normal": [tick for replay in slow for tick in replay["tick_profile"]["slowest"][:3]]}
            row["slow_ticks_processor_bound"] = {
                "real_time": sum(replay["tick_profile"]["slow_ticks_processor_bound"] for replay in fast),
                "normal": sum(replay["tick_profile"]["slow_ticks_processor_bound"] for replay in slow)}
            row["page_faults_in_ticks"] = {"real_time": sum(replay["tick_profile"]["page_faults"] for replay in fast),
                                           "normal": sum(replay["tick_profile"]["page_faults"] for replay in slow)}
            results.append(row)
        fast, slow = idle[(busy, True)], idle[(busy, False)]
        ticks = sum(run["ticks_run"] for run in fast)
        for label, key in (("max", "tick_us_max"), ("overruns", "overruns")):
            row = measurement(
                f"the machine's own noise, {load}: the do-nothing 1 kHz loop at real-time priority, {label} "
                f"(all {PRIORITY_ROUNDS} runs of 4.5 s)", float(np.max([run[key] for run in fast]) if label == "max"
                                                               else sum(run[key] for run in fast)),
                "us" if label == "max" else "ticks", f"the same loop at normal priority, same run: {label}",
                float(np.max([run[key] for run in slow]) if label == "max" else sum(run[key] for run in slow)),
                ticks if label == "max" else 1, machine)
            # Time the host took from this VM's processors meanwhile (no priority inside the VM can win it back).
            row["host_steal_ms"] = {"real_time": round(stolen[(busy, True)], 1), "normal": round(stolen[(busy, False)], 1)}
            results.append(row)
    for row in results:
        row["real_time_priority"] = runs[(next(iter(scenes)), 0, True)][0]["real_time_priority"]
        row["real_time_priority_status"] = granted
    return results
