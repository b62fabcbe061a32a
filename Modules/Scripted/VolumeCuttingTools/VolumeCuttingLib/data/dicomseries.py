"""Write a scalar volume node as a DICOM CT series (one file a slice), with pydicom.

What a CT scanner or PACS hands a clinician is a folder of CT Image Storage
files, one per slice; the patient-scale test case and the own-data tests
produce the same thing from a volume node, so that reading a series goes
through exactly the code path a user's scan takes.

The series carries the node's geometry as DICOM defines it, in LPS:
ImagePositionPatient is the centre of each slice's first voxel,
ImageOrientationPatient the directions of the volume's i (along a row) and j
(down a column) axes, PixelSpacing (row spacing, column spacing), and
SliceThickness / SpacingBetweenSlices the step along k. Any IJK-to-RAS with
orthogonal axes is written as it is (flipped, oblique, left-handed): readers
order the slices by their position, which puts them back in k order.
Voxels are stored as int16 with RescaleSlope/RescaleIntercept (HU).
"""

from __future__ import annotations

import datetime
from pathlib import Path

import numpy as np

from ..scene import nodes

CT_IMAGE_STORAGE = "1.2.840.10008.5.1.4.1.1.2"
RAS_TO_LPS = np.diag([-1.0, -1.0, 1.0])
_INT16 = np.iinfo(np.int16)


def _decimal_string(value: float) -> str:
    """A DICOM DS value (at most 16 characters) as close to ``value`` as fits."""
    for digits in range(10, 0, -1):
        text = f"{value:.{digits}g}"
        if len(text) <= 16:
            return text
    raise ValueError(f"{value} does not fit a DICOM decimal string")


def rescale_for_int16(array: np.ndarray) -> tuple[float, float]:
    """Return (slope, intercept) so that ``stored * slope + intercept`` gives the values back.

    Integral values that fit int16 are stored as they are (slope 1, intercept
    0), so a CT in HU survives bit for bit; anything else is spread over the
    int16 range, which loses at most half a step of ``slope``.
    """
    low, high = float(array.min()), float(array.max())
    integral = np.issubdtype(array.dtype, np.integer) or bool(np.all(np.equal(np.mod(array, 1.0), 0.0)))
    if integral and low >= _INT16.min and high <= _INT16.max:
        return 1.0, 0.0
    # As written to the files (decimal strings), so that storing and reading agree.
    intercept = float(_decimal_string((low + high) / 2.0))
    slope = float(_decimal_string(max(high - low, 1e-6) / float(_INT16.max - _INT16.min - 1)))
    return slope, intercept


def write_ct_series(volume_node, folder, patient_name: str = "Anonymous^Patient", patient_id: str = "VC0001",
                    series_description: str | None = None, series_number: int = 1) -> list[Path]:
    """Write ``volume_node`` (a scalar volume in HU) to ``folder`` as one DICOM CT series.

    Returns the paths of the slice files (``slice_0000.dcm``, ...) in k order.

    Raises:
        ValueError: the node has no voxels or more than one component, or its
            i and j axes are not orthogonal (DICOM cannot describe a sheared grid).
    """
    name = volume_node.GetName() or "volume"
    image = volume_node.GetImageData()
    if image is None or image.GetNumberOfPoints() == 0:
        raise ValueError(f"volume node {name!r} has no voxels to write")
    if image.GetNumberOfScalarComponents() != 1:
        raise ValueError(f"volume node {name!r} has {image.GetNumberOfScalarComponents()} components; "
                         "a CT series holds one value a voxel")
    array = nodes.array_from_volume_node(volume_node)
    ijk_to_ras = nodes.volume_node_ijk_to_ras(volume_node)
    axes = ijk_to_ras[:3, :3]
    spacing = np.linalg.norm(axes, axis=0)
    directions = axes / spacing
    if abs(float(directions[:, 0] @ directions[:, 1])) > 1e-6:
        raise ValueError(f"volume node {name!r}: its i and j axes are not orthogonal; "
                         "DICOM image planes must be rectangular")
    positions = [ijk_to_ras[:3, 3] + k * axes[:, 2] for k in range(array.shape[0])]
    return write_ct_slices(array, positions, directions[:, 0], directions[:, 1], spacing[:2], folder,
                           patient_name=patient_name, patient_id=patient_id,
                           series_description=series_description or name, series_number=series_number,
                           slice_spacing=float(spacing[2]))


