"""A high-resolution right temporal bone, segmented slice by slice as real ones are.

Real temporal-bone data that users bring is a CT of 0.1-0.2 mm voxels and a
labelmap drawn by hand: each axial slice's structures outlined as 2D contours
and filled, one slice independently of the next, so the labels climb in
staircases between slices and a thin structure wobbles from slice to slice.
This case stands in for such data (issue 28's cadaver case: 0.19 mm, 16
structures):

* the anatomy: 14 structures of a right temporal bone from the analytic
  primitives of ``phantom`` (canonical frame: +x lateral, +y anterior,
  +z superior, mm): mastoid bone with air cells, tympanic cavity, ear canal,
  malleus, incus, stapes, labyrinth (cochlea and semicircular canals in
  their otic capsule), facial nerve (a curved canal: tympanic segment,
  second genu, mastoid segment), chorda tympani, sigmoid sinus, dura,
  carotid artery and internal auditory canal;
* the labelmap: per axial slice and structure, the structure's section
  moved and scaled by a small random amount (the hand's tremor, seeded),
  rasterised at the slice's pixel centres; later structures overwrite
  earlier ones (``STRUCTURES`` is in increasing precedence);
* the CT: pseudo-HU from the labels (with the bony walls of the canals and
  the fluid of the labyrinth, which no label names), partial volume by a
  Gaussian of ``PARTIAL_VOLUME_SIGMA_VOXELS`` over the label boundaries, and
  Gaussian noise; int16, seeded: the same arguments give the same arrays.

``write_case`` writes it as a user brings it (``ct.nrrd``, ``labels.nrrd``,
``labels.ctbl``); ``cached_case_files`` keeps one copy in the download cache;
``load_case`` loads it through ``owndata`` as the main job and the
application do, with the roles below.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import phantom

DIMENSIONS = (288, 288, 288)
SPACING = 0.15
# IJK-to-RAS directions (columns i, j, k): stored LPS as scanners write it.
DIRECTIONS = np.diag([-1.0, -1.0, 1.0])
SEED = 28
# The hand's tremor between slices, standard deviations in pixels: the contour's shift, and how far it grows
# or shrinks (as a scaling about the structure's centre).
CONTOUR_SHIFT_PIXELS = 0.35
CONTOUR_GROWTH_PIXELS = 0.3
PARTIAL_VOLUME_SIGMA_VOXELS = 0.6
NOISE_HU = 25.0
HU_AIR = -1000.0
HU_SOFT_TISSUE = 35.0
# Lateral to the skin (canonical x) is the air around the head.
SKIN_X_MM = 18.0
# Bump when the generated data changes, so that cached copies are rebuilt.
CASE_VERSION = 1


@dataclass(frozen=True)
class Structure:
    """One structure: its label name, colour (0-255), HU, role and analytic parts (canonical mm)."""

    name: str
    color: tuple
    hu: float
    role: str  # "cuttable", "protected" or "none"
    parts: tuple


def _turned_about_z(angle):
    """Rows: the x and y axes turned by ``angle`` about z, and z."""
    c, s = math.cos(angle), math.sin(angle)
    return [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]


def _facial_arc(minor_radius):
    """The facial nerve's second genu and mastoid segment: a quarter circle in the sagittal plane."""
    return phantom.TorusArc(center=(-3.0, -1.0, -9.0), normal=(1.0, 0.0, 0.0), start_direction=(0.0, 0.0, 1.0),
                            major_radius=8.0, minor_radius=minor_radius, sweep_angle=math.pi / 2.0)


def _facial_parts(radius):
    """Tympanic segment (from the geniculate ganglion posteriorly above the oval window), genu, mastoid segment."""
    arc = _facial_arc(radius)
    top = arc.end_points[0]  # (-3, -1, -1): the second genu's start
    return (phantom.Capsule((-6.0, 9.0, 0.0), top, radius), arc,
            phantom.Capsule(arc.end_points[1], arc.end_points[1] + np.array([0.5, 0.0, -8.0]), radius))


def _air_cells(rng) -> tuple:
    """Mastoid air cells: seeded spheres in the posterior-lateral mastoid, clear of the sinus and the canals."""
    cells = [phantom.Sphere((3.0, 1.0, 5.0), 2.8)]  # the antrum
    bone = phantom.Ellipsoid((0.0, -4.0, -2.0), (13.5, 17.5, 12.5))
    keep_out = (phantom.Capsule((-9.0, -14.0, 10.0), (-7.0, -10.0, -16.0), 5.5),
                *_facial_parts(2.5), phantom.Capsule((20.0, 4.0, -2.0), (0.5, 5.5, -1.5), 5.0))
    while len(cells) < 45:
        center = rng.uniform((-4.0, -19.0, -14.0), (12.0, 2.0, 9.0))
        radius = float(rng.uniform(0.7, 2.2))
        points = center[None, :]
        if not bone.contains(points)[0] or bone.signed_distance(points)[0] > -radius - 1.0:
            continue
        if any(part.signed_distance(points)[0] < radius for part in keep_out):
            continue
        cells.append(phantom.Sphere(center, radius))
    return tuple(cells)


