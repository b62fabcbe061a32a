"""The scans a session is graded on, as label images: which segment each voxel is, and what each segment means.

The assessment needs, for the scan a recording was drilled on, the voxel grid
(to refuse a recording made on another scan), the segments with their roles
(what the drill may remove, which structures it must spare, what hides the
burr from the camera) and nothing of Slicer: a ``Scan`` is numpy arrays.
A recording names its scan by a descriptor (``Scan.descriptor``: a name, the
parameters that rebuild it, its grid); ``from_descriptor`` rebuilds the
shipped ones: the temporal-bone phantom, the head CT, the analytic box.

The head CT carries no anatomy segmentation: bone is thresholded as the
product's bone segmentation does (cortical from 700 HU, trabecular from
200 HU), and the structures at risk are tubes placed at fixed offsets from the
right mastoid's lateral surface, deeper than the shipped mastoidectomy goes:
a 3 mm facial canal about 4 mm beyond the saucer's floor and an 8 mm sigmoid
sinus posterior to it (the CT's voxels are about 1 x 1 x 1.5 mm). They are stand-ins for grading, not the patient's anatomy.

A user's own scan (``own_scan``) is their segmentation on their CT's grid,
the roles by the names they gave (``owndata.resolve_roles``): its descriptor
names the files, the roles and the segmentation file's sha256, and
``from_descriptor`` reads them again through Slicer's readers (MRML, no Qt),
refusing a segmentation file that changed since the session.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..data import headct, owndata, phantom
from ..scene import nodes


class ScanError(ValueError):
    """A scan that does not fit a recording (another grid) or that cannot be rebuilt; the message says both sides."""


@dataclass
class Scan:
    """A labelled voxel grid: ``labels[k, j, i]`` is 0 or a segment's label (its position in ``segment_names`` + 1)."""

    name: str
    parameters: dict
    labels: np.ndarray
    segment_names: list
    cuttable: tuple
    protected: tuple
    opaque: tuple  # segments that hide the burr from the camera while they remain
    ijk_to_ras: np.ndarray
    entry: np.ndarray | None = None  # where a mastoidectomy starts: the lateral bone surface (RAS mm), when known
    _cache: dict = field(default_factory=dict, repr=False, compare=False)

    @property
    def dimensions(self) -> tuple:
        """Voxel counts along i, j, k."""
        return tuple(int(n) for n in self.labels.shape[::-1])

    @property
    def spacing(self) -> np.ndarray:
        return np.linalg.norm(self.ijk_to_ras[:3, :3], axis=0)

    @property
    def voxel_volume_mm3(self) -> float:
        return float(abs(np.linalg.det(self.ijk_to_ras[:3, :3])))

    def label(self, name: str) -> int:
        return self.segment_names.index(name) + 1

    def grid(self) -> dict:
        return {"dimensions": list(self.dimensions), "ijk_to_ras": [round(float(v), 6) for v in self.ijk_to_ras.ravel()]}

    def descriptor(self) -> dict:
        """What a recording stores of its scan: the name, how to rebuild it, its grid."""
        return {"name": self.name, "parameters": self.parameters, "grid": self.grid()}

    def ras_to_ijk(self, points) -> np.ndarray:
        matrix = self._cache.get("ras_to_ijk")
        if matrix is None:
            matrix = self._cache["ras_to_ijk"] = np.linalg.inv(self.ijk_to_ras)
        points = np.asarray(points, dtype=float)
        return points @ matrix[:3, :3].T + matrix[:3, 3]

    def ijk_to_ras_points(self, ijk) -> np.ndarray:
        return np.asarray(ijk, dtype=float) @ self.ijk_to_ras[:3, :3].T + self.ijk_to_ras[:3, 3]

    def lookup(self, names) -> np.ndarray:
        """A table from label to whether that label is one of ``names``."""
        table = np.zeros(len(self.segment_names) + 1, dtype=bool)
        for name in names:
            if name in self.segment_names:
                table[self.label(name)] = True
        return table

    def surface_points(self, name: str) -> np.ndarray:
        """RAS centres of the segment's voxels that touch another segment (its surface), cached."""
        key = ("surface", name)
        if key not in self._cache:
            mask = self.labels == self.label(name)
            inner = mask.copy()
            for axis in range(3):
                for shift in (1, -1):
                    inner &= np.roll(mask, shift, axis=axis)
            # np.roll wraps around: voxels on the grid's border are surface too.
            for axis in range(3):
                index = [slice(None)] * 3
                index[axis] = 0
                inner[tuple(index)] = False
                index[axis] = -1
                inner[tuple(index)] = False
            self._cache[key] = self.ijk_to_ras_points(np.argwhere(mask & ~inner)[:, ::-1])
        return self._cache[key]


