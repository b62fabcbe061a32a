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


@pytest.fixture(autouse=True, scope="session")
def generous_program_build_time_limit():
    """These tests check what the GPU path draws, not how fast llvmpipe compiles: on a busy 2-core machine the
    first build of a large program took 10-23 s, over the product's 10 s default, and the mapper rightly drew on
    the CPU instead, failing image tests that had nothing to do with build time. test_volume_cut_gpu_program.py
    sets its own limits where the limit is what it tests."""
    import slicer_volumecutting as vc

    product_mapper = vc.vtkVolumeCutVolumeMapper

    class PatientMapper(product_mapper):
        def __init__(self):
            super().__init__()
            self.SetProgramBuildTimeLimit(600.0)

    vc.vtkVolumeCutVolumeMapper = PatientMapper
    yield
    vc.vtkVolumeCutVolumeMapper = product_mapper


@pytest.fixture(scope="module")
def scene():
    """The analytic cut-cube scene (a module with other needs defines its own)."""
    from VolumeCuttingLib.data import analyticscene

    return analyticscene.default_scene()


@pytest.fixture(scope="module")
def intensities(scene):
    """The scene's CT, once a module."""
    return scene.intensities()
