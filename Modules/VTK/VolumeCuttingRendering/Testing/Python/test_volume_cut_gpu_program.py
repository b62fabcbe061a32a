"""The GPU program: specialized to the scene, built without freezing the view, cached on disk.

Every failure of the GPU path (a driver that rejects the program, a build
over the time limit, a volume beyond the texture limit, a lost context, a
volume of one slice) must leave the CPU image in the view and a readable
reason, never a frozen view or a crash. Each test compares the image drawn
with the CPU path's image of the same view, rendered by the same mapper.
The OpenGL context is whatever VTK gives offscreen (Mesa llvmpipe through
EGL here): llvmpipe links synchronously, so a build still pending on a
driver with parallel compile cannot be reached from these tests.
"""

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
import slicer_volumecutting as vc
import vtk
from test_volume_cut_mapper import ErrorLog, add_cut_volume, read_window, render_window

from VolumeCuttingLib.data import analyticscene as A

GPU = vc.vtkVolumeCutVolumeMapper.GPUPath
CPU = vc.vtkVolumeCutVolumeMapper.CPUPath
WIDTH = 32


@pytest.fixture(scope="module")
def scene():
    return A.default_scene(32)


def cut_cube(scene, intensities, cache_directory, width=WIDTH):
    """A window showing the cut cube; the mapper keeps its program binaries in ``cache_directory``."""
    window, renderer = render_window(width)
    renderer.SetActiveCamera(A.make_camera(scene, 1.0, width, width))
    mapper, _ = add_cut_volume(scene, intensities, scene.cut_field(1), renderer)
    mapper.SetProgramCacheDirectory(str(cache_directory))
    return window, mapper


def cpu_image(window, mapper, width=WIDTH):
    """The CPU path's image of the window's view (the reference of every fallback)."""
    requested = mapper.GetRequestedRenderPath()
    mapper.SetRequestedRenderPath(CPU)
    window.Render()
    image = read_window(window, width)
    mapper.SetRequestedRenderPath(requested)
    return image


def assert_same_image(expected, drawn):
    for a, b in zip(expected, drawn):
        assert np.array_equal(a, b)


def filtering(gpu):
    """The features' suffix where the texture unit interpolates the 16-bit CT (test_volume_cut_gpu_filtering.py)."""
    return " ct-filtered" if 0.0 <= gpu.GetFilterWeightError() <= gpu.GetMaximumFilterWeightError() else ""


def test_programs_are_specialized_to_the_features_in_use(scene, intensities, tmp_path):
    window, mapper = cut_cube(scene, intensities, tmp_path)
    mapper.SetRequestedRenderPath(GPU)
    gpu = mapper.GetOpenGLRayCaster()
    caster = mapper.GetRayCaster()
    planes = vtk.vtkPlaneCollection()
    plane = vtk.vtkPlane()
    plane.SetOrigin(*scene.center)
    plane.SetNormal(0.0, 0.0, -1.0)
    planes.AddItem(plane)
    sizes = {}

    def draw(name, expected_features):
        window.Render()
        assert mapper.GetLastRenderPath() == GPU, mapper.GetGPUFallbackReason()
        assert gpu.GetProgramFeatures() == expected_features + filtering(gpu)
        sizes[name] = gpu.GetProgramSourceLength()

    draw("iso", "cuts=1 iso ct16 cut16")
    caster.SetAmbientOcclusion(True)
    draw("occlusion", "cuts=1 iso occlusion ct16 cut16")
    caster.SetAmbientOcclusion(False)
    caster.ThinBoneShadingOn()
    mapper.SetClippingPlanes(planes)
    draw("thin bone, plane", "cuts=1 iso thin-bone planes=1 ct16 cut16")
    # The specialized program draws what the CPU draws (the mapper tests' tolerance).
    gpu_depth, gpu_color = read_window(window, WIDTH)
    cpu_depth, cpu_color = cpu_image(window, mapper)
    assert np.any(cpu_depth < 1.0)
    assert np.max(np.abs(cpu_depth - gpu_depth)) < 1e-4
    assert np.mean(np.max(np.abs(cpu_color - gpu_color), axis=2) > 2) < 0.005
    caster.ThinBoneShadingOff()
    mapper.RemoveAllClippingPlanes()
    mapper.SetBlendMode(vtk.vtkVolumeMapper.COMPOSITE_BLEND)
    draw("composite", "cuts=1 composite ct16 cut16")
    # A stage not in use leaves its code out of the program.
    assert sizes["iso"] < sizes["thin bone, plane"] and sizes["iso"] < sizes["occlusion"] and sizes["iso"] < sizes["composite"]
    print("fragment shader characters per feature set:", sizes)


