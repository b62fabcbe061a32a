"""The high-resolution temporal-bone case: a labelmap drawn slice by slice, pseudo-HU, loaded as a user's data.

The full case (288^3 voxels of 0.15 mm) is generated once into the download
cache and read back through ``owndata``; properties of the generator are
checked on a coarser grid of the same anatomy, which takes a second.
"""

import numpy as np
import pytest

from VolumeCuttingLib.data import temporalbone

COARSE = dict(dimensions=(128, 128, 128), spacing=0.35)


@pytest.fixture(scope="module")
def coarse():
    return temporalbone.generate(**COARSE)


@pytest.fixture(scope="module")
def full_files():
    return temporalbone.cached_case_files()


def test_the_default_case_is_high_resolution_and_holds_every_structure():
    assert 0.1 <= temporalbone.SPACING <= 0.2
    extent = np.array(temporalbone.DIMENSIONS) * temporalbone.SPACING
    assert np.all((extent >= 40.0) & (extent <= 50.0))
    names = [s.name for s in temporalbone.structures()]
    assert len(names) >= 12 and len(set(names)) == len(names)
    for required in ("Mastoid bone", "Mastoid air cells", "Malleus", "Incus", "Stapes", "Labyrinth", "Facial nerve",
                     "Chorda tympani", "Sigmoid sinus", "Dura", "Carotid artery", "External ear canal",
                     "Internal auditory canal"):
        assert required in names
    cuttable, protected = temporalbone.roles()
    assert cuttable == ["Mastoid bone", "Mastoid air cells"]
    assert len(protected) >= 10 and not set(cuttable) & set(protected)


def test_every_structure_is_in_the_labelmap(coarse):
    present = set(np.unique(coarse.labels)) - {0}
    assert present == set(range(1, len(coarse.structures) + 1))
    assert coarse.ct.dtype == np.int16 and coarse.labels.dtype == np.uint8
    assert coarse.spacing == pytest.approx((0.35, 0.35, 0.35))


def test_the_same_arguments_give_the_same_arrays_and_another_seed_other_ones(coarse):
    again = temporalbone.generate(**COARSE)
    assert np.array_equal(again.ct, coarse.ct) and np.array_equal(again.labels, coarse.labels)
    other = temporalbone.generate(seed=temporalbone.SEED + 1, **COARSE)
    assert not np.array_equal(other.ct, coarse.ct)
    assert not np.array_equal(other.labels, coarse.labels)


def _nerve_centre_wobble(case):
    """Std (mm) of the facial nerve's per-slice centre about a straight line, over its straight mastoid segment; lag-1 correlation."""
    label = next(n for n, s in enumerate(case.structures, start=1) if s.name == "Facial nerve")
    z = case.ijk_to_ras[2, 2] * np.arange(case.labels.shape[0]) + case.ijk_to_ras[2, 3]
    rows = []
    for k in np.nonzero((z > -16.0) & (z < -10.0))[0]:
        j, i = np.nonzero(case.labels[k] == label)
        if len(i):
            rows.append((z[k], case.ijk_to_ras[0, 0] * i.mean() + case.ijk_to_ras[0, 3],
                         case.ijk_to_ras[1, 1] * j.mean() + case.ijk_to_ras[1, 3]))
    rows = np.array(rows)
    residuals = []
    for column in (1, 2):
        fit = np.polyfit(rows[:, 0], rows[:, column], 1)
        residuals.append(rows[:, column] - np.polyval(fit, rows[:, 0]))
    residuals = np.array(residuals)
    lag1 = np.mean([np.corrcoef(r[:-1], r[1:])[0, 1] for r in residuals])
    return float(residuals.std()), float(lag1), len(rows)


def test_slices_are_drawn_independently_so_a_straight_nerve_climbs_in_steps(coarse, monkeypatch):
    wobble, lag1, slices = _nerve_centre_wobble(coarse)
    assert slices >= 15
    # Each slice's contour has its own tremor: the centre wanders by about the
    # tremor's size, and one slice's error says little about the next one's.
    pixel = coarse.spacing[0]
    assert 0.25 * temporalbone.CONTOUR_SHIFT_PIXELS * pixel < wobble < 3.0 * temporalbone.CONTOUR_SHIFT_PIXELS * pixel
    assert abs(lag1) < 0.6
    # Without the tremor the same tube is a smooth stack (the check can fail).
    monkeypatch.setattr(temporalbone, "CONTOUR_SHIFT_PIXELS", 0.0)
    monkeypatch.setattr(temporalbone, "CONTOUR_GROWTH_PIXELS", 0.0)
    smooth_wobble, _, _ = _nerve_centre_wobble(temporalbone.generate(**COARSE))
    assert smooth_wobble < 0.5 * wobble