def describe_grid(grid: dict) -> str:
    dims = grid.get("dimensions")
    matrix = np.asarray(grid.get("ijk_to_ras", np.eye(4).ravel()), dtype=float).reshape(4, 4)
    spacing = np.linalg.norm(matrix[:3, :3], axis=0)
    return (f"{'x'.join(map(str, dims))} voxels of {'x'.join(f'{s:.3g}' for s in spacing)} mm, "
            f"voxel 0 at ({', '.join(f'{v:.2f}' for v in matrix[:3, 3])}) mm")


def same_grid(first: dict, second: dict) -> bool:
    return list(first.get("dimensions", [])) == list(second.get("dimensions", [])) and np.allclose(
        np.asarray(first["ijk_to_ras"], dtype=float), np.asarray(second["ijk_to_ras"], dtype=float), atol=1e-4)


def check_fits(scan: Scan, descriptor: dict | None, what: str) -> None:
    """Raise ScanError, both grids described, unless the recording's scan is ``scan``."""
    if descriptor is None:
        return
    grid = descriptor.get("grid")
    if descriptor.get("name") != scan.name or grid is None or not same_grid(grid, scan.grid()):
        theirs = f"'{descriptor.get('name')}' ({describe_grid(grid) if grid else 'no grid'})"
        raise ScanError(f"{what} was made on scan {theirs}, not on '{scan.name}' ({describe_grid(scan.grid())})")


# ---------------------------------------------------------------------------
# The shipped scans
# ---------------------------------------------------------------------------

PHANTOM_DEFAULTS = {"dimensions": [128, 128, 96], "spacing": [0.4, 0.4, 0.5], "seed": 0}


@functools.lru_cache(maxsize=2)
def _phantom(dimensions: tuple, spacing: tuple, seed: int) -> Scan:
    # Labels are taken at voxel centres whatever the scanner's blur (which only blends HU), and noise is HU only.
    generated = phantom.generate_phantom(dimensions=dimensions, spacing=spacing, seed=seed, noise_sigma=0.0)
    names = list(generated.segment_names)
    opaque = tuple(phantom.BONE_SEGMENTS) + tuple(phantom.PROTECTED_SEGMENTS)
    matrix = np.eye(4)
    matrix[:3, :3] = generated.direction * np.asarray(generated.spacing, dtype=float)[None, :]
    matrix[:3, 3] = generated.origin
    scan = Scan("phantom", {"dimensions": list(dimensions), "spacing": list(spacing), "seed": seed},
                generated.labelmap, names, tuple(s for s in phantom.CUTTABLE_SEGMENTS if s in names),
                tuple(s for s in phantom.PROTECTED_SEGMENTS if s in names), tuple(s for s in opaque if s in names), matrix)
    # As the main job aims: from the right, through the middle of the air cells' box, onto the first bone.
    cells = scan.ijk_to_ras_points(np.argwhere(generated.labelmap == scan.label("MastoidAirCells"))[:, ::-1])
    middle = (cells.min(axis=0) + cells.max(axis=0)) / 2.0
    bone = scan.lookup(phantom.BONE_SEGMENTS)[generated.labelmap].astype(np.int16) * int(HEAD_CT_CORTICAL_HU)
    scan.entry = lateral_entry(bone, matrix, middle[1], middle[2])
    return scan


def phantom_scan(dimensions=PHANTOM_DEFAULTS["dimensions"], spacing=PHANTOM_DEFAULTS["spacing"], seed=0) -> Scan:
    """The temporal-bone phantom as the main job and the web application generate it."""
    return _phantom(tuple(int(n) for n in dimensions), tuple(float(s) for s in spacing), int(seed))


