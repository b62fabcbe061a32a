"""Own data in: a clinician's CT and segmentation, loaded through Slicer's own readers.

A user points the product at what their scanner, PACS or segmentation tool
made, and names the segments in their own words:

* ``load_ct``: a DICOM series (its folder, or any one file of it), NRRD
  (``.nrrd``/``.nhdr``), NIfTI (``.nii``/``.nii.gz``) or MetaImage
  (``.mha``/``.mhd``), read by ``vtkMRMLVolumeArchetypeStorageNode`` (ITK) as
  desktop Slicer reads it, with the file's own axes kept (a flipped or
  left-handed IJK-to-RAS stays as it is, so voxel indices mean what they mean
  in the file), then checked for what drilling needs: a volume, in HU.
* ``load_segmentation``: a Slicer ``.seg.nrrd`` or a labelmap volume with a
  colour/name table, brought onto the CT's voxel grid.
* ``resolve_roles``: cuttable and protected segments by name.

Every failure raises ``InputError``, whose message names the file and says
what to do, and leaves the scene as it was: every node a call added (volume,
storage, display, colour table, intermediate labelmap) is removed again.
Warnings (a CT without air, labels without names, a resampled segmentation)
go to the optional ``messages`` list.
"""

from __future__ import annotations

import contextlib
import re
from pathlib import Path

import numpy as np

from ..scene import nodes
from . import dicomimport

VOLUME_EXTENSIONS = (".nrrd", ".nhdr", ".nii", ".nii.gz", ".mha", ".mhd")
SEGMENTATION_EXTENSION = ".seg.nrrd"
COLOR_TABLE_EXTENSIONS = (".ctbl", ".txt")
SOURCE_PATH_ATTRIBUTE = "VolumeCutting.SourcePath"

# Hounsfield units: air is -1000, water 0, cortical bone 1000-2000; scanners
# pad outside the field of view with values down to -3024 (some -32768).
AIR_BELOW_HU = -500.0
BONE_FROM_HU = 200.0
HU_LIMITS = (-32768.0, 32767.0)
# A labelmap with more distinct values than this is an image, not labels.
MAX_LABELS = 1000
# Grids agree when the segmentation's voxel lattice maps onto the CT's to
# this fraction of a voxel (a tolerance relative to the voxel size).
GRID_TOLERANCE_VOXELS = 1e-3

_FORMATS = "a DICOM series folder, NRRD (.nrrd/.nhdr), NIfTI (.nii/.nii.gz) or MetaImage (.mha/.mhd)"
_LABELMAP_FORMATS = "a Slicer segmentation (.seg.nrrd) or a labelmap volume (.nrrd, .nii, .nii.gz, .mha)"


class InputError(ValueError):
    """Input the product cannot use; the message names the file and says what to do."""

    def __init__(self, path, problem: str, remedy: str):
        self.path = str(path)
        self.problem = problem
        self.remedy = remedy
        super().__init__(f"{self.path}: {problem}. {remedy}")


# --------------------------------------------------------------------------- scene and log hygiene


@contextlib.contextmanager
def _scene_transaction(scene):
    """On an exception, remove every node added to ``scene`` inside the block."""
    before = {scene.GetNthNode(index).GetID() for index in range(scene.GetNumberOfNodes())}
    try:
        yield
    except BaseException:
        added = [scene.GetNthNode(index) for index in range(scene.GetNumberOfNodes())]
        for node in reversed(added):
            if node is not None and node.GetID() not in before and scene.IsNodePresent(node):
                scene.RemoveNode(node)
        raise


def remove_nodes(scene, *nodes_to_remove):
    """Remove nodes with their display and storage nodes (intermediates a load made)."""
    for node in nodes_to_remove:
        if node is None or not scene.IsNodePresent(node):
            continue
        for related in _display_and_storage_nodes(node):
            if scene.IsNodePresent(related):
                scene.RemoveNode(related)
        scene.RemoveNode(node)


def _display_and_storage_nodes(node):
    related = []
    if node.IsA("vtkMRMLDisplayableNode"):
        related += [node.GetNthDisplayNode(index) for index in range(node.GetNumberOfDisplayNodes())]
    if node.IsA("vtkMRMLStorableNode"):
        related += [node.GetNthStorageNode(index) for index in range(node.GetNumberOfStorageNodes())]
    return [r for r in related if r is not None]


