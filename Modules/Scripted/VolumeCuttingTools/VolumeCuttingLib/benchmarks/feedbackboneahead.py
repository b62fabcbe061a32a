"""The bone left ahead of the burr (issue 25: the drill's pitch rises as it thins), for the area ``feedback``.

Accuracy: an analytic plate of bone 3.0 mm thick (its label's voxels end half
a voxel beyond its faces, so the labelled surface is the plate's), drilled
from above by a round burr of 1 mm radius down to leave 0.2 to 2.0 mm, read
by ``vtkVolumeCutBoneAhead`` from the burr's surface along the plate's normal
and at 20 and 40 degrees from it (the wall along the line is the height of
the start point over the far face over the cosine), at 0.15 mm voxels (the
temporal-bone scale) and 0.4 mm (the phantoms'); the bound is half a voxel.

Cost: the product's path per sound tick, in one process: the module logic's
``MeasureBoneAhead`` through ``soundsource.DrillSoundSource.bone_ahead_mm``
on a plate scene with a protected nerve beside the path, against the
stand-in it replaces (the nerve monitor's nearest structure,
``nervemonitor.nearest_mm``), and the query alone (``Measure``, called from
Python) on the analytic plate; and the desktop controller's whole tick
(``desktopfeedback.DesktopFeedback.tick``: the meter's rows, the bone ahead,
the sound's parameters handed to a silent output, the removed volume every
0.1 s) against the widget's display period.
"""

from __future__ import annotations

import math
import time

import numpy as np
import slicer
import vtk
from vtkmodules.util import numpy_support

from ..config import toolconfig
from ..data import boneplate
from ..feedback import audioout, desktopfeedback, nervemonitor, soundsource
from ..scene.application import HeadlessSlicer
from .harness import machine_description, measurement

PLATE_MM = 3.0
LEFT_MM = (0.2, 0.5, 1.0, 1.5, 2.0)
TILTS_DEG = (0.0, 20.0, 40.0)
SPACINGS_MM = (0.15, 0.4)
BURR = 1.0
CALLS = 2000


def _plate(spacing: float):
    """A plate of bone between z = 0 and 3 mm on a cube of side 10 mm; its label, grid and an empty cut field."""
    n = int(round(10.0 / spacing)) + 1
    origin = -(n - 1) / 2 * spacing
    z = origin + spacing * np.arange(n)
    inside = (z > 0.0 + 1e-9) & (z < PLATE_MM - 1e-9)
    labels = np.zeros((n, n, n), np.uint16)
    labels[inside, :, :] = 1
    image = vtk.vtkImageData()
    image.SetDimensions(n, n, n)
    image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(labels.ravel(), deep=1, array_type=vtk.VTK_UNSIGNED_SHORT))
    ijk_to_ras = vtk.vtkMatrix4x4()
    for axis in range(3):
        ijk_to_ras.SetElement(axis, axis, spacing)
        ijk_to_ras.SetElement(axis, 3, origin)
    field = slicer.vtkVolumeCutField()
    if not field.Initialize([n, n, n], ijk_to_ras, 2):
        raise RuntimeError("the plate's cut field could not be made")
    query = slicer.vtkVolumeCutBoneAhead()
    if not query.SetBone(image, ijk_to_ras):
        raise RuntimeError("the plate's bone was refused (see the log)")
    query.SetCutField(field)
    return query, field, origin


def _plate_accuracy(machine) -> list[dict]:
    results = []
    for spacing in SPACINGS_MM:
        query, field, _ = _plate(spacing)
        errors = []
        # Deeper and deeper: each cut leaves less, as a burr drilling down does.
        for left in sorted(LEFT_MM, reverse=True):
            centre = [0.0, 0.0, left + BURR]
            if not field.CutCapsule([0.0, 0.0, 4.9], centre, BURR):
                raise RuntimeError("the plate could not be drilled")
            for tilt in TILTS_DEG:
                angle = math.radians(tilt)
                direction = [math.sin(angle), 0.0, -math.cos(angle)]
                start = [centre[axis] + BURR * direction[axis] for axis in range(3)]
                expected = start[2] / math.cos(angle)
                errors.append(abs(query.Measure(start, direction) - expected))
        where = (f"3.0 mm plate drilled to {min(LEFT_MM)}-{max(LEFT_MM)} mm, {len(TILTS_DEG)} directions 0-40 deg, "
                 f"{spacing} mm voxels")
        results.append(measurement(f"bone ahead thickness error, max ({where})", float(max(errors)), "mm",
                                   "bound: half a voxel", spacing / 2, len(errors), machine))
    return results


