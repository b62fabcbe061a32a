"""DICOM series as scanners and PACS hand them over (VolumeCuttingLib.data.dicomimport through owndata and the app).

The ground truth is analytic: a ball of radius ``RADIUS`` around ``CENTRE``
(RAS mm), sampled at each voxel's true patient position of a series written
with a gantry tilt and uneven gaps between slices (``dicomseries.write_ct_slices``).
Loaded, its centre and its radius along each principal axis (for a solid ball
the variance of the inside points along any direction is R^2/5) are measured
on the volume and compared with the analytic values.
"""

import math
import zipfile
from pathlib import Path

import numpy as np
import pytest
import slicer

from VolumeCuttingLib.data import dicomimport, dicomseries, owndata
from VolumeCuttingLib.scene import nodes

CENTRE = np.array([4.0, -6.0, 10.0])
RADIUS = 15.0
EDGE_MM = 0.6  # width of the ball's blurred edge, as a scanner's point spread makes it
PIXEL_MM = 0.8
PIXELS = 80
TILT_DEGREES = 18.5
# Gaps along the slice normal: 3 mm, with the three uneven ones of the clinical series.
GAPS_MM = [3.0] * 5 + [4.2] + [3.0] * 3 + [1.1] + [3.0] * 4 + [7.4] + [3.0] * 4
# The ball's edge is sharp (EDGE_MM) while slices lie up to 7.4 mm apart, so between two
# slices the interpolated surface is a step at the midpoint: the 7.4 mm gap crosses the
# ball's cap (slices at 10.95 mm, cross-section radius 10.2 mm, and 18.35 mm from the centre),
# whose flat top at 14.65 mm lies up to sqrt(10.2^2 + 14.65^2) - 15 = 2.85 mm outside the
# sphere; averaged over the surface, centre and radii stay within these (mm).
CENTRE_TOLERANCE_MM = 0.5
TOLERANCE_MM = 0.75
GAP_SURFACE_TOLERANCE_MM = 2.85
# With even gaps finer than the edge's curvature matters, the tilt is corrected to this (mm).
TILT_SURFACE_TOLERANCE_MM = 0.2


def rotation_about(axis, degrees):
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    angle = math.radians(degrees)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * (k @ k)


def ball_value(points):
    distance = np.linalg.norm(points - CENTRE, axis=-1)
    return -1000.0 + 2000.0 / (1.0 + np.exp((distance - RADIUS) / (EDGE_MM / 4.0)))


def tilted_geometry(tilt_degrees=TILT_DEGREES, gaps=GAPS_MM):
    """Row, column and first-voxel positions of an axial series on a gantry tilted about the left-right axis.

    The table moves along S; the image plane is tilted, so each slice's
    position steps off the slice normal by tan(tilt) of its step along it.
    """
    row = np.array([-1.0, 0.0, 0.0])  # LPS +x, as scanners write axial images
    column = rotation_about(row, tilt_degrees) @ np.array([0.0, -1.0, 0.0])
    normal = np.cross(row, column)
    table = np.array([0.0, 0.0, 1.0])
    along_normal = np.concatenate([[0.0], np.cumsum(gaps)]) - 0.5 * sum(gaps)
    table_steps = along_normal / float(table @ normal)
    half = (PIXELS - 1) * PIXEL_MM / 2.0
    positions = [CENTRE + s * table - half * row - half * column for s in table_steps]
    return row, column, positions


def write_ball_series(folder, tilt_degrees=TILT_DEGREES, gaps=GAPS_MM, **kwargs):
    row, column, positions = tilted_geometry(tilt_degrees, gaps)
    j, i = np.mgrid[0:PIXELS, 0:PIXELS] * PIXEL_MM
    slices = np.array([ball_value(p + i[..., None] * row + j[..., None] * column) for p in positions])
    return dicomseries.write_ct_slices(np.rint(slices).astype(np.int16), positions, row, column,
                                       (PIXEL_MM, PIXEL_MM), folder, series_description="Head tilted", **kwargs)


