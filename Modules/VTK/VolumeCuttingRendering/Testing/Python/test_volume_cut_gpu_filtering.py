"""The CT and fractions interpolated by the texture unit (HardwareFiltering) where that keeps the stated accuracy.

vtkVolumeCutOpenGLRayCaster samples a 16-bit normalized CT (R16) and 16-bit
fractions (RGBA16) with GL_LINEAR at (index + 0.5) / dimensions: one fetch
where the shader's own trilinear interpolation takes eight, where the texture
unit interpolates finely enough (its measured FilterWeightError within
MaximumFilterWeightError, 2^-16). Mesa's llvmpipe, which runs these tests,
filters with float weights. GPUs weight texels in fixed point (NVIDIA: 8
fraction bits, weights rounded to the nearest 1/256), so the filtered value
is the CPU's trilinear value at a point at most 2^-9 voxel away along each
axis: a surface moves by at most sqrt(3) 2^-9 voxel. Those weights are
emulated on any driver by EmulatedFilterWeightBits (the shader's own
interpolation with its weights rounded as a texture unit rounds them).
Compared with the CPU path at the mapper tests' stated tolerance and with an
exact sphere.
"""

import math

import numpy as np
import pytest
import slicer_volumecutting as vc
import vtk
from test_volume_cut_gpu_textures import assert_images_agree, draw, image_of
from test_volume_cut_mapper import add_cut_volume, look_down_z, render_window, set_transfer_functions, sphere_segment
from vtk.util import numpy_support

from VolumeCuttingLib.data import analyticscene as A

GPU = vc.vtkVolumeCutVolumeMapper.GPUPath
CPU = vc.vtkVolumeCutVolumeMapper.CPUPath

# How far a texture unit with 8-bit weights may move a surface (voxels).
EIGHT_BIT_SHIFT = math.sqrt(3.0) * 2.0**-9


@pytest.fixture(scope="module")
def scene():
    return A.default_scene()


@pytest.fixture(scope="module")
def program_cache(tmp_path_factory):
    return tmp_path_factory.mktemp("programs")


def integer_ct(scene):
    """The analytic cut cube's CT rounded to integers (int16): what R16 holds without loss, so the texture unit filters it."""
    values = numpy_support.vtk_to_numpy(scene.intensities().GetPointData().GetScalars())
    n = scene.dimensions
    return image_of(np.rint(values).reshape(n, n, n), np.int16)


def parity_view(scene, width, pixels_per_voxel, program_cache, cut_factor=2):
    window, renderer = render_window(width)
    renderer.SetActiveCamera(A.make_camera(scene, pixels_per_voxel, width, width))
    mapper, _ = add_cut_volume(scene, integer_ct(scene), scene.cut_field(cut_factor), renderer)
    mapper.SetProgramCacheDirectory(str(program_cache))
    return window, mapper


def filters_by_default(gpu):
    """Whether the caster filters in this context: on Mesa's llvmpipe (float weights) it must."""
    error, maximum = gpu.GetFilterWeightError(), gpu.GetMaximumFilterWeightError()
    if "llvmpipe" in gpu.GetDriverDescription():
        assert 0.0 <= error < 1e-6
    return 0.0 <= error <= maximum


def filtered_and_exact(window, mapper, width):
    """The GPU image with HardwareFiltering on (the default), then off; the setting is left on."""
    gpu = mapper.GetOpenGLRayCaster()
    assert gpu.GetHardwareFiltering()
    filtered = draw(window, mapper, GPU, width)
    if not filters_by_default(gpu):
        pytest.skip(f"this driver's texture unit interpolates with an error of {gpu.GetFilterWeightError()}: not filtered")
    filtered_state = (gpu.GetAnatomyHardwareFiltered(), gpu.GetFractionsHardwareFiltered(), gpu.GetProgramFeatures())
    gpu.HardwareFilteringOff()
    exact = draw(window, mapper, GPU, width)
    assert not gpu.GetAnatomyHardwareFiltered() and not gpu.GetFractionsHardwareFiltered()
    assert "filtered" not in gpu.GetProgramFeatures()
    gpu.HardwareFilteringOn()
    return filtered, exact, filtered_state


def assert_within_tolerance(cpu, gpu):
    """The mapper tests' stated CPU/GPU tolerance: depth within 1e-4, colour within 2 levels but for 0.5 % of the
    pixels; a silhouette pixel a ray grazes for less than a refined sub-interval may be covered on one path only
    (float against double), at most 0.1 % of them (test_volume_cut_gpu_textures.assert_like_cpu)."""
    assert_images_agree(cpu, gpu)


