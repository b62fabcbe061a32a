"""The cut field from Python (slicer.vtkVolumeCutField), against analytic geometry."""

import math

import numpy as np
import pytest
import slicer
import vtk
from vtkmodules.util import numpy_support


def oblique_grid():
    """A 25-degree rotation about S, spacing 0.4 x 0.5 x 0.6 mm."""
    angle = math.radians(25.0)
    rotation = np.array([[math.cos(angle), -math.sin(angle), 0.0], [math.sin(angle), math.cos(angle), 0.0], [0.0, 0.0, 1.0]])
    matrix = vtk.vtkMatrix4x4()
    for row in range(3):
        for column in range(3):
            matrix.SetElement(row, column, rotation[row, column] * (0.4, 0.5, 0.6)[column])
    return matrix


def test_sphere_and_capsule_volumes_on_an_oblique_grid():
    field = slicer.vtkVolumeCutField()
    assert field.Initialize([40, 40, 40], oblique_grid(), 2)
    center = [2.3, 12.1, 11.7]
    assert field.CutCapsule(center, center, 2.0)
    exact = 4.0 / 3.0 * math.pi * 8.0
    assert abs(field.ComputeRemovedVolume() - exact) / exact < 0.005
    assert field.GetSignedDistance(center) < 0.0
    assert field.GetSignedDistance([center[0] + 2.0, center[1], center[2]]) == pytest.approx(0.0, abs=0.01)


def test_fraction_export_matches_volume_and_undo_restores():
    matrix = vtk.vtkMatrix4x4()
    field = slicer.vtkVolumeCutField()
    field.Initialize([30, 30, 30], matrix, 4)
    field.BeginStroke()
    for x in np.linspace(8.0, 20.0, 25):
        field.CutCapsule([x, 15.0, 15.0], [x + 0.5, 15.0, 15.0], 3.0)
    field.EndStroke()
    assert field.GetNumberOfUndoSteps() == 1
    fraction = vtk.vtkImageData()
    field.ExportRemovedFraction(fraction)
    values = numpy_support.vtk_to_numpy(fraction.GetPointData().GetScalars())
    assert values.min() >= 0.0 and values.max() <= 1.0
    assert abs(values.sum() - field.ComputeRemovedVolume()) < 1e-3 * values.sum()
    capsule = math.pi * 9.0 * 12.5 + 4.0 / 3.0 * math.pi * 27.0
    assert abs(field.ComputeRemovedVolume() - capsule) / capsule < 0.005
    assert field.Undo()
    assert field.ComputeRemovedVolume() == 0.0


def test_bad_poses_are_refused_and_keep_the_cut():
    field = slicer.vtkVolumeCutField()
    field.Initialize([20, 20, 20], vtk.vtkMatrix4x4(), 2)
    field.CutCapsule([10.0, 10.0, 10.0], [10.0, 10.0, 10.0], 3.0)
    before = field.ComputeRemovedVolume()
    assert not field.CutCapsule([float("nan"), 10.0, 10.0], [10.0, 10.0, 10.0], 1.0)
    assert not field.CutCapsule([10.0, 10.0, 10.0], [10.0, 10.0, 10.0], -2.0)
    assert not field.CutCapsule([10.0, 10.0, 10.0], [10.0, 10.0, 900.0], 1.0)
    assert field.ComputeRemovedVolume() == before
    assert not field.Initialize([20, 20, 20], vtk.vtkMatrix4x4(), 3)
    assert field.ComputeRemovedVolume() == before


def test_removed_surface_is_closed_and_encloses_the_removed_volume():
    field = slicer.vtkVolumeCutField()
    field.Initialize([40, 40, 40], oblique_grid(), 2)
    center = [2.3, 12.1, 11.7]
    field.CutCapsule(center, [center[0] + 3.0, center[1] - 1.0, center[2]], 2.5)
    surface = vtk.vtkPolyData()
    field.ExtractRemovedSurface(surface)
    assert surface.GetNumberOfCells() > 100
    edges = vtk.vtkFeatureEdges()
    edges.SetInputData(surface)
    edges.BoundaryEdgesOn()
    edges.NonManifoldEdgesOn()
    edges.FeatureEdgesOff()
    edges.ManifoldEdgesOff()
    edges.Update()
    assert edges.GetOutput().GetNumberOfCells() == 0  # closed
    mass = vtk.vtkMassProperties()
    mass.SetInputData(surface)
    mass.Update()
    assert abs(mass.GetVolume() - field.ComputeRemovedVolume()) / field.ComputeRemovedVolume() < 0.01

    empty = vtk.vtkPolyData()
    slicer.vtkVolumeCutField().ExtractRemovedSurface(empty)
    assert empty.GetNumberOfPoints() == 0


