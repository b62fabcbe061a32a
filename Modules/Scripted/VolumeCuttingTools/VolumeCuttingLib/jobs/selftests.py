"""Slicer self-tests of VolumeCutting, written once and run in two places.

Desktop Slicer runs them as the VolumeCuttingTools module's self-test
(``VolumeCuttingToolsTest``, with ``slicer.mrmlScene`` and the module logic);
pytest runs them here against slicer-core (``test_selftests.py``, with a
``HeadlessSlicer`` scene). They use only what both have: MRML, the module
logic, the Qt-free VolumeCuttingLib, and a second ``HeadlessSlicer`` for
reloading a saved bundle. A failed check raises AssertionError with what
was expected.
"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np


@dataclass
class SelfTestContext:
    """Where a self-test runs: a scene with the VolumeCutting logic, a folder to write to, a way to report progress."""

    scene: object
    logic: object
    folder: Path
    log: Callable[[str], None] = print
    figures: dict = field(default_factory=dict)


def check(condition, message: str) -> None:
    if not condition:
        raise AssertionError(message)


def cut_samples_by_position(field) -> np.ndarray:
    """Every stored sample of a cut field that is not 'far outside': rows of its RAS position
    (micrometres, rounded) and value, sorted by position.

    Two fields whose arrays are equal hold the same cut bit for bit, whatever
    the order of their grid axes (Slicer's reader may reindex a scan).
    """
    import vtk

    matrix = vtk.vtkMatrix4x4()
    field.GetSubVoxelIJKToRAS(matrix)
    sub_to_ras = np.array([[matrix.GetElement(r, c) for c in range(4)] for r in range(4)])
    dims = field.GetBrickDimensions()
    size = np.array(field.GetDimensions())
    local = np.arange(512)
    offsets = np.stack([local % 8, (local // 8) % 8, local // 64], axis=1)
    values = np.zeros(512, dtype=np.int16)
    rows = []
    for n in range(field.GetNumberOfAllocatedBricks()):
        brick = field.GetAllocatedBrickId(n)
        field.CopyBrick(brick, values)
        origin = np.array([brick % dims[0], (brick // dims[0]) % dims[1], brick // (dims[0] * dims[1])]) * 8
        index = origin + offsets
        keep = (values != 32767) & np.all(index < size, axis=1)
        ras = (sub_to_ras[:3, :3] @ index[keep].T).T + sub_to_ras[:3, 3]
        rows.append(np.c_[np.round(ras * 1000.0).astype(np.int64), values[keep].astype(np.int64)])
    samples = np.concatenate(rows) if rows else np.zeros((0, 4), np.int64)
    return samples[np.lexsort(samples[:, 2::-1].T)]


def same_cut(first, second) -> bool:
    """Whether two cut fields hold the same samples at the same places."""
    a = cut_samples_by_position(first)
    b = cut_samples_by_position(second)
    return a.shape == b.shape and bool(np.array_equal(a, b))


def _tube_segment(segmentation_node, volume_node, name, start, end, radius):
    """Add a segment of the voxels within ``radius`` of the segment start-end (RAS), on the CT's grid."""
    import slicer

    from ..scene import nodes

    image = volume_node.GetImageData()
    dims = image.GetDimensions()
    ijk_to_ras = nodes.volume_node_ijk_to_ras(volume_node)
    # Only the voxels of the tube's bounding box are looked at.
    corners = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)
    low = np.minimum(start, end) - radius
    high = np.maximum(start, end) + radius
    box = low + corners * (high - low)
    ijk = (np.linalg.inv(ijk_to_ras) @ np.c_[box, np.ones(8)].T)[:3]
    lower = np.clip(np.floor(ijk.min(axis=1)).astype(int), 0, np.array(dims) - 1)
    upper = np.clip(np.ceil(ijk.max(axis=1)).astype(int), 0, np.array(dims) - 1)
    k, j, i = np.mgrid[lower[2] : upper[2] + 1, lower[1] : upper[1] + 1, lower[0] : upper[0] + 1]
    ras = np.einsum("rc,ckji->rkji", ijk_to_ras[:3, :3], np.stack([i, j, k]).astype(float)) + ijk_to_ras[:3, 3, None, None, None]
    a = np.asarray(start, float)[:, None, None, None]
    ab = (np.asarray(end, float) - np.asarray(start, float))[:, None, None, None]
    t = np.clip(((ras - a) * ab).sum(axis=0) / (ab * ab).sum(), 0.0, 1.0)
    inside = np.linalg.norm(ras - (a + t * ab), axis=0) <= radius
    labels = np.zeros((dims[2], dims[1], dims[0]), np.uint8)
    labels[lower[2] : upper[2] + 1, lower[1] : upper[1] + 1, lower[0] : upper[0] + 1] = inside
    mask = slicer.vtkOrientedImageData()
    mask.ShallowCopy(nodes.image_data_from_array(labels))
    mask.SetImageToWorldMatrix(nodes.numpy_to_vtk_matrix(ijk_to_ras))
    segment = slicer.vtkSegment()
    segment.SetName(name)
    segment.SetColor(0.3, 0.5, 1.0)
    segment.AddRepresentation(slicer.vtkSegmentationConverter.GetBinaryLabelmapRepresentationName(), mask)
    segmentation_node.GetSegmentation().AddSegment(segment, name)
    return int(inside.sum())