@contextlib.contextmanager
def _reader_log_quiet():
    """Keep VTK/ITK reader errors off the terminal: they are turned into one InputError."""
    import vtk

    previous = vtk.vtkObject.GetGlobalWarningDisplay()
    vtk.vtkObject.GlobalWarningDisplayOff()
    try:
        yield
    finally:
        vtk.vtkObject.SetGlobalWarningDisplay(previous)


def _user_messages(storage_node, event_name):
    import vtk

    collection = storage_node.GetUserMessages()
    event = getattr(vtk.vtkCommand, event_name)
    return [collection.GetNthMessageText(index) for index in range(collection.GetNumberOfMessages())
            if collection.GetNthMessageType(index) == event]


def _first_error(storage_node):
    """What the reader said first went wrong (the later messages only repeat that reading failed)."""
    errors = _user_messages(storage_node, "ErrorEvent")
    return errors[0] if errors else "the reader gave no details"


def _warn(messages, text):
    if messages is not None:
        messages.append(text)


# --------------------------------------------------------------------------- reading volumes


def _has_extension(path: Path, extensions) -> bool:
    name = path.name.lower()
    return any(name.endswith(extension) for extension in extensions)


def _base_name(path: Path) -> str:
    name = path.name
    for extension in (SEGMENTATION_EXTENSION,) + VOLUME_EXTENSIONS + COLOR_TABLE_EXTENSIONS + (".dcm",):
        if name.lower().endswith(extension):
            return name[: -len(extension)]
    return name


def _read_volume(scene, node_class, files, name, source):
    """Read ``files`` (one file, or a DICOM series in any order) into a new ``node_class`` node."""
    import slicer

    volume = scene.AddNewNodeByClass(node_class, name)
    storage = slicer.vtkMRMLVolumeArchetypeStorageNode()
    scene.AddNode(storage)
    storage.SetFileName(str(files[0]))
    if len(files) > 1:
        # ITK orders the slices by their position along the slice normal.
        for file in files:
            storage.AddFileName(str(file))
        storage.SetSingleFile(0)
    else:
        storage.SetSingleFile(1)
    # Keep the axes as the file has them: Slicer's default would reverse k
    # of a left-handed grid, so indices would no longer match the file's.
    storage.SetForceRightHandedIJKCoordinateSystem(False)
    volume.SetAndObserveStorageNodeID(storage.GetID())
    with _reader_log_quiet():
        ok = storage.ReadData(volume)
    image = volume.GetImageData()
    if not ok or image is None or image.GetNumberOfPoints() == 0:
        raise InputError(source, f"is not an image Slicer can read ({_first_error(storage)})",
                         f"Give {_FORMATS}.")
    return volume, _user_messages(storage, "WarningEvent")


def _check_nrrd_readable(path):
    """Raise ``InputError`` unless ITK reads ``path`` as a NRRD volume (3D, or 4D with a list axis).

    Slicer's segmentation storage node lets an ITK exception escape on a
    malformed or truncated NRRD, which aborts the whole process; the volume
    reader catches it. So a ``.seg.nrrd`` is read as a volume first, in a
    scratch scene, and reaches the segmentation reader only if that works.
    """
    import slicer

    scratch = slicer.vtkMRMLScene()
    error = None
    # Segments that overlap are stored in several layers: a 4D file, read as a vector volume.
    for node_class in ("vtkMRMLScalarVolumeNode", "vtkMRMLVectorVolumeNode"):
        volume = scratch.AddNewNodeByClass(node_class)
        storage = slicer.vtkMRMLVolumeArchetypeStorageNode()
        scratch.AddNode(storage)
        storage.SetFileName(str(path))
        storage.SetSingleFile(1)
        with _reader_log_quiet():
            if storage.ReadData(volume) and volume.GetImageData() is not None:
                return
        error = error or _first_error(storage)
    raise InputError(path, f"is not a readable NRRD file ({error}): "
                           "damaged, truncated or not NRRD", f"Save the segmentation again; give {_LABELMAP_FORMATS}.")


def _check_is_volume(volume, source, what):
    image = volume.GetImageData()
    dimensions = image.GetDimensions()
    if min(dimensions) < 2:
        raise InputError(
            source, f"is a 2D image ({dimensions[0]} x {dimensions[1]} x {dimensions[2]} voxels)",
            "Cutting needs a volume: a drill removes bone in depth, through several slices. "
            f"Give the whole {what}" + (" (for DICOM, the folder of the series or one file of it, not a lone slice)."
                                        if what == "CT" else "."))
    components = image.GetNumberOfScalarComponents()
    if components != 1:
        raise InputError(source, f"has {components} values a voxel (a colour or vector image)",
                         f"Give a {what} with one value a voxel.")


