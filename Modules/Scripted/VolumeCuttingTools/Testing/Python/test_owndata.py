"""Own data in (VolumeCuttingLib.data.owndata, dicomseries, patientscale): the user's CT and segmentation.

Real scenes and Slicer's own storage nodes throughout. Small volumes are
generated and written into ``tmp_path`` with Slicer's writers (and pydicom
for DICOM); the one test marked ``realdata`` builds the patient-scale case
from the real head CT.
"""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import slicer

from VolumeCuttingLib.cutting import drilling
from VolumeCuttingLib.data import dicomseries, owndata, patientscale
from VolumeCuttingLib.scene import nodes

MODULE_DIR = Path(__file__).resolve().parents[2]

# A flipped x axis (i runs to the patient's left, as the chest CT of issue 11), off-origin.
FLIPPED = np.array([[-0.7, 0.0, 0.0, 12.5], [0.0, 0.7, 0.0, -20.0], [0.0, 0.0, 2.5, 31.0], [0.0, 0.0, 0.0, 1.0]])


def rotation(axis, angle):
    c, s = np.cos(angle), np.sin(angle)
    a, b = [(1, 2), (0, 2), (0, 1)][axis]
    matrix = np.eye(3)
    matrix[a, a], matrix[a, b], matrix[b, a], matrix[b, b] = c, -s, s, c
    return matrix


def geometry(directions, spacing, origin):
    matrix = np.eye(4)
    matrix[:3, :3] = np.asarray(directions) * np.asarray(spacing)[None, :]
    matrix[:3, 3] = origin
    return matrix


GEOMETRIES = {
    "flipped_x": FLIPPED,
    "dicom_axial": geometry(np.diag([-1.0, -1.0, 1.0]), (0.8, 0.8, 2.0), (100.0, 90.0, -40.0)),
    "oblique": geometry(rotation(2, 0.3) @ rotation(0, 0.2) @ np.diag([1.0, -1.0, 1.0]), (0.7, 0.8, 2.5), (5.0, 6.0, 7.0)),
    "reversed_z": geometry(np.diag([1.0, 1.0, -1.0]), (0.9, 0.9, 3.0), (0.0, 0.0, 60.0)),
}


def ct_array(shape=(10, 14, 16)):
    """Air around a soft-tissue body holding a bone block, with a distinct value in every voxel of the body."""
    array = np.full(shape, -1000, dtype=np.int16)
    body = np.arange(np.prod(shape)).reshape(shape) % 97
    array[1:-1, 2:-2, 2:-2] = (body[1:-1, 2:-2, 2:-2] + 20).astype(np.int16)
    array[3:-3, 4:-4, 5:-5] = 1200 + body[3:-3, 4:-4, 5:-5]
    return array


def write_volume(path, array, ijk_to_ras, labelmap=False):
    """Write a volume with Slicer's own writer (a scratch scene: the test's scene stays untouched)."""
    scene = slicer.vtkMRMLScene()
    if labelmap:
        node = scene.AddNewNodeByClass("vtkMRMLLabelMapVolumeNode", "labels")
        node.SetAndObserveImageData(nodes.image_data_from_array(array))
        node.SetIJKToRASMatrix(nodes.numpy_to_vtk_matrix(ijk_to_ras))
    else:
        node = nodes.create_scalar_volume_node(scene, array, ijk_to_ras, "ct")
    storage = slicer.vtkMRMLVolumeArchetypeStorageNode()
    scene.AddNode(storage)
    storage.SetFileName(str(path))
    assert storage.WriteData(node)
    return Path(path)


def write_dicom(folder, array, ijk_to_ras, **kwargs):
    scene = slicer.vtkMRMLScene()
    return dicomseries.write_ct_series(nodes.create_scalar_volume_node(scene, array, ijk_to_ras, "ct"), folder, **kwargs)


def assert_same_volume(node, array, ijk_to_ras):
    assert np.abs(nodes.volume_node_ijk_to_ras(node) - ijk_to_ras).max() < 1e-4
    assert np.array_equal(nodes.array_from_volume_node(node), array)


@pytest.fixture
def scene():
    return slicer.vtkMRMLScene()


