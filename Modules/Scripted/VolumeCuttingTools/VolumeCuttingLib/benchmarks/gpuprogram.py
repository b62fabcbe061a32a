"""Benchmark area ``gpuprogram``: building the GPU program, first start against a cached start.

It also compares the CT and label textures as R32F (NormalizedTextures off,
as before 16-bit textures) with R16/R8 (on) on the head CT and the
patient-scale case: texture memory, and the GPU path's frame time with each,
frames alternating in one process; and, the same way, the R16 CT interpolated
by the texture unit (HardwareFiltering on) against the shader's eight texel
fetches (off). On llvmpipe the frame time is a proxy only: a CPU rasterizer
has no texture cache or memory bandwidth of a GPU's, and its filtering is
code too, so the ratio says how much shader work filtering removes, not what
a GPU gains.
On the same cases it compares the GPU path's empty-space skipping as the
CPU path does it (EmptySpaceSkipping on) with one empty block at a time
(off): frame time, and how closely each draws the CPU path's image; on
llvmpipe the ratio shows the work removed, not a GPU's speed. Every timed
frame casts every ray (LocalizedUpdates off: a frame in which nothing
changed would only show the kept image).

A start is a new process (as a new start of the application), rendering the
analytic cut cube of ``analyticscene.py`` on the GPU path; its build time is
the mapper's ``GetLastProgramBuildTime()``: compile and link (or loading the
cached binary) and the program's first image, as drivers may compile the
machine code at the first draw (Mesa's llvmpipe does). Mesa keeps a shader
cache of its own (``MESA_SHADER_CACHE_DIR``), so each configuration gets
fresh folders for both caches, and the baseline (the first start with both
empty) is measured in the same run.
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from .harness import machine_description, measurement

WIDTH = 128

# Feature sets whose program size and cold build time are reported.
FEATURE_SETS = {
    "iso, 1 cut": {},
    "iso, 4 cuts": {"cuts": 4},
    "iso, ambient occlusion": {"occlusion": True},
    "iso, thin bone, 1 clip plane": {"thin_bone": True, "plane": True},
    "composite, 1 cut": {"composite": True},
}


def one_start(cache_directory: str, use_cache: bool, features: dict) -> dict:
    """In this process: render the cut cube once on the GPU path, return the program's figures."""
    import time

    import slicer_volumecutting as vc
    import vtk

    from ..data import analyticscene as A

    scene = A.default_scene()
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(WIDTH, WIDTH)
    renderer = vtk.vtkRenderer()
    window.AddRenderer(renderer)
    renderer.SetActiveCamera(A.make_camera(scene, 2.0, WIDTH, WIDTH))
    mapper = vc.vtkVolumeCutVolumeMapper()
    mapper.SetInputData(scene.intensities())
    caster = mapper.GetRayCaster()
    caster.SetIsoValue(scene.iso_value())
    for _ in range(features.get("cuts", 1)):
        caster.AddCutField(scene.cut_field(1))
    caster.SetAmbientOcclusion(features.get("occlusion", False))
    caster.SetThinBoneShading(features.get("thin_bone", False))
    if features.get("plane"):
        planes = vtk.vtkPlaneCollection()
        plane = vtk.vtkPlane()
        plane.SetOrigin(*scene.center)
        plane.SetNormal(0.0, 0.0, -1.0)
        planes.AddItem(plane)
        mapper.SetClippingPlanes(planes)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetUserMatrix(scene.ijk_to_ras())
    if features.get("composite"):
        color = vtk.vtkColorTransferFunction()
        color.AddRGBPoint(0.0, 1.0, 1.0, 1.0)
        color.AddRGBPoint(1000.0, 1.0, 0.9, 0.8)
        opacity = vtk.vtkPiecewiseFunction()
        opacity.AddPoint(400.0, 0.0)
        opacity.AddPoint(1000.0, 0.5)
        volume.GetProperty().SetColor(color)
        volume.GetProperty().SetScalarOpacity(opacity)
        mapper.SetBlendMode(vtk.vtkVolumeMapper.COMPOSITE_BLEND)
    renderer.AddVolume(volume)
    gpu = mapper.GetOpenGLRayCaster()
    gpu.SetProgramCache(use_cache)
    mapper.SetProgramCacheDirectory(cache_directory)
    mapper.SetProgramBuildTimeLimit(600.0)
    mapper.SetRequestedRenderPath(vc.vtkVolumeCutVolumeMapper.GPUPath)
    start = time.perf_counter()
    window.Render()
    first_frame = time.perf_counter() - start
    start = time.perf_counter()
    window.Render()
    second_frame = time.perf_counter() - start
    return {
        "path": mapper.GetLastRenderPathAsString(),
        "reason": mapper.GetGPUFallbackReason(),
        "build_s": mapper.GetLastProgramBuildTime(),
        "loaded_from_cache": bool(gpu.GetLastProgramLoadedFromCache()),
        "first_frame_s": first_frame,
        "second_frame_s": second_frame,
        "fragment_characters": gpu.GetProgramSourceLength(),
        "features": gpu.GetProgramFeatures(),
        "driver": gpu.GetDriverDescription(),
        "parallel_compile": bool(gpu.GetParallelCompile()),
        "binary_formats": gpu.GetNumberOfProgramBinaryFormats(),
    }


