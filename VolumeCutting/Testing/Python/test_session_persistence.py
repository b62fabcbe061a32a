"""A saved drilling session comes back whole: the cut bit for bit, on the grids real scans have.

Real scans have spacings such as 0.957031 mm, flipped or oblique axes; their
scene files store the geometry as text. These tests save sessions on such
grids through a scene bundle (.mrb) and through a scene file (.mrml with its
data files), reload them into a fresh application, and check the cut itself:
its samples, its removed volume, what undo may do after a reload, and that
drilling goes on. A damaged cut-field file is refused, naming the file, while
the rest of the scene loads.
"""

import math
import os
import shutil
import zipfile

import numpy as np
import pytest
import slicer
import vtk

from VolumeCuttingLib.jobs import selftests
from VolumeCuttingLib.scene import nodes
from VolumeCuttingLib.scene.application import HeadlessSlicer


def rotation_about(axis, degrees):
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    angle = math.radians(degrees)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


GRIDS = {
    # The shipped head CT's spacing, which broke reloading before.
    "head_ct": (np.diag([0.957031, 0.957031, 1.5]), [-122.49, -110.27, -80.25]),
    # A chest CT made by others: x flipped, thick slices.
    "flipped_chest": (np.diag([-0.703125, 0.703125, 2.5]), [180.1, -210.77, -333.3]),
    # Oblique: tilted 13 degrees, non-round anisotropic spacing.
    "oblique": (rotation_about([0.3, 1.0, 0.2], 13.0) @ np.diag([0.4296875, 0.4296875, 0.625]), [12.3, -45.6, 78.9]),
}


def ct_on_grid(application, grid_name, shape=(24, 40, 44)):
    """A bone block with a protected tube through it, on the named grid."""
    directions, origin = GRIDS[grid_name]
    ijk_to_ras = np.eye(4)
    ijk_to_ras[:3, :3] = directions
    ijk_to_ras[:3, 3] = origin
    k, j, i = np.mgrid[0 : shape[0], 0 : shape[1], 0 : shape[2]]
    voxels = np.full(shape, -1000, dtype=np.int16)
    bone = (i >= 6) & (i < shape[2] - 6) & (j >= 6) & (j < shape[1] - 6) & (k >= 3) & (k < shape[0] - 3)
    voxels[bone] = 1200
    volume = nodes.create_scalar_volume_node(application.scene, voxels, ijk_to_ras, "CT")
    labels = np.zeros(shape, dtype=np.uint8)
    labels[bone] = 1
    tube = (i - shape[2] / 2) ** 2 + (j - shape[1] / 2) ** 2 <= 9
    labels[tube & bone] = 2
    segmentation = application.scene.AddNewNodeByClass("vtkMRMLSegmentationNode", "Anatomy")
    segmentation.CreateDefaultDisplayNodes()
    segmentation.SetReferenceImageGeometryParameterFromVolumeNode(volume)
    for value, name in ((1, "Bone"), (2, "Nerve")):
        mask = slicer.vtkOrientedImageData()
        mask.ShallowCopy(nodes.image_data_from_array((labels == value).astype(np.uint8)))
        mask.SetImageToWorldMatrix(nodes.numpy_to_vtk_matrix(ijk_to_ras))
        segment = slicer.vtkSegment()
        segment.SetName(name)
        segment.AddRepresentation(slicer.vtkSegmentationConverter.GetBinaryLabelmapRepresentationName(), mask)
        segmentation.GetSegmentation().AddSegment(segment, name)
    return volume, segmentation, ijk_to_ras


def drilled_session(application, grid_name):
    logic = application.volume_cutting_logic
    volume, segmentation, ijk_to_ras = ct_on_grid(application, grid_name)
    cut = logic.AddVolumeCutNode(volume, segmentation)
    assert cut.SetSegmentCuttable("Bone", True)
    assert cut.SetSegmentProtected("Nerve", True)

    def ras(i, j, k):
        return (ijk_to_ras @ np.array([i, j, k, 1.0]))[:3].tolist()

    # Two strokes, the second into the nerve.
    for path in ([ras(10, 12, 12), ras(30, 14, 12)], [ras(22, 10, 12), ras(22, 20, 12)]):
        assert logic.BeginStroke(cut)
        for p0, p1 in zip(path[:-1], path[1:]):
            assert logic.CutSphereSweep(cut, p0, p1, 2.0)
        assert logic.EndStroke(cut)
    return cut, ras


def assert_same_cut(expected, actual):
    """The same samples at the same places, whatever the order of the grid's axes."""
    assert actual is not None
    assert sorted(actual.GetDimensions()) == sorted(expected.GetDimensions())
    a = selftests.cut_samples_by_position(expected)
    assert len(a) > 1000
    assert selftests.same_cut(expected, actual)


