"""Slice views outline and fill the cut region where their plane meets it.

Real scene, real logic, Slicer's slice logic and slice displayable managers in
an offscreen render window. A sphere of radius R cut with the logic into a CT
with anisotropic spacing and a flipped axis: a plane at distance d from its
centre must show a circle of radius sqrt(R^2 - d^2) around the centre's
projection, in the outline's polydata and in the rendered pixels.
"""

import math

import numpy as np
import pytest
import slicer
import vtk
from vtkmodules.util import numpy_support

from VolumeCuttingLib.scene import nodes
from VolumeCuttingLib.scene.application import HeadlessSlicer

SPACING = np.array([0.6, 0.7, 1.3])  # mm, anisotropic
DIMENSIONS = (40, 36, 24)  # i, j, k
RADIUS = 5.0  # mm
# Off the sample lattice on purpose.
CENTER = np.array([1.37, -0.82, 0.55])
VIEW_SIZE = 256
PIXEL = 0.06  # mm per pixel: the sphere's section spans about 160 pixels


def ijk_to_ras():
    """The x axis flipped (as in the chest CT of the issue), origin so that RAS 0 is near the middle."""
    matrix = np.diag([-SPACING[0], SPACING[1], SPACING[2], 1.0])
    matrix[:3, 3] = [(DIMENSIONS[0] - 1) / 2 * SPACING[0], -(DIMENSIONS[1] - 1) / 2 * SPACING[1], -(DIMENSIONS[2] - 1) / 2 * SPACING[2]]
    return matrix


@pytest.fixture()
def session():
    application = HeadlessSlicer()
    k, j, i = np.meshgrid(np.arange(DIMENSIONS[2]), np.arange(DIMENSIONS[1]), np.arange(DIMENSIONS[0]), indexing="ij")
    # Bone-like values with some structure, so the background shows where the plane is.
    ct = (900 + 300 * np.sin(i / 3.0) * np.cos(j / 4.0) + 20 * k).astype(np.int16)
    volume = nodes.create_scalar_volume_node(application.scene, ct, ijk_to_ras(), "CT")
    volume.GetDisplayNode().SetAutoWindowLevel(False)
    volume.GetDisplayNode().SetWindowLevel(1600, 900)
    logic = application.volume_cutting_logic
    cut_node = logic.AddVolumeCutNode(volume, None)
    view = application.create_slice_view("Axial", VIEW_SIZE, VIEW_SIZE, "Red")
    view.slice_node.SetFieldOfView(VIEW_SIZE * PIXEL, VIEW_SIZE * PIXEL, 1.0)
    view.slice_node.SetXYZOrigin(0.0, 0.0, 0.0)
    yield application, volume, cut_node, view
    view.close()


def cut_sphere(application, cut_node):
    center = [float(c) for c in CENTER]
    assert application.volume_cutting_logic.CutSphereSweep(cut_node, center, center, RADIUS)


def center_axial_view(view, height):
    """An axial plane at S = height, centred (in R and A) on the sphere."""
    matrix = np.eye(4)
    matrix[:3, 3] = [CENTER[0], CENTER[1], height]
    view.set_slice_to_ras(matrix)


def outline_ras(view, cut_node):
    outline = view.volume_cut_displayable_manager.GetOutline(cut_node)
    assert outline is not None
    xy = numpy_support.vtk_to_numpy(outline.GetPoints().GetData()) if outline.GetNumberOfPoints() else np.zeros((0, 3))
    xy_to_ras = nodes.vtk_matrix_to_numpy(view.slice_node.GetXYToRAS())
    homogeneous = np.c_[xy[:, 0], xy[:, 1], np.zeros(len(xy)), np.ones(len(xy))]
    return (homogeneous @ xy_to_ras.T)[:, :3], outline