def _start(mesa_cache: Path, our_cache: Path, use_cache: bool, features: dict) -> dict:
    """One start in a new process with these cache folders."""
    code = (
        "import json, sys; from VolumeCuttingLib.benchmarks import gpuprogram as p; "
        f"print('RESULT ' + json.dumps(p.one_start({str(our_cache)!r}, {use_cache!r}, {features!r})))"
    )
    environment = dict(os.environ, MESA_SHADER_CACHE_DIR=str(mesa_cache))
    environment.pop("MESA_SHADER_CACHE_DISABLE", None)
    environment["PYTHONPATH"] = os.pathsep.join([str(Path(__file__).resolve().parents[2]), environment.get("PYTHONPATH", "")])
    result = subprocess.run([sys.executable, "-c", code], env=environment, capture_output=True, text=True, timeout=900)
    lines = [line for line in result.stdout.splitlines() if line.startswith("RESULT ")]
    if result.returncode != 0 or not lines:
        raise RuntimeError(f"gpuprogram benchmark: a start failed ({result.returncode}): {result.stderr[-2000:]}")
    figures = json.loads(lines[-1][len("RESULT "):])
    if figures["path"] != "GPU":
        raise RuntimeError(f"gpuprogram benchmark: the GPU path did not draw: {figures['reason']}")
    return figures


def _image(array_kji) -> vtk.vtkImageData:
    import vtk
    from vtkmodules.util import numpy_support

    image = vtk.vtkImageData()
    image.SetDimensions(array_kji.shape[2], array_kji.shape[1], array_kji.shape[0])
    image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(np.ascontiguousarray(array_kji).ravel(), deep=True))
    return image