def _check_hounsfield(volume, source, messages):
    low, high = volume.GetImageData().GetScalarRange()
    if low < HU_LIMITS[0] or high > HU_LIMITS[1]:
        raise InputError(
            source, f"has values {low:g} to {high:g}, outside any CT's range in Hounsfield units",
            "Export the CT in HU (Hounsfield units: air -1000, water 0, bone several hundred and more).")
    if low >= 0.0:
        raise InputError(
            source, f"has values {low:g} to {high:g}: no air below {AIR_BELOW_HU:g} HU, so these are not "
            "Hounsfield units (an MR image, or a CT stored without its rescale slope and intercept)",
            "Drilling needs a CT in HU (air -1000, bone from about 200). Give the CT series itself, "
            "or export it in HU (for raw CT values, subtract the rescale intercept, usually 1024).")
    if low > AIR_BELOW_HU and high < BONE_FROM_HU:
        raise InputError(
            source, f"has values {low:g} to {high:g}: neither air (-1000 HU) nor bone (200 HU and more), "
            "an MR-like or normalised range, not Hounsfield units",
            "Drilling needs a CT in HU. Give the CT as the scanner made it, not a normalised copy.")
    if low > AIR_BELOW_HU:
        _warn(messages, f"{source}: no value below {AIR_BELOW_HU:g} HU (lowest {low:g}): a CT usually shows "
                        "air; check that it is in Hounsfield units and not cropped inside the patient")
    if high < BONE_FROM_HU:
        _warn(messages, f"{source}: no value of {BONE_FROM_HU:g} HU or more (highest {high:g}): "
                        "no bone for a drill to cut")


# --------------------------------------------------------------------------- DICOM series


def find_dicom_series(path, messages=None, choose_series=False) -> tuple[list[Path], dict]:
    """Return the image files of the DICOM series at ``path`` (a folder, or one file of the series).

    Returns (files, info): the files in name order (the reader sorts them by
    position) and the series' Modality, SeriesDescription and SeriesInstanceUID.
    A folder is searched with its subfolders (through its DICOMDIR if it has
    one, as CD and PACS exports are laid out). Of several series, with
    ``choose_series`` the CT with the most slices is taken, with a message in
    ``messages`` naming it and the others (the application, which shows it);
    without, the folder is refused (a job names the series it means).
    Damaged DICOM files are skipped and named in ``messages``.
    Raises ``InputError`` for a folder without DICOM images, or with several
    series not to be chosen from (name one file of the one you mean).
    """
    path = Path(path)
    folder = path if path.is_dir() else path.parent
    chosen_uid = None
    if path.is_file():
        header = dicomimport.read_header(path)
        if header is None or "Rows" not in header:
            raise InputError(path, "is not an image file this product reads (neither DICOM nor a volume file)",
                             f"Give {_FORMATS}.")
        chosen_uid = str(header.get("SeriesInstanceUID", ""))
        # One file names its series among the files beside it.
        series = {}
        for candidate in sorted(p for p in folder.iterdir() if p.is_file()):
            other = dicomimport.read_header(candidate)
            if other is not None and "Rows" in other and str(other.get("SeriesInstanceUID", "")) == chosen_uid:
                series.setdefault(chosen_uid, {"files": [], "Modality": str(header.get("Modality", "")),
                                               "SeriesDescription": str(header.get("SeriesDescription", "")),
                                               "SeriesInstanceUID": chosen_uid})["files"].append(candidate)
        info = series[chosen_uid]
    else:
        series = dicomimport.find_series(folder, messages)
        if not series:
            raise InputError(folder, "contains no DICOM image files (its subfolders and any DICOMDIR searched too)",
                             f"Give {_FORMATS}; for DICOM, the folder that holds the slice files of one series.")
        info, note = dicomimport.choose_series(series)
        if len(series) > 1 and (info is None or not choose_series):
            listing = "; ".join(dicomimport.describe_series(entry) + f", e.g. {entry['files'][0].name}"
                                for entry in series.values())
            why = " and no single CT series has the most slices" if choose_series else ""
            raise InputError(folder, f"holds {len(series)} DICOM series{why} ({listing})",
                             "Give one file of the series you mean instead of the folder.")
        if note:
            _warn(messages, f"{folder}: {note}")
    return info["files"], {key: info[key] for key in ("Modality", "SeriesDescription", "SeriesInstanceUID")}


