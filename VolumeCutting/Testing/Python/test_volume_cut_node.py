"""The volume-cut node and the module logic from Python, in a real MRML scene.

The classes are reached as ``slicer.<ClassName>``, exactly as Python code written
for desktop Slicer reaches a loadable module's wrapped classes.
"""

import numpy as np
import pytest
import slicer
import vtk
from vtkmodules.util import numpy_support

from VolumeCuttingLib.scene.application import HeadlessSlicer


@pytest.fixture
def scene():
    # The module logic registers vtkMRMLVolumeCutNode, as the module does at start-up.
    application = HeadlessSlicer()
    scene = application.scene
    scene.volumeCuttingLogic = application.volume_cutting_logic
    scene.application = application
    return scene


def add_ball_ct(scene, name="CT", spacing=(0.6, 0.6, 1.0)):
    """A trabecular ball (radius 5 voxels) in a cortical shell (radius 7), in HU."""
    k, j, i = np.mgrid[0:20, 0:22, 0:22]
    r = np.sqrt((i - 11.0) ** 2 + (j - 11.0) ** 2 + (k - 10.0) ** 2)
    voxels = np.full(r.shape, -1000, dtype=np.int16)
    voxels[r <= 7.0] = 1500
    voxels[r <= 5.0] = 450
    image = vtk.vtkImageData()
    image.SetDimensions(22, 22, 20)
    image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(voxels.ravel(), deep=True, array_type=vtk.VTK_SHORT))
    volume = scene.AddNewNodeByClass("vtkMRMLScalarVolumeNode", name)
    volume.SetAndObserveImageData(image)
    volume.SetSpacing(*spacing)
    volume.SetOrigin(-5.0, 3.0, 20.0)
    volume.CreateDefaultDisplayNodes()
    return volume, int((r <= 5.0).sum()), int(((r > 5.0) & (r <= 7.0)).sum())


# Centre of the ball of add_ball_ct (voxel 11, 11, 10) in RAS.
BALL_CENTRE = [-5.0 + 11 * 0.6, 3.0 + 11 * 0.6, 20.0 + 10 * 1.0]


def ball_session(scene, cuttable=("TrabecularBone",)):
    """The ball CT, its bone segmentation and a cut node with these segments cuttable."""
    volume, _, _ = add_ball_ct(scene)
    logic = scene.volumeCuttingLogic
    bone = logic.CreateBoneSegmentation(volume, 700.0, 200.0, 0.0)
    cut = logic.AddVolumeCutNode(volume, bone)
    cut.SetCuttableSegmentIDs(list(cuttable))
    return volume, bone, cut, logic


def test_classes_are_in_the_slicer_namespace():
    node = slicer.vtkMRMLVolumeCutNode()
    assert isinstance(node, slicer.vtkMRMLNode)
    assert node.GetSubVoxelFactor() == 2
    assert issubclass(slicer.vtkSlicerVolumeCuttingLogic, slicer.vtkSlicerModuleLogic)
    assert issubclass(slicer.vtkImageBoneSegmentation, vtk.vtkImageAlgorithm)


def test_bone_segmentation_and_roles(scene):
    volume, trabecular_count, cortical_count = add_ball_ct(scene)
    logic = scene.volumeCuttingLogic
    bone = logic.CreateBoneSegmentation(volume, 700.0, 200.0, 0.0)
    assert bone is not None
    cortical_id = logic.GetCorticalBoneSegmentID()
    trabecular_id = logic.GetTrabecularBoneSegmentID()
    assert bone.GetSegmentation().GetSegmentIDs() == (cortical_id, trabecular_id)

    def count(segment_id):
        labelmap = bone.GetBinaryLabelmapInternalRepresentation(segment_id)
        return int(numpy_support.vtk_to_numpy(labelmap.GetPointData().GetScalars()).astype(bool).sum())

    assert count(cortical_id) == cortical_count
    assert count(trabecular_id) == trabecular_count

    cut = logic.AddVolumeCutNode(volume, bone)
    assert cut.GetAnatomyVolumeNode() is volume
    assert cut.GetSegmentationNode() is bone
    assert cut.SetSegmentCuttable(trabecular_id, True)
    assert cut.SetSegmentProtected(cortical_id, True)
    assert cut.IsSegmentCuttable(trabecular_id)
    assert cut.GetProtectedSegmentIDs() == (cortical_id,)
    messages = slicer.vtkMRMLMessageCollection()
    assert logic.CheckInputs(cut, messages)
    assert messages.GetNumberOfMessages() == 0