def _alternating_case(ct, labels, ijk_to_ras, repeats: int, switch: str, width: int = 256) -> dict:
    """GPU-path figures of one CT with its label map, the OpenGL caster's boolean ``switch`` off and on, frames
    alternating: NormalizedTextures (textures R32F or R16/R8), EmptySpaceSkipping (one block at a time or the CPU's skipping),
    HardwareFiltering (the texture unit interpolating the R16 CT or the shader's texel fetches)."""
    import time

    import slicer_volumecutting as vc
    import vtk
    from vtkmodules.util import numpy_support

    from .harness import finish_frame

    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(width, width)
    renderer = vtk.vtkRenderer()
    window.AddRenderer(renderer)
    mapper = vc.vtkVolumeCutVolumeMapper()
    mapper.SetInputData(_image(ct))
    caster = mapper.GetRayCaster()
    caster.SetIsoValue(300.0)
    caster.SetLabelMap(_image(labels.astype(np.uint16)))
    for label in range(1, int(labels.max()) + 1):
        caster.SetSegmentAppearance(label, (0.9, 0.85, 0.7), 1.0, 300.0)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    matrix = vtk.vtkMatrix4x4()
    matrix.DeepCopy(np.asarray(ijk_to_ras, dtype=float).ravel())
    volume.SetUserMatrix(matrix)
    renderer.AddVolume(volume)
    renderer.ResetCamera()
    renderer.GetActiveCamera().Azimuth(30.0)
    renderer.GetActiveCamera().Elevation(20.0)
    renderer.ResetCameraClippingRange()
    mapper.SetProgramBuildTimeLimit(600.0)
    mapper.SetRequestedRenderPath(vc.vtkVolumeCutVolumeMapper.GPUPath)
    gpu = mapper.GetOpenGLRayCaster()
    # Every frame casts every ray: a frame in which nothing changed would otherwise only show the kept image.
    gpu.LocalizedUpdatesOff()
    if switch == "NormalizedTextures":
        # The shader's texel fetches with either format: the row shows the format alone (R32F is never filtered).
        gpu.HardwareFilteringOff()
    figures = {normalized: {"frame_s": [], "frame_cpu_s": [], "upload_frame_s": [], "pixels_recast": []} for normalized in (False, True)}

    def frame():
        window.Modified()
        start, cpu = time.perf_counter(), time.process_time()
        window.Render()
        finish_frame(window)
        if mapper.GetLastRenderPath() != vc.vtkVolumeCutVolumeMapper.GPUPath:
            raise RuntimeError(f"gpuprogram benchmark: the GPU path did not draw: {mapper.GetGPUFallbackReason()}")
        return time.perf_counter() - start, time.process_time() - cpu

    # Both programs built before anything is timed.
    def turn(on):
        getattr(gpu, f"Set{switch}")(on)

    for normalized in (False, True):
        turn(normalized)
        frame()
    for _ in range(repeats):
        for normalized in (False, True):
            turn(normalized)
            figures[normalized]["upload_frame_s"].append(frame()[0])
            for _ in range(2):
                wall, cpu = frame()
                figures[normalized]["frame_s"].append(wall)
                figures[normalized]["frame_cpu_s"].append(cpu)
                figures[normalized]["pixels_recast"].append(gpu.GetNumberOfPixelsRecast())
            figures[normalized]["texture_bytes"] = gpu.GetTextureMemorySize()
            figures[normalized]["ct_bytes_per_voxel"] = gpu.GetAnatomyTextureBytesPerVoxel()
            figures[normalized]["label_bytes_per_voxel"] = gpu.GetLabelTextureBytesPerVoxel()
            figures[normalized]["features"] = gpu.GetProgramFeatures()
            figures[normalized]["ct_filtered"] = bool(gpu.GetAnatomyHardwareFiltered())
    # Whether each setting draws the CPU path's surfaces: pixels covered on one path only, and the largest depth
    # difference where both cover.
    def depth_image(path):
        mapper.SetRequestedRenderPath(path)
        window.Modified()
        window.Render()
        depth = vtk.vtkFloatArray()
        window.GetZbufferData(0, 0, width - 1, width - 1, depth)
        return numpy_support.vtk_to_numpy(depth).copy()

    cpu_depth = depth_image(vc.vtkVolumeCutVolumeMapper.CPUPath)
    agreement = {}
    for normalized in (False, True):
        turn(normalized)
        depth = depth_image(vc.vtkVolumeCutVolumeMapper.GPUPath)
        both = (depth < 1.0) & (cpu_depth < 1.0)
        agreement["on" if normalized else "off"] = {
            "pixels_covered_on_one_path_only": int(np.count_nonzero((depth < 1.0) != (cpu_depth < 1.0))),
            "largest_depth_difference": float(np.max(np.abs(depth - cpu_depth)[both], initial=0.0)),
        }
    return {
        "agreement_with_the_cpu_path": agreement,
        "switch": switch,
        "filter_weight_error": gpu.GetFilterWeightError(),
        "dimensions": [int(ct.shape[2]), int(ct.shape[1]), int(ct.shape[0])],
        "window": [width, width],
        "driver": gpu.GetDriverDescription(),
        "off": figures[False],
        "on": figures[True],
    }


