"""vtkVolumeCutFractionMirror: the removed fraction image kept up to date brick by brick.

Ground truth: the field's own exact fractions of the whole volume
(``ExportRemovedFraction``), as 0-255 bytes. After each stroke, an update in
slices of no time at all (one brick a call) must reproduce them everywhere,
change nothing outside its box, and an undo must bring the image back.
"""

from __future__ import annotations

import numpy as np
import slicer
import vtk
from vtkmodules.util import numpy_support

DIMENSIONS = (40, 36, 32)


def exact_bytes(field) -> np.ndarray:
    image = vtk.vtkImageData()
    field.ExportRemovedFraction(image)
    dims = image.GetDimensions()
    fractions = numpy_support.vtk_to_numpy(image.GetPointData().GetScalars()).reshape(dims[2], dims[1], dims[0])
    return np.rint(np.clip(fractions, 0.0, 1.0) * 255.0).astype(np.uint8)


def mirrored(mirror) -> np.ndarray:
    image = mirror.GetImage()
    dims = image.GetDimensions()
    return numpy_support.vtk_to_numpy(image.GetPointData().GetScalars()).reshape(dims[2], dims[1], dims[0]).copy()


def update(mirror) -> tuple[int, tuple]:
    """Run one whole update a few voxels at a time; the calls it took and its box (i0, i1, j0, j1, k0, k1)."""
    assert mirror.BeginUpdate()
    calls = 0
    while not mirror.Advance(0.0):
        calls += 1
    box = [0] * 6
    mirror.GetUpdateBox(box)
    return calls + 1, tuple(box)


def field(factor: int):
    matrix = vtk.vtkMatrix4x4()
    for axis, spacing in enumerate((0.4, 0.4, 0.5)):
        matrix.SetElement(axis, axis, spacing)
    cut = slicer.vtkVolumeCutField()
    assert cut.Initialize(list(DIMENSIONS), matrix, factor)
    return cut


def test_each_update_reproduces_the_exact_fractions_inside_its_box_and_touches_nothing_outside():
    for factor in (1, 2):
        cut = field(factor)
        cut.BeginStroke()
        assert cut.CutCapsule([3.0, 3.0, 3.0], [6.0, 4.0, 5.0], 1.6)
        cut.EndStroke()
        mirror = slicer.vtkVolumeCutFractionMirror()
        assert mirror.Reset(cut)
        assert mirror.GetImage().GetDimensions() == DIMENSIONS
        first = mirrored(mirror)
        assert np.array_equal(first, exact_bytes(cut)) and first.max() == 255
        assert not mirror.BeginUpdate()  # nothing changed since

        cut.BeginStroke()
        assert cut.CutCapsule([10.0, 9.0, 9.0], [12.0, 10.0, 11.0], 1.4)
        cut.EndStroke()
        calls, box = update(mirror)
        second = mirrored(mirror)
        assert 1 < calls < mirror.GetNumberOfUpdateVoxels()  # Advance(0) does a few voxels a call
        assert np.array_equal(second, exact_bytes(cut)), f"factor {factor}"
        inside = np.zeros(second.shape, dtype=bool)
        inside[box[4]:box[5], box[2]:box[3], box[0]:box[1]] = True
        assert np.array_equal(second[~inside], first[~inside]) and not np.array_equal(second[inside], first[inside])

        assert cut.Undo()
        update(mirror)
        assert np.array_equal(mirrored(mirror), first)
