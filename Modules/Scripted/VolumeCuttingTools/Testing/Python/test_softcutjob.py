"""The main job's SoftCut part on the real head CT, and the softcut benchmark's resampling.

A cheek resection planned, previewed, carved, measured and exported through
real nodes and the product's 3D view; the images must show the outline, a
pit that deepens with the depth of cut, and the resection's mesh.
"""

import csv

import numpy as np
import pytest
import vtk
from vtkmodules.util import numpy_support

from VolumeCuttingLib.benchmarks import softcut as softcutbenchmarks
from VolumeCuttingLib.jobs import softcutjob


def read_png(path):
    reader = vtk.vtkPNGReader()
    reader.SetFileName(str(path))
    reader.Update()
    image = reader.GetOutput()
    width, height, _ = image.GetDimensions()
    return numpy_support.vtk_to_numpy(image.GetPointData().GetScalars()).reshape(height, width, -1)[:, :, :3].astype(int)


def changed(a, b):
    return float((np.abs(a - b).sum(axis=2) > 30).mean())


def test_without_the_head_ct_nothing_is_planned(tmp_path):
    summary = softcutjob.run(tmp_path, head_ct=False)
    assert summary["planned"] is False and "head CT" in summary["reason"]
    assert not list(tmp_path.iterdir())


@pytest.mark.realdata
def test_cheek_resection_on_the_head_ct(tmp_path):
    summary = softcutjob.run(tmp_path, size=(320, 240))
    assert summary["planned"]
    assert summary["outline"]["control_points"] == softcutjob.CONTROL_POINTS
    measurements = summary["measurements"]
    volume = measurements["Resected volume"][0]
    area = summary["outline"]["projected_area_mm2"]
    depth = summary["depth_mm"]
    # A slab of about the outline's area and the depth of cut (the cheek curves, bone may stop it).
    assert 0.6 * area * depth < volume < 1.6 * area * depth
    assert measurements["Length"][0] == pytest.approx(2 * softcutjob.CHEEK_RADII[0], rel=0.15)
    assert measurements["Width"][0] == pytest.approx(2 * softcutjob.CHEEK_RADII[1], rel=0.15)
    assert measurements["Volume before smoothing"][0] == pytest.approx(volume, rel=0.02)
    carve = summary["carve"]
    assert carve["undo_steps"] == 1 and carve["undo_then_redo_restores"]
    assert carve["removed_volume_mm3"] > volume  # the tissue, and the air just above the skin
    soft_tissue = carve["removed_volume_per_segment"]["Soft tissue"]  # by name, its ID beside
    assert soft_tissue["segment_id"] == "SoftTissue" and soft_tissue["removed_volume_mm3"] > 0.0
    with open(tmp_path / "softcut_measurements.csv") as stream:
        rows = {row["Measurement"]: float(row["Value"]) for row in csv.DictReader(stream)}
    assert rows["Resected volume"] == pytest.approx(volume, rel=1e-3)
    mesh = vtk.vtkSTLReader()
    mesh.SetFileName(summary["exports"]["stl"])
    mesh.Update()
    assert mesh.GetOutput().GetNumberOfCells() == summary["estimate_triangles"]
    images = {name: read_png(path) for name, path in summary["images"].items()}
    outline, shallow, deep, carved = images["outline"], images["preview_4mm"], images["preview_8mm"], images["carved"]
    assert outline.shape == (240, 320, 3)
    # The outline is red on the skin; the previews open the cheek, deeper at 8 mm; the carve shows the 8 mm pit.
    red = (outline[:, :, 0] > 150) & (outline[:, :, 1] < 80) & (outline[:, :, 2] < 80)
    assert red.mean() > 0.001
    assert 0.005 < changed(outline, shallow) < 0.3
    assert changed(shallow, deep) > 0.002
    assert changed(deep, carved) < 0.02
    assert changed(images["carved_zoom"], carved) > 0.1
    assert (np.abs(images["resection_mesh"] - images["resection_mesh"][:1, :1]).sum(axis=2) > 30).mean() > 0.05


@pytest.mark.realdata
def test_benchmark_resampling_keeps_the_field_of_view():
    array, ijk_to_ras = softcutbenchmarks.resample_head_ct((128, 128, 54))
    assert array.shape == (54, 128, 128) and array.dtype == np.int16
    spacing = np.linalg.norm(ijk_to_ras[:3, :3], axis=0)
    assert spacing == pytest.approx([0.957 * 2, 0.957 * 2, 3.0], rel=1e-3)
    # The grid is centred on the RAS origin as the head CT is.
    center = ijk_to_ras @ np.array([63.5, 63.5, 26.5, 1.0])
    assert center[:3] == pytest.approx([0.0, 0.0, 0.0], abs=1e-9)
    assert -1100 < array.min() and 1000 < array.max() < 3100