def _cases():
    from ..data import headct, patientscale

    head, _, head_ijk_to_ras = headct.load_array()
    patient = patientscale.generate(head=(head, head_ijk_to_ras))
    return {
        "head CT": (head, (head >= 300).astype(np.uint8), head_ijk_to_ras),
        "patient-scale case": (patient.ct, patient.labels, patient.ijk_to_ras),
    }


def texture_formats(repeats: int, cases: dict) -> list[dict]:
    results = []
    for name, (ct, labels, ijk_to_ras) in cases.items():
        figures = _alternating_case(ct, labels, ijk_to_ras, repeats, "NormalizedTextures")
        figures["float"], figures["normalized"] = figures.pop("off"), figures.pop("on")
        driver = figures["driver"]
        machine = machine_description(driver.split(", OpenGL")[0])
        size = " x ".join(str(d) for d in figures["dimensions"])
        new, old = figures["normalized"], figures["float"]
        memory = measurement(
            f"{name} ({size}) on the GPU path: texture memory, CT as R16 and labels as R8",
            new["texture_bytes"] / 2**20, "MiB", "the same with CT and labels as R32F (NormalizedTextures off)",
            old["texture_bytes"] / 2**20, 1, machine)
        frame = measurement(
            f"{name} ({size}) on the GPU path: frame time, CT as R16 and labels as R8 ({driver.split(',')[0]}, a proxy only)",
            statistics.median(new["frame_s"]), "s", "the same frames with CT and labels as R32F, alternating in the same process",
            statistics.median(old["frame_s"]), repeats, machine)
        for result in (memory, frame):
            result["details"] = figures
        results += [memory, frame]
    return results


def texture_filtering(repeats: int) -> list[dict]:
    """GPU-path frame time on the head CT, its R16 CT interpolated by the texture unit against the shader's texel fetches."""
    from ..data import headct

    head, _, head_ijk_to_ras = headct.load_array()
    load_before = os.getloadavg()
    figures = _alternating_case(head, (head >= 300).astype(np.uint8), head_ijk_to_ras, repeats, "HardwareFiltering")
    figures["load_average"] = {"before": [round(v, 2) for v in load_before], "after": [round(v, 2) for v in os.getloadavg()]}
    if not figures["on"]["ct_filtered"]:
        raise RuntimeError(f"gpuprogram benchmark: the CT was not filtered ({figures['on']['features']}, "
                           f"interpolation error {figures['filter_weight_error']})")
    driver = figures["driver"]
    machine = machine_description(driver.split(", OpenGL")[0])
    size = " x ".join(str(d) for d in figures["dimensions"])
    results = []
    for key, what in (("frame_s", "frame time"), ("frame_cpu_s", "processor time a frame")):
        result = measurement(
            f"head CT ({size}) on the GPU path: {what}, R16 CT interpolated by the texture unit ({driver.split(',')[0]}: "
            "shader work removed, not GPU speed)",
            statistics.median(figures["on"][key]), "s",
            "the same frames with the shader's eight texel fetches a sample (HardwareFiltering off), alternating in the same process",
            statistics.median(figures["off"][key]), repeats, machine)
        result["details"] = figures
        results.append(result)
    return results


