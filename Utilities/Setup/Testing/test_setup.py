"""The setup's own rules: what it changes in the SDKs, and how it refuses a wrong machine."""

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import bootstrap  # noqa: E402
import vtk_sdk  # noqa: E402


def test_library_locations_point_at_the_wheel():
    text = (
        'set_target_properties(VTK::CommonCore PROPERTIES\n'
        '  IMPORTED_LOCATION_NONE "${_IMPORT_PREFIX}/lib/x86_64-linux-gnu/libvtkCommonCore-9.6.so.9.6"\n'
        '  IMPORTED_SONAME_NONE "libvtkCommonCore-9.6.so.1"\n  )\n'
        'list(APPEND _cmake_import_check_files_for_VTK::CommonCore "${_IMPORT_PREFIX}/lib/x86_64-linux-gnu/libvtkCommonCore-9.6.so.9.6" )\n'
        'list(APPEND _cmake_import_check_files_for_VTK::IOGDAL "${_IMPORT_PREFIX}/lib/x86_64-linux-gnu/libvtkIOGDAL-9.6.so.9.6" )\n'
        'list(APPEND _cmake_import_check_files_for_VTK::WrappingTools "${_IMPORT_PREFIX}/lib/x86_64-linux-gnu/libvtkWrappingTools-9.6.so.9.6" )\n'
        'list(APPEND _cmake_import_check_files_for_VTK::WrapJava "${_IMPORT_PREFIX}/bin/vtkWrapJava-9.6" )\n'
        'list(APPEND _cmake_import_check_files_for_VTK::WrapPython "${_IMPORT_PREFIX}/bin/vtkWrapPython-9.6" )\n'
        '  IMPORTED_LOCATION_NONE "${_IMPORT_PREFIX}/lib/x86_64-linux-gnu/libvtkWrappingPythonCore3.14-9.6.so.9.6"\n'
        '  IMPORTED_LOCATION_NONE "${_IMPORT_PREFIX}/lib/python3/dist-packages/vtkmodules/vtkCommonCore.cpython-314-x86_64-linux-gnu.so"\n')
    patched = vtk_sdk.patch_targets_none(text, {"libvtkCommonCore.so"})
    assert '"${VTK_WHEEL_LIBRARY_DIR}/libvtkCommonCore.so"' in patched
    assert '"libvtkCommonCore.so"' in patched
    assert "libvtkIOGDAL" not in patched  # the wheel has no GDAL: its check is dropped
    assert "vtkWrapJava" not in patched
    assert "bin/vtkWrapPython-9.6" in patched  # the wrap tools stay sid's
    assert "lib/x86_64-linux-gnu/libvtkWrappingTools-9.6.so.9.6" in patched
    assert "${VTK_WHEEL_LIBRARY_DIR}/libvtkWrappingPythonCore3.11.so" in patched
    assert "${VTK_WHEEL_LIBRARY_DIR}/vtkCommonCore.cpython-311-x86_64-linux-gnu.so" in patched


def test_link_interfaces_keep_only_vtk_threads_and_python():
    text = ('  INTERFACE_LINK_LIBRARIES "VTK::vtkplatform;TBB::tbb;Threads::Threads;'
            '\\$<COMPILE_ONLY:X11::X11>;\\$<LINK_ONLY:\\$<\\$<PLATFORM_ID:SunOS>:socket>>;ZLIB::ZLIB"\n')
    patched = vtk_sdk.patch_targets(text)
    assert patched == ('  INTERFACE_LINK_LIBRARIES "VTK::vtkplatform;Threads::Threads;'
                       '\\$<LINK_ONLY:\\$<\\$<PLATFORM_ID:SunOS>:socket>>"\n')


def test_external_packages_are_not_searched_but_python_is():
    text = "  find_package(TBB\n  find_package(Python3\n    3.14\n  find_package(Threads\n"
    patched = vtk_sdk.patch_find_packages(text)
    assert "vtk_wheel_provides_package(TBB" in patched
    assert "find_package(Python3\n    3.11" in patched
    assert "find_package(Threads" in patched


def test_smp_header_describes_the_wheel():
    header = ("#define VTK_SMP_ENABLE_OPENMP 0\n#define VTK_SMP_ENABLE_SEQUENTIAL 1\n"
              "#define VTK_SMP_ENABLE_STDTHREAD 1\n#define VTK_SMP_ENABLE_TBB 1\n"
              "#define VTK_SMP_DEFAULT_IMPLEMENTATION_TBB 1\n")
    patched = vtk_sdk.patch_smp_header(header)
    assert "#define VTK_SMP_ENABLE_TBB 0" in patched
    assert "#define VTK_SMP_DEFAULT_IMPLEMENTATION_STDTHREAD 1" in patched
    with pytest.raises(vtk_sdk.SetupError):
        vtk_sdk.patch_smp_header("#define VTK_SMP_ENABLE_TBB 1\n")


def test_wrong_python_is_refused_with_a_message(monkeypatch):
    monkeypatch.setattr(bootstrap, "PYTHON_VERSION", (3, 99))
    with pytest.raises(vtk_sdk.SetupError, match="Python 3.99 is required"):
        bootstrap.check_machine()


def test_unobtainable_sid_package_is_named(monkeypatch, tmp_path):
    monkeypatch.setattr(vtk_sdk, "SID_PACKAGES", {"libvtk9-dev": ("0.0.0-does-not-exist", "0" * 64)})

    def no_network(command, what, **kwargs):
        if "update" in command:
            return
        raise AssertionError("unexpected command")

    monkeypatch.setattr(vtk_sdk, "run", no_network)
    with pytest.raises(vtk_sdk.SetupError, match="libvtk9-dev=0.0.0-does-not-exist"):
        vtk_sdk.download_sid_packages(tmp_path)