def test_a_driver_that_rejects_the_program_leaves_the_cpu_image(scene, intensities, tmp_path):
    window, mapper = cut_cube(scene, intensities, tmp_path)
    expected = cpu_image(window, mapper)
    log = ErrorLog(mapper, warnings=True)
    gpu = mapper.GetOpenGLRayCaster()
    gpu.SetExtraFragmentDeclarations("this is not GLSL;\n")
    mapper.SetRequestedRenderPath(GPU)
    for _ in range(3):
        window.Render()
        assert mapper.GetLastRenderPath() == CPU
        assert_same_image(expected, read_window(window, WIDTH))
    assert gpu.GetProgramStatus() == vc.vtkVolumeCutOpenGLRayCaster.ProgramFailed
    reason = mapper.GetGPUFallbackReason()
    assert "rejects the GPU program" in reason and "does not compile" in reason
    assert gpu.GetDriverDescription() in reason and gpu.GetDriverDescription().strip()
    assert sum("rejects the GPU program" in m for m in log.messages) == 1  # once, not every frame
    # Valid code again: the GPU draws.
    gpu.SetExtraFragmentDeclarations("")
    window.Render()
    assert mapper.GetLastRenderPath() == GPU, mapper.GetGPUFallbackReason()


def test_a_build_over_the_time_limit_leaves_the_cpu_path_with_the_driver_and_time(scene, intensities, tmp_path):
    window, mapper = cut_cube(scene, intensities, tmp_path)
    expected = cpu_image(window, mapper)
    log = ErrorLog(mapper, warnings=True)
    mapper.SetProgramBuildTimeLimit(0.0)
    mapper.SetRequestedRenderPath(GPU)
    for _ in range(3):
        window.Render()
        assert mapper.GetLastRenderPath() == CPU
        assert_same_image(expected, read_window(window, WIDTH))
    gpu = mapper.GetOpenGLRayCaster()
    assert gpu.GetProgramStatus() == vc.vtkVolumeCutOpenGLRayCaster.ProgramTimedOut
    assert mapper.GetLastProgramBuildTime() > 0.0
    reason = mapper.GetGPUFallbackReason()
    assert "ProgramBuildTimeLimit (0.00 s)" in reason and "the GPU program took" in reason
    assert f"{mapper.GetLastProgramBuildTime():.2f} s" in reason
    assert gpu.GetDriverDescription() in reason
    warnings = [m for m in log.messages if "ProgramBuildTimeLimit" in m]
    assert len(warnings) == 1
    # A new limit lets the GPU try again.
    mapper.SetProgramBuildTimeLimit(600.0)
    window.Render()
    assert mapper.GetLastRenderPath() == GPU, mapper.GetGPUFallbackReason()
    assert 0.0 < mapper.GetLastProgramBuildTime() < 600.0


