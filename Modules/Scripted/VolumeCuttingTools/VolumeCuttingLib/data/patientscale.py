"""The patient-scale test case: a chest-CT-sized scan and long segments, made from the real head CT.

Real scans that users bring are larger and less regular than the shipped head
CT: 512 x 512 voxels a slice, slices 2-3 mm apart, an axis flipped in the
IJK-to-RAS, and automatic segmentations with long thin structures through
the whole scan. Without such a scan in the repository, this case stands in
for one (the chest CT of issue 11: 512 x 512 x 133 voxels of 0.70 x 0.70 x
2.5 mm, x flipped; three vertebrae cuttable, spinal cord and aorta protected):

* the CT: the real head CT (``headct``) resampled with ``vtkImageReslice``
  (linear) onto that grid, centred on the same RAS origin, -1000 HU (air)
  wherever the head does not reach;
* the segmentation, as an automatic tool labels it (one label a voxel):
  ``Spinal cord``, a tube of radius 5 mm along the z axis, and ``Aorta``, a
  tube of radius 10 mm along a curve, both through the whole volume and
  meant to be protected; ``Vertebra 1..3``, the bone (>= 200 HU) outside
  them, split into three slabs along z, meant to be cuttable.

``create_nodes`` puts the case into a scene; ``write_case`` writes it as a
user would receive it (NRRD, NIfTI, a DICOM series, a Slicer ``.seg.nrrd``,
a labelmap with its colour table); ``cached_case_files`` keeps one written
copy under the download cache (``$VOLUMECUTTING_CACHE``, default
``~/.cache/volumecutting``), never in the repository.
"""

from __future__ import annotations

import hashlib
import json
import shutil
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..scene import nodes

DIMENSIONS = (512, 512, 133)
SPACING = (0.70, 0.70, 2.5)
# IJK-to-RAS directions (columns i, j, k): i runs to the patient's left.
DIRECTIONS = np.diag([-1.0, 1.0, 1.0])
AIR_HU = -1000
BONE_HU = 200.0
SPINAL_CORD_RADIUS = 5.0
SPINAL_CORD_XY = (0.0, -25.0)  # RAS mm: behind the centre of the head, where the brainstem runs
AORTA_RADIUS = 10.0

LABELS = {1: "Vertebra 1", 2: "Vertebra 2", 3: "Vertebra 3", 4: "Spinal cord", 5: "Aorta"}
COLORS = {1: (241, 214, 145), 2: (230, 200, 120), 3: (216, 186, 110), 4: (244, 214, 49), 5: (216, 101, 79)}
CUTTABLE = ("Vertebra 1", "Vertebra 2", "Vertebra 3")
PROTECTED = ("Spinal cord", "Aorta")
FORMATS = ("nrrd", "nifti", "dicom", "seg.nrrd", "labelmap")
# Bump when the generated data changes, so that cached copies are rebuilt.
CASE_VERSION = 1


@dataclass
class PatientScaleCase:
    """The case as arrays indexed [k, j, i]: CT in HU (int16), labels (uint8, see ``LABELS``), geometry."""

    ct: np.ndarray
    labels: np.ndarray
    ijk_to_ras: np.ndarray


def ijk_to_ras_matrix(dimensions=DIMENSIONS, spacing=SPACING, directions=DIRECTIONS) -> np.ndarray:
    """The IJK-to-RAS matrix of a grid centred on the RAS origin."""
    matrix = np.eye(4)
    matrix[:3, :3] = np.asarray(directions, dtype=float) * np.asarray(spacing, dtype=float)[None, :]
    center = (np.asarray(dimensions, dtype=float) - 1.0) / 2.0
    matrix[:3, 3] = -matrix[:3, :3] @ center
    return matrix


def resample(array_kji, ijk_to_ras, dimensions, target_ijk_to_ras, background=AIR_HU) -> np.ndarray:
    """Resample a volume onto another grid with ``vtkImageReslice`` (linear), ``background`` outside it."""
    import vtk

    source = nodes.image_data_from_array(array_kji)
    reslice = vtk.vtkImageReslice()
    reslice.SetInputData(source)
    # Both images in index space: output IJK -> RAS -> source IJK.
    reslice.SetResliceAxes(nodes.numpy_to_vtk_matrix(np.linalg.inv(ijk_to_ras) @ target_ijk_to_ras))
    reslice.SetOutputOrigin(0.0, 0.0, 0.0)
    reslice.SetOutputSpacing(1.0, 1.0, 1.0)
    reslice.SetOutputExtent(0, dimensions[0] - 1, 0, dimensions[1] - 1, 0, dimensions[2] - 1)
    reslice.SetInterpolationModeToLinear()
    reslice.SetBackgroundLevel(float(background))
    reslice.Update()
    return nodes.array_from_image_data(reslice.GetOutput()).astype(array_kji.dtype, copy=False)