def pose(translation, axis=(0.0, 0.0, 1.0), degrees=0.0):
    transform = vtk.vtkTransform()
    transform.Translate(*translation)
    transform.RotateWXYZ(degrees, *axis)
    return transform.GetMatrix()


def fresh_field(dims=(60, 60, 60), spacing=0.5):
    matrix = vtk.vtkMatrix4x4()
    for axis in range(3):
        matrix.SetElement(axis, axis, spacing)
    field = slicer.vtkVolumeCutField()
    assert field.Initialize(list(dims), matrix, 2)
    return field


@pytest.mark.parametrize("kind", ["cylinder", "box", "ellipsoid"])
def test_tool_shapes_remove_their_exact_volume(kind):
    field = fresh_field()
    if kind == "cylinder":
        tool = slicer.vtkVolumeCutCylinderTool()
        tool.SetRadius(2.0)
        tool.SetLength(6.0)
        exact, tolerance = math.pi * 4.0 * 6.0, 0.01
    elif kind == "box":
        tool = slicer.vtkVolumeCutBoxTool()
        tool.SetSize(8.0, 1.5, 5.0)
        exact, tolerance = 8.0 * 1.5 * 5.0, 0.01
    else:
        tool = slicer.vtkVolumeCutEllipsoidTool()
        tool.SetRadii(2.0, 3.0, 4.0)
        exact, tolerance = 4.0 / 3.0 * math.pi * 24.0, 0.005
    at = pose([14.9, 15.2, 14.7], axis=(1.0, 1.0, 0.0), degrees=30.0)
    assert field.CutToolSweep(tool, at, at)
    assert abs(field.ComputeRemovedVolume() - exact) / exact < tolerance


def test_a_translated_blade_cuts_a_slot_without_gaps():
    field = fresh_field()
    blade = slicer.vtkVolumeCutBoxTool()
    # 1 mm thick: four sub-voxels. Thinner blades are reconstructed with
    # larger errors (a sampled distance cannot hold a slab of two samples).
    blade.SetSize(4.0, 1.0, 5.0)
    # Along its own x: the slot is the blade extruded by the travel.
    assert field.CutToolSweep(blade, pose([10.0, 15.0, 15.0]), pose([18.0, 15.0, 15.0]))
    exact = (4.0 + 8.0) * 1.0 * 5.0
    assert abs(field.ComputeRemovedVolume() - exact) / exact < 0.02


def test_a_rotating_disk_saw_sweeps_every_angle():
    field = fresh_field()
    saw = slicer.vtkVolumeCutCylinderTool()
    saw.SetRadius(6.0)
    saw.SetLength(0.4)  # a disk
    centre = [15.0, 15.0, 15.0]
    # The disk (normal along z) tilts 90 degrees about x: a half ball of
    # rotation, which sampled poses must cover at every intermediate angle.
    assert field.CutToolSweep(saw, pose(centre), pose(centre, axis=(1.0, 0.0, 0.0), degrees=90.0))
    for degrees in (10.0, 37.0, 45.0, 71.0):
        angle = math.radians(degrees)
        # A point of the disk's rim region at that tilt: radius 4 mm along y rotated about x.
        point = [centre[0], centre[1] + 4.0 * math.cos(angle), centre[2] + 4.0 * math.sin(angle)]
        assert field.GetSignedDistance(point) < 0.0, degrees


