"""The logic drills with tool nodes from any source, and keeps tables and events for the GUI.

Real scene, real tool nodes from the shipped presets, real segments: a pose
stream through MoveActiveTool cuts exactly what the equivalent direct sweep
cuts; a tool's own sensibility keeps it out of segments it may not cut; the
removed-volume table and the contact table follow the strokes; a tool going
into a protected segment raises the node's ProtectedContactEvent.
"""

import numpy as np
import pytest
import slicer
import vtk

from VolumeCuttingLib.config import toolconfig
from VolumeCuttingLib.scene import nodes
from VolumeCuttingLib.scene.application import HeadlessSlicer

SHAPE = (30, 48, 48)  # k, j, i
SPACING = (0.5, 0.5, 0.8)


def session():
    application = HeadlessSlicer()
    scene = application.scene
    logic = application.volume_cutting_logic
    ijk_to_ras = np.diag([SPACING[0], SPACING[1], SPACING[2], 1.0])
    ijk_to_ras[:3, 3] = [-12.0, -12.0, -12.0]
    k, j, i = np.mgrid[0 : SHAPE[0], 0 : SHAPE[1], 0 : SHAPE[2]]
    ct = np.where((i > 8) & (i < 40) & (j > 8) & (j < 40) & (k > 4) & (k < 26), 1200, -1000).astype(np.int16)
    volume = nodes.create_scalar_volume_node(scene, ct, ijk_to_ras, "CT")
    labels = np.zeros(SHAPE, np.uint8)
    labels[ct > 0] = 1
    labels[(ct > 0) & (i >= 30)] = 2  # "Cortex": a slab of the block
    labels[(ct > 0) & ((j - 24) ** 2 + (k - 15) ** 2 <= 4) & (i < 30)] = 3  # "Nerve": a canal along i
    segmentation = nodes.create_segmentation_from_labels(scene, volume, labels, {1: "Bone", 2: "Cortex", 3: "Nerve"}, "Anatomy")
    cut = logic.AddVolumeCutNode(volume, segmentation)
    cut.SetCuttableSegmentIDs(["Bone", "Cortex"])
    cut.SetProtectedSegmentIDs(["Nerve"])

    def ras(i_, j_, k_):
        return (ijk_to_ras @ np.array([i_, j_, k_, 1.0]))[:3]

    return application, logic, cut, ras


def preset(name):
    return next(p for p in toolconfig.load_presets() if p.name == name)


def pose(translation, angle_degrees=0.0):
    matrix = vtk.vtkMatrix4x4()
    transform = vtk.vtkTransform()
    transform.Translate(*translation)
    transform.RotateX(angle_degrees)
    matrix.DeepCopy(transform.GetMatrix())
    return matrix


def fields_equal(a, b):
    dims = a.GetBrickDimensions()
    x = np.zeros(512, np.int16)
    y = np.zeros(512, np.int16)
    for brick in range(dims[0] * dims[1] * dims[2]):
        a.CopyBrick(brick, x)
        b.CopyBrick(brick, y)
        if not np.array_equal(x, y):
            return False
    return True


def test_pose_stream_cuts_like_the_direct_sweep():
    application, logic, cut, ras = session()
    tool = toolconfig.create_tool_node(application.scene, toolconfig.from_preset(preset("Cutting burr 4 mm")), "Burr")
    cut.SetAndObserveActiveToolNodeID(tool.GetID())
    path = [ras(12, 20, 10) + [0.0, 0.3 * n, 0.0] for n in range(12)]
    assert logic.BeginStroke(cut)
    for point in path:
        assert logic.MoveActiveTool(cut, pose(point, 5.0 * len(point)), logic.ToolCut)
    assert logic.EndStroke(cut)
    # The tool's transform node followed the stream.
    transform = tool.GetParentTransformNode()
    matrix = vtk.vtkMatrix4x4()
    transform.GetMatrixTransformToParent(matrix)
    assert [matrix.GetElement(r, 3) for r in range(3)] == pytest.approx(list(path[-1]))
    assert cut.GetCutField().GetNumberOfUndoSteps() == 1

    # The same stroke as direct capsules of the same radius: the same field, bit for bit.
    other, other_logic, other_cut, _ = session()
    assert other_logic.BeginStroke(other_cut)
    assert other_logic.CutSphereSweep(other_cut, list(path[0]), list(path[0]), 2.0)
    for p0, p1 in zip(path[:-1], path[1:]):
        assert other_logic.CutSphereSweep(other_cut, list(p0), list(p1), 2.0)
    assert other_logic.EndStroke(other_cut)
    assert fields_equal(logic.GetCutField(cut), other_logic.GetCutField(other_cut))

    # Moving without cutting changes nothing; outside a stroke neither.
    before = logic.GetRemovedVolume(cut)
    assert logic.MoveActiveTool(cut, pose(ras(30, 30, 15)), logic.ToolMove)
    assert logic.MoveActiveTool(cut, pose(ras(31, 30, 15)), logic.ToolCut)
    assert logic.GetRemovedVolume(cut) == before