def surface_error(volume):
    """The largest distance (mm) by which the loaded ball's surface (0 HU) misses the analytic sphere.

    Every voxel classified otherwise than the analytic ball says so (its
    centre's distance from the sphere is how far the surface moved there).
    """
    array = nodes.array_from_volume_node(volume)
    k, j, i = np.indices(array.shape)
    ijk_to_ras = nodes.volume_node_ijk_to_ras(volume)
    points = np.einsum("ab,bkji->kjia", ijk_to_ras[:3, :3], np.stack([i, j, k]).astype(float)) + ijk_to_ras[:3, 3]
    distance = np.linalg.norm(points - CENTRE, axis=-1) - RADIUS
    wrong = (array > 0) != (distance < 0)
    return float(np.abs(distance[wrong]).max()) if wrong.any() else 0.0


def measure_ball(volume):
    """(centre, radii along the three principal axes) of the voxels above 0 HU, in RAS mm."""
    array = nodes.array_from_volume_node(volume)
    k, j, i = np.nonzero(array > 0)
    ijk_to_ras = nodes.volume_node_ijk_to_ras(volume)
    points = (ijk_to_ras[:3, :3] @ np.stack([i, j, k]).astype(float)).T + ijk_to_ras[:3, 3]
    centre = points.mean(axis=0)
    radii = np.sqrt(5.0 * np.linalg.eigvalsh(np.cov(points.T)))
    return centre, radii


@pytest.fixture
def scene():
    return slicer.vtkMRMLScene()


def test_tilted_series_with_uneven_gaps_is_regularized_with_a_message(scene, tmp_path):
    write_ball_series(tmp_path / "SE0003")
    messages = []
    volume = owndata.load_ct(scene, tmp_path / "SE0003", messages=messages)
    geometry = [m for m in messages if "DICOM series" in m]
    assert len(geometry) == 1, messages
    assert f"gantry tilt {TILT_DEGREES}° corrected" in geometry[0]
    assert "3 uneven gap(s) between slices (4.2, 1.1, 7.4 mm; the others 3 mm)" in geometry[0]
    assert "onto a regular grid 1.08 mm between slices (the smallest gap, 1.1 mm, evened over the 60.7 mm" in geometry[0]
    centre, radii = measure_ball(volume)
    print(f"regularized: centre error {np.linalg.norm(centre - CENTRE):.3f} mm, radii {radii}, "
          f"surface error {surface_error(volume):.2f} mm")
    assert surface_error(volume) < GAP_SURFACE_TOLERANCE_MM
    assert np.linalg.norm(centre - CENTRE) < CENTRE_TOLERANCE_MM, centre
    assert np.all(np.abs(radii - RADIUS) < TOLERANCE_MM), radii
    # The grid is orthogonal: rows, columns and the slice normal.
    axes = nodes.volume_node_ijk_to_ras(volume)[:3, :3]
    directions = axes / np.linalg.norm(axes, axis=0)
    np.testing.assert_allclose(directions.T @ directions, np.eye(3), atol=1e-9)


def test_without_regularization_the_ball_is_distorted(scene, tmp_path):
    """What the reader alone makes of the series (the product's behaviour before the fix)."""
    files = write_ball_series(tmp_path / "SE0003")
    volume, _ = owndata._read_volume(scene, "vtkMRMLScalarVolumeNode", files, "raw", tmp_path / "SE0003")
    centre, radii = measure_ball(volume)
    print(f"reader alone: centre error {np.linalg.norm(centre - CENTRE):.2f} mm, radii {radii}, "
          f"surface error {surface_error(volume):.2f} mm")
    # Measured 1.78 mm and 16.44 mm: both far outside what the regularized volume keeps to.
    assert np.linalg.norm(centre - CENTRE) > 2 * CENTRE_TOLERANCE_MM
    assert float(np.abs(radii - RADIUS).max()) > 1.5 * TOLERANCE_MM
    # ITK keeps a tilt as a sheared grid (k along the table), which no cut field or renderer here takes.
    axes = nodes.volume_node_ijk_to_ras(volume)[:3, :3]
    unit = axes / np.linalg.norm(axes, axis=0)
    assert math.degrees(math.acos(abs(float(unit[:, 1] @ unit[:, 2])))) == pytest.approx(90.0 - TILT_DEGREES, abs=0.01)


