"""SoftCut through the logic: plan on a markups outline, preview, carve, measure, export.

Real scene, real markups closed curve, real cut node and module logic, and a
real 3D view for the preview. The anatomy is the sphere phantom of
VolumeCuttingLib.data.softcutphantom (skin an analytic sphere over a bone shell),
on an anisotropic grid whose i axis is flipped, so that volumes are checked
against exact values.
"""

import math

import numpy as np
import pytest
import slicer
import vtk

from VolumeCuttingLib.cutting import softcut
from VolumeCuttingLib.data import softcutphantom
from VolumeCuttingLib.scene import nodes
from VolumeCuttingLib.scene.application import HeadlessSlicer

RADIUS = 12.0  # mm from the axis: 12 voxels across in-plane
MAXIMUM_DEPTH = 14.0


@pytest.fixture(scope="module")
def phantom():
    return softcutphantom.make_sphere_phantom(spacing=(1.0, 1.0, 1.25), flip_x=True)


def make_session(phantom, segments=False):
    application = HeadlessSlicer()
    volume = softcutphantom.add_volume_node(application.scene, phantom)
    segmentation = None
    if segments:
        # A protected "vessel" (a small ball in the soft tissue under the
        # outline) and a cuttable "Soft tissue" segment elsewhere.
        segmentation = application.scene.AddNewNodeByClass("vtkMRMLSegmentationNode", "Anatomy")
        segmentation.SetReferenceImageGeometryParameterFromVolumeNode(volume)
        centers = phantom.voxel_centers_ras()
        vessel_center = np.array([0.0, 0.0, phantom.skin_radius - 4.0])
        masks = {
            "Vessel": np.linalg.norm(centers - vessel_center, axis=-1) <= 2.5,
            "Soft tissue": (phantom.radius_of_voxels() < phantom.skin_radius) & (phantom.radius_of_voxels() > phantom.bone_outer),
        }
        for name, mask in masks.items():
            image = slicer.vtkOrientedImageData()
            image.ShallowCopy(nodes.image_data_from_array(mask.astype(np.uint8)))
            image.SetImageToWorldMatrix(nodes.numpy_to_vtk_matrix(phantom.ijk_to_ras))
            segment = slicer.vtkSegment()
            segment.SetName(name)
            segment.AddRepresentation("Binary labelmap", image)
            segmentation.GetSegmentation().AddSegment(segment, name)
    cut = application.volume_cutting_logic.AddVolumeCutNode(volume, segmentation)
    if segments:
        cut.SetCuttableSegmentIDs(["Soft tissue"])
        cut.SetProtectedSegmentIDs(["Vessel"])
    logic = softcut.create_logic(application)
    logic.SetSkinIsoValue(softcutphantom.SKIN_ISO_HU)
    logic.SetSoftTissueRange(softcutphantom.SKIN_ISO_HU, softcutphantom.BONE_THRESHOLD_HU)
    logic.SetMaximumDepth(MAXIMUM_DEPTH)
    return application, volume, cut, logic


def circle(application, phantom, radius=RADIUS, count=12, sittings=1, name="Outline"):
    return softcut.add_outline(application.scene, softcutphantom.circle_outline(phantom, radius, count), name=name, sittings=sittings)


def removed_fraction(application, cut):
    field = application.volume_cutting_logic.GetCutField(cut)
    image = vtk.vtkImageData()
    field.ExportRemovedFraction(image)
    return nodes.array_from_image_data(image)