def dicom_mastoidectomy_with_presets_and_reload(context: SelfTestContext) -> dict:
    """The main scenario: DICOM in, bone segmented, two burrs from presets, a recorded mastoidectomy replayed,
    volumes per segment with the protected one at zero, STL and segment exported, the bundle reloaded with the same cut."""
    import vtk

    from ..config import toolconfig
    from ..cutting import recording
    from ..data import dicomseries, headct, owndata
    from ..scene.application import HeadlessSlicer

    scene, logic, folder = context.scene, context.logic, Path(context.folder)

    context.log("Writing the head CT as a DICOM series and loading it as a user would")
    scratch = HeadlessSlicer()
    source = headct.load_volume_node(scratch.scene, name="HeadCT")
    dicom_folder = folder / "dicom"
    files = dicomseries.write_ct_series(source, dicom_folder, series_description="Head CT")
    check(len(files) == source.GetImageData().GetDimensions()[2], f"one DICOM file per slice expected, got {len(files)}")
    volume = owndata.load_ct(scene, dicom_folder, name="HeadCT")
    check(volume.GetImageData().GetDimensions() == source.GetImageData().GetDimensions(), "the DICOM series read back with other dimensions")

    context.log("Segmenting bone automatically")
    bone = logic.CreateBoneSegmentation(volume, 700.0, 200.0, 0.5)
    check(bone is not None, "the bone segmentation failed")
    cortical, trabecular = logic.GetCorticalBoneSegmentID(), logic.GetTrabecularBoneSegmentID()
    session = recording.load(recording.head_ct_mastoidectomy_path())
    # A critical structure (a sinus-like canal) where the deepest layer passes.
    deepest = np.array(session["strokes"][-1]["positions"])
    middle = deepest[len(deepest) // 2]
    canal_voxels = _tube_segment(bone, volume, "Canal", middle + [-2.0, -8.0, 0.0], middle + [-2.0, 8.0, 0.0], 1.5)
    check(canal_voxels > 50, "the protected canal is empty")
    cut = logic.AddVolumeCutNode(volume, bone)
    cut.SetCuttableSegmentIDs([cortical, trabecular])
    cut.SetProtectedSegmentIDs(["Canal"])
    volume_table = logic.GetRemovedVolumeTableNode(cut)

    context.log("Configuring a cutting burr and a diamond burr from presets")
    presets = {preset.name: preset for preset in toolconfig.load_presets()}
    tools = {
        "cutting": toolconfig.create_tool_node(scene, toolconfig.from_preset(presets["Cutting burr 5 mm"]), "Cutting burr 5 mm"),
        "diamond": toolconfig.create_tool_node(scene, toolconfig.from_preset(presets["Diamond burr 3 mm"]), "Diamond burr 3 mm"),
    }
    check(tools["diamond"].GetBurrType() == tools["diamond"].Diamond, "the diamond preset is not a diamond burr")

    context.log("Replaying the recorded mastoidectomy")
    contacts = []
    import slicer

    observer = cut.AddObserver(slicer.vtkMRMLVolumeCutNode.ProtectedContactEvent, lambda caller, event: contacts.append(1))
    replayed = recording.replay(logic, cut, session, tools)
    cut.RemoveObserver(observer)
    check(replayed["refused_poses"] == 0, f"{replayed['refused_poses']} poses were refused")
    removed = logic.GetRemovedVolume(cut)
    per_segment = {segment_id: logic.GetRemovedVolumeInSegment(cut, segment_id) for segment_id in (cortical, trabecular, "Canal")}
    check(removed > 1000.0, f"the mastoidectomy removed only {removed:.1f} mm3")
    check(per_segment[cortical] > 100.0, f"the mastoid cortex was not opened ({per_segment[cortical]:.1f} mm3)")
    check(per_segment["Canal"] == 0.0, f"the protected canal reports {per_segment['Canal']} mm3 removed")
    check(contacts, "touching the protected canal raised no ProtectedContactEvent")
    contact_table = logic.GetContactTableNode(cut)
    check(contact_table.GetNumberOfRows() > 0 and contact_table.GetCellText(0, 0) == "Canal", "the contact table does not name the canal")
    rows = {volume_table.GetCellText(r, 0): float(volume_table.GetCellText(r, 3)) for r in range(volume_table.GetNumberOfRows())}
    check(abs(rows[cortical] - per_segment[cortical]) < 1e-3, "the removed-volume table is not up to date")

    context.log("Exporting the removed region as STL and as a segment")
    model = logic.ExportRemovedSurfaceToModel(cut, None)
    storage = model.CreateDefaultStorageNode()
    stl = folder / "removed.stl"
    storage.SetFileName(str(stl))
    check(storage.WriteData(model), "writing the STL failed")
    reader = vtk.vtkSTLReader()
    reader.SetFileName(str(stl))
    reader.Update()
    edges = vtk.vtkFeatureEdges()
    edges.SetInputConnection(reader.GetOutputPort())
    edges.BoundaryEdgesOn()
    edges.FeatureEdgesOff()
    edges.NonManifoldEdgesOff()
    edges.ManifoldEdgesOff()
    edges.Update()
    check(edges.GetOutput().GetNumberOfCells() == 0, "the exported STL surface is not closed")
    mass = vtk.vtkMassProperties()
    mass.SetInputConnection(reader.GetOutputPort())
    mass.Update()
    check(abs(mass.GetVolume() - removed) < 0.02 * removed, f"the STL encloses {mass.GetVolume():.1f} mm3, the cut {removed:.1f} mm3")
    exported = logic.ExportRemovedRegionToSegmentation(cut, None)
    check(exported is not None and exported.GetSegmentation().GetNumberOfSegments() == 1, "the removed region was not exported as a segment")

    context.log("Saving the scene bundle and reloading it")
    bundle = folder / "session.mrb"
    check(scene.WriteToMRB(str(bundle)), "saving the scene bundle failed")
    reloaded = HeadlessSlicer()
    reloaded.load_bundle(bundle)
    read = reloaded.scene.GetFirstNodeByClass("vtkMRMLVolumeCutNode")
    check(read is not None and read.GetCutField() is not None, "the reloaded scene has no cut")
    reloaded_removed = reloaded.volume_cutting_logic.GetRemovedVolume(read)
    # The same samples; the sum may run in another order where Slicer's reader reindexed the scan.
    check(abs(reloaded_removed - removed) <= 1e-9 * removed, f"the reloaded cut removes {reloaded_removed} mm3, {removed} before saving")
    check(same_cut(read.GetCutField(), logic.GetCutField(cut)), "the reloaded cut differs")
    check(reloaded.volume_cutting_logic.GetRemovedVolumeInSegment(read, "Canal") == 0.0, "the reloaded canal reports removed volume")
    check(len(read.GetProtectedSegmentIDs()) == 1, "the reloaded roles differ")
    figures = {
        "removed_volume_mm3": round(removed, 2),
        "removed_volume_per_segment_mm3": {key: round(value, 2) for key, value in per_segment.items()},
        "replay": replayed,
        "contact_rows": contact_table.GetNumberOfRows(),
        "stl_volume_mm3": round(mass.GetVolume(), 2),
    }
    context.figures.update(figures)
    return figures


CASES = {
    "dicom_mastoidectomy_with_presets_and_reload": dicom_mastoidectomy_with_presets_and_reload,
}


def run_all(scene, logic, log=print) -> dict:
    """Run every case against a scene and logic (desktop Slicer's, or a HeadlessSlicer's); return their figures."""
    results = {}
    for name, case in CASES.items():
        with tempfile.TemporaryDirectory(prefix=f"volumecutting-{name}-") as folder:
            results[name] = case(SelfTestContext(scene, logic, Path(folder), log))
    return results