def test_axial_outline_is_the_exact_circle(session):
    application, volume, cut_node, view = session
    cut_sphere(application, cut_node)
    manager = view.volume_cut_displayable_manager
    errors = []
    for d in (0.0, 1.9, 3.3, -4.1):
        center_axial_view(view, CENTER[2] + d)
        ras, outline = outline_ras(view, cut_node)
        expected = math.sqrt(RADIUS**2 - d**2)
        assert outline.GetNumberOfPoints() > 50
        # One closed loop: as many segments as points.
        assert outline.GetNumberOfLines() == outline.GetNumberOfPoints()
        assert np.allclose(ras[:, 2], CENTER[2] + d, atol=1e-9)
        radii = np.hypot(ras[:, 0] - CENTER[0], ras[:, 1] - CENTER[1])
        errors.append(np.max(np.abs(radii - expected)))
        angles = np.sort(np.arctan2(ras[:, 1] - CENTER[1], ras[:, 0] - CENTER[0]))
        assert np.max(np.diff(np.r_[angles, angles[0] + 2 * np.pi])) < 0.1  # all the way round
        # Sampled no coarser than the field's sub-voxel spacing (0.3 mm at factor 2).
        assert 0.0 < manager.GetSampleSpacing(cut_node) <= 0.5 * SPACING.min() + 1e-12
    # The field reconstructs the surface to a small fraction of a voxel.
    max_error = max(errors)
    print(f"outline radius, max error over 4 planes: {max_error:.4f} mm = {max_error / SPACING.min():.4f} voxel")
    assert max_error < 0.1 * SPACING.min()


def test_field_on_an_oblique_grid():
    """The CT's grid rotated 30 degrees about S and tilted 20 degrees about R, x flipped: bricks cross the plane obliquely."""
    application = HeadlessSlicer()
    rotation = vtk.vtkTransform()
    rotation.RotateZ(30.0)
    rotation.RotateX(20.0)
    matrix = nodes.vtk_matrix_to_numpy(rotation.GetMatrix()) @ np.diag([-SPACING[0], SPACING[1], SPACING[2], 1.0])
    half = (np.array(DIMENSIONS) - 1) / 2.0
    matrix[:3, 3] = -matrix[:3, :3] @ half
    ct = np.full(DIMENSIONS[::-1], 1000, np.int16)
    volume = nodes.create_scalar_volume_node(application.scene, ct, matrix, "ObliqueCT")
    cut_node = application.volume_cutting_logic.AddVolumeCutNode(volume, None)
    view = application.create_slice_view("Axial", VIEW_SIZE, VIEW_SIZE, "Red")
    view.slice_node.SetFieldOfView(VIEW_SIZE * PIXEL, VIEW_SIZE * PIXEL, 1.0)
    cut_sphere(application, cut_node)
    for d in (0.0, 3.1):
        center_axial_view(view, CENTER[2] + d)
        ras, outline = outline_ras(view, cut_node)
        assert outline.GetNumberOfPoints() > 50
        radii = np.hypot(ras[:, 0] - CENTER[0], ras[:, 1] - CENTER[1])
        max_error = np.max(np.abs(radii - math.sqrt(RADIUS**2 - d**2)))
        print(f"oblique grid, axial plane at {d} mm: max error {max_error:.4f} mm")
        assert max_error < 0.1 * SPACING.min()
    view.close()


