"""A segment's appearance changes (a role change in the application) without redoing what it does not touch.

Making a segment cuttable draws it at the CT's iso-value instead of by its
smoothed shape, and protecting it does the reverse. On the 288^3 temporal
bone each such change smoothed every shape segment's labels again (one pass
over each segment's box, seconds each on 2 cores) although a shown segment's
smoothed fraction depends only on its own voxels and the smoothing. These
tests count the smoothings (``GetNumberOfLabelSmoothings``) across role
changes and compare every picture with one a new caster draws from scratch
with the same appearances: the reuse must not change a pixel.
"""

import numpy as np
import slicer_volumecutting as vc
import vtk
from vtkmodules.util import numpy_support

from test_partial_volume_labels import SIZE, image  # a 48^3 grid of 0.5 mm voxels

WIDTH = 80
ISO = 300.0
# label: (centre in voxels, radius in voxels, HU)
BALLS = {1: ((18.0, 24.0, 24.0), 9.3, 1500.0), 2: ((32.0, 18.0, 24.0), 5.2, 60.0), 3: ((32.0, 31.0, 25.0), 6.1, 80.0)}
COLORS = {1: (0.94, 0.84, 0.57), 2: (0.9, 0.8, 0.2), 3: (0.7, 0.2, 0.2)}


def scene_images():
    """CT (soft tissue at 40 HU) and label map of three balls; label 4 is the soft tissue around them."""
    z, y, x = np.meshgrid(*(np.arange(SIZE, dtype=float),) * 3, indexing="ij")
    ct = np.full((SIZE, SIZE, SIZE), 40.0)
    labels = np.full((SIZE, SIZE, SIZE), 4, dtype=np.uint16)
    for label, (centre, radius, hu) in BALLS.items():
        distance = np.sqrt((x - centre[0]) ** 2 + (y - centre[1]) ** 2 + (z - centre[2]) ** 2)
        inside = np.clip(radius + 0.5 - distance, 0.0, 1.0)  # partial volume over one voxel
        ct = ct + inside * (hu - 40.0)
        labels[distance <= radius] = label
    return image(ct.astype(np.float32)), image(labels)


def world_to_ndc():
    camera = vtk.vtkCamera()
    centre = np.full(3, 0.5 * (SIZE - 1) * 0.5)
    camera.SetFocalPoint(*centre)
    camera.SetPosition(*(centre + np.array([6.0, -34.0, 9.0])))
    camera.SetViewUp(0.0, 0.0, 1.0)
    camera.SetViewAngle(30.0)
    camera.SetClippingRange(10.0, 80.0)
    matrix = vtk.vtkMatrix4x4()
    matrix.DeepCopy(camera.GetCompositeProjectionTransformMatrix(1.0, -1.0, 1.0))
    return matrix


def set_roles(caster, cuttable):
    """Cuttable segments at the iso-value, the others by their shape (NaN), as the displayable manager sets them."""
    caster.RemoveAllSegmentAppearances()
    for label, color in COLORS.items():
        caster.SetSegmentAppearance(label, color, 1.0, ISO if label in cuttable else float("nan"))


def pictures(caster):
    assert caster.Render(world_to_ndc(), WIDTH, WIDTH)
    result = []
    for getter in (caster.GetColorImage, caster.GetDepthImage, caster.GetSegmentImage):
        data = vtk.vtkImageData()
        getter(data)
        result.append(numpy_support.vtk_to_numpy(data.GetPointData().GetScalars()).copy())
    return result


def new_caster(ct, labels, cuttable):
    caster = vc.vtkVolumeCutRayCaster()
    caster.SetAnatomy(ct, None)
    caster.SetIsoValue(ISO)
    caster.SetLabelSmoothing(1.0)
    caster.SetLabelMap(labels)
    set_roles(caster, cuttable)
    return caster


def test_a_role_change_smooths_only_the_segment_newly_drawn_by_its_shape_and_draws_what_a_new_caster_draws():
    ct, labels = scene_images()
    caster = new_caster(ct, labels, cuttable={1})
    first = pictures(caster)
    assert caster.GetNumberOfLabelSmoothings() == 2  # segments 2 and 3
    assert np.count_nonzero(first[2] == 2) > 100 and np.count_nonzero(first[2] == 3) > 100  # both in view

    for cuttable, smoothings in (({1, 2}, 2), ({1}, 3), ({1, 3}, 3), ({1, 2, 3}, 3), (set(), 6)):
        set_roles(caster, cuttable)
        changed = pictures(caster)
        # Before: every change smoothed all shape segments again.
        assert caster.GetNumberOfLabelSmoothings() == smoothings, cuttable
        for after, scratch in zip(changed, pictures(new_caster(ct, labels, cuttable))):
            np.testing.assert_array_equal(after, scratch)


def test_new_labels_or_smoothing_smooth_again():
    ct, labels = scene_images()
    caster = new_caster(ct, labels, cuttable={1})
    pictures(caster)
    caster.SetLabelSmoothing(1.5)
    pictures(caster)
    assert caster.GetNumberOfLabelSmoothings() == 4
    moved = numpy_support.vtk_to_numpy(labels.GetPointData().GetScalars()).reshape(SIZE, SIZE, SIZE).copy()
    moved[moved == 2] = 4  # segment 2 gone: only segment 3 left to smooth
    caster.SetLabelMap(image(moved))
    changed = pictures(caster)
    assert caster.GetNumberOfLabelSmoothings() == 5
    scratch = new_caster(ct, image(moved), cuttable={1})
    scratch.SetLabelSmoothing(1.5)
    for after, expected in zip(changed, pictures(scratch)):
        np.testing.assert_array_equal(after, expected)