def test_program_binaries_are_cached_and_a_bad_cache_file_is_rebuilt(scene, intensities, tmp_path):
    window, mapper = cut_cube(scene, intensities, tmp_path)
    mapper.SetRequestedRenderPath(GPU)
    window.Render()
    gpu = mapper.GetOpenGLRayCaster()
    assert mapper.GetLastRenderPath() == GPU, mapper.GetGPUFallbackReason()
    if gpu.GetNumberOfProgramBinaryFormats() == 0:
        pytest.skip(f"{gpu.GetDriverDescription()} offers no program binary format")
    assert not gpu.GetLastProgramLoadedFromCache()
    files = list(tmp_path.glob("*.bin"))
    assert len(files) == 1
    first = read_window(window, WIDTH)

    def second_start():
        """Another window and mapper (another context): as the next start of the application."""
        window2, mapper2 = cut_cube(scene, intensities, tmp_path)
        mapper2.SetRequestedRenderPath(GPU)
        log = ErrorLog(mapper2.GetOpenGLRayCaster(), warnings=True)
        window2.Render()
        assert mapper2.GetLastRenderPath() == GPU, mapper2.GetGPUFallbackReason()
        assert_same_image(first, read_window(window2, WIDTH))
        return mapper2.GetOpenGLRayCaster(), log.messages

    cached, messages = second_start()
    assert cached.GetLastProgramLoadedFromCache() and messages == []

    # Truncated, corrupt or another program's file: one warning, a rebuild from source, a good file again.
    good = files[0].read_bytes()
    for damage, why in ((good[: len(good) // 2], "truncated"), (b"\0" * 64, "not a program binary"),
                        (good[:-1] + bytes([good[-1] ^ 0xFF]), "checksum mismatch")):
        files[0].write_bytes(damage)
        rebuilt, messages = second_start()
        assert not rebuilt.GetLastProgramLoadedFromCache()
        assert len(messages) == 1 and why in messages[0] and str(files[0]) in messages[0]
        assert files[0].read_bytes() != damage
    # Another program's binary under this program's name.
    mapper.GetRayCaster().ThinBoneShadingOn()
    window.Render()
    other = [f for f in tmp_path.glob("*.bin") if f != files[0]]
    assert len(other) == 1
    files[0].write_bytes(other[0].read_bytes())
    rebuilt, messages = second_start()
    assert not rebuilt.GetLastProgramLoadedFromCache()
    assert len(messages) == 1 and "of another program or driver" in messages[0]


def test_without_binary_formats_programs_are_built_from_source_without_warnings(tmp_path):
    """Mesa offers no program binary format with its shader cache disabled: the cache stays empty, silently."""
    script = textwrap.dedent(
        f"""
        import slicer_volumecutting as vc
        from test_volume_cut_gpu_program import cut_cube, ErrorLog, GPU
        from VolumeCuttingLib.data import analyticscene as A
        scene = A.default_scene(32)
        window, mapper = cut_cube(scene, scene.intensities(), {str(tmp_path)!r})
        mapper.SetRequestedRenderPath(GPU)
        log = ErrorLog(mapper.GetOpenGLRayCaster(), warnings=True)
        window.Render()
        gpu = mapper.GetOpenGLRayCaster()
        print(mapper.GetLastRenderPath() == GPU, gpu.GetNumberOfProgramBinaryFormats(), len(log.messages), gpu.GetDriverDescription())
        """
    )
    environment = dict(os.environ, MESA_SHADER_CACHE_DISABLE="true")
    environment["PYTHONPATH"] = os.pathsep.join([str(Path(__file__).parent), *sys.path])
    result = subprocess.run([sys.executable, "-c", script], env=environment, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    drawn, formats, warnings, driver = result.stdout.strip().splitlines()[-1].split(" ", 3)
    if "Mesa" not in driver:
        pytest.skip(f"MESA_SHADER_CACHE_DISABLE means nothing to {driver}")
    assert (drawn, formats, warnings) == ("True", "0", "0")
    assert list(tmp_path.iterdir()) == []


def test_a_lost_context_between_programs_builds_again(scene, intensities, tmp_path):
    """The context goes (Finalize releases every GPU resource) when the features change: the next frame builds the new program."""
    window, mapper = cut_cube(scene, intensities, tmp_path)
    mapper.SetProgramCacheDirectory("")
    mapper.GetOpenGLRayCaster().ProgramCacheOff()
    mapper.SetRequestedRenderPath(GPU)
    window.Render()
    assert mapper.GetLastRenderPath() == GPU
    mapper.GetRayCaster().ThinBoneShadingOn()
    window.Finalize()
    window.Render()
    assert mapper.GetLastRenderPath() == GPU, mapper.GetGPUFallbackReason()
    gpu = mapper.GetOpenGLRayCaster()
    assert gpu.GetProgramFeatures() == "cuts=1 iso thin-bone ct16 cut16" + filtering(gpu)
    drawn = read_window(window, WIDTH)
    depth, color = cpu_image(window, mapper)
    assert np.max(np.abs(depth - drawn[0])) < 1e-4
    assert np.mean(np.max(np.abs(color - drawn[1]), axis=2) > 2) < 0.005


def test_a_volume_of_one_slice_gives_a_reason_and_no_crash():
    flat = vtk.vtkImageData()
    flat.SetDimensions(12, 12, 1)
    flat.AllocateScalars(vtk.VTK_FLOAT, 1)
    flat.GetPointData().GetScalars().Fill(1000.0)
    window, renderer = render_window(WIDTH)
    mapper = vc.vtkVolumeCutVolumeMapper()
    mapper.SetInputData(flat)
    mapper.GetRayCaster().SetIsoValue(500.0)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    renderer.AddVolume(volume)
    renderer.ResetCamera()
    log = ErrorLog(mapper.GetRayCaster())
    expected = cpu_image(window, mapper)
    mapper.SetRequestedRenderPath(GPU)
    window.Render()
    assert mapper.GetLastRenderPath() != GPU
    assert "cannot be rendered" in mapper.GetGPUFallbackReason()
    assert any("at least 2 voxels" in m for m in log.messages)
    assert_same_image(expected, read_window(window, WIDTH))