def test_unknown_segment_is_refused(scene):
    volume, _, _ = add_ball_ct(scene)
    logic = scene.volumeCuttingLogic
    bone = logic.CreateBoneSegmentation(volume, 700.0, 200.0, 0.0)
    cut = logic.AddVolumeCutNode(volume, bone)
    assert not cut.SetSegmentCuttable("NoSuchSegment", True)
    assert cut.GetCuttableSegmentIDs() == ()


def test_save_scene_file_and_reload(scene, tmp_path):
    volume, _, _ = add_ball_ct(scene)
    logic = scene.volumeCuttingLogic
    bone = logic.CreateBoneSegmentation(volume, 700.0, 200.0, 0.0)
    cut = logic.AddVolumeCutNode(volume, bone)
    cut.SetSegmentCuttable(logic.GetTrabecularBoneSegmentID(), True)
    cut.SetSegmentProtected(logic.GetCorticalBoneSegmentID(), True)
    cut.SetSubVoxelFactor(4)
    center = BALL_CENTRE
    assert logic.CutSphereSweep(cut, center, [center[0] + 2.0, center[1], center[2]], 1.5)
    removed = logic.GetRemovedVolume(cut)
    assert removed > 10.0

    bundle = tmp_path / "session.mrb"
    assert scene.WriteToMRB(str(bundle))
    assert bundle.stat().st_size > 0

    reloaded = HeadlessSlicer()
    reloaded.load_bundle(bundle)
    read = reloaded.scene.GetFirstNodeByClass("vtkMRMLVolumeCutNode")
    assert read is not None
    assert read.GetSubVoxelFactor() == 4
    assert read.GetCuttableSegmentIDs() == (logic.GetTrabecularBoneSegmentID(),)
    assert read.GetProtectedSegmentIDs() == (logic.GetCorticalBoneSegmentID(),)
    read_volume = read.GetAnatomyVolumeNode()
    assert read_volume is not None and read_volume.GetImageData() is not None
    assert np.allclose(read_volume.GetSpacing(), volume.GetSpacing())
    original = numpy_support.vtk_to_numpy(volume.GetImageData().GetPointData().GetScalars())
    restored = numpy_support.vtk_to_numpy(read_volume.GetImageData().GetPointData().GetScalars())
    assert np.array_equal(original, restored)
    read_bone = read.GetSegmentationNode()
    assert read_bone is not None
    assert read_bone.GetSegmentation().GetNumberOfSegments() == 2
    assert logic.CheckInputs(read, slicer.vtkMRMLMessageCollection())
    # The cut came back with the scene, bit for bit, and the logic keeps it
    # (its shield follows the roles again, so the volumes agree too).
    assert read.GetCutField() is not None
    assert_same_samples(cut.GetCutField(), read.GetCutField())
    assert reloaded.volume_cutting_logic.GetRemovedVolume(read) == pytest.approx(removed, rel=1e-9)
    assert_same_samples(cut.GetCutField(), read.GetCutField())


def assert_same_samples(expected, actual):
    assert actual.GetDimensions() == expected.GetDimensions()
    assert actual.GetNumberOfAllocatedBricks() == expected.GetNumberOfAllocatedBricks()
    dims = expected.GetBrickDimensions()
    a = np.zeros(512, dtype=np.int16)
    b = np.zeros(512, dtype=np.int16)
    for brick in range(dims[0] * dims[1] * dims[2]):
        expected.CopyBrick(brick, a)
        actual.CopyBrick(brick, b)
        assert np.array_equal(a, b), f"brick {brick} differs"


def test_mrml_text_round_trip(scene, tmp_path):
    cut = scene.AddNewNodeByClass("vtkMRMLVolumeCutNode", "Cut")
    cut.SetSubVoxelFactor(1)
    scene_file = tmp_path / "scene.mrml"
    scene.SetURL(str(scene_file))
    assert scene.Commit()
    text = scene_file.read_text()
    assert "<VolumeCut" in text and 'subVoxelFactor="1"' in text
    reloaded = slicer.vtkMRMLScene()
    reloaded.RegisterNodeClass(slicer.vtkMRMLVolumeCutNode())
    reloaded.SetURL(str(scene_file))
    reloaded.Import()
    assert reloaded.GetFirstNodeByClass("vtkMRMLVolumeCutNode").GetSubVoxelFactor() == 1