def structures(seed: int = SEED) -> tuple:
    """The case's structures in increasing precedence (label = position + 1)."""
    rng = np.random.default_rng(seed)
    cochlea_axis = np.array([-1.0, 1.0, 0.3]) / np.linalg.norm([-1.0, 1.0, 0.3])
    labyrinth = (
        phantom.Torus((-9.0, 10.5, -3.0), cochlea_axis, 2.6, 1.1),  # basal turn
        phantom.Torus((-9.8, 11.3, -2.8), cochlea_axis, 1.5, 0.8),  # middle and apical turns
        phantom.Sphere((-8.0, 5.0, 0.0), 1.8),  # vestibule
        phantom.Torus((-8.0, 2.0, 1.5), (0.0, 0.0, 1.0), 2.8, 0.6),  # lateral canal
        phantom.Torus((-10.0, 6.0, 5.0), (0.0, 1.0, 0.0), 3.0, 0.6),  # superior canal
        phantom.Torus((-11.5, -1.5, 3.0), (1.0, 0.0, 0.0), 3.0, 0.6),  # posterior canal
    )
    return (
        Structure("Mastoid bone", (241, 214, 145), 1150.0, "cuttable", (
            phantom.Ellipsoid((0.0, -4.0, -2.0), (15.0, 19.0, 14.0)),
            # The petrous ridge, running anteromedially.
            phantom.Ellipsoid((-12.0, 9.0, -1.0), (13.0, 6.5, 6.5), axes=_turned_about_z(-math.pi / 4.0)),
        )),
        Structure("Mastoid air cells", (128, 174, 128), -900.0, "cuttable", _air_cells(rng)),
        Structure("Dura", (255, 180, 140), 45.0, "protected", (
            phantom.Box((-4.0, 0.0, 12.8), (20.0, 22.0, 0.5)),  # middle fossa dura, on the tegmen
            phantom.Box((-13.5, -6.0, 0.0), (0.5, 12.0, 12.0)),  # posterior fossa dura
        )),
        Structure("Sigmoid sinus", (0, 151, 206), 50.0, "protected", (
            phantom.Capsule((-9.0, -14.0, 10.0), (-7.0, -11.0, -4.0), 3.2),
            phantom.Capsule((-7.0, -11.0, -4.0), (-9.0, -6.0, -18.0), 3.2),
        )),
        Structure("Tympanic cavity", (200, 230, 255), HU_AIR, "none", (
            phantom.Ellipsoid((-2.0, 6.0, -1.0), (2.4, 5.0, 5.5)),
        )),
        Structure("External ear canal", (180, 210, 255), HU_AIR, "protected", (
            phantom.Capsule((24.0, 4.0, -2.0), (2.0, 5.5, -1.5), 3.4),
        )),
        Structure("Internal auditory canal", (170, 130, 230), 15.0, "protected", (
            phantom.Capsule((-9.5, 7.0, 0.5), (-24.0, 9.0, 1.0), 2.0),
        )),
        Structure("Carotid artery", (216, 101, 79), 45.0, "protected", (
            phantom.Capsule((-5.0, 15.0, -24.0), (-6.5, 14.0, -8.0), 2.6),
            phantom.Capsule((-6.5, 14.0, -8.0), (-16.0, 21.0, -3.0), 2.6),
        )),
        Structure("Labyrinth", (255, 250, 220), 1900.0, "protected", labyrinth),
        Structure("Facial nerve", (244, 214, 49), 40.0, "protected", _facial_parts(0.8)),
        Structure("Chorda tympani", (250, 170, 50), 40.0, "protected", (
            phantom.Capsule((-2.4, -2.0, -13.0), (-0.5, 2.0, -5.0), 0.3),
            phantom.Capsule((-0.5, 2.0, -5.0), (-0.8, 5.0, -2.5), 0.3),
        )),
        Structure("Malleus", (250, 250, 225), 1700.0, "protected", (
            phantom.Capsule((-0.8, 7.5, 2.5), (-0.3, 7.0, -3.0), 0.55),  # head to manubrium
            phantom.Sphere((-1.0, 7.6, 2.8), 1.1),
        )),
        Structure("Incus", (230, 220, 180), 1700.0, "protected", (
            phantom.Ellipsoid((-2.5, 5.2, 2.5), (1.1, 1.5, 1.2)),
            phantom.Capsule((-2.5, 5.0, 1.5), (-2.8, 5.4, -1.6), 0.4),  # long process
        )),
        Structure("Stapes", (255, 200, 150), 1700.0, "protected", (
            phantom.Capsule((-2.9, 5.5, -1.9), (-4.6, 5.6, -2.2), 0.45),
        )),
    )


