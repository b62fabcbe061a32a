"""The 3D view shows a volume-cut node through the multivolume mapper, and follows its cuts.

Real scene, real logic, Slicer's displayable-manager group and an offscreen
render window; depths are checked against the exact geometry of the analytic
cube (VolumeCuttingLib.data.analyticscene).
"""

import math

import numpy as np
import pytest
import slicer
import vtk
from vtkmodules.util import numpy_support

from VolumeCuttingLib.data import analyticscene
from VolumeCuttingLib.scene import nodes
from VolumeCuttingLib.scene.application import HeadlessSlicer


@pytest.fixture()
def session():
    application = HeadlessSlicer()
    scene = analyticscene.CubeScene(dimensions=40, half_size_voxels=10)
    array = numpy_support.vtk_to_numpy(scene.intensities().GetPointData().GetScalars()).reshape((40, 40, 40))
    ijk_to_ras = nodes.vtk_matrix_to_numpy(scene.ijk_to_ras())
    volume = nodes.create_scalar_volume_node(application.scene, array.astype(np.int16), ijk_to_ras, "Cube")
    logic = application.volume_cutting_logic
    bone = logic.CreateBoneSegmentation(volume, 700.0, 200.0, 0.0)
    cut_node = logic.AddVolumeCutNode(volume, bone)
    cut_node.SetCuttableSegmentIDs([logic.GetCorticalBoneSegmentID(), logic.GetTrabecularBoneSegmentID()])
    cut_node.SetSurfaceIsoValue(scene.iso_value())
    view = application.create_3d_view(64, 64)
    # Looking straight down at the top face.
    center = scene.center
    camera = view.renderer.GetActiveCamera()
    camera.SetFocalPoint(*center)
    camera.SetPosition(*(center + [0.0, 0.0, 60.0]))
    camera.SetViewUp(0.0, 1.0, 0.0)
    camera.SetClippingRange(30.0, 100.0)
    yield application, scene, volume, cut_node, view
    view.close()


def surface_z(view, x, y):
    depth = vtk.vtkFloatArray()
    view.render_window.GetZbufferData(x, y, x, y, depth)
    renderer = view.renderer
    renderer.SetDisplayPoint(x + 0.5, y + 0.5, depth.GetValue(0))
    renderer.DisplayToWorld()
    world = renderer.GetWorldPoint()
    return world[2] / world[3], depth.GetValue(0)


def test_view_shows_the_cut_node_and_follows_cuts(session):
    application, scene, volume, cut_node, view = session
    manager = view.volume_cut_displayable_manager
    actor = manager.GetVolumeActor(cut_node)
    assert actor is not None and actor.GetVisibility()
    mapper = actor.GetMapper()
    assert mapper.GetInput() is volume.GetImageData()
    view.render()
    assert mapper.GetLastRenderPath() != 0
    top = scene.center[2] + scene.half_size
    z, depth = surface_z(view, 32, 32)
    assert depth < 1.0
    assert z == pytest.approx(top, abs=0.02)

    # A cut through the logic re-renders the view with the pit.
    logic = application.volume_cutting_logic
    events = []
    cut_node.AddObserver(slicer.vtkMRMLVolumeCutNode.CutModifiedEvent, lambda caller, event: events.append(event))
    pit = [scene.center[0], scene.center[1], top]
    assert logic.CutSphereSweep(cut_node, pit, pit, 2.5)
    assert events
    view.render()
    z, _ = surface_z(view, 32, 32)
    # The pixel's ray is a little off the pit's axis.
    renderer = view.renderer
    renderer.SetDisplayPoint(32.5, 32.5, 0.0)
    renderer.DisplayToWorld()
    near = renderer.GetWorldPoint()
    off_axis = math.hypot(near[0] / near[3] - pit[0], near[1] / near[3] - pit[1])
    assert z == pytest.approx(top - math.sqrt(2.5**2 - off_axis**2), abs=0.02)

    # Undo through the logic puts the face back.
    assert logic.UndoStroke(cut_node)
    view.render()
    z, _ = surface_z(view, 32, 32)
    assert z == pytest.approx(top, abs=0.02)

    # Removing the node removes its volume from the view.
    application.scene.RemoveNode(cut_node)
    assert manager.GetVolumeActor(cut_node) is None
    assert view.renderer.GetVolumes().GetNumberOfItems() == 0


def test_rendering_settings_are_saved_with_the_node(scene_xml_round_trip):
    scene = slicer.vtkMRMLScene()
    scene.RegisterNodeClass(slicer.vtkMRMLVolumeCutNode())
    node = scene.AddNewNodeByClass("vtkMRMLVolumeCutNode")
    node.SetSurfaceIsoValue(412.5)
    node.SetThinBoneShading(True)
    node.SetThinBoneThickness(1.75)
    node.SetAmbientOcclusion(False)
    node.SetLabelSmoothing(0.5)
    node.SetMaterialSegmentIDs(["Cortex", "Cancellous;bone", "Cortex"])
    copy = scene_xml_round_trip(node)
    assert copy.GetSurfaceIsoValue() == pytest.approx(412.5)
    assert copy.GetThinBoneShading()
    assert copy.GetThinBoneThickness() == pytest.approx(1.75)
    assert not copy.GetAmbientOcclusion()
    assert copy.GetLabelSmoothing() == pytest.approx(0.5)
    assert list(copy.GetMaterialSegmentIDs()) == ["Cortex", "Cancellous;bone"]


