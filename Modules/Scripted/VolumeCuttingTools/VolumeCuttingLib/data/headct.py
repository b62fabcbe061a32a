"""Loader for the real head CT shipped by Debian (package invesalius-examples).

Debian bookworm's ``invesalius-examples`` 3.1.99998-4 (GPL-2, about 18 MB)
contains ``Cranium.inv3``, an InVesalius 3 project: a gzipped tar holding
``main.plist`` (``matrix.shape`` = (z, y, x), ``matrix.dtype``, ``spacing``
= (x, y, z) in mm, ``scalar_range``), ``matrix.dat`` (little-endian int16
Hounsfield units, C order, shape (108, 256, 256)), threshold masks and two
bone surfaces. Slices 10-30 show both temporal bones with mastoid air cells
and ear canals, which makes it a useful real-data check for the drilling
tools.

The data is never stored in the repository. ``fetch`` runs
``apt-get download invesalius-examples=3.1.99998-4`` into
``${VOLUMECUTTING_CACHE:-${XDG_CACHE_HOME:-~/.cache}/volumecutting}/data/``,
checks the SHA-256 of the .deb against the value pinned below (the same as
in the Debian archive's package index), and unpacks it there with
``dpkg-deb -x``. A .deb placed in that folder by hand is used as well,
after the same checksum test.

Orientation
-----------
The .inv3 format (version 1) stores no patient orientation, so
``load_array`` returns a documented IJK-to-RAS matrix:

* i (column, x) -> patient Left:      RAS direction (-1, 0, 0)   ASSUMED
* j (row, y)    -> patient Anterior:  RAS direction ( 0, 1, 0)   verified
* k (slice, z)  -> patient Superior:  RAS direction ( 0, 0, 1)   verified

Verified from the voxels: the head cross-section shrinks to nothing towards
the last slices (skull vertex at k ~ 105) while the first slices contain the
teeth and skull base, so k runs inferior to superior; the curved head-rest
and the occiput are at row 0, and the teeth and the frontal and maxillary
sinuses at high rows, so j runs posterior to anterior. This matches how
InVesalius builds the matrix from a standard supine axial DICOM series
(ImageOrientationPatient 1\\0\\0\\0\\1\\0): it reverses the row order
(rows of the DICOM image run anterior to posterior) and keeps the column
order. Left/right is *assumed* from that same convention (DICOM columns run
towards patient left and InVesalius does not flip them); it cannot be
checked on this anonymised, nearly symmetric head, which has no side marker.
The grid is centred on the RAS origin (the file has no position either).
"""

import hashlib
import math
import os
import plistlib
import shutil
import subprocess
import tarfile
import tempfile
import zlib
from pathlib import Path, PurePosixPath

import numpy as np

PACKAGE = "invesalius-examples"
VERSION = "3.1.99998-4"
DEB_FILENAME = f"{PACKAGE}_{VERSION}_all.deb"
# SHA-256 of the .deb as listed in Debian bookworm's Packages index.
DEB_SHA256 = "f2f14bdfef6dc3812eafc5013d133c6c18370aaab5666b78d54af2e7db432f97"
INV3_MEMBER = "usr/share/doc/invesalius-examples/examples/Cranium.inv3"

