"""DICOM series as scanners and PACS export them: found in nested folders, checked, made regular.

A CD or PACS export holds its slices in nested folders (often with a
DICOMDIR), may hold several series (a scout, a soft-tissue and a bone
reconstruction, a dose report), and a CT series need not be a regular grid:
a tilted gantry makes the slices shear along the table, and a series may
have uneven gaps or missing slices. ITK's series reader ignores both and puts
the slices on an evenly spaced, untilted grid (it only logs "Non uniform
sampling or missing slices detected"), which distorts the anatomy.

* ``find_series``: every DICOM image below a folder (through its DICOMDIR when
  there is one), grouped by SeriesInstanceUID; ``choose_series`` picks the CT
  series with the most slices and says which others were there.
* ``read_geometry``: each slice's ImagePositionPatient / ImageOrientationPatient
  / PixelSpacing with pydicom; refuses what cannot be one volume (slices in
  different orientations or sizes, two slices at one position).
* ``regularize``: as Slicer's DICOM scalar volume plugin does when it hardens its
  acquisition-geometry regularization transform, compares every slice's true
  corners with the grid the reader made (tolerance ``CORNER_TOLERANCE_MM``,
  Slicer's) and, where they differ or the reader's grid is sheared (ITK
  steps k along a tilted stack), resamples the voxels (trilinear) onto a
  regular grid whose axes are the image rows, columns and the slice normal,
  so the tilt is removed and every voxel sits at its true patient position.
  It returns the message that says what was corrected.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

# A reader grid off the true slice corners by more than this (mm) is corrected (Slicer's cornerEpsilon).
CORNER_TOLERANCE_MM = 1e-3
# Gaps between slices that differ by more than this (mm) are uneven (Slicer's spacingEpsilon).
GAP_TOLERANCE_MM = 1e-2
# Direction cosines that differ by more than this belong to different orientations
# (Slicer uses 1e-6; scanners write the cosines with 6 to 10 digits).
ORIENTATION_TOLERANCE = 1e-4
# Two slices closer than this (mm) along the normal are at one position: two acquisitions mixed.
SAME_POSITION_MM = 1e-2
# A regularized volume larger than this (voxels) is refused rather than filling the memory.
MAX_REGULAR_VOXELS = 1024 ** 3

LPS_TO_RAS = np.array([-1.0, -1.0, 1.0])
DICOMDIR_NAME = "DICOMDIR"


class SeriesError(ValueError):
    """A series that cannot be made one volume: ``problem`` says why, ``remedy`` what to do."""

    def __init__(self, problem: str, remedy: str):
        self.problem = problem
        self.remedy = remedy
        super().__init__(f"{problem}. {remedy}")


# --------------------------------------------------------------------------- finding series


def read_header(path: Path):
    """The DICOM header of ``path`` (pixels not read), or None for a file that is not DICOM."""
    import pydicom

    try:
        return pydicom.dcmread(path, stop_before_pixels=True)
    except (pydicom.errors.InvalidDicomError, OSError, ValueError, EOFError, KeyError, TypeError, AttributeError):
        return None


def looks_like_dicom(path: Path) -> bool:
    """Whether ``path`` carries the DICOM file marker ("DICM" after the 128-byte preamble)."""
    try:
        with open(path, "rb") as stream:
            stream.seek(128)
            return stream.read(4) == b"DICM"
    except OSError:
        return False


def _pixel_bytes_missing(path: Path, header) -> int:
    """How many bytes of uncompressed pixel data ``path`` lacks (0 if whole or compressed)."""
    import pydicom

    syntax = getattr(getattr(header, "file_meta", None), "TransferSyntaxUID", None)
    if syntax is None or syntax.is_compressed:
        return 0
    try:
        dataset = pydicom.dcmread(path)
        stored = len(dataset.PixelData) if "PixelData" in dataset else 0
    except (OSError, ValueError, EOFError, KeyError, TypeError, AttributeError):
        stored = 0
    expected = (int(header.Rows) * int(header.Columns) * int(header.get("BitsAllocated", 16)) // 8
                * int(header.get("SamplesPerPixel", 1)) * int(header.get("NumberOfFrames", 1) or 1))
    return max(expected - stored, 0)


def _dicomdir_files(dicomdir: Path) -> list[Path] | None:
    """The image files a DICOMDIR lists, or None when it cannot be read or lists none that exist."""
    import pydicom

    try:
        index = pydicom.dcmread(dicomdir)
    except (pydicom.errors.InvalidDicomError, OSError, ValueError, EOFError, KeyError, TypeError):
        return None
    files = []
    for record in index.get("DirectoryRecordSequence", []):
        reference = record.get("ReferencedFileID")
        if record.get("DirectoryRecordType", "") != "IMAGE" or not reference:
            continue
        parts = [reference] if isinstance(reference, str) else list(reference)
        files.append(dicomdir.parent.joinpath(*parts))
    existing = [f for f in files if f.is_file()]
    return existing or None


def find_series(folder: Path, messages: list | None = None) -> dict[str, dict]:
    """Every DICOM image series below ``folder``: ``{uid: {files, Modality, SeriesDescription, SeriesInstanceUID}}``.

    Nested folders are searched; a DICOMDIR found there names the files
    (the folders are searched instead if it cannot be read). A file with the
    DICOM marker that cannot be read, or whose pixel data is cut short, is
    skipped and named in ``messages``.
    """
    folder = Path(folder)
    dicomdirs = sorted(folder.rglob(DICOMDIR_NAME), key=lambda p: len(p.parts))
    candidates = _dicomdir_files(dicomdirs[0]) if dicomdirs else None
    if dicomdirs and candidates is None and messages is not None:
        messages.append(f"{dicomdirs[0]}: the DICOMDIR cannot be read or lists no image; the folders were searched instead")
    if candidates is None:
        candidates = sorted(p for p in folder.rglob("*") if p.is_file() and p.name != DICOMDIR_NAME)
    series, damaged = {}, []
    for candidate in candidates:
        header = read_header(candidate)
        if header is None:
            if looks_like_dicom(candidate):
                damaged.append(f"{candidate.name} (unreadable header)")
            continue
        if "Rows" not in header:
            continue  # DICOMDIR, structured reports, other non-image objects
        missing = _pixel_bytes_missing(candidate, header)
        if missing:
            damaged.append(f"{candidate.name} ({missing} bytes of pixel data missing)")
            continue
        uid = str(header.get("SeriesInstanceUID", ""))
        entry = series.setdefault(uid, {"files": [], "Modality": str(header.get("Modality", "")),
                                        "SeriesDescription": str(header.get("SeriesDescription", "")),
                                        "SeriesNumber": str(header.get("SeriesNumber", "")),
                                        "SeriesInstanceUID": uid})
        entry["files"].append(candidate)
    if damaged and messages is not None:
        messages.append(f"{folder}: skipped {len(damaged)} damaged DICOM file(s): " + ", ".join(damaged[:10])
                        + (" ..." if len(damaged) > 10 else ""))
    return series


def describe_series(entry: dict) -> str:
    """``'series 3 'Head 5mm' (CT, 28 files)'``-like text."""
    number = f"series {entry['SeriesNumber']} " if entry.get("SeriesNumber") else "series "
    return f"{number}'{entry['SeriesDescription']}' ({entry['Modality'] or '?'}, {len(entry['files'])} files)"


def choose_series(series: dict[str, dict]) -> tuple[dict | None, str]:
    """The CT series with the most slices and a note naming the others; (None, listing) when two tie."""
    if len(series) == 1:
        return next(iter(series.values())), ""
    ct = [entry for entry in series.values() if entry["Modality"] == "CT"] or list(series.values())
    most = max(len(entry["files"]) for entry in ct)
    best = [entry for entry in ct if len(entry["files"]) == most]
    listing = "; ".join(describe_series(entry) for entry in series.values())
    if len(best) > 1:
        return None, listing
    chosen = best[0]
    others = "; ".join(describe_series(entry) for entry in series.values() if entry is not chosen)
    return chosen, f"chose the CT {describe_series(chosen)}, the one with the most slices; also present: {others}"


# --------------------------------------------------------------------------- slice geometry


@dataclass
class SliceStack:
    """The true geometry of a series, in RAS, its slices sorted along the slice normal."""

    files: list[Path]
    row: np.ndarray           # unit direction along an image row (increasing column index, i)
    column: np.ndarray        # unit direction down a column (increasing row index, j)
    normal: np.ndarray        # row x column
    pixel_spacing: tuple      # (along i, along j) in mm
    positions: np.ndarray     # (slices, 3): centre of each slice's first pixel
    distances: np.ndarray     # along the normal, from the first slice

    @property
    def gaps(self) -> np.ndarray:
        return np.diff(self.distances)

    @property
    def in_plane_offsets(self) -> np.ndarray:
        """Each slice's shift from the first along (row, column), in mm: zero for an untilted stack."""
        relative = self.positions - self.positions[0]
        return np.stack([relative @ self.row, relative @ self.column], axis=1)

    @property
    def tilt_degrees(self) -> float:
        """Angle between the line from the first to the last slice position and the slice normal."""
        shift = float(np.linalg.norm(self.in_plane_offsets[-1]))
        return math.degrees(math.atan2(shift, float(self.distances[-1])))