@pytest.fixture
def ct(scene, tmp_path):
    array = ct_array()
    return owndata.load_ct(scene, write_volume(tmp_path / "ct.nrrd", array, FLIPPED)), array


# --------------------------------------------------------------------------- the CT


@pytest.mark.parametrize("extension", [".nrrd", ".nhdr", ".nii", ".nii.gz", ".mha", ".mhd"])
def test_ct_formats_keep_geometry_and_values(scene, tmp_path, extension):
    array = ct_array()
    path = write_volume(tmp_path / f"patient{extension}", array, FLIPPED)
    messages = []
    volume = owndata.load_ct(scene, path, messages=messages)
    assert volume.IsA("vtkMRMLScalarVolumeNode") and volume.GetName() == "patient"
    assert_same_volume(volume, array, FLIPPED)
    assert nodes.volume_node_ijk_to_ras(volume)[0, 0] < 0.0  # the flipped axis is kept
    assert volume.GetDisplayNode() is not None and volume.GetStorageNode() is not None
    assert messages == []


@pytest.mark.parametrize("name", sorted(GEOMETRIES))
def test_dicom_series_round_trip(scene, tmp_path, name):
    array = ct_array()
    files = write_dicom(tmp_path / "series", array, GEOMETRIES[name], series_description="Thorax 2.5 mm")
    assert len(files) == array.shape[0]
    volume = owndata.load_ct(scene, tmp_path / "series")
    assert volume.GetName() == "Thorax 2.5 mm"
    assert_same_volume(volume, array, GEOMETRIES[name])
    # One file of the series stands for the whole series in its folder.
    assert_same_volume(owndata.load_ct(scene, files[3]), array, GEOMETRIES[name])


def test_dicom_series_tags(tmp_path):
    import pydicom

    array = ct_array()
    files = write_dicom(tmp_path / "series", array, FLIPPED)
    datasets = [pydicom.dcmread(f) for f in files]
    assert {ds.SeriesInstanceUID for ds in datasets} == {datasets[0].SeriesInstanceUID}
    assert len({ds.SOPInstanceUID for ds in datasets}) == len(files)
    first, second = datasets[0], datasets[1]
    assert first.SOPClassUID == dicomseries.CT_IMAGE_STORAGE and first.Modality == "CT"
    assert first.file_meta.MediaStorageSOPClassUID == dicomseries.CT_IMAGE_STORAGE
    assert (first.BitsAllocated, first.PixelRepresentation, first.Rows, first.Columns) == (16, 1, 14, 16)
    assert (float(first.RescaleSlope), float(first.RescaleIntercept)) == (1.0, 0.0)
    assert [float(v) for v in first.PixelSpacing] == [0.7, 0.7] and float(first.SliceThickness) == 2.5
    # LPS: the flipped RAS x axis (i towards patient left) is +L.
    assert np.allclose([float(v) for v in first.ImageOrientationPatient], [1, 0, 0, 0, -1, 0])
    assert np.allclose([float(v) for v in first.ImagePositionPatient], [-12.5, 20.0, 31.0])
    assert np.allclose([float(v) for v in second.ImagePositionPatient], [-12.5, 20.0, 33.5])
    assert np.array_equal(first.pixel_array, array[0])


def test_dicom_series_of_a_float_volume_is_rescaled(scene, tmp_path):
    values = ct_array().astype(np.float32) + 0.25
    values[0, 0, 0] = 3000.5
    write_dicom(tmp_path / "series", values, FLIPPED)
    volume = owndata.load_ct(scene, tmp_path / "series")
    import pydicom

    slope = float(pydicom.dcmread(next((tmp_path / "series").iterdir())).RescaleSlope)
    assert slope != 1.0
    assert np.abs(nodes.array_from_volume_node(volume) - values).max() <= slope
    assert np.abs(nodes.volume_node_ijk_to_ras(volume) - FLIPPED).max() < 1e-4


def test_dicom_series_refuses_a_sheared_grid(tmp_path):
    sheared = FLIPPED.copy()
    sheared[0, 1] = 0.3
    with pytest.raises(ValueError, match="not orthogonal"):
        write_dicom(tmp_path / "series", ct_array(), sheared)