def test_oblique_plane_and_fill_polygons(session):
    application, volume, cut_node, view = session
    cut_sphere(application, cut_node)
    # Normal tilted 35 degrees from S towards R and A.
    normal = np.array([math.sin(math.radians(35)) * math.cos(math.radians(20)), math.sin(math.radians(35)) * math.sin(math.radians(20)), math.cos(math.radians(35))])
    u = np.cross(normal, [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    d = 2.2
    origin = CENTER + d * normal
    slice_to_ras = np.eye(4)
    slice_to_ras[:3, 0], slice_to_ras[:3, 1], slice_to_ras[:3, 2], slice_to_ras[:3, 3] = u, v, normal, origin
    view.set_slice_to_ras(slice_to_ras)
    ras, outline = outline_ras(view, cut_node)
    assert outline.GetNumberOfPoints() > 50
    assert np.max(np.abs((ras - origin) @ normal)) < 1e-9
    radii = np.linalg.norm(ras - origin, axis=1)
    expected = math.sqrt(RADIUS**2 - d**2)
    max_error = np.max(np.abs(radii - expected))
    print(f"oblique outline radius, max error: {max_error:.4f} mm")
    assert max_error < 0.1 * SPACING.min()

    # The fill covers the disk: its area is the circle's, to the polygonisation.
    fill = view.volume_cut_displayable_manager.GetFill(cut_node)
    assert fill.GetNumberOfPolys() > 0
    triangles = vtk.vtkTriangleFilter()
    triangles.SetInputData(fill)
    mass = vtk.vtkMassProperties()
    mass.SetInputConnection(triangles.GetOutputPort())
    mass.Update()
    pixel_area = PIXEL * PIXEL
    area = mass.GetSurfaceArea() * pixel_area
    assert area == pytest.approx(math.pi * expected**2, rel=2e-3)


def test_ring_cut_is_filled_around_its_island(session):
    """A burr led round a circle leaves a ring in the plane: bone stays in the middle, unfilled."""
    application, volume, cut_node, view = session
    logic = application.volume_cutting_logic
    path_radius, burr_radius = 4.0, 1.5
    angles = np.linspace(0.0, 2 * np.pi, 101)  # chords 0.25 mm long: 0.002 mm inside the circle
    poses = [[float(CENTER[0] + path_radius * math.cos(a)), float(CENTER[1] + path_radius * math.sin(a)), float(CENTER[2])] for a in angles]
    assert logic.BeginStroke(cut_node)
    for start, end in zip(poses[:-1], poses[1:]):
        assert logic.CutSphereSweep(cut_node, start, end, burr_radius)
    assert logic.EndStroke(cut_node)
    center_axial_view(view, CENTER[2])
    ras, outline = outline_ras(view, cut_node)
    radii = np.hypot(ras[:, 0] - CENTER[0], ras[:, 1] - CENTER[1])
    inner, outer = radii[radii < path_radius], radii[radii > path_radius]
    assert len(inner) > 50 and len(outer) > 50
    assert np.max(np.abs(inner - (path_radius - burr_radius))) < 0.1 * SPACING.min()
    assert np.max(np.abs(outer - (path_radius + burr_radius))) < 0.1 * SPACING.min()

    fill = view.volume_cut_displayable_manager.GetFill(cut_node)
    triangles = vtk.vtkTriangleFilter()
    triangles.SetInputData(fill)
    mass = vtk.vtkMassProperties()
    mass.SetInputConnection(triangles.GetOutputPort())
    mass.Update()
    area = mass.GetSurfaceArea() * PIXEL * PIXEL
    assert area == pytest.approx(math.pi * ((path_radius + burr_radius) ** 2 - (path_radius - burr_radius) ** 2), rel=2e-3)
    # The island: no fill polygon covers the centre.
    middle = VIEW_SIZE / 2.0
    locator = vtk.vtkCellLocator()
    locator.SetDataSet(triangles.GetOutput())
    locator.BuildLocator()
    cell = vtk.vtkGenericCell()
    assert locator.FindCell([middle, middle, 0.0], 1e-9, cell, [0.0, 0.0, 0.0], [0.0] * 3) < 0
    assert locator.FindCell([middle + path_radius / PIXEL, middle, 0.0], 1e-9, cell, [0.0, 0.0, 0.0], [0.0] * 3) >= 0


def pixel_radii(view, mask):
    """Distance (mm) from the sphere's axis of the centre of each pixel in the mask, on an axial plane."""
    rows, columns = np.nonzero(mask)
    xy_to_ras = nodes.vtk_matrix_to_numpy(view.slice_node.GetXYToRAS())
    points = np.c_[columns + 0.5, rows + 0.5, np.zeros(len(rows)), np.ones(len(rows))] @ xy_to_ras.T
    return np.hypot(points[:, 0] - CENTER[0], points[:, 1] - CENTER[1])


def test_rendered_outline_and_fill(session, tmp_path):
    application, volume, cut_node, view = session
    cut_sphere(application, cut_node)
    d = 2.5
    center_axial_view(view, CENTER[2] + d)
    expected = math.sqrt(RADIUS**2 - d**2)
    color = np.array(cut_node.GetSliceColor())

    # On black (no background volume): the outline is the slice colour at
    # full strength, the fill the colour at the opacity.
    cut_node.SetSliceFillVisibility(False)
    image = view.rgb()
    outline_pixels = np.all(np.abs(image.astype(float) - 255 * color) < 40, axis=2)
    radii = pixel_radii(view, outline_pixels)
    assert len(radii) > 200
    thickness_mm = cut_node.GetSliceOutlineThickness() * PIXEL
    print(f"rendered outline: mean radius {radii.mean():.4f} mm (expected {expected:.4f}), spread {radii.min():.3f}..{radii.max():.3f} mm")
    assert radii.mean() == pytest.approx(expected, abs=0.5 * PIXEL)
    assert radii.min() > expected - thickness_mm and radii.max() < expected + thickness_mm

    # With the CT behind: the fill blends the colour at SliceFillOpacity over
    # the inside pixels and leaves the others alone.
    view.set_background_volume(volume)
    cut_node.SetSliceOutlineVisibility(False)
    without = view.rgb().astype(float)
    assert without.max() > 50  # the CT is shown
    cut_node.SetSliceFillVisibility(True)
    cut_node.SetSliceFillOpacity(0.4)
    with_fill = view.rgb().astype(float)
    rows, columns = np.indices(without.shape[:2])
    all_radii = pixel_radii(view, np.ones(without.shape[:2], bool)).reshape(without.shape[:2])
    inside = all_radii < expected - 2 * PIXEL
    outside = all_radii > expected + 2 * PIXEL
    blended = 0.6 * without + 0.4 * 255 * color
    assert np.max(np.abs(with_fill[inside] - blended[inside])) <= 2.0
    assert np.max(np.abs(with_fill[outside] - without[outside])) == 0.0

    cut_node.SetSliceOutlineVisibility(True)
    cut_node.SetSliceFillOpacity(0.3)
    path = view.screenshot(tmp_path / "axial_sphere_section.png")
    assert path.stat().st_size > 0
    print(f"screenshot: {path}")


def test_events_request_renders_and_undo_removes_the_overlay(session, tmp_path):
    application, volume, cut_node, view = session
    manager = view.volume_cut_displayable_manager
    center_axial_view(view, CENTER[2] + 1.0)
    view.render()
    assert manager.GetOutline(cut_node).GetNumberOfPoints() == 0
    assert not manager.GetOutlineActor(cut_node).GetVisibility()

    requests = []
    view.displayable_managers.AddObserver(vtk.vtkCommand.UpdateEvent, lambda caller, event: requests.append(event))
    renders = []
    view.render_window.AddObserver(vtk.vtkCommand.StartEvent, lambda caller, event: renders.append(event))
    cut_sphere(application, cut_node)
    # A render is requested, none is made from the event.
    assert requests
    assert not renders
    view.render()
    assert manager.GetOutlineActor(cut_node).GetVisibility()
    assert manager.GetFillActor(cut_node).GetVisibility()
    red = view.rgb()[..., 0] > 150
    assert red.sum() > 100

    # Display properties request a render too, and hide their part.
    requests.clear()
    cut_node.SetSliceOutlineVisibility(False)
    assert requests
    assert not manager.GetOutlineActor(cut_node).GetVisibility()
    assert manager.GetOutline(cut_node).GetNumberOfPoints() == 0
    assert manager.GetFillActor(cut_node).GetVisibility()
    cut_node.SetSliceFillVisibility(False)
    assert not manager.GetFillActor(cut_node).GetVisibility()
    assert view.rgb().max() == 0
    cut_node.SetSliceOutlineVisibility(True)
    cut_node.SetSliceFillVisibility(True)
    assert manager.GetOutlineActor(cut_node).GetVisibility()

    # Moving the slice requests a render and redraws at the new height.
    requests.clear()
    view.set_slice_offset(CENTER[2] + 4.0)
    assert requests
    ras, _ = outline_ras(view, cut_node)
    assert np.max(np.abs(np.hypot(ras[:, 0] - CENTER[0], ras[:, 1] - CENTER[1]) - 3.0)) < 0.1 * SPACING.min()

    # Undo through the logic: nothing is left to draw.
    requests.clear()
    assert application.volume_cutting_logic.UndoStroke(cut_node)
    assert requests
    view.render()
    assert manager.GetOutline(cut_node).GetNumberOfPoints() == 0
    assert manager.GetFill(cut_node).GetNumberOfCells() == 0
    assert not manager.GetOutlineActor(cut_node).GetVisibility()
    assert not manager.GetFillActor(cut_node).GetVisibility()
    assert view.rgb().max() == 0
    view.screenshot(tmp_path / "after_undo.png")

    # Removing the node removes its actors.
    actors = view.renderer.GetActors2D().GetNumberOfItems()
    application.scene.RemoveNode(cut_node)
    assert manager.GetOutline(cut_node) is None
    assert view.renderer.GetActors2D().GetNumberOfItems() == actors - 2


def test_a_reloaded_scene_shows_its_cut_in_slice_views(session, tmp_path):
    application, volume, cut_node, view = session
    cut_sphere(application, cut_node)
    cut_node.SetSliceColor(0.2, 0.4, 1.0)
    bundle = application.save_bundle(tmp_path / "cut.mrb")
    view.close()

    reloaded = HeadlessSlicer()
    reloaded.load_bundle(bundle)
    cut_node = reloaded.scene.GetFirstNodeByClass("vtkMRMLVolumeCutNode")
    assert cut_node.GetCutField() is not None
    assert cut_node.GetSliceColor() == pytest.approx((0.2, 0.4, 1.0))
    view = reloaded.create_slice_view("Axial", VIEW_SIZE, VIEW_SIZE, "Red")
    view.slice_node.SetFieldOfView(VIEW_SIZE * PIXEL, VIEW_SIZE * PIXEL, 1.0)
    d = -2.0
    center_axial_view(view, CENTER[2] + d)
    ras, outline = outline_ras(view, cut_node)
    assert outline.GetNumberOfPoints() > 50
    radii = np.hypot(ras[:, 0] - CENTER[0], ras[:, 1] - CENTER[1])
    assert np.max(np.abs(radii - math.sqrt(RADIUS**2 - d**2))) < 0.1 * SPACING.min()
    blue = view.rgb()
    assert np.sum((blue[..., 2] > 200) & (blue[..., 0] < 100)) > 100
    view.close()


def test_slice_display_properties_survive_a_scene_round_trip(scene_xml_round_trip):
    scene = slicer.vtkMRMLScene()
    scene.RegisterNodeClass(slicer.vtkMRMLVolumeCutNode())
    node = scene.AddNewNodeByClass("vtkMRMLVolumeCutNode")
    assert node.GetSliceOutlineVisibility() and node.GetSliceFillVisibility()
    assert node.GetSliceFillOpacity() == pytest.approx(0.3)
    node.SetSliceOutlineVisibility(False)
    node.SetSliceFillVisibility(False)
    node.SetSliceFillOpacity(0.55)
    node.SetSliceColor(0.1, 0.8, 0.25)
    node.SetSliceOutlineThickness(3.5)
    copy = scene_xml_round_trip(node)
    assert not copy.GetSliceOutlineVisibility()
    assert not copy.GetSliceFillVisibility()
    assert copy.GetSliceFillOpacity() == pytest.approx(0.55)
    assert copy.GetSliceColor() == pytest.approx((0.1, 0.8, 0.25))
    assert copy.GetSliceOutlineThickness() == pytest.approx(3.5)
    # Copies (scene undo, node duplication) carry them too.
    duplicate = copy.GetScene().AddNewNodeByClass("vtkMRMLVolumeCutNode")
    duplicate.CopyContent(copy)
    assert duplicate.GetSliceColor() == pytest.approx((0.1, 0.8, 0.25))
    assert duplicate.GetSliceOutlineThickness() == pytest.approx(3.5)
