"""An analytic scene for the drill's feedback: a plate of bone with a nerve canal beside the burr's path.

The plate (segment "Bone", cuttable) fills the grid between x = -5.25 and
4.75 mm: its labelled voxels end half a voxel inside those faces, where the
interpolated label crosses one half. The nerve canal (segment "Nerve",
protected) runs along z at x = 2, y = 4.5 mm with a radius of about 1 mm, in
the bone. A burr that drills along +x at y = z = 0 (``drilling_pose``) has the
plate's far face ahead of it and the nerve to its side: the wall ahead of its
tip and its distance to the nerve differ, so a test tells one from the other.
Voxels of 0.5 mm, 40 x 28 x 24, a 1200 HU plate in air.
"""

from __future__ import annotations

import numpy as np
import vtk

from ..scene import nodes

SPACING = 0.5
FAR_FACE_X = 4.75
NERVE_X, NERVE_Y = 2.0, 4.5


def plate_with_nerve(application, tool_node=None):
    """Add the plate's CT, segmentation and a cut node (roles set; ``tool_node`` its active tool) to the
    application's scene; the cut node."""
    shape = (24, 28, 40)  # k, j, i
    origin = (-10.0, -7.0, -6.0)
    ijk_to_ras = np.diag([SPACING, SPACING, SPACING, 1.0])
    ijk_to_ras[:3, 3] = origin
    k, j, i = np.mgrid[0:shape[0], 0:shape[1], 0:shape[2]]
    x, y = origin[0] + SPACING * i, origin[1] + SPACING * j
    bone = (x > -5.2) & (x < 4.7)
    volume = nodes.create_scalar_volume_node(application.scene, np.where(bone, 1200, -1000).astype(np.int16), ijk_to_ras, "CT")
    labels = np.zeros(shape, np.uint8)
    labels[bone] = 1
    labels[bone & ((x - NERVE_X) ** 2 + (y - NERVE_Y) ** 2 <= 1.0)] = 2
    segmentation = nodes.create_segmentation_from_labels(application.scene, volume, labels, {1: "Bone", 2: "Nerve"}, "Anatomy")
    cut = application.volume_cutting_logic.AddVolumeCutNode(volume, segmentation)
    cut.SetCuttableSegmentIDs(["Bone"])
    cut.SetProtectedSegmentIDs(["Nerve"])
    cut.SetSurfaceIsoValue(300.0)
    if tool_node is not None:
        cut.SetAndObserveActiveToolNodeID(tool_node.GetID())
    return cut


def drilling_pose(x: float) -> vtk.vtkMatrix4x4:
    """A tool at (x, 0, 0) with its shaft (local z) along -x: it drills towards +x, the far face ahead."""
    matrix = vtk.vtkMatrix4x4()
    matrix.DeepCopy((0.0, 0.0, -1.0, float(x),
                     0.0, 1.0, 0.0, 0.0,
                     1.0, 0.0, 0.0, 0.0,
                     0.0, 0.0, 0.0, 1.0))
    return matrix