class VtkMessages:
    """Collects what VTK logs while a scene loads (errors and warnings)."""

    def __enter__(self):
        self.window = vtk.vtkStringOutputWindow()
        self.previous = vtk.vtkOutputWindow.GetInstance()
        vtk.vtkOutputWindow.SetInstance(self.window)
        return self

    def __exit__(self, *exc):
        vtk.vtkOutputWindow.SetInstance(self.previous)

    @property
    def text(self):
        return self.window.GetOutput()


def reload_and_check(path, original_cut, removed, grid_name, via):
    reloaded = HeadlessSlicer()
    logic = reloaded.volume_cutting_logic
    with VtkMessages() as messages:
        if via == "mrb":
            reloaded.load_bundle(path)
        else:
            reloaded.scene.SetURL(str(path))
            assert reloaded.scene.Connect()
    cut = reloaded.scene.GetFirstNodeByClass("vtkMRMLVolumeCutNode")
    field = cut.GetCutField()
    assert_same_cut(original_cut.GetCutField(), field)
    # The logic keeps the reloaded cut without a warning. (Slicer's reader
    # turns a left-handed IJK-to-RAS, as the flipped chest has, right-handed
    # by reversing k: the cut then follows, copied exactly.)
    with VtkMessages() as messages:
        assert logic.GetRemovedVolume(cut) == pytest.approx(removed, rel=1e-12)
    assert messages.text == "", messages.text
    reindexed = np.linalg.det(GRIDS[grid_name][0]) < 0
    assert (logic.GetCutField(cut) is field) != reindexed
    field = logic.GetCutField(cut)
    assert_same_cut(original_cut.GetCutField(), field)
    assert logic.GetRemovedVolumeInSegment(cut, "Nerve") == 0.0
    # Undo history is not part of a saved scene (as in Slicer): undo says so
    # and changes nothing.
    assert field.GetNumberOfUndoSteps() == 0
    with VtkMessages() as messages:
        assert not logic.UndoStroke(cut)
    assert "nothing to undo" in messages.text or "no stroke to undo" in messages.text
    assert logic.GetRemovedVolume(cut) == pytest.approx(removed, rel=1e-12)
    # Drilling goes on, and its stroke undoes back to the reloaded cut exactly.
    ijk_to_ras = nodes.volume_node_ijk_to_ras(cut.GetAnatomyVolumeNode())
    p0 = (ijk_to_ras @ np.array([12.0, 26.0, 14.0, 1.0]))[:3].tolist()
    p1 = (ijk_to_ras @ np.array([28.0, 26.0, 14.0, 1.0]))[:3].tolist()
    assert logic.CutSphereSweep(cut, p0, p1, 2.0)
    assert logic.GetRemovedVolume(cut) > removed + 10.0
    assert logic.UndoStroke(cut)
    assert_same_cut(original_cut.GetCutField(), field)
    return reloaded


@pytest.mark.parametrize("grid_name", sorted(GRIDS))
@pytest.mark.parametrize("via", ["mrb", "mrml"])
def test_reloaded_session_keeps_its_cut(tmp_path, grid_name, via):
    application = HeadlessSlicer()
    cut, _ = drilled_session(application, grid_name)
    logic = application.volume_cutting_logic
    removed = logic.GetRemovedVolume(cut)
    assert removed > 50.0
    assert logic.GetRemovedVolumeInSegment(cut, "Nerve") == 0.0
    assert logic.GetContactSegmentID(cut) == "Nerve"
    bundle = application.save_bundle(tmp_path / "session.mrb")
    if via == "mrb":
        reload_and_check(bundle, cut, removed, grid_name, via)
    else:
        # The same scene as a .mrml file beside its data files.
        folder = tmp_path / "unpacked"
        with zipfile.ZipFile(bundle) as archive:
            archive.extractall(folder)
        scene_files = list(folder.rglob("*.mrml"))
        assert len(scene_files) == 1
        assert list(folder.rglob("*.vcut"))
        reload_and_check(scene_files[0], cut, removed, grid_name, via)


def test_relative_bundle_paths(tmp_path, monkeypatch):
    application = HeadlessSlicer()
    cut, _ = drilled_session(application, "head_ct")
    removed = application.volume_cutting_logic.GetRemovedVolume(cut)
    monkeypatch.chdir(tmp_path)
    saved = application.save_bundle(os.path.join("sessions", "drilled.mrb"))
    assert saved.is_absolute() and saved.is_file()
    reloaded = HeadlessSlicer()
    reloaded.load_bundle(os.path.join("sessions", "drilled.mrb"))
    read = reloaded.scene.GetFirstNodeByClass("vtkMRMLVolumeCutNode")
    assert reloaded.volume_cutting_logic.GetRemovedVolume(read) == pytest.approx(removed, rel=1e-12)
    with pytest.raises(FileNotFoundError):
        reloaded.load_bundle("no/such/bundle.mrb")