def _plate_scene():
    """The desktop test's scene (``data.boneplate``), a 4 mm burr 1.75 mm from the far face after a stroke."""
    application = HeadlessSlicer()
    logic = application.volume_cutting_logic
    burr = toolconfig.from_preset(next(p for p in toolconfig.load_presets() if p.name == "Cutting burr 4 mm"))
    cut = boneplate.plate_with_nerve(application, toolconfig.create_tool_node(application.scene, burr, name="burr"))
    nervemonitor.monitor_for(logic, cut)
    pose = boneplate.drilling_pose(1.0)
    if not (logic.BeginStroke(cut) and logic.MoveActiveTool(cut, pose, logic.ToolCut) and logic.EndStroke(cut)):
        raise RuntimeError("the plate scene could not be drilled")
    return application, logic, cut


def _per_call_us(function, calls: int, clock=time.perf_counter) -> np.ndarray:
    """Microseconds per call: wall time, or with ``clock=time.thread_time`` the processor time of this thread
    (what the call costs, without the waits of a machine shared with other jobs)."""
    times = np.empty(calls)
    for n in range(calls):
        started = clock()
        function()
        times[n] = (clock() - started) * 1e6
    return times


def _cost(machine) -> list[dict]:
    application, logic, cut = _plate_scene()
    source = soundsource.DrillSoundSource(logic)
    monitor = logic.GetNerveMonitor(cut)
    source.bone_ahead_mm(cut)  # the first call makes the bone mask: not a tick's cost
    new = _per_call_us(lambda: source.bone_ahead_mm(cut), CALLS)
    old = _per_call_us(lambda: nervemonitor.nearest_mm(monitor), CALLS)
    # The desktop controller's whole tick (monitor rows, bone ahead, parameters to a silent output) on that scene.
    feedback = desktopfeedback.DesktopFeedback(logic, output=audioout.DrillSoundOutput())
    feedback.cut_node = cut
    clock = iter(np.arange(CALLS + 1) * desktopfeedback.TICK_PERIOD_S)
    ticks = _per_call_us(lambda: feedback.tick(True, float(next(clock))), CALLS)
    clock = iter(np.arange(CALLS + 1) * desktopfeedback.TICK_PERIOD_S)
    tick_cpu = _per_call_us(lambda: feedback.tick(True, float(next(clock))), CALLS, time.thread_time)
    query, field, _ = _plate(0.15)
    field.CutCapsule([0.0, 0.0, 4.9], [0.0, 0.0, 1.0 + BURR], BURR)
    start, down = [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]
    alone = _per_call_us(lambda: query.Measure(start, down), CALLS)
    where = "the logic's MeasureBoneAhead from Python, 4 mm burr on a 1.75 mm wall, 0.5 mm voxels"
    return [
        measurement(f"bone ahead per sound tick, p50 ({where})", float(np.percentile(new, 50)), "us",
                    "the stand-in it replaces (nearest monitored structure), p50", float(np.percentile(old, 50)), CALLS, machine),
        measurement(f"bone ahead per sound tick, p99 ({where})", float(np.percentile(new, 99)), "us",
                    "the stand-in it replaces (nearest monitored structure), p99", float(np.percentile(old, 99)), CALLS, machine),
        measurement("desktop feedback tick (meter rows of 1 structure, bone ahead, sound parameters), p50",
                    float(np.percentile(ticks, 50)), "us", "the widget's display tick", desktopfeedback.TICK_PERIOD_S * 1e6,
                    CALLS, machine),
        measurement("desktop feedback tick (meter rows of 1 structure, bone ahead, sound parameters), p99",
                    float(np.percentile(ticks, 99)), "us", "the widget's display tick", desktopfeedback.TICK_PERIOD_S * 1e6,
                    CALLS, machine),
        measurement("desktop feedback tick, processor time of its thread, p99", float(np.percentile(tick_cpu, 99)), "us",
                    "the widget's display tick", desktopfeedback.TICK_PERIOD_S * 1e6, CALLS, machine),
        measurement("bone ahead query alone (vtkVolumeCutBoneAhead.Measure from Python, 1.0 mm wall at 0.15 mm voxels), p50",
                    float(np.percentile(alone, 50)), "us", "one sound tick at 75 Hz", 1e6 / 75.0, CALLS, machine),
    ]


def bone_ahead_measurements(repeats: int) -> list[dict]:
    """The bone-ahead query's accuracy on an analytic plate and its cost per sound tick."""
    machine = machine_description()
    return _plate_accuracy(machine) + _cost(machine)
