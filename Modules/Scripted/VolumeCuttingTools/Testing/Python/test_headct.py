"""Tests of the real head CT loader (VolumeCuttingLib.data.headct).

Tests marked ``realdata`` use Debian's invesalius-examples package, fetched
once into the user cache (outside the repository); they are skipped only if
the package cannot be obtained. All other tests use small synthetic .inv3
files written into ``tmp_path`` and need no network.
"""

import io
import plistlib
import tarfile

import numpy as np
import pytest

from VolumeCuttingLib.data import headct

# --------------------------------------------------------------------------- synthetic .inv3 files


def synthetic_array(shape=(4, 5, 6)):
    """Small int16 'CT' with distinct values so orderings can be checked."""
    return (np.arange(np.prod(shape), dtype=np.int16).reshape(shape) * 7 - 1000).astype(np.int16)


def default_plist(array, spacing=(0.8, 0.9, 2.0)):
    return {
        "format_version": 1,
        "matrix": {"dtype": "int16", "filename": "matrix.dat", "shape": list(array.shape)},
        "spacing": list(spacing),
        "scalar_range": [int(array.min()), int(array.max())],
        "modality": "CT",
    }


def write_inv3(path, plist, matrix_bytes, folder="tmpabc", extra=None):
    """Write a gzipped tar laid out like an InVesalius 3 project."""
    members = {"main.plist": plistlib.dumps(plist) if isinstance(plist, dict) else plist}
    if matrix_bytes is not None:
        members["matrix.dat"] = matrix_bytes
    members.update(extra or {})
    with tarfile.open(path, "w:gz") as archive:
        for name, data in members.items():
            info = tarfile.TarInfo(f"{folder}/{name}")
            info.size = len(data)
            archive.addfile(info, io.BytesIO(data))
    return path


def test_synthetic_inv3_round_trip(tmp_path):
    array = synthetic_array()
    path = write_inv3(tmp_path / "ok.inv3", default_plist(array), array.astype("<i2").tobytes())
    loaded, spacing, ijk_to_ras = headct.load_array(path)
    assert loaded.dtype == np.int16 and np.array_equal(loaded, array)
    assert spacing == (0.8, 0.9, 2.0)  # (x, y, z) as stored
    # i -> left (-R), j -> anterior, k -> superior, scaled by the spacing.
    assert np.allclose(ijk_to_ras[:3, :3], np.diag([-0.8, 0.9, 2.0]))
    # The grid is centred on the RAS origin.
    center_ijk = (np.array(array.shape[::-1]) - 1) / 2.0
    assert np.allclose(ijk_to_ras @ np.append(center_ijk, 1.0), [0, 0, 0, 1])


def test_synthetic_volume_node(tmp_path):
    slicer = pytest.importorskip("slicer")
    from VolumeCuttingLib.scene import nodes

    array = synthetic_array()
    path = write_inv3(tmp_path / "ok.inv3", default_plist(array), array.astype("<i2").tobytes())
    node = headct.load_volume_node(slicer.vtkMRMLScene(), name="Tiny", path=path)
    assert node.GetName() == "Tiny"
    assert np.array_equal(nodes.array_from_volume_node(node), array)
    assert np.allclose(nodes.volume_node_ijk_to_ras(node), headct.load_array(path)[2])


