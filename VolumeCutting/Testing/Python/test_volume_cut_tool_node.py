"""The cutting-tool node in a real scene from Python: scene bundles and undo.

The C++ test (vtkMRMLVolumeCutToolNodeTest1) covers validation and the scene
XML; here the node goes through Slicer's own bundle writer and reader, with
its pose transform, display node and mesh, as a saved session would.
"""

import numpy as np
import pytest
import slicer
import vtk
from vtkmodules.util import numpy_support

from VolumeCuttingLib.scene.application import HeadlessSlicer

Tool = slicer.vtkMRMLVolumeCutToolNode


def pose_matrix():
    """A rigid pose: a rotation about an oblique axis and a translation."""
    transform = vtk.vtkTransform()
    transform.Translate(12.5, -30.25, 41.0)
    transform.RotateWXYZ(37.0, 1.0, 2.0, 3.0)
    return transform.GetMatrix()


def add_tool_session(scene):
    """A disk saw with every property off its default, posed, with a glyph and a mesh."""
    pose = scene.AddNewNodeByClass("vtkMRMLLinearTransformNode", "Saw pose")
    pose.SetMatrixTransformToParent(pose_matrix())
    cube = vtk.vtkCubeSource()
    cube.SetBounds(-1.0, 2.0, -0.5, 0.5, -3.0, 0.0)
    cube.Update()
    mesh = scene.AddNewNodeByClass("vtkMRMLModelNode", "Saw mesh")
    mesh.SetAndObservePolyData(cube.GetOutput())
    tool = scene.AddNewNodeByClass("vtkMRMLVolumeCutToolNode", "Saw")
    tool.SetShape(Tool.DiskSaw)
    tool.SetBurrType(Tool.Diamond)
    tool.SetDiameter(18.25)
    tool.SetLength(7.5)
    tool.SetThickness(0.45)
    tool.SetWidth(8.0)
    tool.SetPower(0.6)
    tool.SetSpeed(11000.0)
    tool.SetUseCutNodeRoles(False)
    tool.SetCuttableSegmentIDs(["Lamina", "SpinousProcess"])
    tool.SetAndObserveMeshModelNodeID(mesh.GetID())
    tool.SetAndObserveTransformNodeID(pose.GetID())
    tool.CreateDefaultDisplayNodes()
    display = tool.GetVolumeCutToolDisplayNode()
    display.SetColor(0.2, 0.6, 0.9)
    display.SetOpacity(0.8)
    display.SetShowAxis(False)
    display.SetGlyphOpacityWhileCutting(0.15)
    return tool


def tool_state(tool):
    """Everything a saved tool must bring back, as comparable values."""
    display = tool.GetVolumeCutToolDisplayNode()
    matrix = vtk.vtkMatrix4x4()
    tool.GetParentTransformNode().GetMatrixTransformToParent(matrix)
    mesh = tool.GetMeshModelNode()
    points = numpy_support.vtk_to_numpy(mesh.GetPolyData().GetPoints().GetData())
    return {
        "name": tool.GetName(),
        "shape": Tool.GetShapeAsString(tool.GetShape()),
        "burr": Tool.GetBurrTypeAsString(tool.GetBurrType()),
        "sizes": (tool.GetDiameter(), tool.GetLength(), tool.GetThickness(), tool.GetWidth()),
        "drive": (tool.GetPower(), tool.GetSpeed()),
        "sensibility": (tool.GetUseCutNodeRoles(), tool.GetCuttableSegmentIDs()),
        "pose name": tool.GetParentTransformNode().GetName(),
        "pose": [matrix.GetElement(r, c) for r in range(4) for c in range(4)],
        "display": (display.GetClassName(), display.GetColor(), display.GetOpacity(), display.GetShowAxis(),
                    display.GetGlyphOpacityWhileCutting()),
        "mesh": (mesh.GetName(), points.tolist()),
    }


def test_scene_bundle_round_trip(tmp_path):
    application = HeadlessSlicer()
    tool = add_tool_session(application.scene)
    saved = tool_state(tool)
    bundle = application.save_bundle(tmp_path / "tool.mrb")

    reloaded = HeadlessSlicer()
    reloaded.load_bundle(bundle)
    tools = [reloaded.scene.GetNthNodeByClass(i, "vtkMRMLVolumeCutToolNode")
             for i in range(reloaded.scene.GetNumberOfNodesByClass("vtkMRMLVolumeCutToolNode"))]
    assert len(tools) == 1
    read = tool_state(tools[0])
    # The tool's own properties come back bit for bit (scene XML writes doubles
    # in full). The pose is Slicer's transform file, an ITK transform in LPS:
    # the conversion from and to RAS may round the last bit.
    assert read.pop("pose") == pytest.approx(saved.pop("pose"), rel=0.0, abs=1e-12)
    assert read == saved
    assert reloaded.scene.GetNumberOfNodesByClass("vtkMRMLVolumeCutToolDisplayNode") == 1
    assert tools[0].GetBoundingRadius() == pytest.approx(np.hypot(18.25 / 2, 0.45 / 2))


def test_undo_restores_the_tool(tmp_path):
    application = HeadlessSlicer()
    scene = application.scene
    tool = add_tool_session(scene)
    saved = tool_state(tool)
    scene.SetUndoOn()
    scene.SaveStateForUndo()
    tool.SetShape(Tool.Sphere)
    tool.SetDiameter(2.0)
    tool.SetSpeed(80000.0)
    tool.GetVolumeCutToolDisplayNode().SetShowAxis(True)
    scene.Undo()
    assert tool_state(scene.GetFirstNodeByClass("vtkMRMLVolumeCutToolNode")) == saved


def test_bad_values_are_refused_from_python():
    tool = Tool()
    tool.SetDiameter(12.0)  # not a burr size: refused, logged
    assert tool.GetDiameter() == 4.0
    tool.SetShape(Tool.GetShapeFromString("Hammer"))
    assert tool.GetShape() == Tool.Sphere