def _series_label(info, files) -> str:
    """How messages name a series: its description, else its folder."""
    return f"'{info['SeriesDescription']}'" if info["SeriesDescription"] else str(Path(files[0]).parent.name)


# --------------------------------------------------------------------------- the CT


def load_ct(scene, path, name=None, messages=None, choose_series=False):
    """Load the user's CT into ``scene`` and return its ``vtkMRMLScalarVolumeNode``.

    Args:
        scene: the MRML scene.
        path: a DICOM series folder or one file of a series, or a NRRD, NIfTI
            or MetaImage file.
        name: the node's name (default: the file's base name, or the series
            description).
        messages: optional list that receives warnings (strings), among them
            what was corrected in a tilted or unevenly spaced DICOM series
            (resampled onto a regular grid, see ``dicomimport``).
        choose_series: of a folder with several DICOM series, take the CT
            with the most slices (saying so in ``messages``) instead of refusing.

    Raises:
        InputError: a missing path, a folder without DICOM, a file that is
            not an image, a 2D image, values that cannot be Hounsfield units,
            or a DICOM series that cannot be one volume (slices in several
            orientations, two at one position).
            The scene is left as it was.
    """
    path = Path(path).expanduser()
    with _scene_transaction(scene):
        if not path.exists():
            raise InputError(path, "does not exist", f"Check the path; give {_FORMATS}.")
        if _has_extension(path, (SEGMENTATION_EXTENSION,)):
            raise InputError(path, "is a segmentation, not a CT",
                             "Give it as the segmentation (--segmentation) and the CT itself as the CT.")
        if path.is_dir() or not _has_extension(path, VOLUME_EXTENSIONS):
            files, info = find_dicom_series(path, messages, choose_series)
            if info["Modality"] and info["Modality"] != "CT":
                raise InputError(path, f"is a {info['Modality']} series, not CT",
                                 "Drilling needs a CT in Hounsfield units; give the CT series of the patient.")
            default_name = info["SeriesDescription"] or (path if path.is_dir() else path.parent).name
            try:
                stack = dicomimport.read_geometry(files)
            except dicomimport.SeriesError as error:
                raise InputError(path, f"is not one regular volume: {error.problem}", error.remedy + ".") from error
            volume, warnings = _read_volume(scene, "vtkMRMLScalarVolumeNode", files, name or default_name, path)
            # ITK puts the slices on an even, untilted grid whatever their true positions.
            warnings = [w for w in warnings if "Non uniform sampling" not in w] if stack is not None else warnings
            if stack is not None:
                try:
                    correction = dicomimport.regularize(volume, stack, _series_label(info, files))
                except dicomimport.SeriesError as error:
                    raise InputError(path, f"cannot be put on a regular grid: {error.problem}",
                                     error.remedy + ".") from error
                if correction:
                    _warn(messages, f"{path}: {correction}")
        else:
            volume, warnings = _read_volume(scene, "vtkMRMLScalarVolumeNode", [path], name or _base_name(path), path)
        _check_is_volume(volume, path, "CT")
        _check_hounsfield(volume, path, messages)
        for warning in warnings:
            _warn(messages, f"{path}: {warning}")
        volume.SetAttribute(SOURCE_PATH_ATTRIBUTE, str(path))
        volume.CreateDefaultDisplayNodes()
    return volume


# --------------------------------------------------------------------------- colour / name tables