def _vector(header, keyword, count, path):
    value = header.get(keyword)
    try:
        numbers = [float(v) for v in value]
    except (TypeError, ValueError):
        numbers = []
    if len(numbers) != count or not all(math.isfinite(v) for v in numbers):
        raise SeriesError(f"{path.name} has no valid {keyword} ({value!r})",
                          "Export the series again with its geometry (ImagePositionPatient, ImageOrientationPatient, "
                          "PixelSpacing in every file)")
    return np.array(numbers)


def read_geometry(files: list[Path]) -> SliceStack | None:
    """The true slice geometry of ``files`` (one series), or None for a single (possibly multi-frame) file.

    Raises:
        SeriesError: a slice lacks its geometry, the slices differ in
            orientation, size or pixel spacing, or two lie at one position.
    """
    if len(files) < 2:
        return None
    headers = [read_header(Path(f)) for f in files]
    unreadable = [Path(f).name for f, h in zip(files, headers) if h is None]
    if unreadable:
        raise SeriesError(f"{', '.join(unreadable[:5])} cannot be read as DICOM", "Export the series again")
    first = headers[0]
    orientation = _vector(first, "ImageOrientationPatient", 6, Path(files[0]))
    size = (int(first.Rows), int(first.Columns))
    spacing = _vector(first, "PixelSpacing", 2, Path(files[0]))
    positions = []
    for path, header in zip(files, headers):
        path = Path(path)
        if not np.allclose(_vector(header, "ImageOrientationPatient", 6, path), orientation,
                           rtol=0.0, atol=ORIENTATION_TOLERANCE):
            raise SeriesError(f"its slices lie in different orientations ({Path(files[0]).name}: "
                              f"{_cosines(orientation)}; {path.name}: {_cosines(header.ImageOrientationPatient)})",
                              "Give one series of parallel slices (a localizer or a reformat mixed in must go)")
        if (int(header.Rows), int(header.Columns)) != size or not np.allclose(
                _vector(header, "PixelSpacing", 2, path), spacing, rtol=1e-6, atol=1e-6):
            raise SeriesError(f"its slices differ in size or pixel spacing ({Path(files[0]).name}: {size[1]} x {size[0]} "
                              f"at {spacing[1]:g} x {spacing[0]:g} mm; {path.name}: {int(header.Columns)} x "
                              f"{int(header.Rows)} at {float(header.PixelSpacing[1]):g} x {float(header.PixelSpacing[0]):g} mm)",
                              "Give one series whose slices share one size and pixel spacing")
        positions.append(_vector(header, "ImagePositionPatient", 3, path) * LPS_TO_RAS)
    row = orientation[:3] * LPS_TO_RAS
    column = orientation[3:] * LPS_TO_RAS
    row, column = row / np.linalg.norm(row), column / np.linalg.norm(column)
    normal = np.cross(row, column)
    positions = np.array(positions)
    along = (positions - positions[0]) @ normal
    order = np.argsort(along, kind="stable")
    positions, along = positions[order], along[order]
    stack = SliceStack(files=[Path(files[i]) for i in order], row=row, column=column, normal=normal,
                       pixel_spacing=(float(spacing[1]), float(spacing[0])), positions=positions,
                       distances=along - along[0])
    close = np.nonzero(stack.gaps < SAME_POSITION_MM)[0]
    if close.size:
        k = int(close[0])
        raise SeriesError(f"{close.size} pair(s) of its slices lie at the same position (e.g. {stack.files[k].name} and "
                          f"{stack.files[k + 1].name}): several acquisitions or reconstructions in one series",
                          "Give one acquisition: export the reconstruction you mean as its own series")
    return stack