def _material_layers() -> tuple:
    """HU of what no label names, painted before the labels: the bony walls of canals and vessels, the labyrinth's fluid.

    Rows: (HU, parts); painted right after the air cells, so every later structure lies over them.
    """
    return (
        (1600.0, tuple(phantom.Capsule(c.point0, c.point1, c.radius + 0.6) for c in (
            phantom.Capsule((-5.0, 15.0, -24.0), (-6.5, 14.0, -8.0), 2.6),
            phantom.Capsule((-6.5, 14.0, -8.0), (-16.0, 21.0, -3.0), 2.6)))),
        (1500.0, _facial_parts(1.4)),
    )


LABYRINTH_LUMEN_HU = 10.0


def _lumen_parts(labyrinth):
    """The fluid spaces inside the otic capsule: the same tubes, thinner."""
    parts = []
    for part in labyrinth:
        if isinstance(part, phantom.Torus):
            parts.append(phantom.Torus(part.center, part.normal, part.major_radius, 0.45 * part.minor_radius))
        else:
            parts.append(phantom.Sphere(part.center, 0.6 * part.radius))
    return tuple(parts)


@dataclass
class TemporalBoneCase:
    """The case as arrays indexed [k, j, i]: CT in HU (int16), labels (uint8), geometry, structures."""

    ct: np.ndarray
    labels: np.ndarray
    ijk_to_ras: np.ndarray
    structures: tuple

    @property
    def names(self) -> dict:
        return {label: structure.name for label, structure in enumerate(self.structures, start=1)}

    @property
    def spacing(self) -> tuple:
        return tuple(float(np.linalg.norm(self.ijk_to_ras[:3, axis])) for axis in range(3))


def ijk_to_ras_matrix(dimensions=DIMENSIONS, spacing=SPACING) -> np.ndarray:
    """The IJK-to-RAS matrix of the grid, centred on the RAS origin (the canonical frame's)."""
    matrix = np.eye(4)
    matrix[:3, :3] = DIRECTIONS * float(spacing)
    matrix[:3, 3] = -matrix[:3, :3] @ ((np.asarray(dimensions, dtype=float) - 1.0) / 2.0)
    return matrix


class _SliceRasteriser:
    """Fills 2D sections of analytic parts into one axial slice at a time, only within the parts' boxes."""

    def __init__(self, dimensions, ijk_to_ras):
        self.dimensions = dimensions
        self.ijk_to_ras = ijk_to_ras
        # The grid is axis-aligned: i moves x, j moves y, k moves z.
        self.x = ijk_to_ras[0, 0] * np.arange(dimensions[0]) + ijk_to_ras[0, 3]
        self.y = ijk_to_ras[1, 1] * np.arange(dimensions[1]) + ijk_to_ras[1, 3]
        self.z = ijk_to_ras[2, 2] * np.arange(dimensions[2]) + ijk_to_ras[2, 3]
        self.pixel = (abs(ijk_to_ras[0, 0]), abs(ijk_to_ras[1, 1]))

    @staticmethod
    def _index_range(coordinates, lower, upper):
        inside = np.nonzero((coordinates >= lower) & (coordinates <= upper))[0]
        return (int(inside[0]), int(inside[-1]) + 1) if inside.size else (0, 0)

    def section(self, parts, k, shift, scale):
        """The union of parts in slice k as drawn by a hand: (j range, i range, mask) or None when empty.

        The drawn contour is the true section moved by ``shift`` (mm) and
        scaled by ``scale`` about the parts' centre.
        """
        z = self.z[k]
        lower = np.min([part.bounds[0] for part in parts], axis=0)
        upper = np.max([part.bounds[1] for part in parts], axis=0)
        if not lower[2] <= z <= upper[2]:
            return None
        center = 0.5 * (lower + upper)
        margin = (upper - lower) * abs(scale - 1.0) + np.abs(np.append(shift, 0.0)) + max(self.pixel)
        i0, i1 = self._index_range(self.x, lower[0] - margin[0] + shift[0], upper[0] + margin[0] + shift[0])
        j0, j1 = self._index_range(self.y, lower[1] - margin[1] + shift[1], upper[1] + margin[1] + shift[1])
        if i0 == i1 or j0 == j1:
            return None
        yy, xx = np.meshgrid(self.y[j0:j1], self.x[i0:i1], indexing="ij")
        # A drawn point p is inside when the true section holds c + (p - shift - c) / scale.
        points = np.stack([center[0] + (xx - shift[0] - center[0]) / scale,
                           center[1] + (yy - shift[1] - center[1]) / scale,
                           np.full(xx.shape, z)], axis=-1).reshape(-1, 3)
        mask = np.zeros(len(points), dtype=bool)
        for part in parts:
            candidates = phantom._points_in_box(points, *part.bounds)
            if candidates.size:
                mask[candidates[part._contains(points[candidates])]] = True
        if not mask.any():
            return None
        return (j0, j1), (i0, i1), mask.reshape(xx.shape)