# IJK-to-RAS directions (columns: i, j, k); see "Orientation" above.
IJK_TO_RAS_DIRECTIONS = np.array([[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])

# Values outside this interval are not CT numbers in HU; byte-swapped or
# corrupt int16 data lands there almost surely.
PLAUSIBLE_HU_RANGE = (-2048, 4095)

# Centre (y, z in RAS mm) of the right mastoid, read off the pinned data:
# slice k=21, row j=108, where the air cells lie behind the ear canal (the
# lateral cortex there is at i=67). The main job and the shipped recording
# drill there.
RIGHT_MASTOID_YZ = (-18.6, -48.75)

_DOWNLOAD_TIMEOUT_S = 900
_STAMP_NAME = ".verified-sha256"


class HeadCTUnavailableError(RuntimeError):
    """The package could not be obtained (no apt-get, no network, version unknown to apt)."""


class HeadCTChecksumError(RuntimeError):
    """The obtained .deb does not have the pinned SHA-256."""


def default_cache_dir():
    """Return the data cache folder ``${VOLUMECUTTING_CACHE:-${XDG_CACHE_HOME:-~/.cache}/volumecutting}/data``."""
    explicit = os.environ.get("VOLUMECUTTING_CACHE")
    if explicit:
        return Path(explicit).expanduser() / "data"
    xdg = os.environ.get("XDG_CACHE_HOME")
    base = Path(xdg).expanduser() if xdg else Path.home() / ".cache"
    return base / "volumecutting" / "data"


def _sha256(path):
    digest = hashlib.sha256()
    with open(path, "rb") as stream:
        for block in iter(lambda: stream.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def _download_deb(data_dir):
    """Run ``apt-get download`` for the pinned package version with ``data_dir`` as working folder."""
    command = ["apt-get", "download", f"{PACKAGE}={VERSION}"]
    manual = (
        f"Alternatively place {DEB_FILENAME} (SHA-256 {DEB_SHA256}, from Debian bookworm) in {data_dir}."
    )
    try:
        result = subprocess.run(command, cwd=data_dir, capture_output=True, text=True,
                                timeout=_DOWNLOAD_TIMEOUT_S, check=False)
    except FileNotFoundError as error:
        raise HeadCTUnavailableError(
            f"cannot obtain {PACKAGE} {VERSION}: apt-get is not available on this machine. {manual}"
        ) from error
    except subprocess.TimeoutExpired as error:
        raise HeadCTUnavailableError(
            f"cannot obtain {PACKAGE} {VERSION}: apt-get download timed out after {_DOWNLOAD_TIMEOUT_S} s. {manual}"
        ) from error
    if result.returncode != 0:
        details = (result.stderr or result.stdout).strip()[-800:]
        raise HeadCTUnavailableError(
            f"cannot obtain {PACKAGE} {VERSION}: '{' '.join(command)}' failed with exit code "
            f"{result.returncode}: {details}\nIf apt does not know this version, run 'apt-get update' "
            f"on a Debian bookworm system. {manual}"
        )


def _extract_deb(deb_path, target_dir):
    """Unpack ``deb_path`` with ``dpkg-deb -x`` into ``target_dir``, replacing it atomically."""
    staging = Path(tempfile.mkdtemp(prefix=".extract-", dir=target_dir.parent))
    try:
        try:
            result = subprocess.run(["dpkg-deb", "-x", str(deb_path), str(staging)], capture_output=True,
                                    text=True, check=False)
        except FileNotFoundError as error:
            raise HeadCTUnavailableError(
                f"cannot unpack {PACKAGE} {VERSION}: dpkg-deb is not available on this machine"
            ) from error
        if result.returncode != 0:
            raise HeadCTUnavailableError(
                f"cannot unpack {deb_path} ({PACKAGE} {VERSION}): dpkg-deb failed: {result.stderr.strip()}"
            )
        if not (staging / INV3_MEMBER).is_file():
            raise HeadCTUnavailableError(f"{deb_path} ({PACKAGE} {VERSION}) does not contain {INV3_MEMBER}")
        (staging / _STAMP_NAME).write_text(DEB_SHA256 + "\n")
        if target_dir.exists():
            shutil.rmtree(target_dir)
        staging.rename(target_dir)
    finally:
        if staging.exists():
            shutil.rmtree(staging, ignore_errors=True)


def fetch(cache_dir=None):
    """Obtain, verify and unpack the pinned package; return the path of ``Cranium.inv3``.

    Idempotent: once unpacked (and stamped with the verified checksum) the
    cached file is returned without touching the network. A cached .deb with
    a wrong checksum (for example an interrupted download) is fetched again.

    Args:
        cache_dir: folder for the .deb and its unpacked tree (default
            ``default_cache_dir()``); created if missing. Keep it outside
            the repository.

    Raises:
        HeadCTUnavailableError: apt-get or dpkg-deb is missing or failed.
        HeadCTChecksumError: the downloaded .deb has an unexpected SHA-256
            (it is renamed to ``*.rejected`` so it is not used again).
    """
    data_dir = Path(cache_dir).expanduser() if cache_dir is not None else default_cache_dir()
    extracted = data_dir / f"{PACKAGE}_{VERSION}"
    inv3_path = extracted / INV3_MEMBER
    stamp = extracted / _STAMP_NAME
    if inv3_path.is_file() and stamp.is_file() and stamp.read_text().strip() == DEB_SHA256:
        return inv3_path

    data_dir.mkdir(parents=True, exist_ok=True)
    deb_path = data_dir / DEB_FILENAME
    if not (deb_path.is_file() and _sha256(deb_path) == DEB_SHA256):
        if deb_path.exists():
            deb_path.unlink()
        _download_deb(data_dir)
        if not deb_path.is_file():
            raise HeadCTUnavailableError(
                f"apt-get download reported success but {deb_path} ({PACKAGE} {VERSION}) does not exist"
            )
        digest = _sha256(deb_path)
        if digest != DEB_SHA256:
            rejected = deb_path.with_name(deb_path.name + ".rejected")
            deb_path.replace(rejected)
            raise HeadCTChecksumError(
                f"{PACKAGE} {VERSION}: SHA-256 of the downloaded {DEB_FILENAME} is {digest}, expected "
                f"{DEB_SHA256}; the file was moved to {rejected}"
            )
    _extract_deb(deb_path, extracted)
    return inv3_path


def _require(mapping, key, where):
    if not isinstance(mapping, dict) or key not in mapping:
        raise ValueError(f"{where} lacks the required key {key!r}")
    return mapping[key]


def read_inv3(path):
    """Read and validate the CT matrix of an InVesalius ``.inv3`` project.

    Returns:
        (array, spacing_xyz, plist): the int16 array indexed (z, y, x), the
        voxel size in mm along x, y, z, and the parsed ``main.plist``.

    Raises:
        ValueError: the file is not a gzipped tar, ``main.plist`` or the
            matrix file is missing, a required plist key is missing or
            malformed, the matrix size disagrees with ``matrix.shape``
            (truncated or corrupt file), or the values are not plausible HU.
    """
    path = Path(path)
    where = f"{path.name}/main.plist"
    try:
        with tarfile.open(path, "r:gz") as archive:
            files = {PurePosixPath(member.name).name: member for member in archive.getmembers() if member.isfile()}
            if "main.plist" not in files:
                raise ValueError(f"{path} contains no main.plist; is it an InVesalius .inv3 project?")
            try:
                plist = plistlib.loads(archive.extractfile(files["main.plist"]).read())
            except Exception as error:  # plistlib raises several unrelated types
                raise ValueError(f"{where} is not a valid property list: {error}") from error

            matrix_info = _require(plist, "matrix", where)
            shape = _require(matrix_info, "shape", where + " 'matrix'")
            if (not isinstance(shape, (list, tuple)) or len(shape) != 3
                    or not all(isinstance(n, int) and not isinstance(n, bool) and n > 0 for n in shape)):
                raise ValueError(f"{where}: matrix.shape must be three positive integers (z, y, x), got {shape!r}")
            dtype = matrix_info.get("dtype", "int16")
            if dtype != "int16":
                raise ValueError(f"{where}: matrix.dtype is {dtype!r}; only int16 is supported")
            spacing = _require(plist, "spacing", where)
            if (not isinstance(spacing, (list, tuple)) or len(spacing) != 3
                    or not all(isinstance(s, (int, float)) and not isinstance(s, bool) for s in spacing)
                    or not all(math.isfinite(s) and s > 0 for s in spacing)):
                raise ValueError(f"{where}: spacing must be three positive finite numbers (x, y, z), got {spacing!r}")

            matrix_name = PurePosixPath(str(matrix_info.get("filename", "matrix.dat"))).name
            if matrix_name not in files:
                raise ValueError(f"{path} lacks the matrix file {matrix_name!r} named in main.plist")
            expected_bytes = int(np.prod(shape)) * 2
            member = files[matrix_name]
            if member.size != expected_bytes:
                raise ValueError(
                    f"{path}: {matrix_name} has {member.size} bytes but matrix.shape {tuple(shape)} of int16 needs "
                    f"{expected_bytes}; the file is truncated or corrupt, or the shape is wrong"
                )
            raw = archive.extractfile(member).read()
    except (tarfile.TarError, EOFError, OSError, zlib.error) as error:
        raise ValueError(f"cannot read {path} as a gzipped tar (.inv3) file: {error}") from error
    if len(raw) != expected_bytes:
        raise ValueError(f"{path}: {matrix_name} is truncated ({len(raw)} of {expected_bytes} bytes)")

    array = np.frombuffer(raw, dtype="<i2").reshape(shape).astype(np.int16)
    low, high = int(array.min()), int(array.max())
    if low < PLAUSIBLE_HU_RANGE[0] or high > PLAUSIBLE_HU_RANGE[1]:
        raise ValueError(
            f"{path}: values {low}..{high} are outside the plausible CT range {PLAUSIBLE_HU_RANGE} HU; "
            "the matrix is corrupt or not little-endian int16"
        )
    scalar_range = plist.get("scalar_range")
    if isinstance(scalar_range, (list, tuple)) and len(scalar_range) == 2:
        if low < scalar_range[0] or high > scalar_range[1]:
            raise ValueError(
                f"{path}: values {low}..{high} exceed the scalar_range {list(scalar_range)} recorded in main.plist"
            )
    return array, tuple(float(s) for s in spacing), plist


def ijk_to_ras_matrix(shape_zyx, spacing_xyz):
    """Return the documented IJK-to-RAS matrix for an InVesalius axial matrix, centred on the RAS origin."""
    matrix = np.eye(4)
    matrix[:3, :3] = IJK_TO_RAS_DIRECTIONS * np.asarray(spacing_xyz, dtype=float)[None, :]
    center_ijk = (np.array(shape_zyx[::-1], dtype=float) - 1.0) / 2.0
    matrix[:3, 3] = -matrix[:3, :3] @ center_ijk
    return matrix


def load_array(path=None, cache_dir=None):
    """Load the head CT.

    Args:
        path: an ``.inv3`` file; default: the fetched ``Cranium.inv3``.
        cache_dir: cache folder passed to ``fetch`` when ``path`` is None.

    Returns:
        (array, spacing_xyz, ijk_to_ras): int16 HU array indexed (z, y, x),
        voxel size in mm along x, y, z, and the 4x4 IJK-to-RAS matrix (see
        the module docstring for what is verified and what is assumed).
    """
    if path is None:
        path = fetch(cache_dir)
    array, spacing, _ = read_inv3(path)
    return array, spacing, ijk_to_ras_matrix(array.shape, spacing)


def load_volume_node(scene, name="HeadCT", path=None, cache_dir=None):
    """Add the head CT to ``scene`` as a ``vtkMRMLScalarVolumeNode`` (int16 HU) and return it."""
    from ..scene import nodes

    array, _, ijk_to_ras = load_array(path, cache_dir)
    return nodes.create_scalar_volume_node(scene, array, ijk_to_ras, name)