def test_the_labelmap_has_no_partial_voxels_but_the_ct_has(coarse):
    # Labels are whole voxels; the CT blurs each boundary over neighbouring voxels.
    bone = next(n for n, s in enumerate(coarse.structures, start=1) if s.name == "Mastoid bone")
    mask = coarse.labels == bone
    # Bone voxels whose neighbour along i is outside the bone, and those neighbours.
    edge = mask & ~np.roll(mask, 1, axis=2)
    neighbours = coarse.ct[np.roll(edge, -1, axis=2) & ~mask]
    assert neighbours.size > 100
    # Soft tissue is 35 HU, bone 1150 HU: next to bone the CT mixes both.
    assert 150.0 < np.median(neighbours) < 900.0


def test_pseudo_hu_follows_the_labels_with_noise(full_files):
    import slicer
    from VolumeCuttingLib.scene import nodes

    scene = slicer.vtkMRMLScene()
    volume, segmentation, cuttable, protected = temporalbone.load_case(scene, full_files)
    ct = nodes.array_from_image_data(volume.GetImageData())
    labelmap = slicer.vtkMRMLLabelMapVolumeNode()
    scene.AddNode(labelmap)
    logic = slicer.vtkSlicerSegmentationsModuleLogic()
    assert logic.ExportAllSegmentsToLabelmapNode(segmentation, labelmap, slicer.vtkSegmentation.EXTENT_REFERENCE_GEOMETRY)
    labels = nodes.array_from_image_data(labelmap.GetImageData())
    names = {}
    segments = segmentation.GetSegmentation()
    for index, segment_id in enumerate(segments.GetSegmentIDs(), start=1):
        names[segments.GetSegment(segment_id).GetName()] = index

    def median(name):
        return float(np.median(ct[labels == names[name]]))

    assert 950.0 < median("Mastoid bone") < 1300.0
    assert median("Mastoid air cells") < -500.0
    assert median("External ear canal") < -800.0
    for soft in ("Sigmoid sinus", "Dura", "Carotid artery", "Internal auditory canal"):
        assert -50.0 < median(soft) < 400.0, soft
    for ossicle in ("Malleus", "Incus", "Stapes"):
        assert median(ossicle) > 500.0, ossicle
    # Noise: deep inside the bone, where no boundary blurs, the spread is the noise's.
    bone = labels == names["Mastoid bone"]
    deep = bone & np.roll(bone, 3, 0) & np.roll(bone, -3, 0) & np.roll(bone, 3, 1) & np.roll(bone, -3, 1) \
        & np.roll(bone, 3, 2) & np.roll(bone, -3, 2)
    assert 0.7 * temporalbone.NOISE_HU < float(ct[deep].std()) < 1.5 * temporalbone.NOISE_HU


def test_the_written_case_loads_through_owndata_with_its_roles(full_files):
    import slicer

    assert full_files["ct"].suffix == ".nrrd" and full_files["labels"].suffix == ".nrrd"
    assert full_files["colors"].suffix == ".ctbl"
    scene = slicer.vtkMRMLScene()
    messages = []
    volume, segmentation, cuttable, protected = temporalbone.load_case(scene, full_files, messages=messages)
    assert volume.GetImageData().GetDimensions() == temporalbone.DIMENSIONS
    assert volume.GetSpacing() == pytest.approx((temporalbone.SPACING,) * 3)
    segments = segmentation.GetSegmentation()
    assert segments.GetNumberOfSegments() == len(temporalbone.structures())
    assert sorted(segments.GetSegment(s).GetName() for s in protected) == sorted(temporalbone.roles()[1])
    assert len(cuttable) == 2 and len(protected) >= 10
    assert not [m for m in messages if "resampl" in m.lower()]


def test_bad_grids_are_refused():
    with pytest.raises(ValueError, match="dimensions"):
        temporalbone.generate(dimensions=(4, 64, 64))
    with pytest.raises(ValueError, match="spacing"):
        temporalbone.generate(dimensions=(64, 64, 64), spacing=-0.1)