@pytest.mark.parametrize("mode, exact_volume", [
    (0, softcutphantom.exact_volume_local_normal),
    (1, softcutphantom.exact_volume_average_normal),
])
def test_resected_volume_matches_the_exact_value(phantom, mode, exact_volume):
    application, volume, cut, logic = make_session(phantom)
    logic.SetNormalMode(mode)
    # Drawn in two sittings: the curve is the same.
    outline = circle(application, phantom, sittings=2)
    assert logic.PlanResection(cut, outline), logic.GetErrorMessage()
    for depth in (4.0, 7.0, 12.0):  # the last one reaches the bone at 9 mm
        rows = softcut.table_rows(logic.MeasureResection(cut, depth))
        exact = exact_volume(phantom.skin_radius, RADIUS, depth, phantom.bone_outer)
        assert rows["Resected volume"][0] == pytest.approx(exact, rel=0.02), (mode, depth)
        assert rows["Depth of cut"] == (depth, "mm")
        # Length and width: the outline's diameter; thickness: the cap's height plus the depth, at most.
        assert rows["Length"][0] == pytest.approx(2 * RADIUS, abs=1.0)
        assert rows["Width"][0] == pytest.approx(2 * RADIUS, abs=1.0)
        cap = phantom.skin_radius - math.sqrt(phantom.skin_radius ** 2 - RADIUS ** 2)
        reach = min(depth, phantom.skin_radius - phantom.bone_outer)
        assert reach < rows["Thickness"][0] < cap + reach + 1.0
        assert rows["Thickness axis S"][0] == pytest.approx(1.0, abs=1e-3)
        assert rows["Outline length"][0] == pytest.approx(2 * math.pi * RADIUS, rel=0.02)
    table = logic.MeasureResection(cut, 4.0)
    assert cut.GetNodeReference(logic.GetResectionTableReferenceRole()) is table
    assert table.GetNumberOfRows() >= 10


def test_carve_is_one_undo_step_and_never_takes_bone(phantom):
    application, volume, cut, logic = make_session(phantom)
    module = application.volume_cutting_logic
    outline = circle(application, phantom)
    assert logic.PlanResection(cut, outline), logic.GetErrorMessage()
    events = []
    cut.AddObserver(slicer.vtkMRMLVolumeCutNode.CutModifiedEvent, lambda caller, event: events.append(event))
    # Deeper than the soft tissue: the bone stops it.
    assert logic.CarveResection(cut, 12.0), logic.GetErrorMessage()
    assert events
    field = module.GetCutField(cut)
    assert field.GetNumberOfUndoSteps() == 1
    fraction = removed_fraction(application, cut)
    # Bone through and through loses nothing; the bone's surface voxels
    # (partial volume) at most their soft-tissue part.
    assert fraction[phantom.interior_bone_voxels()].max() == 0.0
    surface = np.argwhere(phantom.bone_voxels() & (fraction > 0.0))
    assert len(surface) > 0  # the carve does reach the bone
    taken = fraction[tuple(surface.T)]
    assert np.all(taken <= 1.0 - phantom.bone_fraction(surface) + 0.1)
    # The tissue removed (voxels under the skin) against the exact shell, stopped at the bone.
    spacing = phantom.spacing
    tissue = phantom.radius_of_voxels() < phantom.skin_radius
    removed = float((fraction * tissue).sum()) * spacing[0] * spacing[1] * spacing[2]
    exact = softcutphantom.exact_volume_local_normal(phantom.skin_radius, RADIUS, 12.0, phantom.bone_outer)
    assert removed == pytest.approx(exact, rel=0.05)
    assert module.UndoStroke(cut)
    assert module.GetRemovedVolume(cut) == pytest.approx(0.0, abs=1e-9)
    assert module.RedoStroke(cut)
    assert module.GetRemovedVolume(cut) > 0.9 * exact


def test_carve_respects_the_shield(phantom):
    application, volume, cut, logic = make_session(phantom, segments=True)
    module = application.volume_cutting_logic
    contacts = []
    cut.AddObserver(slicer.vtkMRMLVolumeCutNode.ProtectedContactEvent, lambda caller, event: contacts.append(event))
    assert logic.PlanResection(cut, circle(application, phantom)), logic.GetErrorMessage()
    assert logic.CarveResection(cut, 8.0), logic.GetErrorMessage()
    assert module.GetRemovedVolumeInSegment(cut, "Vessel") == pytest.approx(0.0, abs=1e-9)
    assert module.GetRemovedVolumeInSegment(cut, "Soft tissue") > 1000.0
    assert contacts and module.GetContactSegmentID(cut) == "Vessel"
    assert module.GetContactTableNode(cut).GetNumberOfRows() == 1


