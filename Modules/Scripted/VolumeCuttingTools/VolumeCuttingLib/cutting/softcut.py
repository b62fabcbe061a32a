"""SoftCut from Python: the logic on a headless scene, and outlines drawn as a user draws them.

``create_logic`` gives a ``vtkSlicerVolumeCuttingSoftCutLogic`` wired to a
``HeadlessSlicer``'s scene and volume-cutting logic, as the desktop module
does. ``outline_by_picking`` places a closed markups curve on the skin the way
a user clicking in a 3D view does: each point where the ray from a camera
position along the view direction first meets the skin (the CT's
iso-surface, found by stepping and bisection on the trilinear CT);
``add_outline`` makes the curve from points already on the skin, optionally
in several sittings (the curve is the same whichever way it was drawn).
"""

from __future__ import annotations

import numpy as np
import slicer
import vtk

from ..scene import nodes


def create_logic(application):
    """A SoftCut logic on the application's scene, carving through its volume-cutting logic."""
    logic = slicer.vtkSlicerVolumeCuttingSoftCutLogic()
    logic.SetMRMLScene(application.scene)
    logic.SetVolumeCuttingLogic(application.volume_cutting_logic)
    return logic


class SkinSampler:
    """Trilinear CT values of a volume node at RAS points, for picking the skin."""

    def __init__(self, volume_node):
        self.values = nodes.array_from_volume_node(volume_node).astype(np.float32)
        self.ras_to_ijk = np.linalg.inv(nodes.volume_node_ijk_to_ras(volume_node))

    def __call__(self, ras):
        ijk = (self.ras_to_ijk @ np.append(np.asarray(ras, dtype=float), 1.0))[:3]
        shape = self.values.shape
        base = np.floor(ijk).astype(int)
        fraction = ijk - base
        value = 0.0
        for corner in range(8):
            offset = np.array([corner & 1, (corner >> 1) & 1, (corner >> 2) & 1])
            i, j, k = np.clip(base + offset, 0, np.array(shape[::-1]) - 1)
            weight = np.prod(np.where(offset, fraction, 1.0 - fraction))
            value += weight * self.values[k, j, i]
        return float(value)

    def first_hit(self, origin, direction, iso, length=400.0, step=0.25):
        """Where the ray first crosses the iso-value upwards (RAS), or None."""
        direction = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
        origin = np.asarray(origin, dtype=float)
        previous = 0.0
        for t in np.arange(step, length, step):
            if self(origin + t * direction) >= iso:
                lo, hi = previous, t
                for _ in range(30):
                    mid = 0.5 * (lo + hi)
                    if self(origin + mid * direction) >= iso:
                        hi = mid
                    else:
                        lo = mid
                return origin + 0.5 * (lo + hi) * direction
            previous = t
        return None


def picked_points(volume_node, center, view_direction, radii, count=24, iso=-500.0, view_up=(0.0, 0.0, 1.0), distance=200.0):
    """Skin points (RAS) along an ellipse around ``center`` as seen along ``view_direction``.

    The ellipse has semi-axes ``radii`` (mm) along the view's right and up
    directions; each of its ``count`` points is picked by casting a ray
    from ``distance`` mm in front of it along the view direction.
    """
    sampler = SkinSampler(volume_node)
    forward = np.asarray(view_direction, dtype=float)
    forward /= np.linalg.norm(forward)
    up = np.asarray(view_up, dtype=float)
    up = up - np.dot(up, forward) * forward
    up /= np.linalg.norm(up)
    right = np.cross(forward, up)
    points = []
    for angle in np.linspace(0.0, 2.0 * np.pi, count, endpoint=False):
        target = np.asarray(center, dtype=float) + radii[0] * np.cos(angle) * right + radii[1] * np.sin(angle) * up
        hit = sampler.first_hit(target - distance * forward, forward, iso, length=2.0 * distance)
        if hit is None:
            raise ValueError(f"the ray through {target.round(1).tolist()} along {forward.round(2).tolist()} misses the skin")
        points.append(hit)
    return np.array(points)


def add_outline(scene, points, name="Resection outline", sittings=1):
    """A closed markups curve through skin points (RAS), placed in ``sittings`` batches.

    A user may stop drawing, turn the view and go on: the curve's control
    points are appended in order whichever way the drawing was split.
    """
    curve = scene.AddNewNodeByClass("vtkMRMLMarkupsClosedCurveNode", name)
    batches = np.array_split(np.asarray(points, dtype=float), max(1, sittings))
    for batch in batches:
        for point in batch:
            curve.AddControlPointWorld(vtk.vtkVector3d(*point))
    return curve


def outline_by_picking(scene, volume_node, center, view_direction, radii, count=24, iso=-500.0, view_up=(0.0, 0.0, 1.0),
                       name="Resection outline", sittings=1):
    """A closed curve picked on the skin along an ellipse seen along ``view_direction`` (see ``picked_points``)."""
    points = picked_points(volume_node, center, view_direction, radii, count=count, iso=iso, view_up=view_up)
    return add_outline(scene, points, name=name, sittings=sittings)


def table_rows(table_node):
    """A resection table as {measurement: (value, unit)}."""
    table = table_node.GetTable()
    rows = {}
    for row in range(table.GetNumberOfRows()):
        rows[table.GetValueByName(row, "Measurement").ToString()] = (
            table.GetValueByName(row, "Value").ToDouble(), table.GetValueByName(row, "Unit").ToString())
    return rows