HEAD_CT_CORTICAL_HU = 700.0
HEAD_CT_TRABECULAR_HU = 200.0
# Stand-in structures at risk, from the right mastoid's lateral surface (RAS mm offsets: depth along -x, posterior -y).
HEAD_CT_STRUCTURES = {
    # name: (offset of the tube's centre line from the entry, its direction, radius, half length)
    "FacialNerve": ((-19.0, -2.0, 0.0), (0.0, 0.0, 1.0), 1.5, 12.0),
    "SigmoidSinus": ((-10.0, -18.0, 0.0), (0.0, 0.0, 1.0), 4.0, 15.0),
}


def lateral_entry(array, ijk_to_ras, y: float, z: float, threshold: float = HEAD_CT_CORTICAL_HU) -> np.ndarray:
    """The first voxel at or above ``threshold`` met coming from the patient's right at (y, z), as ``drilling.lateral_entry``."""
    inverse = np.linalg.inv(ijk_to_ras)
    dims = array.shape[::-1]
    corners = np.array([[i, j, k] for i in (0, dims[0] - 1) for j in (0, dims[1] - 1) for k in (0, dims[2] - 1)], dtype=float)
    ras = corners @ ijk_to_ras[:3, :3].T + ijk_to_ras[:3, 3]
    for x in np.arange(ras[:, 0].max(), ras[:, 0].min(), -0.25):
        i, j, k = np.rint(inverse[:3, :3] @ [x, y, z] + inverse[:3, 3]).astype(int)
        if 0 <= i < dims[0] and 0 <= j < dims[1] and 0 <= k < dims[2] and array[k, j, i] >= threshold:
            return np.array([x, y, z])
    raise ScanError(f"no bone above {threshold} HU along x at y={y:.1f}, z={z:.1f} mm")


def _tube(points, start, end, radius) -> np.ndarray:
    axis = np.asarray(end, dtype=float) - start
    t = np.clip((points - start) @ axis / (axis @ axis), 0.0, 1.0)
    return np.linalg.norm(points - (start + t[:, None] * axis), axis=1) <= radius


@functools.lru_cache(maxsize=1)
def _head_ct() -> Scan:
    array, _, matrix = headct.load_array()
    labels = np.zeros(array.shape, dtype=np.uint8)
    labels[array >= HEAD_CT_TRABECULAR_HU] = 2
    labels[array >= HEAD_CT_CORTICAL_HU] = 1
    names = ["CorticalBone", "TrabecularBone"]
    entry = lateral_entry(array, matrix, *headct.RIGHT_MASTOID_YZ)
    inverse = np.linalg.inv(matrix)
    for name, (offset, direction, radius, half_length) in HEAD_CT_STRUCTURES.items():
        center = entry + np.asarray(offset)
        start, end = center - half_length * np.asarray(direction), center + half_length * np.asarray(direction)
        corners = np.array([start - radius, start + radius, end - radius, end + radius])
        ijk = corners @ inverse[:3, :3].T + inverse[:3, 3]
        low = np.maximum(np.floor(ijk.min(axis=0)).astype(int), 0)
        high = np.minimum(np.ceil(ijk.max(axis=0)).astype(int) + 1, array.shape[::-1])
        grid = np.stack(np.meshgrid(*(np.arange(low[a], high[a]) for a in range(3)), indexing="ij"), axis=-1).reshape(-1, 3)
        inside = grid[_tube(grid @ matrix[:3, :3].T + matrix[:3, 3], start, end, radius)]
        names.append(name)
        labels[inside[:, 2], inside[:, 1], inside[:, 0]] = len(names)
    protected = tuple(HEAD_CT_STRUCTURES)
    return Scan("headct", {}, labels, names, ("CorticalBone", "TrabecularBone"), protected,
                ("CorticalBone", "TrabecularBone") + protected, matrix, entry=entry)


def head_ct_scan() -> Scan:
    """Debian's head CT, bone thresholded, with the stand-in structures at risk of the module docstring."""
    return _head_ct()