def test_fractional_labelmap_segments_are_drawn_at_sub_voxel_accuracy(session):
    """A segment whose source representation is a fractional labelmap (Slicer's char -108..108)."""
    application, scene, volume, cut_node, view = session
    n = scene.dimensions
    center = scene.center + np.array([0.13, -0.21, 0.07])  # mm
    radius = 3.1  # mm
    supersampling = 4
    offsets = ((np.arange(supersampling) + 0.5) / supersampling - 0.5) * scene.spacing
    axis = np.arange(n) * scene.spacing
    fraction = np.zeros((n, n, n))
    for dz in offsets:
        for dy in offsets:
            for dx in offsets:
                fraction += (((axis + dx - center[0])[None, None, :] ** 2 + (axis + dy - center[1])[None, :, None] ** 2
                              + (axis + dz - center[2])[:, None, None] ** 2) <= radius**2)
    fraction /= supersampling**3
    chars = np.round(fraction * 216.0 - 108.0).astype(np.int8)
    oriented = slicer.vtkOrientedImageData()
    oriented.SetDimensions(n, n, n)
    oriented.GetPointData().SetScalars(numpy_support.numpy_to_vtk(chars.ravel(), deep=True, array_type=vtk.VTK_CHAR))
    oriented.SetImageToWorldMatrix(scene.ijk_to_ras())
    scalar_range = vtk.vtkDoubleArray()
    scalar_range.SetName(slicer.vtkSegmentationConverter.GetScalarRangeFieldName())
    scalar_range.InsertNextValue(-108.0)
    scalar_range.InsertNextValue(108.0)
    oriented.GetFieldData().AddArray(scalar_range)
    segmentation_node = application.scene.AddNewNodeByClass("vtkMRMLSegmentationNode")
    segmentation_node.CreateDefaultDisplayNodes()
    segmentation = segmentation_node.GetSegmentation()
    name = slicer.vtkSegmentationConverter.GetSegmentationFractionalLabelmapRepresentationName()
    segmentation.SetSourceRepresentationName(name)
    segment = slicer.vtkSegment()
    segment.SetName("Ball")
    segment.AddRepresentation(name, oriented)
    segmentation.AddSegment(segment, "Ball")
    cut_node.SetAndObserveSegmentationNodeID(segmentation_node.GetID())
    # The CT cube is not a segment here: only the ball shows, by its own shape.
    view.render()
    _, depth = surface_z(view, 32, 32)
    assert depth < 1.0
    renderer = view.renderer
    renderer.SetDisplayPoint(32.5, 32.5, 0.0)
    renderer.DisplayToWorld()
    near = renderer.GetWorldPoint()
    off_axis = math.hypot(near[0] / near[3] - center[0], near[1] / near[3] - center[1])
    z, _ = surface_z(view, 32, 32)
    exact = center[2] + math.sqrt(radius**2 - off_axis**2)
    assert z == pytest.approx(exact, abs=0.1 * scene.spacing)


def test_a_stroke_draws_reduced_frames_and_the_full_image_once_it_ends(session):
    application, scene, volume, cut_node, view = session
    logic = application.volume_cutting_logic
    mapper = view.volume_cut_displayable_manager.GetVolumeActor(cut_node).GetMapper()
    mapper.SetMaximumImageSampleDistance(4)
    view.render()
    assert mapper.GetLastImageSampleDistance() == 1
    window = view.render_window
    # The rates a desktop view's interactor asks for while something moves and
    # when it stops (a generic interactor: no display here).
    interactor = vtk.vtkGenericRenderWindowInteractor()
    interactor.SetRenderWindow(window)
    interactor.SetDesiredUpdateRate(1000.0)
    interactor.SetStillUpdateRate(0.0001)
    window.SetDesiredUpdateRate(0.0001)

    top = scene.center[2] + scene.half_size
    pit = [scene.center[0], scene.center[1], top]
    assert logic.BeginStroke(cut_node)
    assert window.GetDesiredUpdateRate() == pytest.approx(1000.0)
    assert logic.CutSphereSweep(cut_node, pit, pit, 2.5)
    view.render()
    assert mapper.GetLastImageSampleDistance() == 4

    assert logic.EndStroke(cut_node)
    assert window.GetDesiredUpdateRate() == pytest.approx(0.0001)
    view.render()
    assert mapper.GetLastImageSampleDistance() == 1
    # The refined frame shows the pit where it is.
    renderer = view.renderer
    renderer.SetDisplayPoint(32.5, 32.5, 0.0)
    renderer.DisplayToWorld()
    near = renderer.GetWorldPoint()
    off_axis = math.hypot(near[0] / near[3] - pit[0], near[1] / near[3] - pit[1])
    z, _ = surface_z(view, 32, 32)
    assert z == pytest.approx(top - math.sqrt(2.5**2 - off_axis**2), abs=0.02)


def test_a_role_change_that_changes_no_appearance_leaves_the_ray_caster_untouched(session):
    """Protected and role-less segments look alike (their own shape): switching between them redraws nothing.

    The displayable manager used to give the caster every appearance again on
    any change of the node, which modified it: on the temporal bone the caster
    then rebuilt its empty-space data (seconds) and drew the view again.
    """
    application, scene, volume, cut_node, view = session
    logic = application.volume_cutting_logic
    cortical, trabecular = logic.GetCorticalBoneSegmentID(), logic.GetTrabecularBoneSegmentID()
    caster = view.volume_cut_displayable_manager.GetVolumeActor(cut_node).GetMapper().GetRayCaster()
    cut_node.SetCuttableSegmentIDs([cortical])
    cut_node.SetProtectedSegmentIDs([trabecular])
    view.render()
    before = caster.GetMTime()
    cut_node.SetProtectedSegmentIDs([])  # trabecular bone: from protected to no role
    assert caster.GetMTime() == before
    cut_node.SetCuttableSegmentIDs([cortical, trabecular])  # a real appearance change still reaches it
    assert caster.GetMTime() > before