def bad_ct(tmp_path, case):
    """Make the bad input of ``case``; return (path, words the message must contain)."""
    array = ct_array()
    if case == "missing":
        return tmp_path / "nowhere" / "ct.nrrd", ["does not exist"]
    if case == "folder without DICOM":
        (tmp_path / "exports").mkdir()
        (tmp_path / "exports" / "notes.txt").write_text("not an image\n")
        return tmp_path / "exports", ["no DICOM"]
    if case == "non-image file":
        path = tmp_path / "report.pdf"
        path.write_bytes(b"%PDF-1.4 not an image")
        return path, ["not an image file"]
    if case == "corrupt nrrd":
        path = tmp_path / "ct.nrrd"
        path.write_text("NRRD0004\ntype: nonsense\n")
        return path, ["not an image"]
    if case == "2D image":
        return write_volume(tmp_path / "slice.nrrd", array[4:5], FLIPPED), ["2D", "volume"]
    if case == "MR-like values":
        return write_volume(tmp_path / "mr.nii.gz", (array + 1000).astype(np.int16), FLIPPED), ["Hounsfield", "MR"]
    if case == "normalised values":
        return write_volume(tmp_path / "norm.mha", array.astype(np.float32) / 3000.0, FLIPPED), ["Hounsfield"]
    if case == "MR DICOM series":
        files = write_dicom(tmp_path / "mr", array, FLIPPED)
        import pydicom

        for file in files:
            dataset = pydicom.dcmread(file)
            dataset.Modality = "MR"
            dataset.save_as(file)
        return tmp_path / "mr", ["MR series"]
    if case == "two series in one folder":
        write_dicom(tmp_path / "mixed", array, FLIPPED, series_number=1)
        (tmp_path / "mixed" / "slice_0000.dcm").rename(tmp_path / "mixed" / "a.dcm")
        write_dicom(tmp_path / "mixed", array, FLIPPED, series_number=2)
        return tmp_path / "mixed", ["2 DICOM series", "one file"]
    if case == "segmentation given as CT":
        path = tmp_path / "labels.seg.nrrd"
        path.write_bytes(b"NRRD0004\n")
        return path, ["segmentation", "--segmentation"]
    raise AssertionError(case)


@pytest.mark.parametrize("case", ["missing", "folder without DICOM", "non-image file", "corrupt nrrd", "2D image",
                                  "MR-like values", "normalised values", "MR DICOM series",
                                  "two series in one folder", "segmentation given as CT"])
def test_bad_ct_is_refused_and_leaves_nothing(scene, tmp_path, case):
    path, words = bad_ct(tmp_path, case)
    owndata.load_ct(scene, write_volume(tmp_path / "earlier.nrrd", ct_array(), FLIPPED))  # work already done
    count = scene.GetNumberOfNodes()
    with pytest.raises(owndata.InputError) as raised:
        owndata.load_ct(scene, path)
    message = str(raised.value)
    assert str(path) in message
    for word in words:
        assert word in message
    assert scene.GetNumberOfNodes() == count


def test_ct_without_air_loads_with_a_warning(scene, tmp_path):
    array = ct_array()
    array[array < -100] = -80  # cropped inside the patient
    messages = []
    volume = owndata.load_ct(scene, write_volume(tmp_path / "crop.nrrd", array, FLIPPED), messages=messages)
    assert_same_volume(volume, array, FLIPPED)
    assert len(messages) == 1 and "crop.nrrd" in messages[0] and "-500 HU" in messages[0]


# --------------------------------------------------------------------------- segmentations


def labels_array(shape=(10, 14, 16)):
    labels = np.zeros(shape, dtype=np.uint8)
    labels[3:-3, 4:-4, 5:8] = 1
    labels[3:-3, 4:-4, 8:-5] = 2
    labels[1:-1, 2:4, 2:-2] = 7
    return labels


TABLE = "# label name R G B A\n0 Background 0 0 0 0\n1 Vertebra L1 230 200 120 255\n2 Vertebra L2 216 186 110 255\n" \
        "7 Spinal cord 244 214 49 255\n"