def analytic_scan(dimensions=(40, 40, 40), spacing=0.5, bone_box=((2.0, 2.0, 2.0), (18.0, 18.0, 12.0)),
                  nerve_start=(2.0, 10.0, 15.0), nerve_end=(18.0, 10.0, 15.0), nerve_radius=1.0) -> Scan:
    """A box of bone with a protected cylinder (the nerve) above it, on an axis-aligned grid with voxel 0 at the origin.

    Everything is in mm; a voxel belongs to a shape when its centre does, so
    volumes, distances and removals can be counted by hand.
    """
    dims = np.asarray(dimensions, dtype=int)
    matrix = np.diag([spacing, spacing, spacing, 1.0])
    k, j, i = np.meshgrid(*(np.arange(n) for n in dims[::-1]), indexing="ij")
    centers = np.stack([i, j, k], axis=-1).reshape(-1, 3) * spacing
    low, high = np.asarray(bone_box, dtype=float)
    labels = np.zeros(dims[::-1], dtype=np.uint8).reshape(-1)
    labels[np.all((centers >= low) & (centers <= high), axis=1)] = 1
    labels[_tube(centers, np.asarray(nerve_start, dtype=float), np.asarray(nerve_end, dtype=float), nerve_radius)] = 2
    parameters = {"dimensions": dims.tolist(), "spacing": spacing, "bone_box": np.asarray(bone_box).tolist(),
                  "nerve_start": list(nerve_start), "nerve_end": list(nerve_end), "nerve_radius": nerve_radius}
    return Scan("analytic", parameters, labels.reshape(dims[::-1]), ["Bone", "Nerve"], ("Bone",), ("Nerve",), ("Bone", "Nerve"), matrix)


# ---------------------------------------------------------------------------
# The user's own scan
# ---------------------------------------------------------------------------

OWN = "own"