def read_color_table(path) -> dict[int, tuple[str, tuple[float, float, float, float]]]:
    """Read a colour/name table: ``{label: (name, (r, g, b, a) in 0..1)}``.

    Two text layouts are read, one entry a line, ``#`` starting a comment:
    Slicer's colour table (``.ctbl``/``.txt``: ``label name R G B A``, 0-255,
    the name may contain spaces) and ITK-SNAP's label description
    (``label R G B A visible mesh "name"``, A from 0 to 1).
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError as error:
        raise InputError(path, f"cannot be read ({error.strerror})", "Give a readable colour table file.") from error
    table = {}
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        quoted = re.fullmatch(r'(-?\d+)\s+(\d+)\s+(\d+)\s+(\d+)\s+([\d.]+)\s+\d+\s+\d+\s+"(.*)"', line)
        try:
            if quoted:
                label, r, g, b, alpha, label_name = quoted.groups()
                rgba = (int(r) / 255.0, int(g) / 255.0, int(b) / 255.0, float(alpha))
            else:
                tokens = line.split()
                if len(tokens) < 5:
                    raise ValueError("it has fewer than five fields")
                label = tokens[0]
                has_alpha = len(tokens) >= 6
                colour_fields = tokens[-4:] if has_alpha else tokens[-3:] + ["255"]
                if not all(value.isdigit() for value in colour_fields):
                    raise ValueError("R G B A must be whole numbers from 0 to 255")
                colour = [int(value) for value in colour_fields]
                label_name = " ".join(tokens[1:-4] if has_alpha else tokens[1:-3])
                rgba = tuple(min(max(value, 0), 255) / 255.0 for value in colour)
            if not re.fullmatch(r"-?\d+", label):
                raise ValueError("the label must be a whole number")
            label_value = int(label)
        except ValueError as error:
            raise InputError(path, f"line {number} ({raw.strip()!r}) is not 'label name R G B A': {error}",
                             "Write one label a line as 'label name R G B A' (colours 0-255), "
                             "as Slicer's .ctbl colour tables do.") from error
        if label_value < 0:
            raise InputError(path, f"line {number} gives the negative label {label_value}",
                             "Labels are the non-negative values of the labelmap.")
        table[label_value] = (label_name.strip() or f"Label {label_value}", rgba)
    if not table:
        raise InputError(path, "holds no label entries", "Write one label a line as 'label name R G B A'.")
    return table


def find_color_table(labelmap_path) -> Path | None:
    """A colour table beside ``labelmap_path`` with the same base name (``.ctbl``, then ``.txt``)."""
    labelmap_path = Path(labelmap_path)
    base = _base_name(labelmap_path)
    for extension in COLOR_TABLE_EXTENSIONS:
        candidate = labelmap_path.with_name(base + extension)
        if candidate.is_file():
            return candidate
    return None


# --------------------------------------------------------------------------- segmentations


def _labels_of(volume, source):
    array = nodes.array_from_volume_node(volume)
    if not np.issubdtype(array.dtype, np.integer):
        if not np.all(np.isfinite(array)) or np.any(np.mod(array, 1.0) != 0.0):
            raise InputError(source, "has non-integer values, so it is not a labelmap",
                             f"Give {_LABELMAP_FORMATS} whose voxels hold label numbers.")
        array = array.astype(np.int64)
    low, high = int(array.min()), int(array.max())
    if low < 0:
        raise InputError(source, f"has negative values (down to {low}), so it is not a labelmap",
                         f"Give {_LABELMAP_FORMATS} whose voxels hold label numbers (0 for background).")
    if high - low < 1 << 20:
        counts = np.bincount((array - low).ravel())
        labels = [int(value) + low for value in np.nonzero(counts)[0]]
    else:
        labels = [int(value) for value in np.unique(array)]
    labels = [label for label in labels if label != 0]
    if not labels:
        raise InputError(source, "has no labelled voxel (every voxel is 0)",
                         "Give the labelmap that holds the segments.")
    if len(labels) > MAX_LABELS:
        raise InputError(source, f"has {len(labels)} distinct values: an image, not a labelmap",
                         f"Give {_LABELMAP_FORMATS}; the CT itself goes in as the CT.")
    return labels


def labelmap_color_node(scene, labels, table, source=None, messages=None, name="LabelNames"):
    """A ``vtkMRMLColorTableNode`` naming and colouring ``labels`` from ``table`` (see ``read_color_table``).

    A label the table lacks is named ``Label <k>`` (with a warning naming the
    table, or the labelmap if there is none).
    """
    color_node = scene.AddNewNodeByClass("vtkMRMLColorTableNode", name)
    color_node.SetTypeToUser()
    color_node.SetNumberOfColors(max(labels) + 1)
    color_node.SetColor(0, "Background", 0.0, 0.0, 0.0, 0.0)
    unnamed = []
    for label in labels:
        if label in table:
            label_name, rgba = table[label]
        else:
            unnamed.append(label)
            # Distinct, reproducible colours for unnamed labels.
            hue = (label * 0.618033988749895) % 1.0
            label_name, rgba = f"Label {label}", (*_hue_to_rgb(hue), 1.0)
        color_node.SetColor(label, label_name, *rgba)
    if unnamed and source is not None:
        listed = ", ".join(str(label) for label in unnamed[:20]) + (" ..." if len(unnamed) > 20 else "")
        _warn(messages, f"{source}: no name for label(s) {listed}; named 'Label <k>'. Give a colour table "
                        "('label name R G B A' a line) to name them")
    return color_node


def _hue_to_rgb(hue):
    import colorsys

    return colorsys.hsv_to_rgb(hue, 0.65, 0.95)


def segmentation_from_labelmap(scene, labelmap_node, color_node, reference_volume, name):
    """Import a labelmap volume node into a new segmentation node with Slicer's segmentation logic.

    Each label becomes a segment named and coloured from ``color_node``; the
    segmentation's reference geometry is ``reference_volume``'s. The labelmap
    and colour nodes are left for the caller.
    """
    import slicer

    display = scene.AddNewNodeByClass("vtkMRMLLabelMapVolumeDisplayNode")
    display.SetAndObserveColorNodeID(color_node.GetID())
    labelmap_node.SetAndObserveDisplayNodeID(display.GetID())
    segmentation_node = scene.AddNewNodeByClass("vtkMRMLSegmentationNode", name)
    segmentation_node.SetReferenceImageGeometryParameterFromVolumeNode(reference_volume)
    user_messages = slicer.vtkMRMLMessageCollection()
    if not slicer.vtkSlicerSegmentationsModuleLogic.ImportLabelmapToSegmentationNode(
            labelmap_node, segmentation_node, "", user_messages):
        raise RuntimeError(f"importing the labelmap {labelmap_node.GetName()!r} failed: "
                           + user_messages.GetAllMessagesAsString())
    return segmentation_node


def _matrix_of(oriented_image):
    import vtk

    matrix = vtk.vtkMatrix4x4()
    oriented_image.GetImageToWorldMatrix(matrix)
    return nodes.vtk_matrix_to_numpy(matrix)


def describe_grid(ijk_to_ras, extent) -> str:
    """``'512 x 512 x 133 voxels of 0.70 x 0.70 x 2.50 mm, axes (-R, +A, +S)'``-like text for messages."""
    ijk_to_ras = np.asarray(ijk_to_ras, dtype=float)
    spacing = np.linalg.norm(ijk_to_ras[:3, :3], axis=0)
    counts = [extent[2 * axis + 1] - extent[2 * axis] + 1 for axis in range(3)]
    axes = []
    for axis in range(3):
        direction = ijk_to_ras[:3, axis] / spacing[axis]
        main = int(np.argmax(np.abs(direction)))
        label = ("+" if direction[main] > 0 else "-") + "RAS"[main]
        axes.append(label if abs(direction[main]) > 0.9999 else label + "~")
    return (" x ".join(str(c) for c in counts) + " voxels of " + " x ".join(f"{s:.3g}" for s in spacing)
            + " mm, axes (" + ", ".join(axes) + "), origin (" + ", ".join(f"{v:.1f}" for v in ijk_to_ras[:3, 3]) + ")")


def _ct_grid(reference_volume):
    dimensions = reference_volume.GetImageData().GetDimensions()
    extent = (0, dimensions[0] - 1, 0, dimensions[1] - 1, 0, dimensions[2] - 1)
    return nodes.volume_node_ijk_to_ras(reference_volume), extent


def _box_in_ct(transform, extent, ct_extent):
    """The CT index box covering ``extent`` mapped by ``transform`` (segment IJK -> CT IJK), clipped to the CT."""
    corners = np.array([[extent[0 + a], extent[2 + b], extent[4 + c], 1.0]
                        for a in (0, 1) for b in (0, 1) for c in (0, 1)])
    mapped = (transform @ corners.T).T[:, :3]
    low = np.maximum(np.floor(mapped.min(axis=0) - GRID_TOLERANCE_VOXELS).astype(int), ct_extent[0::2])
    high = np.minimum(np.ceil(mapped.max(axis=0) + GRID_TOLERANCE_VOXELS).astype(int), ct_extent[1::2])
    if np.any(low > high):
        return None
    return [int(v) for pair in zip(low, high) for v in pair]


def _bring_onto_ct_grid(segmentation_node, reference_volume, source, messages):
    """Resample every labelmap layer not on the CT's voxel lattice onto it (nearest neighbour).

    A layer whose lattice coincides with the CT's (a Slicer segmentation
    cropped to its segments' extent, say) is kept as it is. Raises
    ``InputError`` if no layer overlaps the CT.
    """
    import slicer

    ct_matrix, ct_extent = _ct_grid(reference_volume)
    ras_to_ct = np.linalg.inv(ct_matrix)
    segmentation = segmentation_node.GetSegmentation()
    overlapping, resampled, outside, other_grid = False, [], [], None
    for layer in range(segmentation.GetNumberOfLayers()):
        image = segmentation.GetLayerDataObject(layer)
        segment_ids = list(segmentation.GetSegmentIDsForLayer(layer))
        extent = image.GetExtent() if image is not None else (0, -1, 0, -1, 0, -1)
        if image is None or extent[1] < extent[0] or extent[3] < extent[2] or extent[5] < extent[4]:
            continue  # empty segments
        layer_matrix = _matrix_of(image)
        transform = ras_to_ct @ layer_matrix
        box = _box_in_ct(transform, extent, ct_extent)
        names = [segmentation.GetSegment(segment_id).GetName() for segment_id in segment_ids]
        if box is None:
            outside.extend(names)
            continue
        overlapping = True
        same_lattice = (np.allclose(transform[:3, :3], np.eye(3), atol=GRID_TOLERANCE_VOXELS)
                        and np.allclose(transform[:3, 3], np.round(transform[:3, 3]), atol=GRID_TOLERANCE_VOXELS))
        if same_lattice:
            continue
        other_grid = other_grid or describe_grid(layer_matrix, extent)
        reference = slicer.vtkOrientedImageData()
        reference.SetImageToWorldMatrix(nodes.numpy_to_vtk_matrix(ct_matrix))
        reference.SetExtent(*box)
        output = slicer.vtkOrientedImageData()
        if not slicer.vtkOrientedImageDataResample.ResampleOrientedImageToReferenceOrientedImage(
                image, reference, output, False):
            raise RuntimeError(f"resampling the segments {names} of {source} onto the CT's grid failed")
        # In place: every segment of the layer shares this image.
        image.DeepCopy(output)
        image.Modified()
        resampled.extend(names)
    if not overlapping:
        segmentation_bounds = describe_grid(_matrix_of(segmentation.GetLayerDataObject(0)),
                                            segmentation.GetLayerDataObject(0).GetExtent()) \
            if segmentation.GetNumberOfLayers() else "no voxels"
        raise InputError(
            source, f"does not overlap the CT '{reference_volume.GetName()}' (segmentation: {segmentation_bounds}; "
            f"CT: {describe_grid(ct_matrix, ct_extent)})",
            "Give the segmentation made from this CT (same patient, same scan).")
    if resampled:
        _warn(messages, f"{source}: on another voxel grid ({other_grid}) than the CT '{reference_volume.GetName()}' "
                        f"({describe_grid(ct_matrix, ct_extent)}); segments {', '.join(resampled)} were resampled "
                        "onto the CT's grid (nearest neighbour)")
    if outside:
        _warn(messages, f"{source}: segments {', '.join(outside)} lie outside the CT and stay empty")


def load_segmentation(scene, path, reference_volume, color_table=None, name=None, messages=None):
    """Load the user's segmentation onto ``reference_volume``'s grid; return the ``vtkMRMLSegmentationNode``.

    Args:
        scene: the MRML scene.
        path: a Slicer ``.seg.nrrd``, or a labelmap volume (NRRD, NIfTI,
            MetaImage) whose values are labels (0 background).
        reference_volume: the CT (``load_ct``) the segmentation belongs to.
        color_table: the labelmap's colour/name table (see ``read_color_table``);
            default: a table beside the labelmap with its base name, else
            segments are named ``Label <k>`` with a warning.
        name: the node's name (default: the file's base name).
        messages: optional list that receives warnings (strings).

    The segmentation's reference image geometry becomes the CT's and its
    binary labelmaps lie on the CT's voxel lattice: a segmentation on another
    grid is resampled (nearest neighbour) with a warning.

    Raises:
        InputError: a missing path, a file that is neither a segmentation nor
            a labelmap, a 2D labelmap, no labels, a bad colour table, or no
            overlap with the CT. The scene is left as it was.
    """
    import slicer

    path = Path(path).expanduser()
    name = name or _base_name(path)
    with _scene_transaction(scene):
        if not path.exists():
            raise InputError(path, "does not exist", f"Check the path; give {_LABELMAP_FORMATS}.")
        if path.is_dir() or not _has_extension(path, (SEGMENTATION_EXTENSION,) + VOLUME_EXTENSIONS):
            raise InputError(path, "is not a segmentation file this product reads", f"Give {_LABELMAP_FORMATS}.")
        if _has_extension(path, (SEGMENTATION_EXTENSION,)):
            _check_nrrd_readable(path)
            segmentation_node = scene.AddNewNodeByClass("vtkMRMLSegmentationNode", name)
            storage = slicer.vtkMRMLSegmentationStorageNode()
            scene.AddNode(storage)
            storage.SetFileName(str(path))
            segmentation_node.SetAndObserveStorageNodeID(storage.GetID())
            with _reader_log_quiet():
                ok = storage.ReadData(segmentation_node)
            if not ok:
                raise InputError(path, f"cannot be read as a Slicer segmentation ({_first_error(storage)})",
                                 f"Give {_LABELMAP_FORMATS}.")
            if segmentation_node.GetSegmentation().GetNumberOfSegments() == 0:
                raise InputError(path, "holds no segments", "Give the segmentation that holds the segments.")
        else:
            table_path = Path(color_table).expanduser() if color_table is not None else find_color_table(path)
            table = read_color_table(table_path) if table_path is not None else {}
            labelmap, warnings = _read_volume(scene, "vtkMRMLLabelMapVolumeNode", [path], name + "-labels", path)
            _check_is_volume(labelmap, path, "labelmap")
            for warning in warnings:
                _warn(messages, f"{path}: {warning}")
            labels = _labels_of(labelmap, path)
            color_node = labelmap_color_node(scene, labels, table, table_path or path, messages, name + "-names")
            segmentation_node = segmentation_from_labelmap(scene, labelmap, color_node, reference_volume, name)
            remove_nodes(scene, labelmap, color_node)
        _bring_onto_ct_grid(segmentation_node, reference_volume, path, messages)
        segmentation_node.SetReferenceImageGeometryParameterFromVolumeNode(reference_volume)
        segmentation_node.SetAttribute(SOURCE_PATH_ATTRIBUTE, str(path))
        segmentation_node.CreateDefaultDisplayNodes()
    return segmentation_node


# --------------------------------------------------------------------------- roles


def split_names(names):
    """A list of names from a list or a comma-separated string, blanks dropped."""
    if names is None:
        return []
    if isinstance(names, str):
        names = names.split(",")
    return [name.strip() for name in names if name and name.strip()]


def _name_key(name):
    """Names compare case-insensitively, with '_' as a space (Slicer's and many tools' tables write 'spinal_cord')."""
    return " ".join(name.replace("_", " ").lower().split())


def resolve_roles(segmentation_node, cuttable_names, protected_names):
    """Map the user's segment names (case-insensitive, '_' as ' '; segment IDs accepted too) to segment IDs.

    ``cuttable_names`` and ``protected_names`` are lists of names or one
    comma-separated string. Returns (cuttable_ids, protected_ids).

    Raises:
        InputError: a name matches no segment (the message lists the
            available names), matches several, or is in both lists.
    """
    segmentation = segmentation_node.GetSegmentation()
    source = segmentation_node.GetAttribute(SOURCE_PATH_ATTRIBUTE) or f"segmentation '{segmentation_node.GetName()}'"
    segment_ids = list(segmentation.GetSegmentIDs())
    by_name = {}
    for segment_id in segment_ids:
        by_name.setdefault(_name_key(segmentation.GetSegment(segment_id).GetName()), []).append(segment_id)
    available = ", ".join(f"'{segmentation.GetSegment(s).GetName()}'" for s in segment_ids) or "none"

    def resolve(name):
        if name in segment_ids:
            return name
        matches = by_name.get(_name_key(name), [])
        if not matches:
            raise InputError(source, f"has no segment named '{name}'",
                             f"Use one of its segment names: {available}.")
        if len(matches) > 1:
            raise InputError(source, f"has {len(matches)} segments named '{name}' ({', '.join(matches)})",
                             "Give their segment IDs instead, or rename them.")
        return matches[0]

    cuttable = list(dict.fromkeys(resolve(name) for name in split_names(cuttable_names)))
    protected = list(dict.fromkeys(resolve(name) for name in split_names(protected_names)))
    both = [segmentation.GetSegment(s).GetName() for s in cuttable if s in protected]
    if both:
        raise InputError(source, f"segment(s) {', '.join(repr(n) for n in both)} named both cuttable and protected",
                         "A segment is either cut or protected: name it in one list only.")
    return cuttable, protected