def segments_by_name(segmentation_node):
    segmentation = segmentation_node.GetSegmentation()
    return {segmentation.GetSegment(s).GetName(): s for s in segmentation.GetSegmentIDs()}


def segment_mask_on(segmentation_node, segment_id, volume):
    """The segment as a boolean array on ``volume``'s grid (it must lie on that lattice)."""
    labelmap = slicer.vtkOrientedImageData()
    assert slicer.vtkSlicerSegmentationsModuleLogic.GetSegmentBinaryLabelmapRepresentation(
        segmentation_node, segment_id, labelmap)
    label = segmentation_node.GetSegmentation().GetSegment(segment_id).GetLabelValue()
    transform = np.linalg.inv(nodes.volume_node_ijk_to_ras(volume)) @ owndata._matrix_of(labelmap)
    assert np.allclose(transform[:3, :3], np.eye(3), atol=1e-6)
    offset = np.round(transform[:3, 3]).astype(int)
    assert np.allclose(transform[:3, 3], offset, atol=1e-6)
    extent = labelmap.GetExtent()
    mask = np.zeros(nodes.array_from_volume_node(volume).shape, dtype=bool)
    if extent[1] < extent[0]:
        return mask
    values = nodes.array_from_image_data(labelmap) == label
    start = np.array(extent[0::2]) + offset
    mask[start[2]:start[2] + values.shape[0], start[1]:start[1] + values.shape[1],
         start[0]:start[0] + values.shape[2]] = values
    return mask


def assert_reference_is(segmentation_node, volume):
    reference = slicer.vtkMRMLSegmentationNode()
    reference.SetReferenceImageGeometryParameterFromVolumeNode(volume)
    parameter = slicer.vtkSegmentationConverter.GetReferenceImageGeometryParameterName()
    assert segmentation_node.GetSegmentation().GetConversionParameter(parameter) == \
        reference.GetSegmentation().GetConversionParameter(parameter)


@pytest.mark.parametrize("table", ["sidecar", "explicit", "itksnap"])
def test_labelmap_with_a_colour_table_gives_named_segments(scene, tmp_path, ct, table):
    volume, _ = ct
    labels = labels_array()
    path = write_volume(tmp_path / "auto.nii.gz", labels, FLIPPED, labelmap=True)
    color_table = None
    if table == "sidecar":
        (tmp_path / "auto.ctbl").write_text(TABLE)
    elif table == "explicit":
        color_table = tmp_path / "names.txt"
        color_table.write_text(TABLE)
    else:
        color_table = tmp_path / "snap.label"
        color_table.write_text('# ITK-SNAP Label Description File\n    0     0    0    0        0  0  0    "Clear Label"\n'
                               '    1   230  200  120        1  1  1    "Vertebra L1"\n'
                               '    2   216  186  110        1  1  1    "Vertebra L2"\n'
                               '    7   244  214   49        1  1  1    "Spinal cord"\n')
    count = scene.GetNumberOfNodes()
    messages = []
    segmentation = owndata.load_segmentation(scene, path, volume, color_table=color_table, messages=messages)
    assert messages == []
    by_name = segments_by_name(segmentation)
    assert sorted(by_name) == ["Spinal cord", "Vertebra L1", "Vertebra L2"]
    assert np.allclose(segmentation.GetSegmentation().GetSegment(by_name["Spinal cord"]).GetColor(),
                       (244 / 255, 214 / 255, 49 / 255))
    for name, label in (("Vertebra L1", 1), ("Vertebra L2", 2), ("Spinal cord", 7)):
        assert np.array_equal(segment_mask_on(segmentation, by_name[name], volume), labels == label)
    assert_reference_is(segmentation, volume)
    # Only the segmentation and its display node stay: intermediate labelmap and colour nodes are gone.
    assert scene.GetNumberOfNodes() == count + 2
    assert segmentation.GetDisplayNode() is not None


def test_labelmap_without_a_table_names_labels_with_a_warning(scene, tmp_path, ct):
    volume, _ = ct
    path = write_volume(tmp_path / "auto.mha", labels_array(), FLIPPED, labelmap=True)
    messages = []
    segmentation = owndata.load_segmentation(scene, path, volume, messages=messages)
    assert sorted(segments_by_name(segmentation)) == ["Label 1", "Label 2", "Label 7"]
    assert len(messages) == 1 and "auto.mha" in messages[0] and "Label <k>" in messages[0]