def test_mesh_tool_and_its_refusals():
    sphere = vtk.vtkSphereSource()
    sphere.SetRadius(3.0)
    sphere.SetThetaResolution(64)
    sphere.SetPhiResolution(64)
    sphere.Update()
    tool = slicer.vtkVolumeCutMeshTool()
    tool.SetSurface(sphere.GetOutput())
    assert tool.IsValid()
    field = fresh_field()
    at = pose([15.0, 15.0, 15.0])
    assert field.CutToolSweep(tool, at, at)
    mass = vtk.vtkMassProperties()
    mass.SetInputData(sphere.GetOutput())
    mass.Update()
    assert abs(field.ComputeRemovedVolume() - mass.GetVolume()) / mass.GetVolume() < 0.01

    # An open surface has no inside: refused, nothing cut.
    plane = vtk.vtkPlane()
    plane.SetNormal(0.0, 0.0, 1.0)
    clip = vtk.vtkClipPolyData()
    clip.SetInputConnection(sphere.GetOutputPort())
    clip.SetClipFunction(plane)
    clip.Update()
    open_tool = slicer.vtkVolumeCutMeshTool()
    open_tool.SetSurface(clip.GetOutput())
    assert not open_tool.IsValid()
    before = field.ComputeRemovedVolume()
    assert not field.CutToolSweep(open_tool, at, at)
    # Non-rigid or non-finite poses, and bad sizes, are refused too.
    scaled = vtk.vtkMatrix4x4()
    scaled.SetElement(0, 0, 2.0)
    assert not field.CutToolSweep(tool, scaled, scaled)
    broken = vtk.vtkMatrix4x4()
    broken.SetElement(1, 3, float("nan"))
    assert not field.CutToolSweep(tool, broken, at)
    bad = slicer.vtkVolumeCutCylinderTool()
    bad.SetRadius(-1.0)
    assert not field.CutToolSweep(bad, at, at)
    assert field.ComputeRemovedVolume() == before


