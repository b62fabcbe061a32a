"""`Utilities/vc build` on a built checkout does no work: no reconfigure, no compile, no wheel repack.

The first minute of every `vc main`, `vc app` and `vc test` used to go to scikit-build-core reconfiguring
the build and recompiling part of it although ninja had nothing to do (issue 28, finding 4).
"""

import os
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[2]
sys.path.insert(0, str(HERE.parent))
import prune_install  # noqa: E402


def _newest_object_time(build: Path) -> float:
    return max((p.stat().st_mtime for p in build.rglob("*.o")), default=0.0)


@pytest.mark.skipif(not (REPO / "build" / "core" / ".vc-installed").exists(), reason="needs a checkout built by Utilities/vc build")
def test_a_build_with_nothing_changed_neither_reconfigures_nor_compiles():
    build = REPO / "build" / "core"
    cache_time = (build / "CMakeCache.txt").stat().st_mtime
    object_time = _newest_object_time(build)
    # Other test folders point XDG_CACHE_HOME at a temporary folder for the session; the build's setup needs
    # the download cache it was set up from.
    env = {k: v for k, v in os.environ.items() if not (k == "XDG_CACHE_HOME" and v.startswith(tempfile.gettempdir()))}
    result = subprocess.run([str(REPO / "Utilities" / "vc"), "build"], cwd=REPO, capture_output=True, text=True,
                            timeout=600, env=env)
    assert result.returncode == 0, result.stdout + result.stderr
    assert (build / "CMakeCache.txt").stat().st_mtime == cache_time, "the build was reconfigured"
    assert _newest_object_time(build) == object_time, "something was recompiled"
    assert "ninja: no work to do" in result.stdout


def test_files_the_build_no_longer_installs_are_removed(tmp_path):
    package = tmp_path / "site" / "VolumeCuttingLib"
    (package / "data").mkdir(parents=True)
    kept = [package / "__init__.py", package / "data" / "__init__.py", package / "data" / "headct.py"]
    moved = [package / "headct.py", package / "old" / "gone.py"]
    for path in kept + moved:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text("x = 1\n")
    manifest = tmp_path / "install_manifest.txt"
    manifest.write_text("\n".join(str(p) for p in kept) + "\n")

    removed = prune_install.prune(manifest, package)

    assert sorted(removed) == sorted(moved)
    assert all(p.exists() for p in kept)
    assert not (package / "old").exists(), "an emptied folder stays importable as a namespace package"