def report(name, filtered, exact, cpu):
    def differences(a, b):
        both = (a[0] < 1.0) & (b[0] < 1.0)
        over = np.mean(np.max(np.abs(a[1] - b[1]), axis=2) > 2)
        return f"depth max {np.max(np.abs(a[0][both] - b[0][both]), initial=0.0):.2e}, {100 * over:.2f} % pixels over 2/255"

    print(f"{name}: filtered vs CPU: {differences(filtered, cpu)}; exact vs CPU: {differences(exact, cpu)};"
          f" filtered vs exact: {differences(filtered, exact)}")


def test_the_filtered_cut_cube_is_the_cpu_image_within_the_stated_tolerance(scene, program_cache):
    width = 96
    window, mapper = parity_view(scene, width, 8.0, program_cache)
    filtered, exact, (ct_filtered, _, features) = filtered_and_exact(window, mapper, width)
    assert ct_filtered and features.endswith(" ct16 cut16 ct-filtered")
    cpu = draw(window, mapper, CPU, width)
    report("cut cube, 8 pixels per voxel", filtered, exact, cpu)
    assert np.array_equal(cpu[0] < 1.0, filtered[0] < 1.0)
    assert_within_tolerance(cpu, filtered)
    # And exact on its own: cut edges and silhouettes within half a pixel.
    matrix = A.world_to_ndc(window.GetRenderers().GetFirstRenderer().GetActiveCamera(), width, width)
    reference = A.exact_reference(scene, matrix, width, width, supersampling=4)
    points = A.depth_to_points(matrix, filtered[0].astype(float))
    classes = scene.classify_points(np.nan_to_num(points.reshape(-1, 3)), (filtered[0] < 1.0).ravel()).reshape(width, width)
    assert A.edge_errors(reference, classes).max(initial=0.0) <= 0.5


def test_the_filtered_cube_composites_like_the_cpu(program_cache):
    """test_gpu_and_cpu_paths_composite_the_same_image's scene and tolerance, the CT rounded to integers."""
    scene = A.default_scene(32)
    width = 64
    window, mapper = parity_view(scene, width, 2.0, program_cache, cut_factor=1)
    volume = window.GetRenderers().GetFirstRenderer().GetVolumes().GetItemAsObject(0)
    set_transfer_functions(volume, [(0.0, 1.0, 1.0, 1.0), (1000.0, 1.0, 0.9, 0.8)], [(400.0, 0.0), (1000.0, 0.5)])
    mapper.SetBlendMode(vtk.vtkVolumeMapper.COMPOSITE_BLEND)
    filtered, exact, (ct_filtered, _, features) = filtered_and_exact(window, mapper, width)
    assert ct_filtered and features == "cuts=1 composite ct16 cut16 ct-filtered"
    cpu = draw(window, mapper, CPU, width)
    report("composite cube", filtered, exact, cpu)
    assert np.mean(cpu[1][..., 3] > 0) > 0.2
    difference = np.max(np.abs(cpu[1] - filtered[1]), axis=2)
    assert np.mean(difference > 2) < 0.01
    assert difference.max() <= 12


@pytest.mark.parametrize("with_label_map", [False, True])
def test_filtered_fractions_place_segments_like_the_cpu(scene, program_cache, with_label_map):
    width = 48
    n = scene.dimensions
    fraction, binary = sphere_segment(n, tuple(scene.center / scene.spacing + [0.3, -0.2, 0.1]), 9.0)
    window, mapper = parity_view(scene, width, 1.0, program_cache, cut_factor=1)
    caster = mapper.GetRayCaster()
    if with_label_map:
        caster.SetLabelMap(binary)
    caster.SetSegmentFraction(1, fraction)
    caster.SetSegmentAppearance(1, (0.2, 0.6, 0.9), 1.0, float("nan"))
    filtered, exact, (ct_filtered, fractions_filtered, features) = filtered_and_exact(window, mapper, width)
    assert ct_filtered and fractions_filtered and "fractions-filtered" in features
    cpu = draw(window, mapper, CPU, width)
    report(f"fractional sphere{' with a label map' if with_label_map else ''}", filtered, exact, cpu)
    assert np.any(cpu[0] < 1.0)
    assert np.array_equal(cpu[0] < 1.0, filtered[0] < 1.0)
    assert_within_tolerance(cpu, filtered)


