"""The module logic's bone ahead of the tool: the wall left between the burr's tip and the far side of the bone.

The block of ``test_haptic_session``: its "Bone" segment (cuttable) is a box
whose labelled voxels end half a voxel beyond x = +-7.5 mm, with the nerve
canal (protected, not bone) from x = 3.25 mm on along the x axis. A 4 mm burr
(radius 2 mm) drills along +x from outside the block with its shaft behind it
(local z = -x): ahead of its tip (x + 2) the bone runs to the canal, so the
wall is 3.25 - x - 2 mm, and the query (Range and MaximumThickness 4 mm)
reads that within half a voxel (0.25 mm) once the wall is thinner than 4 mm.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import vtk

from test_haptic_session import add_burr, block_scene

CANAL_X = 3.25
BURR_RADIUS = 2.0
HALF_VOXEL = 0.25


def pose_along_x(x):
    """The burr at (x, 0, 0) with its shaft along -x (it drills towards +x)."""
    matrix = vtk.vtkMatrix4x4()
    for row, column in ((0, 0.0), (1, 0.0), (2, 1.0)):
        matrix.SetElement(row, 0, column)
    matrix.SetElement(1, 1, 1.0)
    matrix.SetElement(2, 1, 0.0)
    matrix.SetElement(0, 2, -1.0)
    matrix.SetElement(2, 2, 0.0)
    matrix.SetElement(0, 3, float(x))
    return matrix


def test_the_wall_ahead_thins_as_the_burr_drills_towards_the_canal():
    application, logic, cut = block_scene()
    add_burr(application.scene, cut)
    assert math.isinf(logic.MeasureBoneAhead(cut, pose_along_x(-14.5)))  # tip 4.75 mm from the bone: beyond Range
    assert logic.MeasureBoneAhead(cut, pose_along_x(-13.0)) == pytest.approx(4.0)  # a thick wall reads as the maximum
    assert logic.BeginStroke(cut)
    readings = []
    for x in np.arange(-13.0, 1.01, 0.25):
        assert logic.MoveActiveTool(cut, pose_along_x(x), logic.ToolCut)
        # The tool's own pose (its transform node, which MoveActiveTool moved) and a given one read alike.
        thickness = logic.MeasureBoneAhead(cut)
        assert thickness == logic.MeasureBoneAhead(cut, pose_along_x(x))
        expected = CANAL_X - x - BURR_RADIUS
        if expected < 4.0 - HALF_VOXEL:
            assert thickness == pytest.approx(expected, abs=HALF_VOXEL), x
            readings.append(thickness)
    assert logic.EndStroke(cut)
    assert len(readings) > 10 and np.all(np.diff(readings) < 0)
    # Through the wall (the tip in the canal): nothing ahead but the canal, then the block's far side beyond Range.
    assert math.isinf(logic.MeasureBoneAhead(cut, pose_along_x(CANAL_X - BURR_RADIUS + 0.5)))


def test_without_bone_or_tool_nothing_thins():
    application, logic, cut = block_scene()
    assert math.isinf(logic.MeasureBoneAhead(cut, pose_along_x(0.0)))  # no active tool
    add_burr(application.scene, cut)
    cut.SetCuttableSegmentIDs([])
    assert math.isinf(logic.MeasureBoneAhead(cut, pose_along_x(0.0)))
    assert logic.GetBoneAhead(cut) is None
    cut.SetCuttableSegmentIDs(["Bone"])
    assert logic.GetBoneAhead(cut) is not None
    assert logic.MeasureBoneAhead(cut, pose_along_x(0.0)) == pytest.approx(CANAL_X - 0.0 - BURR_RADIUS, abs=HALF_VOXEL)