def aorta_center(z: np.ndarray, z_range) -> np.ndarray:
    """Centre (x, y) in RAS mm of the aorta-like curve at heights ``z``: a smooth S through the volume."""
    t = (np.asarray(z, dtype=float) - z_range[0]) / max(z_range[1] - z_range[0], 1e-9)
    x = 35.0 + 15.0 * np.sin(2.0 * np.pi * t)
    y = 30.0 - 50.0 * t + 10.0 * np.cos(np.pi * t)
    return np.stack([x, y], axis=-1)


def make_labels(ct: np.ndarray, ijk_to_ras: np.ndarray) -> np.ndarray:
    """The case's labelmap (see the module docstring), slice by slice to keep memory small."""
    nk, nj, ni = ct.shape
    corners = np.array([[i, j, k, 1.0] for i in (0, ni - 1) for j in (0, nj - 1) for k in (0, nk - 1)])
    z_corners = (ijk_to_ras @ corners.T)[2]
    z_range = (float(z_corners.min()), float(z_corners.max()))
    jj, ii = np.meshgrid(np.arange(nj, dtype=float), np.arange(ni, dtype=float), indexing="ij")

    def slice_ras(k):
        return ijk_to_ras[:3, 0, None, None] * ii + ijk_to_ras[:3, 1, None, None] * jj \
            + (ijk_to_ras[:3, 2] * k + ijk_to_ras[:3, 3])[:, None, None]

    labels = np.zeros(ct.shape, dtype=np.uint8)
    bone_z = [np.inf, -np.inf]
    for k in range(nk):
        ras = slice_ras(k)
        cord = (ras[0] - SPINAL_CORD_XY[0]) ** 2 + (ras[1] - SPINAL_CORD_XY[1]) ** 2 <= SPINAL_CORD_RADIUS ** 2
        center = aorta_center(ras[2], z_range)
        aorta = (ras[0] - center[..., 0]) ** 2 + (ras[1] - center[..., 1]) ** 2 <= AORTA_RADIUS ** 2
        free_bone = (ct[k] >= BONE_HU) & ~cord & ~aorta
        labels[k][cord] = 4
        labels[k][aorta & ~cord] = 5
        labels[k][free_bone] = 1
        if np.any(free_bone):
            bone_z = [min(bone_z[0], float(ras[2][free_bone].min())), max(bone_z[1], float(ras[2][free_bone].max()))]
    # The bone's z extent known, split it into three slabs of equal height.
    height = max(bone_z[1] - bone_z[0], 1e-9)
    for k in range(nk):
        bone = labels[k] == 1
        if np.any(bone):
            slab = np.clip(np.floor((slice_ras(k)[2][bone] - bone_z[0]) / height * 3.0), 0, 2)
            labels[k][bone] = (1 + slab).astype(np.uint8)
    return labels


def generate(dimensions=DIMENSIONS, spacing=SPACING, directions=DIRECTIONS, head=None) -> PatientScaleCase:
    """Build the case from the head CT.

    Args:
        dimensions, spacing, directions: the grid (voxels, mm, IJK-to-RAS
            direction columns); defaults: the chest CT of issue 11.
        head: (array, ijk_to_ras) of the source CT; default the real head CT
            (``headct.load_array``, fetched at setup into the cache).
    """
    from . import headct

    if head is None:
        array, _, head_ijk_to_ras = headct.load_array()
    else:
        array, head_ijk_to_ras = head
    ijk_to_ras = ijk_to_ras_matrix(dimensions, spacing, directions)
    ct = resample(np.asarray(array, dtype=np.int16), head_ijk_to_ras, dimensions, ijk_to_ras)
    return PatientScaleCase(ct=ct, labels=make_labels(ct, ijk_to_ras), ijk_to_ras=ijk_to_ras)


def color_table(labels=LABELS) -> dict:
    """The case's names and colours in ``owndata.read_color_table``'s form."""
    return {label: (name, (*(c / 255.0 for c in COLORS[label]), 1.0)) for label, name in labels.items()}


def create_nodes(scene, case: PatientScaleCase, name: str = "PatientScaleCT"):
    """Add the case to ``scene``: (CT ``vtkMRMLScalarVolumeNode``, ``vtkMRMLSegmentationNode`` on its grid)."""
    from . import owndata

    volume = nodes.create_scalar_volume_node(scene, case.ct, case.ijk_to_ras, name)
    labelmap = scene.AddNewNodeByClass("vtkMRMLLabelMapVolumeNode", name + "-labels")
    labelmap.SetAndObserveImageData(nodes.image_data_from_array(case.labels))
    labelmap.SetIJKToRASMatrix(nodes.numpy_to_vtk_matrix(case.ijk_to_ras))
    present = [label for label in LABELS if np.any(case.labels == label)]
    color_node = owndata.labelmap_color_node(scene, present, color_table(), name=name + "-names")
    segmentation = owndata.segmentation_from_labelmap(scene, labelmap, color_node, volume, name + "-segmentation")
    owndata.remove_nodes(scene, labelmap, color_node)
    segmentation.CreateDefaultDisplayNodes()
    return volume, segmentation