def test_damaged_cut_file_is_refused_and_the_scene_still_loads(tmp_path):
    application = HeadlessSlicer()
    cut, _ = drilled_session(application, "flipped_chest")
    bundle = application.save_bundle(tmp_path / "session.mrb")
    folder = tmp_path / "unpacked"
    with zipfile.ZipFile(bundle) as archive:
        archive.extractall(folder)
    (cut_file,) = folder.rglob("*.vcut")
    data = bytearray(cut_file.read_bytes())
    data[len(data) // 2] ^= 0x5A  # one byte flipped in the middle of the samples
    cut_file.write_bytes(bytes(data))
    (scene_file,) = folder.rglob("*.mrml")

    reloaded = HeadlessSlicer()
    with VtkMessages() as messages:
        reloaded.scene.SetURL(str(scene_file))
        reloaded.scene.Connect()
    assert cut_file.name in messages.text and "damaged" in messages.text, messages.text
    # The rest of the session is there; the cut node holds no other cut.
    read = reloaded.scene.GetFirstNodeByClass("vtkMRMLVolumeCutNode")
    assert read is not None
    assert read.GetCutField() is None or read.GetCutField().GetNumberOfAllocatedBricks() == 0
    assert read.GetAnatomyVolumeNode() is not None and read.GetAnatomyVolumeNode().GetImageData() is not None
    assert read.GetSegmentationNode() is not None
    assert read.GetSegmentationNode().GetSegmentation().GetNumberOfSegments() == 2
    assert list(read.GetProtectedSegmentIDs()) == ["Nerve"]


def test_grid_change_resamples_or_refuses(tmp_path):
    """A real change of the anatomy's grid keeps the cut (resampled) or is refused, never silent."""
    application = HeadlessSlicer()
    logic = application.volume_cutting_logic
    cut, _ = drilled_session(application, "oblique")
    removed = logic.GetRemovedVolume(cut)
    old_field = logic.GetCutField(cut)

    # A finer sub-voxel factor: resampled with a warning naming the change.
    cut.SetSubVoxelFactor(4)
    with VtkMessages() as messages:
        resampled = logic.GetRemovedVolume(cut)
    assert "sub-voxel factor 2 -> 4" in messages.text
    assert resampled == pytest.approx(removed, rel=0.01)
    assert logic.GetCutField(cut) is not old_field

    # The anatomy replaced by a crop that misses part of the cut: refused, the cut stays.
    volume = cut.GetAnatomyVolumeNode()
    original = nodes.array_from_volume_node(volume)
    ijk_to_ras = nodes.volume_node_ijk_to_ras(volume)
    cropped_to_ras = ijk_to_ras.copy()
    cropped_to_ras[:3, 3] = (ijk_to_ras @ np.array([20.0, 0.0, 0.0, 1.0]))[:3]
    cropped = nodes.create_scalar_volume_node(application.scene, original[:, :, 20:], cropped_to_ras, "Cropped")
    field = logic.GetCutField(cut)
    cut.SetAndObserveAnatomyVolumeNodeID(cropped.GetID())
    with VtkMessages() as messages:
        assert logic.GetCutField(cut) is None
    assert "refused" in messages.text and "dimensions 44x40x24 -> 24x40x24" in messages.text, messages.text
    assert cut.GetCutField() is field
    # Put back: the same cut, nothing lost.
    cut.SetAndObserveAnatomyVolumeNodeID(volume.GetID())
    assert logic.GetRemovedVolume(cut) == pytest.approx(resampled, rel=1e-12)
    assert logic.GetCutField(cut) is field


def test_mutated_cut_files_never_load_as_another_cut(tmp_path):
    """150 mutations of a real session's .vcut (byte flips, truncations, header overwrites, appended bytes):
    each is refused with a message naming the file, and the field read into keeps its cut."""
    application = HeadlessSlicer()
    cut, _ = drilled_session(application, "head_ct")
    field = cut.GetCutField()
    path = tmp_path / "session.vcut"
    assert field.WriteFile(str(path))
    original = path.read_bytes()
    rng = np.random.default_rng(150)
    target = slicer.vtkVolumeCutField()
    assert target.ReadFile(str(path))
    refused = 0
    for n in range(150):
        data = bytearray(original)
        kind = n % 4
        if kind == 0:
            position = int(rng.integers(0, len(data)))
            data[position] ^= int(rng.integers(1, 256))
        elif kind == 1:
            data = data[: int(rng.integers(0, len(data)))]
        elif kind == 2:
            start = int(rng.integers(0, 160))
            data[start : start + 8] = bytes(int(rng.integers(0, 256)) for _ in range(8))
            if bytes(data) == original:
                continue
        else:
            data += bytes(int(rng.integers(1, 64)))
        damaged = tmp_path / "damaged.vcut"
        damaged.write_bytes(bytes(data))
        with VtkMessages() as messages:
            loaded = target.ReadFile(str(damaged))
        refused += not loaded
        assert not loaded, f"mutation {n} loaded"
        assert "damaged.vcut" in messages.text
        assert selftests.same_cut(field, target)
    assert refused > 140