def test_seg_nrrd_on_the_ct_grid_loads_as_it_is(scene, tmp_path, ct):
    volume, _ = ct
    labels = labels_array()
    writer_scene = slicer.vtkMRMLScene()
    (tmp_path / "in.ctbl").write_text(TABLE)
    written = owndata.load_segmentation(
        writer_scene, write_volume(tmp_path / "in.nrrd", labels, FLIPPED, labelmap=True), volume)
    storage = slicer.vtkMRMLSegmentationStorageNode()
    writer_scene.AddNode(storage)
    storage.SetFileName(str(tmp_path / "spine.seg.nrrd"))
    assert storage.WriteData(written)  # Slicer crops it to the segments' extent
    messages = []
    segmentation = owndata.load_segmentation(scene, tmp_path / "spine.seg.nrrd", volume, messages=messages)
    assert messages == []
    assert segmentation.GetName() == "spine"
    by_name = segments_by_name(segmentation)
    assert np.array_equal(segment_mask_on(segmentation, by_name["Vertebra L2"], volume), labels == 2)
    assert_reference_is(segmentation, volume)


def off_grid_labels():
    """A labelmap on a 1 mm oblique grid covering the CT, with a block in known RAS bounds."""
    matrix = geometry(rotation(2, 0.25), (1.0, 1.0, 1.0), (-10.0, -25.0, 25.0))
    shape = (40, 30, 30)
    kji = np.stack(np.meshgrid(*[np.arange(n) for n in shape], indexing="ij"), axis=-1).reshape(-1, 3)
    ras = (np.c_[kji[:, ::-1], np.ones(len(kji))] @ matrix.T)[:, :3]
    low, high = np.array([0.0, -15.0, 38.0]), np.array([6.0, -10.0, 46.0])
    inside = np.all((ras >= low) & (ras <= high), axis=1).reshape(shape)
    return inside.astype(np.uint8) * 3, matrix, (low, high)


def ras_mask(volume, low, high):
    array = nodes.array_from_volume_node(volume)
    kji = np.stack(np.meshgrid(*[np.arange(n) for n in array.shape], indexing="ij"), axis=-1).reshape(-1, 3)
    ras = (np.c_[kji[:, ::-1], np.ones(len(kji))] @ nodes.volume_node_ijk_to_ras(volume).T)[:, :3]
    return np.all((ras >= low) & (ras <= high), axis=1).reshape(array.shape)


@pytest.mark.parametrize("kind", ["labelmap", "seg.nrrd"])
def test_segmentation_on_another_grid_is_resampled_with_a_warning(scene, tmp_path, ct, kind):
    volume, _ = ct
    labels, matrix, (low, high) = off_grid_labels()
    path = write_volume(tmp_path / "other.nrrd", labels, matrix, labelmap=True)
    (tmp_path / "other.ctbl").write_text("3 Vessel 200 0 0 255\n")
    if kind == "seg.nrrd":
        writer_scene = slicer.vtkMRMLScene()
        own_grid = nodes.create_scalar_volume_node(writer_scene, labels.astype(np.int16), matrix, "grid")
        written = owndata.load_segmentation(writer_scene, path, own_grid)
        storage = slicer.vtkMRMLSegmentationStorageNode()
        writer_scene.AddNode(storage)
        path = tmp_path / "other.seg.nrrd"
        storage.SetFileName(str(path))
        assert storage.WriteData(written)
    messages = []
    segmentation = owndata.load_segmentation(scene, path, volume, messages=messages)
    assert len(messages) == 1
    warning = messages[0]
    assert path.name in warning and "resampled" in warning and "nearest neighbour" in warning
    assert "16 x 14 x 10 voxels of 0.7 x 0.7 x 2.5 mm" in warning  # the CT's grid
    assert "voxels of 1 x 1 x 1 mm" in warning  # the segmentation's
    (segment_id,) = segmentation.GetSegmentation().GetSegmentIDs()
    mask = segment_mask_on(segmentation, segment_id, volume)  # on the CT's lattice
    expected = ras_mask(volume, low, high)
    assert mask.sum() > 0
    # Nearest neighbour on a 1 mm grid: at most a voxel's width off at the block's faces.
    assert np.all(mask <= ras_mask(volume, low - 1.0, high + 1.0))
    assert np.all(expected <= mask | ~ras_mask(volume, low + 1.0, high - 1.0))
    assert_reference_is(segmentation, volume)