def test_the_texture_unit_is_measured_and_filters_only_within_the_maximum_error(scene, program_cache):
    window, mapper = parity_view(scene, 32, 1.0, program_cache, cut_factor=1)
    gpu = mapper.GetOpenGLRayCaster()
    assert gpu.GetFilterWeightError() == -1.0  # before any Render
    assert gpu.GetMaximumFilterWeightError() == 2.0**-16
    draw(window, mapper, GPU, 32)
    error = gpu.GetFilterWeightError()
    print(f"texture unit interpolation error on {gpu.GetDriverDescription()}: {error:.3g} of a texel difference")
    assert gpu.GetAnatomyHardwareFiltered() == filters_by_default(gpu)
    if error <= 0.0:
        pytest.skip("the texture unit interpolates exactly, or cannot filter R16")
    # Allowed less than that error, the texture unit is not used.
    gpu.SetMaximumFilterWeightError(0.5 * error)
    drawn = draw(window, mapper, GPU, 32)
    assert not gpu.GetAnatomyHardwareFiltered() and "filtered" not in gpu.GetProgramFeatures()
    assert gpu.GetFilterWeightError() == error  # measured once in a context
    assert_within_tolerance(draw(window, mapper, CPU, 32), drawn)
    gpu.SetMaximumFilterWeightError(error)
    draw(window, mapper, GPU, 32)
    assert gpu.GetAnatomyHardwareFiltered() and gpu.GetProgramFeatures().endswith(" ct-filtered")