def file_sha256(path) -> str:
    import hashlib

    digest = hashlib.sha256()
    with open(path, "rb") as stream:
        for block in iter(lambda: stream.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def _segment_mask(segment, ct_to_ras: np.ndarray, shape) -> np.ndarray:
    """The segment's voxels on the CT's grid (``[k, j, i]``); its labelmap lies on the CT's lattice (``owndata``)."""
    import slicer
    import vtk

    mask = np.zeros(shape, dtype=bool)
    image = segment.GetRepresentation(slicer.vtkSegmentationConverter.GetBinaryLabelmapRepresentationName())
    if image is None:
        return mask
    extent = image.GetExtent()
    if extent[1] < extent[0] or extent[3] < extent[2] or extent[5] < extent[4]:
        return mask
    matrix = vtk.vtkMatrix4x4()
    image.GetImageToWorldMatrix(matrix)
    to_ct = np.linalg.inv(ct_to_ras) @ nodes.vtk_matrix_to_numpy(matrix)
    offset = np.rint(to_ct[:3, 3]).astype(int)
    if not np.allclose(to_ct[:3, :3], np.eye(3), atol=1e-3) or not np.allclose(to_ct[:3, 3], offset, atol=1e-3):
        raise ScanError(f"segment '{segment.GetName()}' is not on the CT's voxel grid")
    values = nodes.array_from_image_data(image) == segment.GetLabelValue()
    low = np.array(extent[0::2]) + offset  # i, j, k of the image's first voxel on the CT
    high = low + np.array(values.shape[::-1])
    clipped_low, clipped_high = np.maximum(low, 0), np.minimum(high, np.array(shape[::-1]))
    if np.any(clipped_high <= clipped_low):
        return mask
    source = values[tuple(slice(a - l, b - l) for a, b, l in zip(clipped_low[::-1], clipped_high[::-1], low[::-1]))]
    mask[tuple(slice(a, b) for a, b in zip(clipped_low[::-1], clipped_high[::-1]))] = source
    return mask


def own_scan(volume_node, segmentation_node, cuttable_ids, protected_ids, parameters: dict | None = None) -> Scan:
    """The user's scan as the assessment grades it: their segments on the CT's grid, with the roles given.

    Segments are named as the product shows them (``segment_display_names``).
    Where segments overlap a voxel is the protected one's, else the cuttable
    one's. Cuttable and protected segments hide the burr from the camera.
    """
    segmentation = segmentation_node.GetSegmentation()
    ids = list(segmentation.GetSegmentIDs())
    names = nodes.segment_display_names(segmentation, ids)
    ct_to_ras = nodes.volume_node_ijk_to_ras(volume_node)
    shape = tuple(volume_node.GetImageData().GetDimensions())[::-1]
    labels = np.zeros(shape, dtype=np.uint16 if len(ids) >= 255 else np.uint8)
    ranked = [s for s in ids if s not in cuttable_ids and s not in protected_ids] + list(cuttable_ids) + list(protected_ids)
    for segment_id in ranked:
        labels[_segment_mask(segmentation.GetSegment(segment_id), ct_to_ras, shape)] = ids.index(segment_id) + 1
    cuttable = tuple(names[s] for s in cuttable_ids)
    protected = tuple(names[s] for s in protected_ids)
    return Scan(OWN, dict(parameters or {}), labels, [names[s] for s in ids], cuttable, protected, cuttable + protected, ct_to_ras)


def own_descriptor(volume_node, segmentation_node, cuttable_ids, protected_ids, ct, segmentation, color_table=None) -> dict:
    """What a recording on the user's scan says of it: the files, the roles by name, the segmentation's sha256, the grid."""
    names = nodes.segment_display_names(segmentation_node.GetSegmentation(), segmentation_node.GetSegmentation().GetSegmentIDs())
    ct_to_ras = nodes.volume_node_ijk_to_ras(volume_node)
    return {"name": OWN, "parameters": {
        "ct": str(Path(ct).resolve()), "segmentation": str(Path(segmentation).resolve()),
        "color_table": str(Path(color_table).resolve()) if color_table else None,
        "segmentation_sha256": file_sha256(segmentation),
        "cuttable": [names[s] for s in cuttable_ids], "protected": [names[s] for s in protected_ids]},
        "grid": {"dimensions": list(volume_node.GetImageData().GetDimensions()),
                 "ijk_to_ras": [round(float(v), 6) for v in ct_to_ras.ravel()]}}


def _own_from_files(parameters: dict) -> Scan:
    """Read the user's CT and segmentation again (a fresh MRML scene) and build their scan."""
    import slicer

    needed = [key for key in ("ct", "segmentation", "cuttable", "protected") if key not in parameters]
    if needed:
        raise ScanError(f"the recording's own scan does not say its {', '.join(needed)}")
    segmentation_path = Path(parameters["segmentation"])
    if not segmentation_path.is_file():
        raise ScanError(f"the recording's segmentation {segmentation_path} is no longer there: the session cannot be graded "
                        "without the segmentation it was drilled on")
    if parameters.get("segmentation_sha256") and file_sha256(segmentation_path) != parameters["segmentation_sha256"]:
        raise ScanError(f"the segmentation {segmentation_path} changed since the session (its sha256 differs from the one "
                        "the recording keeps): grade it on the segmentation it was drilled on")
    scene = slicer.vtkMRMLScene()
    try:
        volume = owndata.load_ct(scene, parameters["ct"], choose_series=True)
        segmentation = owndata.load_segmentation(scene, segmentation_path, volume, color_table=parameters.get("color_table"))
        cuttable, protected = owndata.resolve_roles(segmentation, parameters["cuttable"], parameters["protected"])
        return own_scan(volume, segmentation, cuttable, protected, parameters)
    except owndata.InputError as error:
        raise ScanError(f"the recording's own scan cannot be read again: {error}") from None
    finally:
        scene.Clear(True)


def from_descriptor(descriptor: dict | None) -> Scan:
    """Rebuild the scan a recording names; ScanError when it names none or one that cannot be rebuilt here."""
    if not descriptor:
        raise ScanError("the recording does not name its scan (a version 1 recording): say which with --scan phantom|headct")
    name, parameters = descriptor.get("name"), descriptor.get("parameters") or {}
    if name == "phantom":
        scan = phantom_scan(**{key: parameters[key] for key in ("dimensions", "spacing", "seed") if key in parameters})
    elif name == "headct":
        scan = head_ct_scan()
    elif name == "analytic":
        scan = analytic_scan(**parameters)
    elif name == OWN:
        scan = _own_from_files(parameters)
    else:
        raise ScanError(f"the recording's scan '{name}' cannot be rebuilt here (known: phantom, headct, analytic, own)")
    check_fits(scan, descriptor, "the recording")
    return scan


def by_name(name: str) -> Scan:
    """A shipped scan by its name on the command line."""
    if name == "phantom":
        return phantom_scan()
    if name == "headct":
        return head_ct_scan()
    raise ScanError(f"no shipped scan is called '{name}' (phantom, headct)")