def center_surface_depth(view):
    """The window depth at the view's centre pixel."""
    width, height = view.render_window.GetSize()
    depth = vtk.vtkFloatArray()
    view.render_window.GetZbufferData(width // 2, height // 2, width // 2, height // 2, depth)
    renderer = view.renderer
    renderer.SetDisplayPoint(width // 2 + 0.5, height // 2 + 0.5, depth.GetValue(0))
    renderer.DisplayToWorld()
    world = renderer.GetWorldPoint()
    return world[2] / world[3]


def test_preview_shows_the_depth_without_cutting(phantom):
    application, volume, cut, logic = make_session(phantom)
    module = application.volume_cutting_logic
    cut.SetSurfaceIsoValue(softcutphantom.SKIN_ISO_HU)
    view = application.create_3d_view(96, 96)
    try:
        # From above, onto the outline's centre.
        view.look_at([0.0, 0.0, phantom.skin_radius], direction=(0.0, 0.0, 1.0), distance=120.0, view_up=(0.0, 1.0, 0.0))
        view.renderer.GetActiveCamera().SetViewAngle(20.0)
        view.renderer.ResetCameraClippingRange()
        view.render()
        assert center_surface_depth(view) == pytest.approx(phantom.skin_radius, abs=0.2)
        assert logic.PlanResection(cut, circle(application, phantom)), logic.GetErrorMessage()
        for depth in (3.0, 6.0, 4.5):
            assert logic.PreviewDepth(cut, depth), logic.GetErrorMessage()
            view.render()
            # The pit's floor at the outline's centre lies the depth under the skin.
            assert center_surface_depth(view) == pytest.approx(phantom.skin_radius - depth, abs=0.3)
        preview = cut.GetPreviewCutField()
        assert preview is not None and preview.GetSubVoxelFactor() == 1
        caster = view.volume_cut_displayable_manager.GetVolumeActor(cut).GetMapper().GetRayCaster()
        assert caster.GetNumberOfCutFields() == 2
        # Nothing was cut: the preview is not the cut field.
        assert module.GetRemovedVolume(cut) == pytest.approx(0.0, abs=1e-9)
        logic.ClearPreview(cut)
        view.render()
        assert caster.GetNumberOfCutFields() == 1
        assert center_surface_depth(view) == pytest.approx(phantom.skin_radius, abs=0.2)
        # The carve replaces the preview and shows the same floor.
        assert logic.PreviewDepth(cut, 4.5)
        assert logic.CarveResection(cut, 4.5)
        assert cut.GetPreviewCutField() is None
        view.render()
        assert center_surface_depth(view) == pytest.approx(phantom.skin_radius - 4.5, abs=0.3)
    finally:
        view.close()


def test_exports_a_closed_stl_and_a_model(phantom, tmp_path):
    application, volume, cut, logic = make_session(phantom)
    assert logic.PlanResection(cut, circle(application, phantom)), logic.GetErrorMessage()
    path = tmp_path / "resection.stl"
    assert logic.ExportResectionToSTL(cut, 6.0, str(path))
    reader = vtk.vtkSTLReader()
    reader.SetFileName(str(path))
    reader.Update()
    mesh = reader.GetOutput()
    assert mesh.GetNumberOfCells() > 500
    edges = vtk.vtkFeatureEdges()
    edges.SetInputData(mesh)
    edges.BoundaryEdgesOn()
    edges.NonManifoldEdgesOn()
    edges.FeatureEdgesOff()
    edges.ManifoldEdgesOff()
    edges.Update()
    assert edges.GetOutput().GetNumberOfCells() == 0  # closed, printable
    mass = vtk.vtkMassProperties()
    mass.SetInputData(mesh)
    exact = softcutphantom.exact_volume_local_normal(phantom.skin_radius, RADIUS, 6.0, phantom.bone_outer)
    assert mass.GetVolume() == pytest.approx(exact, rel=0.02)
    model = logic.CreateResectionModel(cut, 6.0, "Flap guide")
    assert model.GetName() == "Flap guide" and model.GetPolyData().GetNumberOfCells() == mesh.GetNumberOfCells()
    assert logic.ExportResectionToSTL(cut, 6.0, str(tmp_path / "resection.obj")) is False
    assert "stl" in logic.GetErrorMessage()


def expect_failure(logic, call, fragment):
    """The call fails (and logs the error) with a message naming the problem."""
    assert not call(), fragment
    message = logic.GetErrorMessage()
    assert fragment in message, message


def test_bad_input_is_refused_and_nothing_is_carved(phantom):
    application, volume, cut, logic = make_session(phantom)
    module = application.volume_cutting_logic
    scene = application.scene
    good = circle(application, phantom, name="Good")
    assert logic.PlanResection(cut, good), logic.GetErrorMessage()
    assert logic.CarveResection(cut, 3.0)
    carved = module.GetRemovedVolume(cut)
    planner = logic.GetPlanner(cut)

    open_curve = scene.AddNewNodeByClass("vtkMRMLMarkupsCurveNode", "Open")
    for point in softcutphantom.circle_outline(phantom, RADIUS, 12):
        open_curve.AddControlPointWorld(vtk.vtkVector3d(*point))
    expect_failure(logic, lambda: logic.PlanResection(cut, open_curve), "open curve")
    two = softcut.add_outline(scene, softcutphantom.circle_outline(phantom, RADIUS, 12)[:2], name="Two")
    expect_failure(logic, lambda: logic.PlanResection(cut, two), "at least 3")
    # A figure eight through the pole crosses itself.
    angles = np.linspace(0.0, 2.0 * math.pi, 24, endpoint=False)
    eight = []
    for a in angles:
        x, y = RADIUS * math.sin(2.0 * a) / 2.0, RADIUS * math.sin(a)
        eight.append([x, y, math.sqrt(phantom.skin_radius ** 2 - x * x - y * y)])
    crossing = softcut.add_outline(scene, eight, name="Eight")
    expect_failure(logic, lambda: logic.PlanResection(cut, crossing), "crosses itself")
    lifted = softcutphantom.circle_outline(phantom, RADIUS, 12)
    lifted[5] *= 1.15  # 6 mm above the skin
    floating = softcut.add_outline(scene, lifted, name="Floating")
    expect_failure(logic, lambda: logic.PlanResection(cut, floating), "control point 6")
    assert "from the skin" in logic.GetErrorMessage()
    expect_failure(logic, lambda: logic.PlanResection(cut, None), "no outline")
    # The previous plan is kept through all of these.
    assert logic.GetPlanner(cut) is planner

    expect_failure(logic, lambda: logic.CarveResection(cut, 0.0), "positive")
    expect_failure(logic, lambda: logic.CarveResection(cut, -2.0), "positive")
    expect_failure(logic, lambda: logic.CarveResection(cut, MAXIMUM_DEPTH + 1.0), "beyond the planned maximum depth")
    expect_failure(logic, lambda: logic.PreviewDepth(cut, float("nan")), "positive")
    expect_failure(logic, lambda: logic.MeasureResection(cut, 0.0), "positive")
    logic.SetMaximumDepth(5000.0)
    expect_failure(logic, lambda: logic.PlanResection(cut, good), "beyond the CT")
    logic.SetMaximumDepth(MAXIMUM_DEPTH)
    assert module.GetRemovedVolume(cut) == pytest.approx(carved)
    assert module.GetCutField(cut).GetNumberOfUndoSteps() == 1

    # Bone right under the air: nothing soft to resect.
    bare = softcutphantom.make_sphere_phantom(spacing=(1.0, 1.0, 1.25), bone_outer=40.0, bone_inner=33.0)
    bare_volume = softcutphantom.add_volume_node(scene, bare, "Bare")
    bare_cut = module.AddVolumeCutNode(bare_volume, None)
    expect_failure(logic, lambda: logic.PlanResection(bare_cut, good), "no soft tissue")
    expect_failure(logic, lambda: logic.CarveResection(bare_cut, 3.0), "no resection is planned")
    assert module.GetCutField(bare_cut).GetNumberOfAllocatedBricks() == 0
