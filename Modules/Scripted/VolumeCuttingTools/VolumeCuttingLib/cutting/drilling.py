"""Scripted drilling: a cortical mastoidectomy path, replayed through the module logic.

A cortical mastoidectomy removes the lateral mastoid cortex and air cells in a
saucer: wide at the surface, narrower with depth, so the surgeon keeps sight of
the burr. The path here is that saucer as layers of parallel passes of a
spherical burr, each pass a user stroke (one undo step) made of small device
poses, as a haptic device at 1 kHz would deliver them.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from vtkmodules.util import numpy_support


@dataclass
class MastoidectomyPlan:
    """Geometry of the saucer, in mm, approached along ``direction`` (RAS)."""

    entry: np.ndarray  # a point of the lateral bone surface, centre of the saucer
    direction: np.ndarray = field(default_factory=lambda: np.array([-1.0, 0.0, 0.0]))  # into the bone
    surface_radius: float = 9.0
    depth: float = 10.0
    bottom_radius_fraction: float = 0.4
    burr_radius: float = 2.5
    layer_step: float = 1.0
    pass_spacing: float = 1.5
    pose_step: float = 0.5

    def strokes(self):
        """Yield each pass as an array of poses (N x 3, RAS mm)."""
        direction = self.direction / np.linalg.norm(self.direction)
        # Two axes across the approach direction.
        helper = np.array([0.0, 0.0, 1.0]) if abs(direction[2]) < 0.9 else np.array([0.0, 1.0, 0.0])
        across = np.cross(direction, helper)
        across /= np.linalg.norm(across)
        along = np.cross(direction, across)
        for depth in np.arange(0.0, self.depth + 1e-9, self.layer_step):
            # Burr centre depth: the first layer skims the surface.
            radius = self.surface_radius * (1.0 - (1.0 - self.bottom_radius_fraction) * depth / self.depth)
            center = self.entry + (depth + 0.5 * self.burr_radius) * direction
            for offset in np.arange(-radius, radius + 1e-9, self.pass_spacing):
                half_chord = np.sqrt(max(radius ** 2 - offset ** 2, 0.0))
                if half_chord <= 0.0:
                    continue
                count = max(int(np.ceil(2.0 * half_chord / self.pose_step)), 1)
                t = np.linspace(-half_chord, half_chord, count + 1)
                yield center + offset * across + t[:, None] * along


def lateral_entry(volume_node, y: float, z: float, threshold: float = 700.0) -> np.ndarray:
    """The first bone (>= threshold) met coming from the patient's right (+x) at (y, z)."""
    image = volume_node.GetImageData()
    dims = image.GetDimensions()
    voxels = numpy_support.vtk_to_numpy(image.GetPointData().GetScalars()).reshape(dims[2], dims[1], dims[0])
    import vtk

    ras_to_ijk = vtk.vtkMatrix4x4()
    volume_node.GetRASToIJKMatrix(ras_to_ijk)
    bounds = [0.0] * 6
    volume_node.GetRASBounds(bounds)
    for x in np.arange(bounds[1], bounds[0], -0.25):
        i, j, k, _ = ras_to_ijk.MultiplyPoint([x, y, z, 1.0])
        i, j, k = int(round(i)), int(round(j)), int(round(k))
        if 0 <= i < dims[0] and 0 <= j < dims[1] and 0 <= k < dims[2] and voxels[k, j, i] >= threshold:
            return np.array([x, y, z])
    raise ValueError(f"no bone above {threshold} HU along x at y={y:.1f}, z={z:.1f} mm")


def lateral_entry_into_segments(segmentation_node, segment_ids, direction=(-1.0, 0.0, 0.0)) -> np.ndarray:
    """Where a tool moving along ``direction`` (default: from the patient's right) first meets the segments.

    The approach line runs through the centre of the segments' bounds, or,
    if that line misses them, the nearest parallel line that meets them; the
    entry is the centre of the first segment voxel along it (RAS mm). This is
    ``lateral_entry`` for any segmentation, on any voxel grid.
    """
    import slicer
    import vtk

    direction = np.asarray(direction, dtype=float)
    direction /= np.linalg.norm(direction)
    segmentation = segmentation_node.GetSegmentation()
    points, voxel_sizes = [], []
    for segment_id in segment_ids:
        segment = segmentation.GetSegment(segment_id)
        labelmap = slicer.vtkOrientedImageData()
        if segment is None or not slicer.vtkSlicerSegmentationsModuleLogic.GetSegmentBinaryLabelmapRepresentation(
                segmentation_node, segment_id, labelmap):
            raise ValueError(f"segment {segment_id!r} of {segmentation_node.GetName()!r} has no binary labelmap")
        extent = labelmap.GetExtent()
        if extent[1] < extent[0] or extent[3] < extent[2] or extent[5] < extent[4]:
            continue
        dims = labelmap.GetDimensions()
        voxels = numpy_support.vtk_to_numpy(labelmap.GetPointData().GetScalars()).reshape(dims[2], dims[1], dims[0])
        # Segments may share one labelmap, each with its own label value.
        kji = np.argwhere(voxels == segment.GetLabelValue())
        if len(kji) == 0:
            continue
        image_to_world = vtk.vtkMatrix4x4()
        labelmap.GetImageToWorldMatrix(image_to_world)
        matrix = np.array([[image_to_world.GetElement(r, c) for c in range(4)] for r in range(4)])
        ijk = kji[:, ::-1] + np.array(extent[0::2])
        points.append(ijk @ matrix[:3, :3].T + matrix[:3, 3])
        voxel_sizes.append(float(np.linalg.norm(matrix[:3, :3], axis=0).max()))
    if not points:
        raise ValueError(f"the segments {list(segment_ids)} of {segmentation_node.GetName()!r} are empty: nothing to drill")
    points = np.concatenate(points)
    center = (points.min(axis=0) + points.max(axis=0)) / 2.0
    offsets = points - center
    along = offsets @ direction
    across = np.linalg.norm(offsets - along[:, None] * direction, axis=1)
    near_line = across <= across.min() + max(voxel_sizes)
    first = np.argmin(np.where(near_line, along, np.inf))
    return points[first]


def drill(logic, cut_node, plan: MastoidectomyPlan) -> dict:
    """Replay the plan through the logic; return counts and per-pose timings."""
    pose_times = []
    strokes = 0
    refused = 0
    for poses in plan.strokes():
        if not logic.BeginStroke(cut_node):
            raise RuntimeError("the cut node has no cut field (see the log)")
        for p0, p1 in zip(poses[:-1], poses[1:]):
            start = time.perf_counter()
            ok = logic.CutSphereSweep(cut_node, p0, p1, plan.burr_radius)
            pose_times.append(time.perf_counter() - start)
            refused += not ok
        logic.EndStroke(cut_node)
        strokes += 1
    times_ms = 1000.0 * np.array(pose_times) if pose_times else np.zeros(1)
    return {
        "strokes": strokes,
        "poses": len(pose_times),
        "refused_poses": refused,
        "pose_time_ms_p50": round(float(np.percentile(times_ms, 50)), 4),
        "pose_time_ms_p99": round(float(np.percentile(times_ms, 99)), 4),
    }