def test_only_16_bit_normalized_textures_are_filtered(scene, program_cache):
    n = scene.dimensions
    window, mapper = parity_view(scene, 32, 1.0, program_cache, cut_factor=1)
    fraction, _ = sphere_segment(n, tuple(scene.center / scene.spacing), 9.0)
    mapper.GetRayCaster().SetSegmentFraction(1, fraction)
    mapper.GetRayCaster().SetSegmentAppearance(1, (0.2, 0.6, 0.9), 1.0, float("nan"))
    gpu = mapper.GetOpenGLRayCaster()
    assert not gpu.GetAnatomyHardwareFiltered()  # before any Render
    draw(window, mapper, GPU, 32)
    if not filters_by_default(gpu):
        pytest.skip(f"this driver's texture unit interpolates with an error of {gpu.GetFilterWeightError()}: not filtered")
    assert gpu.GetAnatomyTextureBytesPerVoxel() == 2 and gpu.GetAnatomyHardwareFiltered()
    assert gpu.GetFractionTextureBytesPerVoxel() == 8 and gpu.GetFractionsHardwareFiltered()
    # A CT with fractional values stays R32F and is never filtered; the fractions still are.
    values = numpy_support.vtk_to_numpy(integer_ct(scene).GetPointData().GetScalars()).astype(np.float32).reshape(n, n, n)
    values[n // 2, n // 2, n // 2] += 0.25
    mapper.SetInputData(image_of(values, np.float32))
    drawn = draw(window, mapper, GPU, 32)
    assert gpu.GetAnatomyTextureBytesPerVoxel() == 4
    assert not gpu.GetAnatomyHardwareFiltered() and gpu.GetFractionsHardwareFiltered()
    assert "ct-filtered" not in gpu.GetProgramFeatures() and "fractions-filtered" in gpu.GetProgramFeatures()
    assert_within_tolerance(draw(window, mapper, CPU, 32), drawn)
    # Float textures (NormalizedTextures off) are never filtered.
    mapper.SetInputData(integer_ct(scene))
    gpu.NormalizedTexturesOff()
    draw(window, mapper, GPU, 32)
    assert gpu.GetHardwareFiltering()
    assert not gpu.GetAnatomyHardwareFiltered() and not gpu.GetFractionsHardwareFiltered()
    assert "filtered" not in gpu.GetProgramFeatures()
    gpu.NormalizedTexturesOn()
    draw(window, mapper, GPU, 32)
    assert gpu.GetAnatomyHardwareFiltered() and gpu.GetFractionsHardwareFiltered()


# -- an exact sphere --------------------------------------------------------------------------
SPHERE_N, SPHERE_CENTER, SPHERE_RADIUS = 32, (15.3, 15.6, 15.2), 9.0


def sphere_view(program_cache, width=64):
    """A CT ramping from 0 to 1000 HU across 2 voxels around a sphere (integers, so R16), seen along z in parallel projection."""
    n, c, radius = SPHERE_N, SPHERE_CENTER, SPHERE_RADIUS
    z, y, x = np.meshgrid(np.arange(n) - c[2], np.arange(n) - c[1], np.arange(n) - c[0], indexing="ij")
    values = np.rint(1000.0 * np.clip(0.5 - (np.sqrt(x * x + y * y + z * z) - radius) / 2.0, 0.0, 1.0))
    window, renderer = render_window(width)
    camera = look_down_z(renderer.GetActiveCamera(), c, 11.0)
    mapper = vc.vtkVolumeCutVolumeMapper()
    mapper.SetInputData(image_of(values, np.int16))
    mapper.GetRayCaster().SetIsoValue(500.0)
    mapper.SetProgramCacheDirectory(str(program_cache))
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    renderer.AddVolume(volume)
    return window, mapper, A.world_to_ndc(camera, width, width)


def sphere_errors(matrix, depth):
    """Per pixel where the surface faces the camera (within 0.8 of the radius from the centre, so that a hit moved
    along the surface stays near its pixel): the hit's distance from the exact sphere and its depth error against
    it (voxels); NaN elsewhere."""
    points = A.depth_to_points(matrix, depth.astype(float))
    c = np.array(SPHERE_CENTER)
    radial = np.linalg.norm(points - c, axis=-1) - SPHERE_RADIUS
    r_xy = np.hypot(points[..., 0] - c[0], points[..., 1] - c[1])
    facing = r_xy < 0.8 * SPHERE_RADIUS
    exact_z = c[2] + np.sqrt(np.maximum(SPHERE_RADIUS**2 - r_xy**2, 0.0))
    return np.where(facing, radial, np.nan), np.where(facing, points[..., 2] - exact_z, np.nan)


def rms(values):
    return float(np.sqrt(np.nanmean(values**2)))


def test_a_sphere_moves_by_at_most_the_weights_precision(program_cache):
    """Each hit facing the camera lies at most sqrt(3) 2^-(bits + 1) voxel farther from the exact sphere than the
    exact path's hit of the same pixel: the texture unit's (float weights on llvmpipe) within float rounding, 8-bit
    weights within sqrt(3) 2^-9; 4-bit weights break that bound (so the measure sees such shifts) but keep theirs.
    With 8-bit weights the colour stays within the CPU/GPU tolerance; the depth does not at the silhouette, where a
    ray grazing the surface meets it far along for a tiny shift (measured, not asserted: 2 % of the pixels)."""
    width = 64
    window, mapper, matrix = sphere_view(program_cache, width)
    gpu = mapper.GetOpenGLRayCaster()
    images = {"default": draw(window, mapper, GPU, width)}
    filtered = gpu.GetAnatomyHardwareFiltered()
    assert filtered == filters_by_default(gpu)
    gpu.HardwareFilteringOff()
    images["exact"] = draw(window, mapper, GPU, width)
    for bits in (8, 4):
        gpu.SetEmulatedFilterWeightBits(bits)
        images[f"{bits}-bit weights"] = draw(window, mapper, GPU, width)
        assert gpu.GetProgramFeatures().endswith(f" ct16 weights={bits}")
    gpu.SetEmulatedFilterWeightBits(0)
    gpu.HardwareFilteringOn()
    images["cpu"] = draw(window, mapper, CPU, width)
    hit = images["exact"][0] < 1.0
    assert hit.sum() > 0.5 * math.pi * (SPHERE_RADIUS / 11.0 * width / 2) ** 2
    errors = {name: sphere_errors(matrix, image[0]) for name, image in images.items()}
    for name, (radial, depth) in errors.items():
        difference = np.abs(images[name][0] - images["cpu"][0])
        print(f"sphere, {name}{' (filtered)' if name == 'default' and filtered else ''}: radial error RMS {rms(radial):.5f}"
              f" max {np.nanmax(np.abs(radial)):.5f} voxels, depth RMS against the exact sphere {rms(depth):.5f} voxels;"
              f" window depth vs CPU max {np.max(difference):.2e}, over 1e-4 on {100 * np.mean(difference > 1e-4):.2f} %")
    exact = np.abs(errors["exact"][0])
    # Float rounding, the 2^-22-step bisection and the depth buffer stay far below this.
    slack = 2e-4
    shifts = {"8-bit weights": EIGHT_BIT_SHIFT}
    if filtered:
        shifts["default"] = math.sqrt(3.0) * gpu.GetFilterWeightError()
    for name, shift in shifts.items():
        image = images[name]
        assert np.array_equal(image[0] < 1.0, hit)
        assert np.nanmax(np.abs(errors[name][0]) - exact) <= shift + slack
        assert rms(errors[name][1]) <= rms(errors["exact"][1]) + shift + slack
        assert np.mean(np.max(np.abs(image[1] - images["cpu"][1]), axis=2) > 2) < 0.005
    if filtered:
        assert_within_tolerance(images["cpu"], images["default"])
    four = np.abs(errors["4-bit weights"][0]) - exact
    assert np.nanmax(four) > EIGHT_BIT_SHIFT + slack
    assert np.nanmax(four) <= math.sqrt(3.0) * 2.0**-5 + slack