def test_segmentation_that_does_not_overlap_is_refused(scene, tmp_path, ct):
    volume, _ = ct
    labels, matrix, _ = off_grid_labels()
    matrix[:3, 3] += [400.0, 0.0, 0.0]
    path = write_volume(tmp_path / "elsewhere.nrrd", labels, matrix, labelmap=True)
    count = scene.GetNumberOfNodes()
    with pytest.raises(owndata.InputError, match="does not overlap") as raised:
        owndata.load_segmentation(scene, path, volume)
    assert str(path) in str(raised.value)
    assert scene.GetNumberOfNodes() == count


def bad_segmentation(tmp_path, case):
    """Make the bad input of ``case``; return (path, the file the message names, words it must contain)."""
    labels = labels_array()
    if case == "missing":
        path = tmp_path / "gone.seg.nrrd"
        return path, path, ["does not exist"]
    if case == "folder":
        return tmp_path, tmp_path, ["not a segmentation file"]
    if case == "text file":
        path = tmp_path / "labels.csv"
        path.write_text("1,2,3\n")
        return path, path, ["not a segmentation file"]
    if case == "a CT as labelmap":
        path = write_volume(tmp_path / "ct_again.nrrd", ct_array(), FLIPPED)
        return path, path, ["negative values", "not a labelmap"]
    if case == "empty labelmap":
        path = write_volume(tmp_path / "empty.nrrd", np.zeros_like(labels), FLIPPED, labelmap=True)
        return path, path, ["no labelled voxel"]
    if case == "2D labelmap":
        path = write_volume(tmp_path / "flat.nrrd", labels[5:6], FLIPPED, labelmap=True)
        return path, path, ["2D"]
    if case in ("corrupt seg.nrrd", "truncated seg.nrrd"):
        # Either one aborts the process inside Slicer's segmentation reader if it gets there.
        path = tmp_path / "broken.seg.nrrd"
        if case == "corrupt seg.nrrd":
            path.write_text("NRRD0004\ntype: nonsense\n")
        else:
            scratch = slicer.vtkMRMLScene()
            reference = nodes.create_scalar_volume_node(scratch, ct_array(), FLIPPED, "ct")
            (tmp_path / "whole.ctbl").write_text(TABLE)
            written = owndata.load_segmentation(
                scratch, write_volume(tmp_path / "whole.nrrd", labels, FLIPPED, labelmap=True), reference)
            storage = slicer.vtkMRMLSegmentationStorageNode()
            scratch.AddNode(storage)
            storage.SetFileName(str(path))
            storage.SetUseCompression(False)
            assert storage.WriteData(written)
            path.write_bytes(path.read_bytes()[:-200])
        return path, path, ["not a readable NRRD file"]
    if case == "bad colour table":
        path = write_volume(tmp_path / "named.nrrd", labels, FLIPPED, labelmap=True)
        table = tmp_path / "named.ctbl"
        table.write_text("1 Vertebra L1 230 200 120 255\n2 Vertebra L2 two hundred\n")
        return path, table, ["line 2", "whole numbers from 0 to 255"]
    raise AssertionError(case)


@pytest.mark.parametrize("case", ["missing", "folder", "text file", "a CT as labelmap", "empty labelmap",
                                  "2D labelmap", "corrupt seg.nrrd", "truncated seg.nrrd", "bad colour table"])
def test_bad_segmentation_is_refused_and_leaves_nothing(scene, tmp_path, ct, case):
    volume, _ = ct
    path, named, words = bad_segmentation(tmp_path, case)
    count = scene.GetNumberOfNodes()
    with pytest.raises(owndata.InputError) as raised:
        owndata.load_segmentation(scene, path, volume)
    message = str(raised.value)
    assert str(named) in message
    for word in words:
        assert word in message
    assert scene.GetNumberOfNodes() == count


