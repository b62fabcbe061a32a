"""3D views draw each cutting tool at its true size where its pose puts it (vtkMRMLVolumeCutToolDisplayableManager)."""

import numpy as np
import pytest
import vtk

from VolumeCuttingLib.config import toolconfig
from VolumeCuttingLib.scene.application import HeadlessSlicer


def set_pose(tool, translation):
    matrix = vtk.vtkMatrix4x4()
    for axis in range(3):
        matrix.SetElement(axis, 3, translation[axis])
    tool.GetParentTransformNode().SetMatrixTransformToParent(matrix)


def test_tool_glyph_follows_the_tool():
    application = HeadlessSlicer()
    presets = {preset.name: preset for preset in toolconfig.load_presets()}
    tool = toolconfig.create_tool_node(application.scene, toolconfig.from_preset(presets["Cutting burr 5 mm"]), "Burr")
    tool.GetDisplayNode().SetColor(1.0, 0.0, 0.0)
    view = application.create_3d_view(200, 200)
    manager = view.tool_displayable_manager
    actor = manager.GetToolActor(tool)
    assert actor is not None and actor.GetVisibility()
    set_pose(tool, (10.0, -4.0, 2.0))
    bounds = actor.GetBounds()
    assert [(bounds[2 * a] + bounds[2 * a + 1]) / 2 for a in range(3)] == pytest.approx([10.0, -4.0, 2.0], abs=0.01)
    assert bounds[1] - bounds[0] == pytest.approx(5.0, rel=0.01)
    # The shaft goes along +z from the ball, towards the handpiece.
    shaft = manager.GetShaftActor(tool)
    assert shaft.GetVisibility() and shaft.GetBounds()[4] == pytest.approx(2.0 + 2.5, abs=0.01)

    # Seen from above, the ball is drawn in the tool's colour at its place.
    camera = view.renderer.GetActiveCamera()
    camera.SetFocalPoint(10.0, -4.0, 2.0)
    camera.SetPosition(10.0, -4.0, 150.0)
    camera.SetViewUp(0.0, 1.0, 0.0)
    camera.SetViewAngle(10.0)
    view.renderer.ResetCameraClippingRange()
    tool.GetDisplayNode().SetVisibility3D(True)
    tool.GetVolumeCutToolDisplayNode().SetShowAxis(False)
    view.render()
    grabber = vtk.vtkWindowToImageFilter()
    grabber.SetInput(view.render_window)
    grabber.ReadFrontBufferOff()
    grabber.ShouldRerenderOff()
    grabber.Update()
    from vtkmodules.util import numpy_support

    image = grabber.GetOutput()
    pixels = numpy_support.vtk_to_numpy(image.GetPointData().GetScalars()).reshape(200, 200, -1)
    centre = pixels[100, 100, :3].astype(int)
    assert centre[0] > 150 and centre[1] < 80 and centre[2] < 80, centre

    # Other shapes, sizes and visibility follow the node.
    tool.SetShape(tool.Blade)
    tool.SetWidth(12.0)
    tool.SetThickness(1.0)
    tool.SetLength(6.0)
    bounds = manager.GetToolActor(tool).GetBounds()
    assert [bounds[1] - bounds[0], bounds[3] - bounds[2], bounds[5] - bounds[4]] == pytest.approx([12.0, 1.0, 6.0], rel=0.01)
    tool.GetDisplayNode().SetVisibility(False)
    assert not manager.GetToolActor(tool).GetVisibility()
    application.scene.RemoveNode(tool)
    assert manager.GetToolActor(tool) is None
    view.close()


def test_a_scene_update_observes_each_tool_once_without_warnings():
    """After a batch (a scene import, a bundle read) the manager sees every tool again; it warned 'Observation
    already exists' once per tool and event each time (32 lines in a main job run)."""
    import slicer

    application = HeadlessSlicer()
    presets = {preset.name: preset for preset in toolconfig.load_presets()}
    tools = [toolconfig.create_tool_node(application.scene, toolconfig.from_preset(presets[name]), name)
             for name in ("Cutting burr 5 mm", "Diamond burr 3 mm")]
    view = application.create_3d_view(64, 64)
    messages = vtk.vtkStringOutputWindow()
    previous = vtk.vtkOutputWindow.GetInstance()
    vtk.vtkOutputWindow.SetInstance(messages)
    try:
        for _ in range(2):
            application.scene.StartState(slicer.vtkMRMLScene.BatchProcessState)
            application.scene.EndState(slicer.vtkMRMLScene.BatchProcessState)
    finally:
        vtk.vtkOutputWindow.SetInstance(previous)
    assert "already exist" not in messages.GetOutput(), messages.GetOutput()
    # Still observed once: a change of size reaches the glyph.
    tools[0].SetDiameter(4.0)
    bounds = view.tool_displayable_manager.GetToolActor(tools[0]).GetBounds()
    assert bounds[1] - bounds[0] == pytest.approx(4.0, rel=0.01)
    view.close()