def test_undo_redo_and_copy(scene):
    volume, _, _ = add_ball_ct(scene)
    logic = scene.volumeCuttingLogic
    bone = logic.CreateBoneSegmentation(volume, 700.0, 200.0, 0.0)
    cut = logic.AddVolumeCutNode(volume, bone)
    trabecular_id = logic.GetTrabecularBoneSegmentID()
    scene.SetUndoOn()
    scene.SaveStateForUndo()
    cut.SetSegmentProtected(trabecular_id, True)
    cut.SetSubVoxelFactor(1)
    scene.Undo()
    cut = scene.GetFirstNodeByClass("vtkMRMLVolumeCutNode")
    assert cut.GetSubVoxelFactor() == 2
    assert not cut.IsSegmentProtected(trabecular_id)
    scene.Redo()
    cut = scene.GetFirstNodeByClass("vtkMRMLVolumeCutNode")
    assert cut.GetSubVoxelFactor() == 1
    assert cut.IsSegmentProtected(trabecular_id)

    copy = slicer.vtkMRMLVolumeCutNode()
    copy.CopyContent(cut)
    assert copy.GetProtectedSegmentIDs() == (trabecular_id,)
    assert copy.GetSubVoxelFactor() == 1


def test_events_follow_the_inputs(scene):
    volume, _, _ = add_ball_ct(scene)
    logic = scene.volumeCuttingLogic
    bone = logic.CreateBoneSegmentation(volume, 700.0, 200.0, 0.0)
    cut = logic.AddVolumeCutNode(volume, bone)
    events = []
    cut.AddObserver(slicer.vtkMRMLVolumeCutNode.InputDataModifiedEvent, lambda caller, event: events.append("input"))
    cut.AddObserver(slicer.vtkMRMLVolumeCutNode.SegmentRolesModifiedEvent, lambda caller, event: events.append("roles"))
    cut.SetSegmentProtected(logic.GetCorticalBoneSegmentID(), True)
    assert events == ["roles"]
    bone.GetSegmentation().RemoveSegment(logic.GetCorticalBoneSegmentID())
    assert not cut.IsSegmentProtected(logic.GetCorticalBoneSegmentID())
    assert "input" in events
    scene.RemoveNode(bone)
    assert cut.GetSegmentationNode() is None


def test_bad_inputs_give_errors_not_crashes(scene):
    logic = scene.volumeCuttingLogic
    empty = scene.AddNewNodeByClass("vtkMRMLScalarVolumeNode", "Empty")
    assert logic.CreateBoneSegmentation(empty, 700.0, 200.0, 0.0) is None
    cut = logic.AddVolumeCutNode(empty, None)
    messages = slicer.vtkMRMLMessageCollection()
    assert not logic.CheckInputs(cut, messages)
    assert "no voxels" in messages.GetAllMessagesAsString()
    cut.SetSubVoxelFactor(3)
    assert cut.GetSubVoxelFactor() == 2


def test_exports_of_the_removed_region(scene, tmp_path):
    volume, bone, cut, logic = ball_session(scene)
    center = BALL_CENTRE
    assert logic.CutSphereSweep(cut, center, center, 2.0)
    removed = logic.GetRemovedVolume(cut)
    assert abs(removed - 4.0 / 3.0 * np.pi * 8.0) / removed < 0.005

    drilled = logic.ExportDrilledVolume(cut, -1000.0, None)
    original = numpy_support.vtk_to_numpy(volume.GetImageData().GetPointData().GetScalars()).reshape(20, 22, 22)
    after = numpy_support.vtk_to_numpy(drilled.GetImageData().GetPointData().GetScalars()).reshape(20, 22, 22)
    assert after[10, 11, 11] == -1000  # the centre voxel is air now
    assert np.array_equal(after[:, :, :3], original[:, :, :3])  # far away: untouched
    assert (after <= original).all()  # only ever towards air
    assert drilled.GetName() == "CT drilled"
    assert np.allclose(drilled.GetSpacing(), volume.GetSpacing())

    model = logic.ExportRemovedSurfaceToModel(cut, None)
    assert model.GetPolyData().GetNumberOfCells() > 0
    storage = model.CreateDefaultStorageNode()
    storage.SetFileName(str(tmp_path / "removed.stl"))
    assert storage.WriteData(model)
    assert (tmp_path / "removed.stl").stat().st_size > 1000

    segmentation = logic.ExportRemovedRegionToSegmentation(cut, "Removed")
    labelmap = segmentation.GetBinaryLabelmapInternalRepresentation("Removed")
    counted = numpy_support.vtk_to_numpy(labelmap.GetPointData().GetScalars()).astype(bool).sum()
    voxel = 0.6 * 0.6 * 1.0
    assert abs(counted * voxel - removed) / removed < 0.15