# --------------------------------------------------------------------------- roles


@pytest.fixture
def named_segmentation(scene, tmp_path, ct):
    volume, _ = ct
    (tmp_path / "spine.ctbl").write_text(TABLE)
    path = write_volume(tmp_path / "spine.nrrd", labels_array(), FLIPPED, labelmap=True)
    return owndata.load_segmentation(scene, path, volume)


def test_roles_by_name(named_segmentation):
    by_name = segments_by_name(named_segmentation)
    cuttable, protected = owndata.resolve_roles(named_segmentation, "vertebra l1, VERTEBRA_L2", ["spinal cord"])
    assert cuttable == [by_name["Vertebra L1"], by_name["Vertebra L2"]]
    assert protected == [by_name["Spinal cord"]]
    # Segment IDs are accepted as well, and a name given twice counts once.
    cuttable, protected = owndata.resolve_roles(named_segmentation, [by_name["Vertebra L1"], "Vertebra L1"], [])
    assert (cuttable, protected) == ([by_name["Vertebra L1"]], [])


def test_unknown_segment_name_lists_the_names(named_segmentation):
    with pytest.raises(owndata.InputError) as raised:
        owndata.resolve_roles(named_segmentation, ["Vertebra L3"], ["Spinal cord"])
    message = str(raised.value)
    assert "spine.nrrd" in message and "'Vertebra L3'" in message
    assert "'Vertebra L1', 'Vertebra L2', 'Spinal cord'" in message


def test_segment_named_in_both_lists_is_refused(named_segmentation):
    with pytest.raises(owndata.InputError, match="both cuttable and protected"):
        owndata.resolve_roles(named_segmentation, ["Vertebra L1", "spinal cord"], ["Spinal Cord"])


def test_lateral_entry_into_segments(scene, tmp_path, named_segmentation, ct):
    volume, _ = ct
    by_name = segments_by_name(named_segmentation)
    entry = drilling.lateral_entry_into_segments(named_segmentation, [by_name["Vertebra L1"], by_name["Vertebra L2"]])
    # Coming from the patient's right (+x): the block's first voxel at the smallest i (x = 12.5 - 0.7 i).
    labels = labels_array()
    i_first = np.argwhere(np.isin(labels, (1, 2)))[:, 2].min()
    assert entry[0] == pytest.approx(FLIPPED[0, 3] - 0.7 * i_first)
    k, j = np.argwhere(np.isin(labels, (1, 2)))[:, :2].T
    assert FLIPPED[1, 3] + 0.7 * j.min() <= entry[1] <= FLIPPED[1, 3] + 0.7 * j.max()
    assert FLIPPED[2, 3] + 2.5 * k.min() <= entry[2] <= FLIPPED[2, 3] + 2.5 * k.max()


# --------------------------------------------------------------------------- the main job


def run_main_job(*arguments):
    environment = dict(os.environ, PYTHONPATH=str(MODULE_DIR))
    return subprocess.run([sys.executable, "-m", "VolumeCuttingLib.jobs.mainjob", *map(str, arguments)],
                          capture_output=True, text=True, env=environment, timeout=300)


def small_head(tmp_path):
    """A skull-like shell of bone (1300 HU) around soft tissue, in air; 48 x 40 x 32 voxels, x flipped."""
    k, j, i = np.mgrid[0:32, 0:40, 0:48]
    radius = np.sqrt(((k - 15.5) * 1.5) ** 2 + (j - 19.5) ** 2 + (i - 23.5) ** 2)
    array = np.full(k.shape, -1000, dtype=np.int16)
    array[radius < 18] = 40
    array[(radius >= 13) & (radius < 18)] = 1300
    return write_volume(tmp_path / "head.nrrd", array, geometry(np.diag([-1.0, 1.0, 1.0]), (1.0, 1.0, 1.5),
                                                                 (20.0, -15.0, -20.0)))