def empty_space_skipping(repeats: int, cases: dict) -> list[dict]:
    """The GPU path's frame time with the CPU's empty-space skipping (cell walk, reach and cavity jumps, exact
    hidden-border test) against one empty block at a time (EmptySpaceSkipping off, the GPU path before it), frames
    alternating in one process. llvmpipe rasterizes on the CPU: the ratio shows the work removed, not a GPU's speed."""
    results = []
    for name, (ct, labels, ijk_to_ras) in cases.items():
        figures = _alternating_case(ct, labels, ijk_to_ras, repeats, "EmptySpaceSkipping")
        driver = figures["driver"]
        machine = machine_description(driver.split(", OpenGL")[0])
        size = " x ".join(str(d) for d in figures["dimensions"])

        figures["cell_texture_mib"] = float(np.prod([(d - 1 + 1) // 2 for d in figures["dimensions"]])) / 2**20
        new, old = figures["on"], figures["off"]
        for key, what in (("frame_s", "wall-clock"), ("frame_cpu_s", "processor time (llvmpipe's threads included)")):
            result = measurement(
                f"{name} ({size}) on the GPU path, iso-surface: frame time ({what}), CPU's empty-space skipping "
                f"({driver.split(',')[0]}, the work removed, not a GPU's speed)",
                statistics.median(new[key]), "s",
                "the same frames skipping one empty block at a time (EmptySpaceSkipping off), alternating in the same process",
                statistics.median(old[key]), repeats, machine)
            result["details"] = figures
            results.append(result)
    return results


def gpuprogram(repeats: int) -> list[dict]:
    runs = {"first": [], "cached": [], "mesa_only": [], "ours_only": []}
    for _ in range(repeats):
        with tempfile.TemporaryDirectory() as folder:
            root = Path(folder)
            mesa, ours, fresh_mesa = root / "mesa", root / "programs", root / "mesa-fresh"
            runs["first"].append(_start(mesa, ours, True, {}))
            runs["cached"].append(_start(mesa, ours, True, {}))
            runs["mesa_only"].append(_start(mesa, ours, False, {}))
            runs["ours_only"].append(_start(fresh_mesa, ours, True, {}))
    features = {}
    for name, feature_set in FEATURE_SETS.items():
        with tempfile.TemporaryDirectory() as folder:
            figures = _start(Path(folder) / "mesa", Path(folder) / "programs", True, feature_set)
        features[name] = {key: figures[key] for key in ("features", "fragment_characters", "build_s", "second_frame_s")}
    driver = runs["first"][0]["driver"]
    machine = machine_description(driver.split(", OpenGL")[0])
    machine["driver"] = driver

    def median(kind, key="build_s"):
        return statistics.median(run[key] for run in runs[kind])

    first = median("first")
    baseline = "first start on the same driver: both caches empty (our program cache and Mesa's shader cache in fresh folders), same run"
    details = {
        "driver": driver,
        "parallel_compile": runs["first"][0]["parallel_compile"],
        "program_binary_formats": runs["first"][0]["binary_formats"],
        "scene": f"analytic cut cube 64^3, one cut field, {WIDTH}x{WIDTH}, GPU path requested",
        "build_s": {kind: [round(run["build_s"], 4) for run in values] for kind, values in runs.items()},
        "loaded_from_cache": {kind: [run["loaded_from_cache"] for run in values] for kind, values in runs.items()},
        "first_frame_s": {kind: round(median(kind, "first_frame_s"), 4) for kind in runs},
        "next_frame_s": round(median("first", "second_frame_s"), 4),
        "feature_sets": features,
    }
    results = [
        measurement("second start, program binary from our on-disk cache and Mesa's shader cache warm: build + first image",
                    median("cached"), "s", baseline, first, repeats, machine),
        measurement("second start, our program cache off, Mesa's shader cache warm: build + first image",
                    median("mesa_only"), "s", baseline, first, repeats, machine),
        measurement("second start, program binary from our cache, Mesa's shader cache empty: build + first image",
                    median("ours_only"), "s", baseline, first, repeats, machine),
    ]
    for result in results:
        result["details"] = details
    cases = _cases()
    return results + texture_formats(repeats, cases) + texture_filtering(repeats) + empty_space_skipping(repeats, cases)