def _cosines(values) -> str:
    return "(" + ", ".join(f"{float(v):.4g}" for v in values) + ")"


# --------------------------------------------------------------------------- regularizing


def corner_error(stack: SliceStack, ijk_to_ras: np.ndarray, dimensions, reversed_order: bool) -> float:
    """Largest distance (mm) between a slice's true corners and where the reader's grid puts them."""
    columns, rows = dimensions[0], dimensions[1]
    worst = 0.0
    for k in range(len(stack.files)):
        index = len(stack.files) - 1 - k if reversed_order else k
        for i, j in ((0, 0), (columns - 1, 0), (0, rows - 1), (columns - 1, rows - 1)):
            true = (stack.positions[index] + i * stack.pixel_spacing[0] * stack.row
                    + j * stack.pixel_spacing[1] * stack.column)
            grid = ijk_to_ras[:3, :3] @ np.array([i, j, k], dtype=float) + ijk_to_ras[:3, 3]
            worst = max(worst, float(np.linalg.norm(true - grid)))
    return worst


def regular_spacing(stack: SliceStack) -> float:
    """The spacing between slices of the regular grid: the smallest gap (no detail acquired is lost),
    no finer than the in-plane pixels, shrunk slightly so that whole steps span the first to the last slice."""
    step = max(float(stack.gaps.min()), min(stack.pixel_spacing))
    span = float(stack.distances[-1])
    return span / math.ceil(span / step - 1e-6)