def _gaussian_blur(volume: np.ndarray, sigma: float) -> np.ndarray:
    """Separable Gaussian (in voxels) along the three axes, edges repeated: the scanner's partial volume."""
    radius = max(1, int(math.ceil(3.0 * sigma)))
    taps = np.exp(-0.5 * (np.arange(-radius, radius + 1) / sigma) ** 2)
    taps /= taps.sum()
    result = volume.astype(np.float32)
    for axis in range(3):
        padded = np.pad(result, [(radius, radius) if a == axis else (0, 0) for a in range(3)], mode="edge")
        blurred = np.zeros_like(result)
        length = result.shape[axis]
        for offset, weight in enumerate(taps):
            blurred += np.float32(weight) * np.take(padded, np.arange(offset, offset + length), axis=axis)
        result = blurred
    return result


def generate(dimensions=DIMENSIONS, spacing=SPACING, seed: int = SEED) -> TemporalBoneCase:
    """Build the case (see the module docstring); the same arguments give the same arrays.

    Raises ValueError for a grid that is not three positive sizes or a spacing that is not positive.
    """
    dimensions = tuple(int(n) for n in dimensions)
    if len(dimensions) != 3 or min(dimensions) < 8:
        raise ValueError(f"dimensions must be three sizes of at least 8 voxels, got {dimensions!r}")
    if not (math.isfinite(spacing) and spacing > 0.0):
        raise ValueError(f"spacing must be a positive number of mm, got {spacing!r}")
    table = structures(seed)
    ijk_to_ras = ijk_to_ras_matrix(dimensions, spacing)
    rasteriser = _SliceRasteriser(dimensions, ijk_to_ras)
    rng = np.random.default_rng([seed, 1])
    nk, nj, ni = dimensions[2], dimensions[1], dimensions[0]
    labels = np.zeros((nk, nj, ni), dtype=np.uint8)
    hu = np.full((nk, nj, ni), HU_SOFT_TISSUE, dtype=np.float32)
    hu[:, :, rasteriser.x > SKIN_X_MM] = HU_AIR
    hu_of_label = np.array([0.0] + [s.hu for s in table], dtype=np.float32)
    layers = _material_layers()
    lumen = _lumen_parts(next(s for s in table if s.name == "Labyrinth").parts)
    # Draw order: labels in precedence; the unlabelled walls right after the bone (under every structure),
    # the labyrinth's fluid after the labyrinth.
    plan = []
    for label, structure in enumerate(table, start=1):
        plan.append(("label", label, structure.parts))
        if structure.name == "Mastoid air cells":
            plan += [("hu", value, parts) for value, parts in layers]
        if structure.name == "Labyrinth":
            plan.append(("hu", LABYRINTH_LUMEN_HU, lumen))
    pixel = np.array(rasteriser.pixel)
    # In-plane half size of each contour's parts, which turns growth into a scale.
    half_sizes = np.array([0.25 * (np.max([p.bounds[1][:2] for p in parts], axis=0)
                                   - np.min([p.bounds[0][:2] for p in parts], axis=0)).sum() for _, _, parts in plan])
    for k in range(nk):
        # One tremor per slice and contour, drawn whether or not the contour meets the slice (reproducible).
        shifts = rng.normal(0.0, CONTOUR_SHIFT_PIXELS, size=(len(plan), 2)) * pixel
        scales = 1.0 + rng.normal(0.0, CONTOUR_GROWTH_PIXELS, size=len(plan)) * pixel.mean() / half_sizes
        hu_slice, label_slice = hu[k], labels[k]
        for (kind, value, parts), shift, scale in zip(plan, shifts, scales):
            section = rasteriser.section(parts, k, shift, scale)
            if section is None:
                continue
            (j0, j1), (i0, i1), mask = section
            if kind == "label":
                label_slice[j0:j1, i0:i1][mask] = value
                hu_slice[j0:j1, i0:i1][mask] = hu_of_label[value]
            else:
                hu_slice[j0:j1, i0:i1][mask] = value
    noise = np.random.default_rng([seed, 2]).normal(0.0, NOISE_HU, size=hu.shape).astype(np.float32)
    ct = _gaussian_blur(hu, PARTIAL_VOLUME_SIGMA_VOXELS) + noise
    ct = np.clip(np.rint(ct), -1024, 3071).astype(np.int16)
    return TemporalBoneCase(ct=ct, labels=labels, ijk_to_ras=ijk_to_ras, structures=table)