def test_main_job_on_an_own_ct(tmp_path):
    import json

    out = tmp_path / "out"
    result = run_main_job("--ct", small_head(tmp_path), "--out", out, "--size", "96x64")
    assert result.returncode == 0, result.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["own_data"]["ct"].endswith("head.nrrd")
    # Segments by the names a person reads, their IDs beside.
    assert summary["cuttable_segments"] == ["Cortical bone", "Trabecular bone"]
    assert summary["cuttable_segment_ids"] == ["CorticalBone", "TrabecularBone"]
    cortical = summary["drilling"]["removed_volume_per_segment"]["Cortical bone"]
    assert cortical["segment_id"] == "CorticalBone" and cortical["removed_volume_mm3"] > 50.0
    assert summary["drilling"]["refused_poses"] == 0
    for name in ("3d.png", "scene.mrb", "removed.stl", "session.json"):
        assert (out / name).is_file()
    # The drilling is recorded on the user's grid; the assessment rebuilds only the shipped scans, so it is not graded.
    from VolumeCuttingLib.cutting import recording

    session = recording.load(out / "session.json")
    assert session["scan"]["name"] == "own" and session["scan"]["grid"]["dimensions"] == [48, 40, 32]
    assert summary["assessment"]["score"] is None


@pytest.mark.parametrize("arguments, named", [
    (["--ct", "{tmp}/no_such_scan"], "{tmp}/no_such_scan"),
    (["--ct", "{head}", "--segmentation", "{tmp}/labels.nrrd"], "{tmp}/labels.nrrd"),
    (["--ct", "{head}", "--cuttable", "Femur"], "Femur"),
])
def test_main_job_bad_input_exits_1_with_one_message(tmp_path, arguments, named):
    head = small_head(tmp_path)
    fill = {"tmp": tmp_path, "head": head}
    result = run_main_job(*[a.format(**fill) for a in arguments], "--out", tmp_path / "out", "--size", "32x32")
    assert result.returncode == 1
    assert named.format(**fill) in result.stderr
    assert "Traceback" not in result.stderr
    assert result.stderr.strip().count("\n") == 0  # one line: the message


# --------------------------------------------------------------------------- patient scale


@pytest.mark.realdata
def test_patient_scale_case_loads_back_through_owndata(tmp_path):
    from VolumeCuttingLib.data import headct

    try:
        head = headct.load_array()
    except headct.HeadCTUnavailableError as error:
        pytest.skip(f"head CT unavailable: {error}")
    case = patientscale.generate(head=(head[0], head[2]))
    assert case.ct.shape == (133, 512, 512) and case.ct.dtype == np.int16
    assert case.ct.min() >= -1024 and case.ct.max() > 1500
    assert case.ct[0, 0, 0] == patientscale.AIR_HU  # beyond the head
    counts = np.bincount(case.labels.ravel(), minlength=6)
    assert np.all(counts[1:] > 0)
    # The protected tubes run through every slice.
    for label in (4, 5):
        assert np.all(np.any(case.labels == label, axis=(1, 2)))
    paths = patientscale.write_case(case, tmp_path, formats=("nrrd", "dicom", "seg.nrrd"))
    assert len(list(paths["dicom"].iterdir())) == 133
    scene = slicer.vtkMRMLScene()
    for kind in ("dicom", "nrrd"):
        volume = owndata.load_ct(scene, paths[kind])
        assert volume.GetImageData().GetDimensions() == (512, 512, 133)
        assert np.allclose(volume.GetSpacing(), (0.70, 0.70, 2.5))
        matrix = nodes.volume_node_ijk_to_ras(volume)
        assert matrix[0, 0] == pytest.approx(-0.70)  # x flipped, kept
        assert np.abs(matrix - case.ijk_to_ras).max() < 1e-4
    assert np.array_equal(nodes.array_from_volume_node(volume), case.ct)
    messages = []
    segmentation = owndata.load_segmentation(scene, paths["seg.nrrd"], volume, messages=messages)
    assert messages == []
    cuttable, protected = owndata.resolve_roles(segmentation, patientscale.CUTTABLE, patientscale.PROTECTED)
    assert len(cuttable) == 3 and len(protected) == 2
    cord = segment_mask_on(segmentation, segments_by_name(segmentation)["Spinal cord"], volume)
    assert np.array_equal(cord, case.labels == 4)