def write_ct_slices(slices, positions_ras, row_ras, column_ras, pixel_spacing, folder,
                    patient_name: str = "Anonymous^Patient", patient_id: str = "VC0001",
                    series_description: str = "CT", series_number: int = 1,
                    slice_spacing: float | None = None) -> list[Path]:
    """Write ``slices`` (``[k, j, i]``, HU) as one DICOM CT series whose slice k lies at ``positions_ras[k]``.

    Each slice's first voxel is at ``positions_ras[k]`` (RAS), its rows run
    along ``row_ras`` (i) and its columns along ``column_ras`` (j), with
    ``pixel_spacing`` (along i, along j). The positions may step off the
    slice normal (a gantry tilt) and unevenly (gaps, missing slices), as real
    scanners write them; SpacingBetweenSlices is written only when
    ``slice_spacing`` is given. Returns the paths (``slice_0000.dcm``, ...) in k order.
    """
    import pydicom
    from pydicom.dataset import FileMetaDataset
    from pydicom.uid import ExplicitVRLittleEndian, PYDICOM_IMPLEMENTATION_UID, generate_uid

    array = np.asarray(slices)
    row_lps = RAS_TO_LPS @ np.asarray(row_ras, dtype=float)
    column_lps = RAS_TO_LPS @ np.asarray(column_ras, dtype=float)
    if abs(float(row_lps @ column_lps)) > 1e-6:
        raise ValueError("the row and column directions are not orthogonal; DICOM image planes must be rectangular")
    normal_lps = np.cross(row_lps, column_lps)

    slope, intercept = rescale_for_int16(array)
    stored = np.clip(np.rint((array.astype(np.float64) - intercept) / slope), _INT16.min, _INT16.max).astype("<i2")

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    now = datetime.datetime.now()
    study_uid, series_uid, frame_uid = generate_uid(), generate_uid(), generate_uid()
    orientation = [_decimal_string(v) for v in np.concatenate([row_lps, column_lps])]
    window_center, window_width = 400.0, 2000.0  # a bone window
    paths = []
    for k in range(array.shape[0]):
        sop_uid = generate_uid()
        meta = FileMetaDataset()
        meta.MediaStorageSOPClassUID = CT_IMAGE_STORAGE
        meta.MediaStorageSOPInstanceUID = sop_uid
        meta.TransferSyntaxUID = ExplicitVRLittleEndian
        meta.ImplementationClassUID = PYDICOM_IMPLEMENTATION_UID
        ds = pydicom.Dataset()
        ds.file_meta = meta
        ds.SOPClassUID = CT_IMAGE_STORAGE
        ds.SOPInstanceUID = sop_uid
        ds.SpecificCharacterSet = "ISO_IR 100"
        ds.ImageType = ["DERIVED", "SECONDARY", "AXIAL"]
        ds.StudyDate = ds.SeriesDate = ds.ContentDate = now.strftime("%Y%m%d")
        ds.StudyTime = ds.SeriesTime = ds.ContentTime = now.strftime("%H%M%S")
        ds.Modality = "CT"
        ds.Manufacturer = "VolumeCutting"
        ds.PatientName = patient_name
        ds.PatientID = patient_id
        ds.StudyInstanceUID = study_uid
        ds.SeriesInstanceUID = series_uid
        ds.FrameOfReferenceUID = frame_uid
        ds.StudyID = "1"
        ds.SeriesNumber = series_number
        ds.InstanceNumber = k + 1
        ds.SeriesDescription = series_description
        position = RAS_TO_LPS @ np.asarray(positions_ras[k], dtype=float)
        ds.ImagePositionPatient = [_decimal_string(v) for v in position]
        ds.ImageOrientationPatient = orientation
        ds.SliceLocation = _decimal_string(float(position @ normal_lps))
        ds.PixelSpacing = [_decimal_string(pixel_spacing[1]), _decimal_string(pixel_spacing[0])]  # rows (j), columns (i)
        if slice_spacing is not None:
            ds.SliceThickness = _decimal_string(slice_spacing)
            ds.SpacingBetweenSlices = _decimal_string(slice_spacing)
        ds.SamplesPerPixel = 1
        ds.PhotometricInterpretation = "MONOCHROME2"
        ds.Rows, ds.Columns = array.shape[1], array.shape[2]
        ds.BitsAllocated = 16
        ds.BitsStored = 16
        ds.HighBit = 15
        ds.PixelRepresentation = 1
        ds.RescaleIntercept = _decimal_string(intercept)
        ds.RescaleSlope = _decimal_string(slope)
        ds.RescaleType = "HU"
        ds.WindowCenter = _decimal_string(window_center)
        ds.WindowWidth = _decimal_string(window_width)
        ds.PixelData = stored[k].tobytes()
        path = folder / f"slice_{k:04d}.dcm"
        ds.save_as(path, enforce_file_format=True)
        paths.append(path)
    return paths