def _shifted_bilinear(image: np.ndarray, shift_i: float, shift_j: float, shape, fill) -> np.ndarray:
    """``image`` sampled at (i + shift_i, j + shift_j) for every i, j of ``shape`` (rows, columns); outside: ``fill``."""
    base_i, base_j = math.floor(shift_i), math.floor(shift_j)
    fraction_i, fraction_j = shift_i - base_i, shift_j - base_j
    padded = np.full((shape[0] + 1, shape[1] + 1), fill, dtype=np.float64)
    rows, columns = image.shape
    j0, j1 = max(0, -base_j), min(shape[0] + 1, rows - base_j)
    i0, i1 = max(0, -base_i), min(shape[1] + 1, columns - base_i)
    if j1 > j0 and i1 > i0:
        padded[j0:j1, i0:i1] = image[j0 + base_j:j1 + base_j, i0 + base_i:i1 + base_i]
    return ((1 - fraction_j) * ((1 - fraction_i) * padded[:-1, :-1] + fraction_i * padded[:-1, 1:])
            + fraction_j * ((1 - fraction_i) * padded[1:, :-1] + fraction_i * padded[1:, 1:]))


def resample(stack: SliceStack, slices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Resample ``slices`` (``[k, j, i]`` in the stack's order) onto a regular grid; return (array, IJK-to-RAS).

    The grid's axes are the rows, the columns and the slice normal (the tilt
    is gone); it covers every slice (a tilted stack's shear widens it along
    the columns, filled with the series' lowest value, air). Each voxel is
    interpolated linearly between the two slices around it, bilinearly within
    each (trilinear).
    """
    spacing_i, spacing_j = stack.pixel_spacing
    spacing_k = regular_spacing(stack)
    offsets = stack.in_plane_offsets
    rows, columns = slices.shape[1:]
    low = offsets.min(axis=0)
    high = offsets.max(axis=0) + np.array([(columns - 1) * spacing_i, (rows - 1) * spacing_j])
    counts_ij = np.floor((high - low) / np.array([spacing_i, spacing_j]) + 1e-6).astype(int) + 1
    count_k = int(round(float(stack.distances[-1]) / spacing_k)) + 1
    if int(counts_ij[0]) * int(counts_ij[1]) * count_k > MAX_REGULAR_VOXELS:
        raise SeriesError(f"made regular it would have {counts_ij[0]} x {counts_ij[1]} x {count_k} voxels, more than "
                          f"{MAX_REGULAR_VOXELS} (slices {spacing_k:.3g} mm apart)",
                          "Give the series cropped or with fewer, evenly spaced slices")
    fill = float(slices.min())
    output = np.empty((count_k, counts_ij[1], counts_ij[0]), dtype=slices.dtype)
    for m in range(count_k):
        distance = min(m * spacing_k, float(stack.distances[-1]))
        k = min(int(np.searchsorted(stack.distances, distance, side="right")) - 1, len(stack.distances) - 2)
        weight = (distance - stack.distances[k]) / (stack.distances[k + 1] - stack.distances[k])
        value = np.zeros((counts_ij[1], counts_ij[0]))
        for index, share in ((k, 1.0 - weight), (k + 1, weight)):
            if share <= 0.0:
                continue
            shift = (low - offsets[index]) / np.array([spacing_i, spacing_j])
            value += share * _shifted_bilinear(slices[index], shift[0], shift[1], output.shape[1:], fill)
        if np.issubdtype(output.dtype, np.integer):
            limits = np.iinfo(output.dtype)
            value = np.clip(np.rint(value), limits.min, limits.max)
        output[m] = value
    ijk_to_ras = np.eye(4)
    ijk_to_ras[:3, 0] = stack.row * spacing_i
    ijk_to_ras[:3, 1] = stack.column * spacing_j
    ijk_to_ras[:3, 2] = stack.normal * spacing_k
    ijk_to_ras[:3, 3] = stack.positions[0] + low[0] * stack.row + low[1] * stack.column
    return output, ijk_to_ras


def _millimetres(values) -> str:
    shown = ", ".join(f"{v:.3g}" for v in values[:8])
    return shown + (f", ... ({len(values)} in all)" if len(values) > 8 else "")


def describe_correction(stack: SliceStack, spacing_k: float) -> str:
    """What was irregular and what the grid is now, for the user."""
    gaps = stack.gaps
    median = float(np.median(gaps))
    uneven = [float(g) for g in gaps if abs(g - median) > GAP_TOLERANCE_MM]
    parts = []
    tilt = stack.tilt_degrees
    if float(np.abs(stack.in_plane_offsets).max()) > CORNER_TOLERANCE_MM:
        parts.append(f"gantry tilt {tilt:.1f}° corrected" if tilt >= 0.05 else "slices shifted within their plane corrected")
    if uneven:
        parts.append(f"{len(uneven)} uneven gap(s) between slices ({_millimetres(uneven)} mm; the others "
                     f"{median:.3g} mm) resampled")
    elif not parts:
        parts.append(f"slices {median:.3g} mm apart resampled")
    smallest = max(float(gaps.min()), min(stack.pixel_spacing))
    return (" and ".join(parts) + f" onto a regular grid {spacing_k:.3g} mm between slices (the smallest gap, "
            f"{smallest:.3g} mm, evened over the {float(stack.distances[-1]):.1f} mm from the first of the "
            f"{len(stack.files)} slices to the last; trilinear)")


def regularize(volume_node, stack: SliceStack, label: str) -> str | None:
    """Put ``volume_node`` (the series as ITK read it) onto the true geometry; return the message, or None if it was right.

    Raises:
        SeriesError: the reader's volume does not match the files (slice
            count, in-plane axes), so the slices cannot be placed.
    """
    from ..scene import nodes

    dimensions = volume_node.GetImageData().GetDimensions()
    if dimensions[2] != len(stack.files):
        raise SeriesError(f"the reader made {dimensions[2]} slices of its {len(stack.files)} files",
                          "Export the series again")
    ijk_to_ras = nodes.volume_node_ijk_to_ras(volume_node)
    expected_axes = np.stack([stack.row * stack.pixel_spacing[0], stack.column * stack.pixel_spacing[1]], axis=1)
    if not np.allclose(ijk_to_ras[:3, :2], expected_axes, atol=1e-4) or dimensions[0] * dimensions[1] == 0:
        raise SeriesError("the reader's image axes differ from the files' ImageOrientationPatient / PixelSpacing",
                          "Export the series again, or convert it to NRRD in Slicer")
    reversed_order = float(ijk_to_ras[:3, 2] @ stack.normal) < 0.0
    # ITK steps k along the line through the slice positions: a tilted series comes out sheared,
    # which the cut field and the renderers (orthogonal grids) cannot take.
    unit = ijk_to_ras[:3, :3] / np.linalg.norm(ijk_to_ras[:3, :3], axis=0)
    sheared = float(np.abs(unit[:, :2].T @ unit[:, 2]).max()) > ORIENTATION_TOLERANCE
    if not sheared and corner_error(stack, ijk_to_ras, dimensions, reversed_order) <= CORNER_TOLERANCE_MM:
        return None
    slices = nodes.array_from_volume_node(volume_node)
    if reversed_order:
        slices = slices[::-1]
    array, regular_ijk_to_ras = resample(stack, slices)
    volume_node.SetAndObserveImageData(nodes.image_data_from_array(array))
    volume_node.SetIJKToRASMatrix(nodes.numpy_to_vtk_matrix(regular_ijk_to_ras))
    return f"DICOM series {label}: " + describe_correction(stack, float(np.linalg.norm(regular_ijk_to_ras[:3, 2])))
