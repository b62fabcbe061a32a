"""pytest configuration for the rendering tests: the analytic scene lives in VolumeCuttingLib."""

import os
import sys
from pathlib import Path

import pytest

LIBRARY_DIR = Path(__file__).resolve().parents[4] / "Scripted" / "VolumeCuttingTools"
if str(LIBRARY_DIR) not in sys.path:
    sys.path.insert(0, str(LIBRARY_DIR))


@pytest.fixture(autouse=True, scope="session")
def program_cache_in_a_temporary_folder(tmp_path_factory):
    """GPU program binaries go to $XDG_CACHE_HOME/VolumeCutting/programs by default: not the user's cache in tests."""
    previous = os.environ.get("XDG_CACHE_HOME")
    os.environ["XDG_CACHE_HOME"] = str(tmp_path_factory.mktemp("xdg-cache"))
    yield
    if previous is None:
        os.environ.pop("XDG_CACHE_HOME", None)
    else:
        os.environ["XDG_CACHE_HOME"] = previous


@pytest.fixture(scope="module")
def scene():
    """The analytic cut-cube scene (a module with other needs defines its own)."""
    from VolumeCuttingLib.data import analyticscene

    return analyticscene.default_scene()


@pytest.fixture(scope="module")
def intensities(scene):
    """The scene's CT, once a module."""
    return scene.intensities()