def color_table(table=None) -> dict:
    """Names and colours in ``owndata.read_color_table``'s form: ``{label: (name, rgba 0..1)}``."""
    table = structures() if table is None else table
    return {label: (s.name, (*(c / 255.0 for c in s.color), 1.0)) for label, s in enumerate(table, start=1)}


def roles(table=None) -> tuple[list, list]:
    """(cuttable names, protected names) of the structures."""
    table = structures() if table is None else table
    return ([s.name for s in table if s.role == "cuttable"], [s.name for s in table if s.role == "protected"])


def write_case(case: TemporalBoneCase, folder) -> dict:
    """Write the case into ``folder`` as ``ct.nrrd``, ``labels.nrrd`` and ``labels.ctbl``; return those paths."""
    import slicer

    from ..scene import nodes
    from . import patientscale

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    scene = slicer.vtkMRMLScene()
    volume = nodes.create_scalar_volume_node(scene, case.ct, case.ijk_to_ras, "TemporalBoneCT")
    labelmap = scene.AddNewNodeByClass("vtkMRMLLabelMapVolumeNode", "labels")
    labelmap.SetAndObserveImageData(nodes.image_data_from_array(case.labels))
    labelmap.SetIJKToRASMatrix(nodes.numpy_to_vtk_matrix(case.ijk_to_ras))
    paths = {
        "ct": patientscale._write_storable(scene, volume, "vtkMRMLVolumeArchetypeStorageNode", folder / "ct.nrrd", True),
        "labels": patientscale._write_storable(scene, labelmap, "vtkMRMLVolumeArchetypeStorageNode",
                                               folder / "labels.nrrd", True),
        "colors": patientscale.write_color_table(folder / "labels.ctbl", color_table(case.structures)),
    }
    return paths


def cache_root() -> Path:
    """``$VOLUMECUTTING_CACHE`` (default ``${XDG_CACHE_HOME:-~/.cache}/volumecutting``)/temporalbone."""
    from . import headct

    return headct.default_cache_dir().parent / "temporalbone"


def cached_case_files(dimensions=DIMENSIONS, spacing=SPACING, seed: int = SEED) -> dict:
    """The case written once under ``cache_root()`` (a folder per grid and seed); return its paths.

    A folder is reused only when its stamp, written last, names files that
    exist; otherwise the case is generated and written again.
    """
    key = json.dumps([CASE_VERSION, [int(n) for n in dimensions], round(float(spacing), 6), int(seed)])
    folder = cache_root() / hashlib.sha256(key.encode()).hexdigest()[:16]
    stamp = folder / "complete.json"
    if stamp.is_file():
        written = json.loads(stamp.read_text())
        if all(Path(written.get(name, "")).is_file() for name in ("ct", "labels", "colors")):
            return {name: Path(written[name]) for name in ("ct", "labels", "colors")}
    if stamp.exists():
        stamp.unlink()
    paths = write_case(generate(dimensions, spacing, seed), folder)
    stamp.write_text(json.dumps({"key": json.loads(key), **{n: str(p) for n, p in paths.items()}}, indent=2))
    return paths


def load_case(scene, paths, messages=None):
    """Load written case files through ``owndata`` as a user's data; return (CT, segmentation, cuttable IDs, protected IDs)."""
    from . import owndata

    volume = owndata.load_ct(scene, paths["ct"], name="TemporalBoneCT", messages=messages)
    segmentation = owndata.load_segmentation(scene, paths["labels"], volume, color_table=paths["colors"],
                                             name="TemporalBoneSegmentation", messages=messages)
    cuttable_names, protected_names = roles()
    cuttable, protected = owndata.resolve_roles(segmentation, cuttable_names, protected_names)
    return volume, segmentation, cuttable, protected