def test_file_round_trip_and_corrupt_files(tmp_path):
    field = fresh_field(dims=(30, 30, 30))
    field.CutCapsule([5.0, 5.0, 5.0], [9.0, 7.0, 6.0], 2.0)
    path = tmp_path / "cut.vcut"
    assert field.WriteFile(str(path))
    copy = slicer.vtkVolumeCutField()
    assert copy.ReadFile(str(path))
    assert copy.ComputeRemovedVolume() == pytest.approx(field.ComputeRemovedVolume(), rel=1e-12)
    assert copy.GetSignedDistance([7.0, 6.0, 5.5]) == pytest.approx(field.GetSignedDistance([7.0, 6.0, 5.5]))

    data = path.read_bytes()
    truncated = tmp_path / "truncated.vcut"
    truncated.write_bytes(data[: len(data) // 2])
    foreign = tmp_path / "foreign.vcut"
    foreign.write_bytes(b"not a cut field at all" * 10)
    for bad in (truncated, foreign, tmp_path / "missing.vcut"):
        assert not copy.ReadFile(str(bad))
        assert copy.ComputeRemovedVolume() == pytest.approx(field.ComputeRemovedVolume(), rel=1e-12)

    # A field that never cut round-trips as "nothing yet".
    empty = tmp_path / "empty.vcut"
    assert slicer.vtkVolumeCutField().WriteFile(str(empty))
    assert copy.ReadFile(str(empty))
    assert copy.GetDimensions() == (0, 0, 0)


def test_sawing_extrudes_a_drawn_polygon_to_a_depth():
    # An L-shaped (concave) outline drawn on the view, sawn 6 mm deep along
    # the viewing direction (here the tilted local z).
    saw = slicer.vtkVolumeCutPrismTool()
    for x, y in [(0.0, 0.0), (8.0, 0.0), (8.0, 3.0), (3.0, 3.0), (3.0, 7.0), (0.0, 7.0)]:
        saw.AddVertex(x - 4.0, y - 3.5)
    saw.SetDepth(6.0)
    assert saw.IsValid()
    field = fresh_field()
    view = pose([15.0, 15.0, 12.0], axis=(1.0, 0.0, 0.0), degrees=20.0)
    assert field.CutToolSweep(saw, view, view)
    area = 8.0 * 3.0 + 3.0 * 4.0
    assert abs(field.ComputeRemovedVolume() - area * 6.0) / (area * 6.0) < 0.01
    # The notch of the L is not sawn.
    notch = vtk.vtkMatrix4x4()
    notch.DeepCopy(view)
    local_notch = [6.0 - 4.0, 5.0 - 3.5, 3.0, 1.0]
    assert field.GetSignedDistance(notch.MultiplyPoint(local_notch)[:3]) > 0.0

    degenerate = slicer.vtkVolumeCutPrismTool()
    degenerate.AddVertex(0.0, 0.0)
    degenerate.AddVertex(1.0, 1.0)
    assert not degenerate.IsValid()
    assert not field.CutToolSweep(degenerate, view, view)


def hu_block(dims, value_left, value_right):
    """A CT whose x < middle half has one HU value and the other half another."""
    voxels = np.full((dims[2], dims[1], dims[0]), value_right, dtype=np.int16)
    voxels[:, :, : dims[0] // 2] = value_left
    image = vtk.vtkImageData()
    image.SetDimensions(*dims)
    image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(voxels.ravel(), deep=True, array_type=vtk.VTK_SHORT))
    return image


def drill_for(seconds, hu_value, burr_type=0, steps=20):
    dims = (40, 40, 40)
    field = fresh_field(dims=dims)
    remover = slicer.vtkVolumeCutMaterialRemoval()
    remover.SetBurrType(burr_type)
    assert remover.SetInputs(field, hu_block(dims, hu_value, hu_value))
    for _ in range(steps):
        # A 2 mm burr pressed sideways (axis along z) into the block.
        assert remover.Drill([10.0, 10.0, 10.0], [0.0, 0.0, 1.0], 2.0, seconds / steps)
    return field.ComputeRemovedVolume()


def test_material_removal_follows_time_density_and_burr():
    trabecular = [drill_for(t, 450) for t in (0.05, 0.1, 0.2, 0.4)]
    # More time removes more, up to the burr's own volume.
    assert all(a <= b for a, b in zip(trabecular, trabecular[1:]))
    assert trabecular[0] < trabecular[-1] <= 4.0 / 3.0 * math.pi * 8.0 * 1.01
    # Cortical bone takes longer than trabecular bone, but gives way in the end.
    assert 0.0 < drill_for(0.4, 1500) < drill_for(0.4, 450)
    assert drill_for(2.0, 1500) == pytest.approx(drill_for(2.0, 450), rel=0.05)
    # A diamond burr removes less than a cutting burr in the same time.
    assert 0.0 < drill_for(0.2, 450, burr_type=1) < drill_for(0.2, 450, burr_type=0)
    # Deterministic: the same inputs give the same cut.
    assert drill_for(0.1, 450) == drill_for(0.1, 450)


def test_material_removal_refuses_bad_input():
    dims = (20, 20, 20)
    field = fresh_field(dims=dims)
    remover = slicer.vtkVolumeCutMaterialRemoval()
    assert not remover.Drill([5.0, 5.0, 5.0], [0.0, 0.0, 1.0], 1.0, 0.1)  # no inputs
    assert not remover.SetInputs(field, hu_block((10, 10, 10), 400, 400))  # wrong size
    assert remover.SetInputs(field, hu_block(dims, 400, 400))
    assert not remover.Drill([5.0, float("nan"), 5.0], [0.0, 0.0, 1.0], 1.0, 0.1)
    assert not remover.Drill([5.0, 5.0, 5.0], [0.0, 0.0, 0.0], 1.0, 0.1)
    assert not remover.Drill([5.0, 5.0, 5.0], [0.0, 0.0, 1.0], 1.0, -0.1)
    assert field.ComputeRemovedVolume() == 0.0


def test_a_huge_volume_is_refused_not_allocated():
    field = fresh_field(dims=(20, 20, 20))
    field.CutCapsule([5.0, 5.0, 5.0], [5.0, 5.0, 5.0], 2.0)
    before = field.ComputeRemovedVolume()
    assert not field.Initialize([4096, 4096, 4096], vtk.vtkMatrix4x4(), 4)
    assert field.ComputeRemovedVolume() == before
    # 512^3 at factor 4 is within bounds (2^24 bricks, 256 MiB of directory).
    assert slicer.vtkVolumeCutField().Initialize([512, 512, 512], vtk.vtkMatrix4x4(), 4)


def test_instruction_sets_cut_alike_and_refuse_what_is_missing():
    field_class = slicer.vtkVolumeCutField
    in_use = field_class.GetInstructionSet()
    available = [s for s in range(3) if field_class.IsInstructionSetAvailable(s)]
    assert field_class.InstructionSetBaseline in available
    assert in_use == max(available)
    assert not field_class.SetInstructionSet(7)
    assert field_class.GetInstructionSet() == in_use
    volumes = []
    try:
        for instruction_set in available:
            assert field_class.SetInstructionSet(instruction_set)
            assert field_class.GetInstructionSetAsString(instruction_set) in ("baseline", "AVX2", "AVX-512")
            field = slicer.vtkVolumeCutField()
            assert field.Initialize([40, 40, 40], oblique_grid(), 2)
            assert field.CutCapsule([2.0, 10.5, 9.0], [5.0, 13.0, 11.5], 2.2)
            volumes.append(field.ComputeRemovedVolume())
    finally:
        field_class.SetInstructionSet(in_use)
    length = math.dist([2.0, 10.5, 9.0], [5.0, 13.0, 11.5])
    exact = math.pi * 2.2**2 * length + 4.0 / 3.0 * math.pi * 2.2**3
    assert abs(volumes[0] - exact) / exact < 0.005
    assert all(v == volumes[0] for v in volumes)