def test_tools_affect_only_cuttable_segments(scene):
    volume, bone, cut, logic = ball_session(scene, cuttable=())
    center = BALL_CENTRE
    # No role yet: the trabecular ball is not the tool's to cut.
    assert logic.CutSphereSweep(cut, center, center, 2.0)
    assert logic.GetRemovedVolume(cut) < 0.01
    assert logic.GetContactSegmentID(cut) == logic.GetTrabecularBoneSegmentID()
    cut.SetSegmentCuttable(logic.GetTrabecularBoneSegmentID(), True)
    assert logic.CutSphereSweep(cut, center, center, 2.0)
    assert logic.GetRemovedVolume(cut) > 30.0


def test_a_corrupt_cut_file_is_refused_and_the_cut_kept(scene, tmp_path):
    volume, bone, cut, logic = ball_session(scene)
    center = BALL_CENTRE
    logic.CutSphereSweep(cut, center, center, 2.0)
    removed = logic.GetRemovedVolume(cut)

    storage = cut.CreateDefaultStorageNode()
    scene.AddNode(storage)
    cut.SetAndObserveStorageNodeID(storage.GetID())
    good = tmp_path / "cut.vcut"
    storage.SetFileName(str(good))
    assert storage.WriteData(cut)
    assert cut.GetCutField().ComputeRemovedVolume() == pytest.approx(removed)

    corrupt = tmp_path / "corrupt.vcut"
    corrupt.write_bytes(good.read_bytes()[:100])
    storage.SetFileName(str(corrupt))
    assert not storage.ReadData(cut)
    assert cut.GetCutField().ComputeRemovedVolume() == pytest.approx(removed)

    storage.SetFileName(str(good))
    assert storage.ReadData(cut)
    assert cut.GetCutField().ComputeRemovedVolume() == pytest.approx(removed)


def test_drilling_with_material_removal_through_the_logic(scene):
    volume, bone, cut, logic = ball_session(scene, cuttable=("CorticalBone", "TrabecularBone"))
    center = BALL_CENTRE
    removed = []
    logic.BeginStroke(cut)
    for _ in range(4):
        assert logic.DrillWithMaterialRemoval(cut, center, [0.0, 0.0, 1.0], 1.5, 0.1, slicer.vtkVolumeCutMaterialRemoval.CuttingBurr)
        removed.append(logic.GetCutField(cut).ComputeRemovedVolume())
    logic.EndStroke(cut)
    # Trabecular bone (450 HU) gives way over time, not at once.
    assert removed[0] < removed[-1]
    assert all(a <= b for a, b in zip(removed, removed[1:]))
    assert logic.UndoStroke(cut)
    assert logic.GetRemovedVolume(cut) == 0.0
    assert not logic.DrillWithMaterialRemoval(cut, center, [0.0, 0.0, 0.0], 1.5, 0.1, 0)


def test_fraction_export_keeps_partial_voxels_and_reloads(scene, tmp_path):
    volume, bone, cut, logic = ball_session(scene)
    center = BALL_CENTRE
    logic.CutSphereSweep(cut, center, center, 2.0)
    removed = logic.GetRemovedVolume(cut)

    exported = logic.ExportRemovedFractionToVolume(cut, None)
    values = numpy_support.vtk_to_numpy(exported.GetImageData().GetPointData().GetScalars())
    assert values.min() >= 0.0 and values.max() == pytest.approx(1.0)
    assert ((values > 0.0) & (values < 1.0)).sum() > 10  # boundary voxels keep their fraction
    assert values.sum() * 0.6 * 0.6 * 1.0 == pytest.approx(removed, rel=1e-3)
    matrix, original = vtk.vtkMatrix4x4(), vtk.vtkMatrix4x4()
    exported.GetIJKToRASMatrix(matrix)
    volume.GetIJKToRASMatrix(original)
    assert all(matrix.GetElement(r, c) == original.GetElement(r, c) for r in range(4) for c in range(4))

    bundle = scene.application.save_bundle(tmp_path / "fraction.mrb")
    reloaded = HeadlessSlicer()
    reloaded.load_bundle(bundle)
    read = reloaded.scene.GetFirstNodeByName(exported.GetName())
    assert read is not None
    read_values = numpy_support.vtk_to_numpy(read.GetImageData().GetPointData().GetScalars())
    assert np.allclose(read_values, values)