def test_shaped_tools_sweep_their_shape():
    application, logic, cut, ras = session()
    for name, expected_class in (("Matchstick burr 3 mm", "vtkVolumeCutCylinderTool"), ("Oscillating disk saw 20 mm", "vtkVolumeCutCylinderTool"),
                                 ("Sagittal saw blade 10 mm", "vtkVolumeCutBoxTool")):
        tool = toolconfig.create_tool_node(application.scene, toolconfig.from_preset(preset(name)), name)
        cut.SetAndObserveActiveToolNodeID(tool.GetID())
        built = logic.GetCuttingTool(tool)
        assert built is not None and built.GetClassName() == expected_class
        # Its sweep equals the VTK tool's own sweep on a fresh session.
        p0, p1 = pose(ras(20, 20, 12)), pose(ras(24, 22, 12), 20.0)
        assert logic.CutWithActiveTool(cut, p0, p1)
        other, other_logic, other_cut, _ = session()
        assert other_logic.CutToolSweep(other_cut, built, p0, p1)
        assert fields_equal(logic.GetCutField(cut), other_logic.GetCutField(other_cut)), name
        logic.ClearCut(cut)
    # Geometry edits rebuild the tool (the last one is the blade: thickness along y).
    tool.SetThickness(1.0)
    assert logic.GetCuttingTool(tool).GetSize()[1] == pytest.approx(1.0)


def test_tool_sensibility_and_bad_requests():
    application, logic, cut, ras = session()
    tool = toolconfig.create_tool_node(application.scene, toolconfig.from_preset(preset("Diamond burr 3 mm")), "Diamond")
    cut.SetAndObserveActiveToolNodeID(tool.GetID())
    # This tool may cut the cortex only, whatever the roles say of the bone.
    tool.SetUseCutNodeRoles(False)
    tool.SetCuttableSegmentIDs(["Cortex"])
    assert "Bone" in logic.GetShieldedSegmentIDs(cut)
    path = (pose(ras(20, 20, 12)), pose(ras(36, 20, 12)))
    assert logic.CutWithActiveTool(cut, *path)
    assert logic.GetRemovedVolumeInSegment(cut, "Bone") == 0.0
    assert logic.GetRemovedVolumeInSegment(cut, "Cortex") > 5.0
    assert logic.GetContactSegmentID(cut) == "Bone"
    # With the roles it cuts the bone too.
    tool.SetUseCutNodeRoles(True)
    assert logic.CutWithActiveTool(cut, *path)
    assert logic.GetRemovedVolumeInSegment(cut, "Bone") > 5.0

    mesh = toolconfig.create_tool_node(application.scene, toolconfig.ToolParameters(shape="Mesh"), "Mesh without model")
    cut.SetAndObserveActiveToolNodeID(mesh.GetID())
    assert not logic.CutWithActiveTool(cut, *path)  # logs: no model with a surface
    cut.SetAndObserveActiveToolNodeID(None)
    assert not logic.CutWithActiveTool(cut, *path)
    assert not logic.MoveActiveTool(cut, path[0], logic.ToolCut)
    cut.SetAndObserveActiveToolNodeID(tool.GetID())
    nan_pose = pose([float("nan"), 0.0, 0.0])
    assert not logic.MoveActiveTool(cut, nan_pose, logic.ToolCut)


def test_tables_and_contact_events():
    application, logic, cut, ras = session()
    tool = toolconfig.create_tool_node(application.scene, toolconfig.from_preset(preset("Cutting burr 3 mm")), "Burr")
    cut.SetAndObserveActiveToolNodeID(tool.GetID())
    table = logic.GetRemovedVolumeTableNode(cut)
    assert table.GetNumberOfRows() == 3
    assert [table.GetCellText(r, 0) for r in range(3)] == ["Bone", "Cortex", "Nerve"]
    assert [table.GetCellText(r, 2) for r in range(3)] == ["cuttable", "cuttable", "protected"]
    assert all(float(table.GetCellText(r, 3)) == 0.0 for r in range(3))

    # Hovering near the nerve builds its shield before the burr cuts there.
    protection = logic.GetCutField(cut).GetProtection()
    built = protection.GetNumberOfBuiltBricks()
    assert logic.MoveActiveTool(cut, pose(ras(12, 24, 15)), logic.ToolMove)
    assert protection.GetNumberOfShieldBricks() > 0 and protection.GetNumberOfBuiltBricks() > built
    assert logic.GetRemovedVolume(cut) == 0.0

    events = []
    observer = cut.AddObserver(slicer.vtkMRMLVolumeCutNode.ProtectedContactEvent, lambda caller, event: events.append(logic.GetCutField(cut).GetMaximumContactDepth()))
    # Along the nerve's canal, into it: the nerve stops the burr.
    assert logic.BeginStroke(cut)
    for n in range(10):
        assert logic.MoveActiveTool(cut, pose(ras(12 + n, 24, 15)), logic.ToolCut)
    assert logic.EndStroke(cut)
    cut.RemoveObserver(observer)
    assert events and events == sorted(events)  # raised as the burr went deeper
    removed = {table.GetCellText(r, 0): float(table.GetCellText(r, 3)) for r in range(table.GetNumberOfRows())}
    assert removed["Nerve"] == 0.0
    assert removed["Bone"] == pytest.approx(logic.GetRemovedVolumeInSegment(cut, "Bone"), abs=1e-3)
    assert removed["Bone"] > 1.0
    contacts = logic.GetContactTableNode(cut)
    assert contacts.GetNumberOfRows() == 1
    assert contacts.GetCellText(0, 0) == "Nerve" and contacts.GetCellText(0, 1) == "Nerve"
    assert float(contacts.GetCellText(0, 3)) == pytest.approx(events[-1], rel=1e-6)
    # Undo updates the table; the tables are referenced by the cut node and saved.
    assert logic.UndoStroke(cut)
    assert float(table.GetCellText(0, 3)) == 0.0
    assert cut.GetNodeReference(logic.GetRemovedVolumeTableReferenceRole()) is table
    assert cut.GetNodeReference(logic.GetContactTableReferenceRole()) is contacts