@pytest.mark.parametrize("tilt, gaps, expected, surface_tolerance", [
    (TILT_DEGREES, [2.5] * 20, "gantry tilt 18.5° corrected onto a regular grid 2.5 mm", TILT_SURFACE_TOLERANCE_MM),
    (0.0, GAPS_MM, "3 uneven gap(s)", GAP_SURFACE_TOLERANCE_MM),
])
def test_tilt_alone_and_gaps_alone_are_corrected(scene, tmp_path, tilt, gaps, expected, surface_tolerance):
    write_ball_series(tmp_path / "series", tilt, gaps)
    messages = []
    volume = owndata.load_ct(scene, tmp_path / "series", messages=messages)
    assert any(expected in m for m in messages), messages
    assert (tilt > 0) == any("gantry tilt" in m for m in messages)
    assert surface_error(volume) < surface_tolerance
    centre, radii = measure_ball(volume)
    assert np.linalg.norm(centre - CENTRE) < CENTRE_TOLERANCE_MM and np.all(np.abs(radii - RADIUS) < TOLERANCE_MM), (centre, radii)


def test_regular_series_loads_as_it_is_without_a_message(scene, tmp_path):
    files = write_ball_series(tmp_path / "regular", 0.0, [2.0] * 20)
    messages = []
    volume = owndata.load_ct(scene, tmp_path / "regular", messages=messages)
    assert messages == []
    assert volume.GetImageData().GetDimensions() == (PIXELS, PIXELS, len(files))


def test_series_that_cannot_be_one_volume_is_refused(scene, tmp_path):
    import pydicom

    files = write_ball_series(tmp_path / "turned")
    turned = pydicom.dcmread(files[4])
    turned.ImageOrientationPatient = [0, 1, 0, 0, 0, -1]  # a sagittal reformat slipped in
    turned.save_as(files[4])
    with pytest.raises(owndata.InputError, match=f"different orientations.*{files[4].name}"):
        owndata.load_ct(scene, tmp_path / "turned")
    files = write_ball_series(tmp_path / "twice")
    twice = pydicom.dcmread(files[3])
    twice.ImagePositionPatient = pydicom.dcmread(files[2]).ImagePositionPatient
    twice.save_as(files[3])
    with pytest.raises(owndata.InputError, match=f"same position.*{files[2].name} and {files[3].name}"):
        owndata.load_ct(scene, tmp_path / "twice")
    assert scene.GetNumberOfNodes() == 0


def test_damaged_slice_is_named_and_skipped(scene, tmp_path):
    files = write_ball_series(tmp_path / "damaged", 0.0, [2.0] * 20)
    files[10].write_bytes(files[10].read_bytes()[:-3000])
    messages = []
    volume = owndata.load_ct(scene, tmp_path / "damaged", messages=messages)
    assert any(f"skipped 1 damaged DICOM file(s): {files[10].name} (3000 bytes of pixel data missing)" in m
               for m in messages), messages
    # The hole it leaves is a 4 mm gap, interpolated.
    assert any("1 uneven gap(s) between slices (4 mm; the others 2 mm)" in m for m in messages), messages
    centre, radii = measure_ball(volume)
    assert np.linalg.norm(centre - CENTRE) < CENTRE_TOLERANCE_MM and np.all(np.abs(radii - RADIUS) < TOLERANCE_MM)


# --------------------------------------------------------------------------- exports: nested folders, DICOMDIR, several series


def zip_folder(folder, archive):
    with zipfile.ZipFile(archive, "w") as bundle:
        for path in sorted(Path(folder).rglob("*")):
            if path.is_file():
                bundle.write(path, path.relative_to(folder))
    return archive


def unpacked_upload(tmp_path, archive):
    from VolumeCuttingLib.webapp import app as webapp

    upload = tmp_path / "upload"
    upload.mkdir()
    target = upload / archive.name
    target.write_bytes(archive.read_bytes())
    return webapp.unpack_upload([target], upload, 2**30)


def test_zip_with_the_series_in_nested_folders_loads(scene, tmp_path):
    write_ball_series(tmp_path / "export" / "PATIENT" / "STUDY" / "SE0003")
    path = unpacked_upload(tmp_path, zip_folder(tmp_path / "export", tmp_path / "export.zip"))
    messages = []
    volume = owndata.load_ct(scene, path, messages=messages)
    assert any("gantry tilt 18.5° corrected" in m for m in messages), messages
    centre, _ = measure_ball(volume)
    assert np.linalg.norm(centre - CENTRE) < CENTRE_TOLERANCE_MM


