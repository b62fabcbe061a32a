"""Benchmark area ``sliceview``: a slice view following burr strokes.

A CT of the chest CT's size and grid (512 x 512 x 133 voxels, 0.7 x 0.7 x
2.5 mm, x axis flipped; synthetic values), a cut node without segments, and
an 800 x 800 axial slice view (Slicer's slice logic with the CT as background,
Slicer's slice displayable managers and vtkMRMLVolumeCutSliceDisplayableManager)
whose plane passes through a burr (5 mm) led in 0.5 mm steps along a winding
path. Strokes alternate between two measurements: the time the view's cut
overlay takes to follow the stroke (resampling the field on the plane,
outline, fill; wall and processor time), and the whole frame after the stroke
(which brings the overlay up to date as it starts), each as first call,
median, 99th percentile and maximum. The baseline of each is a frame of the
same view with nothing changed, measured right after (what drawing the view
costs anyway). vtkSMPTools runs its default backend (Sequential in the vtk
wheel), so the overlay's sampling runs on one core here.
"""

from __future__ import annotations

import time

import numpy as np

from ..scene import nodes
from ..scene.application import HeadlessSlicer, opengl_renderer_name
from .harness import machine_description, measurement, millisecond_summary

DIMENSIONS = (512, 512, 133)
SPACING = (0.7, 0.7, 2.5)
VIEW_SIZE = 800
BURR_RADIUS = 2.5
STROKES = 800


def _chest_sized_scene():
    application = HeadlessSlicer()
    j, i = np.ogrid[: DIMENSIONS[1], : DIMENSIONS[0]]
    # A bone-valued disc in air, the same on every slice.
    section = np.where((i - 256) ** 2 + (j - 256) ** 2 < 200**2, 800, -1000).astype(np.int16)
    ct = np.repeat(section[None], DIMENSIONS[2], axis=0)
    ijk_to_ras = np.diag([-SPACING[0], SPACING[1], SPACING[2], 1.0])
    ijk_to_ras[:3, 3] = [DIMENSIONS[0] * SPACING[0] / 2, -DIMENSIONS[1] * SPACING[1] / 2, -DIMENSIONS[2] * SPACING[2] / 2]
    volume = nodes.create_scalar_volume_node(application.scene, ct, ijk_to_ras, "ChestSizedCT")
    cut_node = application.volume_cutting_logic.AddVolumeCutNode(volume, None)
    view = application.create_slice_view("Axial", VIEW_SIZE, VIEW_SIZE, "Red")
    view.set_background_volume(volume)
    view.fit()
    view.set_slice_offset(0.3)
    return application, cut_node, view


def _stroke_path():
    """Poses 0.5 mm apart winding round and across the plane S = 0.3 (the burr reaches 2.5 mm)."""
    poses = [np.array([10.0, 20.0, 0.0])]
    for n in range(STROKES):
        step = np.array([0.5 * np.cos(n / 30.0), 0.5 * np.sin(n / 30.0), 0.0])
        poses.append(poses[-1] + step + [0.0, 0.0, 0.6 * (np.sin((n + 1) / 7.0) - np.sin(n / 7.0))])
    return poses


def sliceview(repeats: int) -> list[dict]:
    del repeats  # every stroke is one repeat
    application, cut_node, view = _chest_sized_scene()
    logic = application.volume_cutting_logic
    manager = view.volume_cut_displayable_manager
    view.render()
    machine = machine_description(opengl_renderer_name(view.render_window))

    update_wall, update_cpu, frame_after, frame_still, samples = [], [], [], [], []
    poses = _stroke_path()
    for n, (start, end) in enumerate(zip(poses[:-1], poses[1:])):
        if not logic.CutSphereSweep(cut_node, [float(v) for v in start], [float(v) for v in end], BURR_RADIUS):
            raise RuntimeError("sliceview benchmark: a burr stroke was refused (see the log)")
        if n % 2 == 0:
            wall, cpu = time.perf_counter(), time.process_time()
            manager.GetOutline(cut_node)  # brings the overlay up to date, as the next frame would
            update_wall.append(time.perf_counter() - wall)
            update_cpu.append(time.process_time() - cpu)
            samples.append(manager.GetNumberOfSamples(cut_node))
            view.render()
        else:
            wall = time.perf_counter()
            view.render()
            frame_after.append(time.perf_counter() - wall)
            wall = time.perf_counter()
            view.render()
            frame_still.append(time.perf_counter() - wall)
    view.close()

    still = millisecond_summary(frame_still)
    results = []
    for label, times in (("wall", update_wall), ("processor", update_cpu)):
        summary = millisecond_summary(times)
        for statistic in ("first", "median", "p99", "max"):
            results.append(measurement(
                f"slice view cut overlay update after one 5 mm burr stroke ({label} time, {statistic} of {len(times)}), "
                f"512x512x133 CT at 0.7x0.7x2.5 mm, 800x800 axial view; samples per update "
                f"{min(samples)}-{max(samples)}, field {cut_node.GetCutField().GetNumberOfAllocatedBricks()} bricks at the end",
                summary[statistic], "ms",
                f"slice view frame with nothing changed (wall, {statistic})", still[statistic], len(times), machine))
    after = millisecond_summary(frame_after)
    for statistic in ("first", "median", "p99", "max"):
        results.append(measurement(
            f"slice view frame after one burr stroke (wall, {statistic} of {len(frame_after)}), CT background and cut overlay",
            after[statistic], "ms",
            f"slice view frame with nothing changed (wall, {statistic})", still[statistic], len(frame_after), machine))
    return results