def write_color_table(path, table) -> Path:
    """Write ``{label: (name, rgba 0..1)}`` as a Slicer-style colour table (``label name R G B A``)."""
    path = Path(path)
    lines = ["# label name R G B A (0-255)", "0 Background 0 0 0 0"]
    for label, (name, rgba) in sorted(table.items()):
        lines.append(f"{label} {name} " + " ".join(str(int(round(255 * c))) for c in rgba))
    path.write_text("\n".join(lines) + "\n")
    return path


def _write_storable(scene, node, storage_class, path: Path, compress: bool):
    import slicer

    storage = getattr(slicer, storage_class)()
    scene.AddNode(storage)
    storage.SetFileName(str(path))
    storage.SetUseCompression(compress)
    try:
        if not storage.WriteData(node):
            raise RuntimeError(f"writing {path} failed (see the log)")
    finally:
        scene.RemoveNode(storage)
    return path


def write_case(case: PatientScaleCase, folder, formats=FORMATS, compress: bool = False) -> dict:
    """Write the case into ``folder``; return ``{format: path}``.

    Formats: ``nrrd`` (ct.nrrd), ``nifti`` (ct.nii, ct.nii.gz with
    ``compress``), ``dicom`` (dicom/, one CT file a slice), ``seg.nrrd``
    (segmentation.seg.nrrd), ``labelmap`` (labels.nrrd with labels.ctbl
    beside it; the path given is the labelmap's).
    """
    import slicer

    from . import dicomseries

    unknown = set(formats) - set(FORMATS)
    if unknown:
        raise ValueError(f"unknown format(s) {sorted(unknown)}; known: {FORMATS}")
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    scene = slicer.vtkMRMLScene()
    volume, segmentation = create_nodes(scene, case)
    paths = {}
    if "nrrd" in formats:
        paths["nrrd"] = _write_storable(scene, volume, "vtkMRMLVolumeArchetypeStorageNode", folder / "ct.nrrd", compress)
    if "nifti" in formats:
        paths["nifti"] = _write_storable(scene, volume, "vtkMRMLVolumeArchetypeStorageNode",
                                         folder / ("ct.nii.gz" if compress else "ct.nii"), compress)
    if "dicom" in formats:
        series = folder / "dicom"
        if series.exists():
            shutil.rmtree(series)
        dicomseries.write_ct_series(volume, series, series_description="Patient-scale test CT")
        paths["dicom"] = series
    if "seg.nrrd" in formats:
        paths["seg.nrrd"] = _write_storable(scene, segmentation, "vtkMRMLSegmentationStorageNode",
                                            folder / "segmentation.seg.nrrd", compress)
    if "labelmap" in formats:
        labelmap = scene.AddNewNodeByClass("vtkMRMLLabelMapVolumeNode", "labels")
        labelmap.SetAndObserveImageData(nodes.image_data_from_array(case.labels))
        labelmap.SetIJKToRASMatrix(nodes.numpy_to_vtk_matrix(case.ijk_to_ras))
        paths["labelmap"] = _write_storable(scene, labelmap, "vtkMRMLVolumeArchetypeStorageNode",
                                            folder / "labels.nrrd", compress)
        write_color_table(folder / "labels.ctbl", color_table())
    return paths


def cache_root() -> Path:
    """``$VOLUMECUTTING_CACHE`` (default ``${XDG_CACHE_HOME:-~/.cache}/volumecutting``)/patientscale."""
    from . import headct

    return headct.default_cache_dir().parent / "patientscale"


def cached_case_files(dimensions=DIMENSIONS, spacing=SPACING, directions=DIRECTIONS, formats=FORMATS,
                      compress: bool = False) -> dict:
    """The case written once under ``cache_root()`` (one folder per grid and compression); return ``{format: path}``.

    A folder is reused only when its stamp, written last, lists every format
    asked for; otherwise the case is generated and written again.
    """
    key = json.dumps([CASE_VERSION, list(dimensions), [round(s, 6) for s in spacing],
                      np.round(np.asarray(directions, dtype=float), 6).tolist(), bool(compress)])
    folder = cache_root() / hashlib.sha256(key.encode()).hexdigest()[:16]
    stamp = folder / "complete.json"
    if stamp.is_file():
        written = json.loads(stamp.read_text())
        if all(f in written for f in formats) and all(Path(written[f]).exists() for f in formats):
            return {f: Path(written[f]) for f in formats}
    if stamp.exists():
        stamp.unlink()
    paths = write_case(generate(dimensions, spacing, directions), folder, formats, compress)
    stamp.write_text(json.dumps({"key": json.loads(key), **{f: str(p) for f, p in paths.items()}}, indent=2))
    return paths