def test_zip_with_a_dicomdir_loads_the_files_it_lists(scene, tmp_path):
    from pydicom.fileset import FileSet

    files = write_ball_series(tmp_path / "flat")
    file_set = FileSet()
    for file in files:
        file_set.add(file)
    file_set.write(tmp_path / "cd")  # DICOMDIR and PT000000/ST000000/SE000000/IM000000..., as on a CD
    assert (tmp_path / "cd" / "DICOMDIR").is_file()
    # A stray copy beside the DICOMDIR that it does not list is not read.
    (tmp_path / "cd" / "stray.dcm").write_bytes(files[0].read_bytes())
    path = unpacked_upload(tmp_path, zip_folder(tmp_path / "cd", tmp_path / "cd.zip"))
    messages = []
    volume = owndata.load_ct(scene, path, messages=messages)
    assert any("DICOM series 'Head tilted'" in m for m in messages), messages
    centre, radii = measure_ball(volume)
    assert np.linalg.norm(centre - CENTRE) < CENTRE_TOLERANCE_MM and np.all(np.abs(radii - RADIUS) < TOLERANCE_MM)


def test_zip_with_several_series_chooses_the_ct_and_names_the_others(scene, tmp_path):
    import pydicom

    write_ball_series(tmp_path / "export" / "SE0003", series_number=3)
    write_ball_series(tmp_path / "export" / "SE0001", 0.0, [20.0, 20.0], series_number=1)  # a 3-slice scout
    mr = write_ball_series(tmp_path / "export" / "SE0009", 0.0, [2.0] * 29, series_number=9)
    for file in mr:
        dataset = pydicom.dcmread(file)
        dataset.Modality = "MR"
        dataset.SeriesDescription = "T1"
        dataset.save_as(file)
    path = unpacked_upload(tmp_path, zip_folder(tmp_path / "export", tmp_path / "export.zip"))
    # A job names the series it means; the application chooses and says so.
    with pytest.raises(owndata.InputError, match="holds 3 DICOM series .*Give one file"):
        owndata.load_ct(scene, path)
    messages = []
    volume = owndata.load_ct(scene, path, messages=messages, choose_series=True)
    note = next(m for m in messages if "chose the CT" in m)
    assert "series 3 'Head tilted' (CT, 20 files), the one with the most slices" in note
    assert "also present: " in note and "series 1 'Head tilted' (CT, 3 files)" in note and "series 9 'T1' (MR, 30 files)" in note
    assert volume.GetImageData().GetDimensions()[2] > 20  # the tilted series, regularized


def test_the_app_loads_a_nested_zip_and_shows_the_correction(tmp_path):
    from trame_slicer.core import SlicerApp

    from VolumeCuttingLib.webapp.session import DrillSession

    write_ball_series(tmp_path / "export" / "DICOM" / "SE0003")
    path = unpacked_upload(tmp_path, zip_folder(tmp_path / "export", tmp_path / "export.zip"))
    slicer_app = SlicerApp()
    logic = slicer_app.register_module_logic(slicer.vtkSlicerVolumeCuttingLogic(), logic_name="VolumeCutting")
    session = DrillSession(slicer_app.scene, logic, tmp_path / "work")
    try:
        steps = list(session.loading("own", ct_path=path))
        assert steps[-1] == (1.0, "Ready")
        assert any("gantry tilt 18.5° corrected" in w for w in session.warnings), session.warnings
    finally:
        session.close()


def test_the_main_job_reports_the_correction_in_its_summary(tmp_path):
    import json
    import os
    import subprocess
    import sys

    write_ball_series(tmp_path / "SE0003")
    module_dir = Path(__file__).resolve().parents[2]
    result = subprocess.run([sys.executable, "-m", "VolumeCuttingLib.jobs.mainjob", "--ct", str(tmp_path / "SE0003"),
                             "--out", str(tmp_path / "out"), "--size", "64x48"],
                            capture_output=True, text=True, env=dict(os.environ, PYTHONPATH=str(module_dir)), timeout=300)
    assert result.returncode == 0, result.stderr[-3000:]
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    warnings = summary["own_data"]["warnings"]
    assert any("gantry tilt 18.5° corrected and 3 uneven gap(s) between slices (4.2, 1.1, 7.4 mm" in w
               for w in warnings), warnings