@pytest.mark.parametrize(
    "case, message",
    [
        ("truncated matrix", "truncated or corrupt"),
        ("wrong shape", "shape"),
        ("missing spacing", "'spacing'"),
        ("missing matrix key", "'matrix'"),
        ("missing shape", "'shape'"),
        ("bad shape value", "three positive integers"),
        ("bad spacing value", "positive finite"),
        ("float dtype", "int16"),
        ("missing matrix file", "lacks the matrix file"),
        ("no main.plist", "no main.plist"),
        ("broken plist", "not a valid property list"),
        ("byte swapped", "plausible CT range"),
        ("outside scalar_range", "scalar_range"),
        ("not a tar", "gzipped tar"),
        ("truncated archive", "gzipped tar"),
    ],
)
def test_corrupt_inv3_gives_clear_error(tmp_path, case, message):
    array = synthetic_array()
    plist = default_plist(array)
    data = array.astype("<i2").tobytes()
    path = tmp_path / "bad.inv3"
    if case == "truncated matrix":
        write_inv3(path, plist, data[:-10])
    elif case == "wrong shape":
        plist["matrix"]["shape"] = [4, 5, 7]
        write_inv3(path, plist, data)
    elif case == "missing spacing":
        del plist["spacing"]
        write_inv3(path, plist, data)
    elif case == "missing matrix key":
        del plist["matrix"]
        write_inv3(path, plist, data)
    elif case == "missing shape":
        del plist["matrix"]["shape"]
        write_inv3(path, plist, data)
    elif case == "bad shape value":
        plist["matrix"]["shape"] = [4, 0, 30]
        write_inv3(path, plist, data)
    elif case == "bad spacing value":
        plist["spacing"] = [0.8, -0.9, 2.0]
        write_inv3(path, plist, data)
    elif case == "float dtype":
        plist["matrix"]["dtype"] = "float32"
        write_inv3(path, plist, data)
    elif case == "missing matrix file":
        write_inv3(path, plist, None)
    elif case == "no main.plist":
        with tarfile.open(path, "w:gz") as archive:
            info = tarfile.TarInfo("x/matrix.dat")
            info.size = len(data)
            archive.addfile(info, io.BytesIO(data))
    elif case == "broken plist":
        write_inv3(path, b"<?xml version='1.0'?><plist><dict><key>", data)
    elif case == "byte swapped":
        del plist["scalar_range"]
        write_inv3(path, plist, array.astype(">i2").tobytes())
    elif case == "outside scalar_range":
        plist["scalar_range"] = [-500, 0]
        write_inv3(path, plist, data)
    elif case == "not a tar":
        path.write_bytes(b"this is not an InVesalius project")
    elif case == "truncated archive":
        big = np.zeros((40, 64, 64), dtype=np.int16)
        big[:, :, ::2] = np.arange(64 * 32, dtype=np.int16).reshape(1, 64, 32) % 1500
        write_inv3(path, default_plist(big), big.tobytes())
        raw = path.read_bytes()
        path.write_bytes(raw[: len(raw) // 2])
    with pytest.raises(ValueError, match=message):
        headct.load_array(path)


# --------------------------------------------------------------------------- fetch (offline)


def test_default_cache_dir(monkeypatch, tmp_path):
    monkeypatch.setenv("VOLUMECUTTING_CACHE", str(tmp_path / "explicit"))
    assert headct.default_cache_dir() == tmp_path / "explicit" / "data"
    monkeypatch.delenv("VOLUMECUTTING_CACHE")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert headct.default_cache_dir() == tmp_path / "xdg" / "volumecutting" / "data"
    monkeypatch.delenv("XDG_CACHE_HOME")
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert headct.default_cache_dir() == tmp_path / "home" / ".cache" / "volumecutting" / "data"


def test_fetch_rejects_wrong_checksum(monkeypatch, tmp_path):
    def fake_download(data_dir):
        (data_dir / headct.DEB_FILENAME).write_bytes(b"not the real package")

    monkeypatch.setattr(headct, "_download_deb", fake_download)
    with pytest.raises(headct.HeadCTChecksumError, match=f"{headct.PACKAGE} {headct.VERSION}.*SHA-256"):
        headct.fetch(tmp_path)
    assert not (tmp_path / headct.DEB_FILENAME).exists()
    assert (tmp_path / (headct.DEB_FILENAME + ".rejected")).exists()


def test_fetch_reports_missing_apt_get(monkeypatch, tmp_path):
    def no_such_program(*args, **kwargs):
        raise FileNotFoundError("apt-get")

    monkeypatch.setattr(headct.subprocess, "run", no_such_program)
    with pytest.raises(headct.HeadCTUnavailableError, match="invesalius-examples 3.1.99998-4.*apt-get"):
        headct.fetch(tmp_path)


def test_fetch_reports_failed_download(monkeypatch, tmp_path):
    class Failed:
        returncode = 100
        stdout = ""
        stderr = "E: Can't select candidate version from package invesalius-examples"

    monkeypatch.setattr(headct.subprocess, "run", lambda *args, **kwargs: Failed())
    with pytest.raises(headct.HeadCTUnavailableError, match="(?s)exit code 100.*apt-get update"):
        headct.fetch(tmp_path)


# --------------------------------------------------------------------------- real data


@pytest.fixture(scope="module")
def cranium_path():
    """Fetch (once; then cached) the real head CT; skip only if it cannot be obtained."""
    try:
        return headct.fetch()
    except headct.HeadCTUnavailableError as error:
        pytest.skip(f"real head CT ({headct.PACKAGE} {headct.VERSION}) cannot be obtained: {error}")


@pytest.mark.realdata
def test_real_head_ct(cranium_path):
    array, spacing, ijk_to_ras = headct.load_array(cranium_path)
    assert array.shape == (108, 256, 256) and array.dtype == np.int16
    assert spacing == pytest.approx((0.9570312, 0.9570312, 1.5))
    assert array.min() == -1024 and array.max() == 2986
    # Both temporal bones: bone (> 300 HU) on the left and right halves of every slice 10-30.
    bone = array[10:31] > 300
    assert np.all(bone[:, :, :128].sum(axis=(1, 2)) > 1000)
    assert np.all(bone[:, :, 128:].sum(axis=(1, 2)) > 1000)
    assert np.allclose(ijk_to_ras[:3, :3], headct.IJK_TO_RAS_DIRECTIONS * np.array(spacing)[None, :])


@pytest.mark.realdata
def test_real_head_ct_orientation_evidence(cranium_path):
    """The verified parts of the documented orientation: k runs inferior->superior, j posterior->anterior."""
    array, _, _ = headct.load_array(cranium_path)
    head_area = (array > -300).sum(axis=(1, 2))
    assert head_area[104] < 0.15 * head_area[50]  # the vertex is at high k
    assert head_area[107] < head_area[100] < head_area[80]
    teeth = np.argwhere(array[:8] > 1500)  # enamel/dentine in the lowest slices
    assert len(teeth) > 1000 and teeth[:, 1].mean() > 160  # at high rows: anterior


@pytest.mark.realdata
def test_real_head_ct_fetch_is_cached(cranium_path, monkeypatch):
    def must_not_download(data_dir):
        raise AssertionError("fetch downloaded again although the data is cached")

    monkeypatch.setattr(headct, "_download_deb", must_not_download)
    assert headct.fetch() == cranium_path


@pytest.mark.realdata
def test_real_head_ct_volume_node(cranium_path):
    slicer = pytest.importorskip("slicer")
    from VolumeCuttingLib.scene import nodes

    scene = slicer.vtkMRMLScene()
    node = headct.load_volume_node(scene)
    array, spacing, ijk_to_ras = headct.load_array(cranium_path)
    assert node.GetName() == "HeadCT"
    assert np.allclose(nodes.volume_node_ijk_to_ras(node), ijk_to_ras)
    assert np.allclose(node.GetSpacing(), spacing)
    assert node.GetImageData().GetDimensions() == (256, 256, 108)
    assert np.array_equal(nodes.array_from_volume_node(node), array)
