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
