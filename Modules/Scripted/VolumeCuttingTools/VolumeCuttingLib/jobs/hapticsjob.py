"""A haptic drilling session, recorded and replayed through the full haptic path.

The main job calls :func:`run` once the mastoidectomy is drilled. A drilling
session is written as a recording of device input (``haptic_session.vchr``):
a hand that brings a 4 mm cutting burr to the bone beside the cavity, presses
the foot switch and pushes into the bone, then lets go and withdraws. The
recording is read back by a replay device and played through what a real
device goes through: the haptic loop on its own thread at 1 kHz, the force
model on the CT's iso-surface minus the cut field, strokes cut into the cut
node's field by the haptic thread, and, at display rate on this thread, the
tool node moved and the cut node's events sent (``vtkSlicerVolumeCuttingHapticSession``).
The forces felt are recorded too (``haptic_replay.vchr``), and so is the
virtual nerve monitor on the protected structures (every tick measures it;
the burr's positions of every tick, as the recorder kept them, give its
readings at 1 kHz for ``nerve_monitor.png``: distance per structure over
time over the threshold bands, whatever the display rate).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import slicer
import vtk

from ..config import toolconfig
from ..cutting import recording
from ..collaboration import forcecoupling
from ..feedback import nervemonitor

#: The tool the session drills with.
BURR_PRESET = "Cutting burr 4 mm"
#: Where the hand starts: this far (mm) outside the bone, on the approach.
STANDOFF_MM = 10.0
#: Phases of the hand's motion: seconds, and where the hand is at their end
#: (mm along the approach from the start), with the drill pedal down or not.
PHASES = (
    (1.2, 12.0, False),  # to the bone (first contact at 10 mm)
    (2.5, 17.0, True),   # pedal down, pushing into the bone
    (0.8, 0.0, False),   # pedal up, back out
)
RATE_HZ = 1000.0
DISPLAY_PERIOD_S = 1.0 / 60.0


def force_model(cut_node, sphere_radius=None):
    """A force model on what the cut node draws (its CT's iso-surface minus its cut field), prepared; None if it cannot be."""
    anatomy = cut_node.GetAnatomyVolumeNode()
    ijk_to_ras = vtk.vtkMatrix4x4()
    anatomy.GetIJKToRASMatrix(ijk_to_ras)
    model = slicer.vtkHapticForceModel()
    model.SetAnatomy(anatomy.GetImageData(), ijk_to_ras)
    model.SetSurfaceIsoValue(cut_node.GetSurfaceIsoValue())
    model.SetCutField(cut_node.GetCutField())
    if sphere_radius is not None:
        model.SetSphereRadius(sphere_radius)
    return model if model.Prepare() else None


def _first_solid(cut_node, start, direction, length=60.0, step=0.1):
    """The first point of the line that is solid as the renderer draws it (None if none)."""
    probe = force_model(cut_node)
    if probe is None:
        return None
    for t in np.arange(0.0, length, step):
        point = start + t * direction
        if probe.IsSolid(point.tolist()):
            return point
    return None


def target_beside(cut_node, plan) -> tuple[np.ndarray, np.ndarray, str]:
    """A point of the bone surface beside the planned cavity, and the approach direction.

    Falls back to the cavity's entry when no bone is found there.
    """
    direction = np.asarray(plan.direction, dtype=float)
    direction /= np.linalg.norm(direction)
    helper = np.array([0.0, 0.0, 1.0]) if abs(direction[2]) < 0.9 else np.array([0.0, 1.0, 0.0])
    across = np.cross(direction, helper)
    along = np.cross(direction, across / np.linalg.norm(across))
    beside = np.asarray(plan.entry, dtype=float) + (plan.surface_radius + 6.0) * along
    surface = _first_solid(cut_node, beside - 30.0 * direction, direction)
    if surface is not None:
        return surface, direction, "bone surface beside the cavity"
    return np.asarray(plan.entry, dtype=float), direction, "the cavity's entry (no bone found beside it)"


def active_burr(scene, cut_node):
    """The cut node's active tool, or a new cutting burr made its active tool."""
    tool = cut_node.GetActiveToolNode()
    if tool is not None:
        return tool, False
    preset = next(p for p in toolconfig.load_presets() if p.name == BURR_PRESET)
    tool = toolconfig.create_tool_node(scene, toolconfig.from_preset(preset), name="Haptic burr")
    cut_node.SetAndObserveActiveToolNodeID(tool.GetID())
    return tool, True


#: A tick slower than this (us) is a slow tick in :func:`tick_profile` (half the 1 kHz period: issue 28's target).
SLOW_TICK_US = 500.0
#: The parts of a tick's profile, in ``vtkHapticLoop.GetTickProfile``'s order.
PROFILE_FIELDS = ("tick_us", "cpu_us", "force_model_us", "cut_us", "nerve_monitor_us", "shield_bricks_built",
                  "page_faults", "preemptions", "contacts", "proxy_steps", "samples", "immersion_um",
                  "cut_samples")


def kept_tick_profiles(loop) -> np.ndarray:
    """The loop's kept ticks, one row each, in ``PROFILE_FIELDS``' order (``vtkHapticLoop.GetTickProfile``)."""
    profiles = np.zeros((loop.GetNumberOfKeptTicks(), len(PROFILE_FIELDS)))
    row = [0.0] * len(PROFILE_FIELDS)
    for n in range(len(profiles)):
        loop.GetTickProfile(n, row)
        profiles[n] = row
    return profiles


def tick_profile(loop, slowest: int = 5, profiles: np.ndarray | None = None) -> dict:
    """What the loop's kept ticks spent their time on: the slowest ticks part by part, and the slow ones' totals.

    A slow tick whose processor time is short and which was preempted lost
    its time to the machine; one with page faults touched new memory; the
    force model's, the cut's and the monitor's parts are the product's own.
    """
    # A copy: the caller's rows (``kept_tick_profiles``, read once) keep their units.
    profiles = kept_tick_profiles(loop) if profiles is None else np.array(profiles, dtype=float)
    # The deepest contact in micrometres, as the times are kept to a tenth of their unit.
    profiles[:, PROFILE_FIELDS.index("immersion_um")] *= 1000.0
    if not len(profiles):
        return {"ticks": 0}
    order = np.argsort(profiles[:, 0])[::-1][:slowest]
    slow = profiles[profiles[:, 0] > SLOW_TICK_US]
    # The force model's pace: processor time per lookup (a CT or cut-field
    # sample) of the ticks that made 100 or more. The same code at a pace
    # several times slower than the run's median was slowed, not given more to do.
    samples = profiles[:, PROFILE_FIELDS.index("samples")]
    busy = samples >= 100
    pace = float(np.median(profiles[busy, 1] / samples[busy])) if busy.any() else 0.0

    def pace_ratio(n):
        return round(float(profiles[n, 1] / (samples[n] * pace)), 1) if pace > 0.0 and samples[n] > 0 else None

    # The tick's own work by kind of lookup: processor time ~ fixed + per CT-only lookup + per cut-field lookup,
    # fitted on the ticks the machine left alone (under the slow threshold and the 99th percentile), so that a
    # slow tick's time can be set against what its own lookups take.
    cut_samples = profiles[:, PROFILE_FIELDS.index("cut_samples")]
    kinds = np.c_[np.ones(len(profiles)), samples - cut_samples, cut_samples]
    calm = (profiles[:, 0] <= SLOW_TICK_US) & (profiles[:, 1] <= np.percentile(profiles[:, 1], 99.0))
    own = None
    if calm.sum() >= 10:
        coefficients = np.linalg.lstsq(kinds[calm], profiles[calm, 1], rcond=None)[0]
        own = kinds @ coefficients

    return {
        "ticks": len(profiles),
        "slow_tick_us": SLOW_TICK_US,
        "slow_ticks": int(len(slow)),
        # Slow ticks whose own compute (processor time) was not slow: the machine took the time.
        "slow_ticks_preempted": int(np.sum((slow[:, 1] <= SLOW_TICK_US) & (slow[:, 7] > 0))),
        # Slow ticks whose processor time was slow too: the tick's own work, or interrupts handled on its processor.
        "slow_ticks_processor_bound": int(np.sum(slow[:, 1] > SLOW_TICK_US)),
        "page_faults": int(profiles[:, 6].sum()),
        "ticks_with_page_faults": int(np.sum(profiles[:, 6] > 0)),
        "preemptions": int(profiles[:, 7].sum()),
        "lookup_us_median": round(pace, 3),
        # The most lookups of a tick at that pace: the longest tick the force model's own work makes.
        "most_lookups_at_median_pace_us": round(float(samples.max() * pace), 1),
        # The fit by kind of lookup (us: per tick, per CT-only lookup, per cut-field lookup) and the longest own work.
        "own_work_fit_us": None if own is None else [round(float(c), 3) for c in coefficients],
        "longest_own_work_us": None if own is None else round(float(own.max()), 1),
        "p50_us": {name: round(float(np.percentile(profiles[:, i], 50)), 1) for i, name in enumerate(PROFILE_FIELDS)},
        "mean_us": {name: round(float(profiles[:, i].mean()), 1) for i, name in enumerate(PROFILE_FIELDS)},
        "p99_us": {name: round(float(np.percentile(profiles[:, i], 99)), 1) for i, name in enumerate(PROFILE_FIELDS)},
        "max_us": {name: round(float(profiles[:, i].max()), 1) for i, name in enumerate(PROFILE_FIELDS)},
        "slowest": [{"tick": int(n), **{name: round(float(profiles[n, i]), 1) for i, name in enumerate(PROFILE_FIELDS)},
                     "pace_ratio": pace_ratio(n),
                     "own_work_us": None if own is None else round(float(own[n]), 1)} for n in order],
    }


def idle_loop(seconds: float = 4.5, real_time_priority: bool = True) -> dict:
    """The machine's own noise: the haptic loop at 1 kHz on the same thread set-up, with ticks that do next to nothing.

    A virtual device held still in the air of a 4-voxel CT, no cut field, no
    monitor: a tick is a device read and a force-model step out of contact
    (a few microseconds), so its longest durations, overruns and jitter are
    what the scheduler of this machine gives any 1 kHz thread.
    ``real_time_priority`` False runs it at normal priority
    (``vtkHapticLoop.SetRequestRealTimePriority``).
    """
    model = forcecoupling.air_force_model()
    device = slicer.vtkVirtualHapticDevice()
    if not device.Open():
        raise RuntimeError("the virtual haptic device could not be opened (see the log)")
    device.SetPose([1.5, 1.5, 1.5], 0)
    loop = slicer.vtkHapticLoop()
    loop.SetRate(RATE_HZ)
    loop.SetDevice(device)
    loop.SetForceModel(model)
    loop.SetRequestRealTimePriority(bool(real_time_priority))
    if not loop.Start():
        raise RuntimeError("the idle haptic loop could not start (see the log)")
    time.sleep(seconds)
    loop.Stop()
    device.Close()
    return {
        "ticks_run": int(loop.GetNumberOfTicks()),
        "tick_us_p50": round(loop.GetTickDurationPercentile(50.0), 1),
        "tick_us_p99": round(loop.GetTickDurationPercentile(99.0), 1),
        "tick_us_max": round(loop.GetMaximumTickDuration(), 1),
        "tick_cpu_us_max": round(loop.GetTickProcessorTimePercentile(100.0), 1),
        "period_jitter_us_p99": round(loop.GetPeriodJitterPercentile(99.0), 1),
        "period_jitter_us_max": round(loop.GetMaximumPeriodJitter(), 1),
        "overruns": int(loop.GetNumberOfOverruns()),
        "real_time_priority": bool(loop.GetRealTimePriority()),
        "real_time_priority_status": loop.GetRealTimePriorityStatus(),
        "profile": tick_profile(loop),
    }


def machine_check(seconds: float, work_us, real_time_priority: bool = True, frame=None) -> dict:
    """What this machine gives a 1 kHz thread of known work (``vtkHapticMachineCheck``).

    The haptic loop's thread set-up, with ticks of arithmetic only (no
    memory): ``work_us`` each, or, given a sequence, each tick its own in
    turn (a loop's ticks replayed as work). A slow tick of it is the
    machine's doing, so with a loop's own work its slow ticks are the share
    of the loop's that the product cannot remove. A slow tick whose
    processor time is as long was slowed without the thread knowing
    (interrupts on its processor, a hypervisor). ``frame``, if given, is
    called meanwhile as it was during the replay (the views render), so that
    the conditions are the replay's.
    """
    check = slicer.vtkHapticMachineCheck()
    check.SetRate(RATE_HZ)
    check.SetDuration(float(seconds))
    work = np.clip(np.atleast_1d(np.asarray(work_us, dtype=float)), 0.0, 0.9e6 / RATE_HZ) * 1e-6
    if len(work) == 1:
        check.SetWorkTime(float(work[0]))
    else:
        sequence = vtk.vtkDoubleArray()
        sequence.SetNumberOfValues(len(work))
        for n, value in enumerate(work):
            sequence.SetValue(n, float(value))
        check.SetWorkTimes(sequence)
    check.SetSlowTickTime(SLOW_TICK_US * 1e-6)
    check.SetRequestRealTimePriority(bool(real_time_priority))
    if not check.Start():
        raise RuntimeError("the machine check could not start (see the log)")
    frames = 0
    while check.IsRunning():
        # As the replay's display loop: frames back to back, or a display period's sleep.
        if frame is None:
            time.sleep(DISPLAY_PERIOD_S)
        else:
            frame()
            frames += 1
    check.Wait()
    return {
        "ticks": int(check.GetNumberOfTicks()),
        # The work a tick did: its median processor time, and the mean work as measured before the first tick.
        "work_us_p50": round(check.GetTickProcessorTimePercentile(50.0), 1),
        "work_us_p99": round(check.GetTickProcessorTimePercentile(99.0), 1),
        "work_us_mean_calibrated": round(check.GetCalibratedWorkTime(), 1),
        "display_frames": frames,
        "tick_us_p50": round(check.GetTickDurationPercentile(50.0), 1),
        "tick_us_p99": round(check.GetTickDurationPercentile(99.0), 1),
        "tick_us_max": round(check.GetTickDurationPercentile(100.0), 1),
        "tick_cpu_us_max": round(check.GetTickProcessorTimePercentile(100.0), 1),
        "overruns": int(check.GetNumberOfOverruns()),
        "overruns_woken_late": int(check.GetNumberOfLateWakeUpOverruns()),
        "wake_up_lateness_us_max": round(check.GetMaximumWakeUpLateness(), 1),
        "slow_ticks": int(check.GetNumberOfSlowTicks()),
        "slow_ticks_processor_bound": int(check.GetNumberOfProcessorBoundSlowTicks()),
        "real_time_priority_status": check.GetRealTimePriorityStatus(),
    }


def write_recording(path: Path, direction: np.ndarray, capabilities) -> int:
    """The hand's input, tick by tick, as a recording a replay device reads; returns its ticks."""
    recorder = slicer.vtkHapticRecorder()
    ticks = int(round(sum(seconds for seconds, _, _ in PHASES) * RATE_HZ))
    recorder.SetCapacity(ticks)
    recorder.SetRate(RATE_HZ)
    recorder.GetCapabilities().DeepCopy(capabilities)
    position = 0.0
    identity = [1.0, 0.0, 0.0, 0.0]
    for seconds, end, pedal in PHASES:
        count = int(round(seconds * RATE_HZ))
        for tick in range(count):
            depth = position + (end - position) * (tick + 1) / count
            recorder.AppendInput((depth * direction).tolist(), identity, 0, 1 if pedal else 0, True)
        position = end
    if not recorder.WriteFile(str(path)):
        raise RuntimeError(f"the haptic recording could not be written to {path} (see the log)")
    return recorder.GetNumberOfTicks()


def run(application, cut_node, plan, out_dir: Path, frame=None, prepare_shield_ahead: bool = True, scan: dict | None = None,
        asynchronous_cutting: bool = True, feel_pending_cuts: bool = True, real_time_priority: bool = True,
        check_machine: bool = True) -> dict:
    """Record a haptic drilling session beside the cavity, replay it through the haptic path; what it did.

    ``frame``, if given, is called at each display frame after the session's
    update (a view's render: the views draw the field while the haptic thread
    cuts it); otherwise this thread sleeps a display period between updates.
    ``prepare_shield_ahead`` False leaves the shield of protected structures
    to be built by the haptic thread where it first reaches it (the
    comparison for the loop's preparer, ``vtkHapticLoop.SetPrepareShieldAhead``);
    ``asynchronous_cutting`` False cuts in the ticks instead of on the loop's
    cutter thread (``vtkHapticLoop.SetAsynchronousCutting``); ``feel_pending_cuts`` False
    leaves out the segments queued and not cut yet from the force model
    (``vtkHapticLoop.SetFeelPendingCuts``: the proxy then meets the bone the
    cutter has not reached); ``real_time_priority`` False runs the loop's
    threads at normal priority (``vtkHapticLoop.SetRequestRealTimePriority``;
    on, the system may still refuse: ``real_time_priority_status`` says why).
    The replayed ticks are also saved as a complete recording
    (``haptic_session.json``, ``recording.from_haptic_ticks``) on ``scan``
    (the scan descriptor a recording names), for grading.
    ``check_machine`` then runs :func:`machine_check` for as long, with the
    replay's own processor time per tick as its work, tick by tick (the
    slowest 1 % cut to the 99th percentile), and the same display frames:
    its slow ticks and overruns are the machine's share.
    """
    logic = application.volume_cutting_logic
    scene = application.scene
    out_dir = Path(out_dir)
    surface, direction, where = target_beside(cut_node, plan)
    start = surface - STANDOFF_MM * direction
    tool, created = active_burr(scene, cut_node)
    # The handpiece held along the approach, shaft outwards: a 3-DOF device
    # moves the tool and keeps this orientation.
    pose = vtk.vtkMatrix4x4()
    rotation = recording.frame_along(direction)
    for row in range(3):
        for column in range(3):
            pose.SetElement(row, column, float(rotation[row, column]))
        pose.SetElement(row, 3, float(start[row]))
    tool.GetParentTransformNode().SetMatrixTransformToParent(pose)

    # The recording: device input only (what a device gives), with the
    # capabilities of the device it stands for (the Falcon's, as the virtual device's).
    recording_path = out_dir / "haptic_session.vchr"
    ticks = write_recording(recording_path, direction, slicer.vtkVirtualHapticDevice().GetCapabilities())

    replay = slicer.vtkReplayHapticDevice()
    if not replay.ReadFile(str(recording_path)):
        raise RuntimeError(f"the haptic recording {recording_path} could not be read back (see the log)")
    session = slicer.vtkSlicerVolumeCuttingHapticSession()
    session.SetLogic(logic)
    loop = session.GetLoop()
    loop.SetRate(RATE_HZ)
    loop.SetPrepareShieldAhead(bool(prepare_shield_ahead))
    loop.SetAsynchronousCutting(bool(asynchronous_cutting))
    loop.SetFeelPendingCuts(bool(feel_pending_cuts))
    loop.SetRequestRealTimePriority(bool(real_time_priority))
    replayed = slicer.vtkHapticRecorder()
    replayed.SetCapacity(ticks + 1000)
    loop.SetRecorder(replayed)
    removed_before = logic.GetRemovedVolume(cut_node)
    events = {"cut_modified": 0}
    observer = cut_node.AddObserver(slicer.vtkMRMLVolumeCutNode.CutModifiedEvent,
                                    lambda caller, event: events.__setitem__("cut_modified", events["cut_modified"] + 1))
    # The monitor's fields are built on the logic's worker; the replay starts once they are.
    build_started = time.perf_counter()
    monitor = nervemonitor.monitor_for(logic, cut_node)
    monitor_build_s = time.perf_counter() - build_started
    display_readings = nervemonitor.MonitorRecording(nervemonitor.thresholds(monitor) if monitor else {})
    started = time.perf_counter()
    if not session.Start(cut_node, replay):
        cut_node.RemoveObserver(observer)
        raise RuntimeError("the haptic session could not start (see the log)")
    frames = 0
    # The node's field as the loop cuts it (the logic's GetCutField may rebuild its shield: not while the loop runs).
    protection = cut_node.GetCutField().GetProtection()
    try:
        while not replay.IsFinished():
            if frame is None:
                time.sleep(DISPLAY_PERIOD_S)
            session.Update()
            if monitor is not None:
                display_readings.add(time.perf_counter() - started, nervemonitor.readings(monitor))
            if frame is not None:
                frame()
            frames += 1
    finally:
        # Read before Stop: ending the stroke may bring the logic's shield up to date, which forgets its bricks.
        shield_bricks_prepared = protection.GetNumberOfPreparedBricks()
        session.Stop()
        cut_node.RemoveObserver(observer)
    wall_s = time.perf_counter() - started
    replayed.WriteFile(str(out_dir / "haptic_replay.vchr"))
    magnitudes = []
    proxies = []
    drilling = []
    for n in range(replayed.GetNumberOfTicks()):
        force = [0.0, 0.0, 0.0]
        replayed.GetTickForce(n, force)
        magnitudes.append(float(np.linalg.norm(force)))
        proxy = [0.0, 0.0, 0.0]
        replayed.GetTickProxy(n, proxy)
        proxies.append(proxy)
        drilling.append(bool(replayed.GetTickDrilling(n)))
    magnitudes = np.array(magnitudes)
    drilling = np.array(drilling, dtype=bool)
    proxies = np.array(proxies)
    nerve_monitor = {"monitored": 0}
    tick_readings = None
    if monitor is not None:
        # The ticks measured the burr at its proxy: the same fields at the same positions give their readings.
        ticks_recording = nervemonitor.recording_along(monitor, proxies, tool.GetCuttingRadius(), 1.0 / RATE_HZ)
        nerve_monitor = {
            "monitored": monitor.GetNumberOfStructures(),
            "fields_build_s": round(monitor_build_s, 3),
            "fields_memory_mib": round(monitor.GetMemorySize() / 2**20, 1),
            "plot": str(ticks_recording.plot(out_dir / "nerve_monitor.png",
                                             title="Virtual nerve monitor during the haptic replay (every tick)",
                                             exact_below_mm=monitor.GetRange() - tool.GetCuttingRadius())),
            "table_rows": logic.GetNerveMonitorTableNode(cut_node).GetTable().GetNumberOfRows(),
            "display_updates": display_readings.summary()["samples"],
            **ticks_recording.summary(),
        }
        # The complete recording keeps the readings of every tick that moved or changed level.
        names = list(ticks_recording.distances_mm)
        tick_readings = dict(recording.monitor_header(monitor, names),
                             distances=np.array([ticks_recording.distances_mm[name] for name in names]).T,
                             levels=np.array([[nervemonitor.LEVEL_NAMES.index(level) if level in nervemonitor.LEVEL_NAMES else -1
                                               for level in ticks_recording.levels[name]] for name in names]).T)
    # How deep the burr's centre went past the surface it started from.
    deepest = float(np.max((proxies - surface) @ direction)) if len(proxies) else 0.0
    parameters = toolconfig.from_tool_node(tool)
    complete = None if not drilling.any() else recording.save(recording.from_haptic_ticks(
        proxies, magnitudes, drilling, RATE_HZ, "haptic", {"name": tool.GetName(), "burr_type": parameters.burr_type,
                                                            "radius_mm": parameters.diameter / 2.0},
        rotation, scan=scan, description="The main job's haptic session, tick by tick", monitor=tick_readings),
        out_dir / "haptic_session.json")
    tool_pose = vtk.vtkMatrix4x4()
    tool.GetParentTransformNode().GetMatrixTransformToWorld(tool_pose)
    kept = kept_tick_profiles(loop)
    profile = tick_profile(loop, profiles=kept)
    machine = None
    if check_machine and profile["ticks"]:
        # The replay's own work, tick by tick; its slowest 1 % cut to its 99th percentile, as those were slowed too.
        work = kept[:, PROFILE_FIELDS.index("cpu_us")]
        machine = machine_check(loop.GetNumberOfTicks() / RATE_HZ, np.minimum(work, np.percentile(work, 99.0)),
                                real_time_priority=real_time_priority, frame=frame)
    return {
        "target": where,
        "surface_ras_mm": [round(float(v), 2) for v in surface],
        "approach": [round(float(v), 3) for v in direction],
        "tool": tool.GetName() + (" (created)" if created else ""),
        "recording": str(recording_path),
        "replay_recording": str(out_dir / "haptic_replay.vchr"),
        "complete_recording": str(complete) if complete else None,
        "device": replay.GetCapabilities().GetModelName() or "replay",
        "ticks_recorded": ticks,
        "ticks_run": int(loop.GetNumberOfTicks()),
        "ticks_drilling": int(drilling.sum()),
        "cut_strokes": loop.GetNumberOfCutStrokes(),
        "drill_presses": loop.GetNumberOfDrillPresses(),
        "display_frames": frames,
        "cut_modified_events": events["cut_modified"],
        "removed_volume_mm3": round(logic.GetRemovedVolume(cut_node) - removed_before, 2),
        "burr_centre_depth_below_surface_mm": round(deepest, 2),
        "tool_node_moved_to_ras_mm": [round(tool_pose.GetElement(axis, 3), 2) for axis in range(3)],
        "force_max_n": round(float(magnitudes.max(initial=0.0)), 3),
        "force_mean_while_drilling_n": round(float(magnitudes[drilling].mean()) if drilling.any() else 0.0, 3),
        "tick_us_p50": round(loop.GetTickDurationPercentile(50.0), 1),
        "tick_us_p99": round(loop.GetTickDurationPercentile(99.0), 1),
        "tick_us_max": round(loop.GetMaximumTickDuration(), 1),
        "tick_cpu_us_p50": round(loop.GetTickProcessorTimePercentile(50.0), 1),
        "tick_cpu_us_p99": round(loop.GetTickProcessorTimePercentile(99.0), 1),
        "tick_cpu_us_max": round(loop.GetTickProcessorTimePercentile(100.0), 1),
        "period_jitter_us_p99": round(loop.GetPeriodJitterPercentile(99.0), 1),
        "overruns": int(loop.GetNumberOfOverruns()),
        # Overruns the thread slept through: woken later than its tick then took (the system's, not the tick's work).
        "overruns_woken_late": int(loop.GetNumberOfLateWakeUpOverruns()),
        "wake_up_lateness_us_max": round(loop.GetMaximumWakeUpLateness(), 1),
        "cut_us_p99": round(loop.GetCutDurationPercentile(99.0), 1),
        "cut_us_max": round(loop.GetCutDurationPercentile(100.0), 1),
        "asynchronous_cutting": bool(loop.GetAsynchronousCutting()),
        "feel_pending_cuts": bool(loop.GetFeelPendingCuts()),
        "cutter_us_p99": round(loop.GetCutterDurationPercentile(99.0), 1),
        "cutter_us_max": round(loop.GetCutterDurationPercentile(100.0), 1),
        "cut_latency_us_max": round(loop.GetMaximumCutLatency(), 1),
        "prepare_shield_ahead": bool(loop.GetPrepareShieldAhead()),
        "protected_segments": len(cut_node.GetProtectedSegmentIDs()),
        "shield_bricks_built_in_ticks": int(loop.GetNumberOfShieldBricksBuiltInTicks()),
        "shield_bricks_prepared_ahead": int(shield_bricks_prepared),
        "ticks_building_shield": int(loop.GetNumberOfTicksBuildingShield()),
        "tick_us_max_building_shield": round(loop.GetMaximumTickDurationBuildingShield(), 1),
        "real_time_priority": bool(loop.GetRealTimePriority()),
        "real_time_priority_status": loop.GetRealTimePriorityStatus(),
        "tick_profile": profile,
        "machine_check": machine,
        "nerve_monitor": nerve_monitor,
        "wall_s": round(wall_s, 2),
    }
