"""The CT, the labels and the cut fields on the GPU: 16-bit (or 8-bit) textures wherever that loses nothing.

vtkVolumeCutOpenGLRayCaster uploads a CT whose values are integers spanning at
most 65536 values as R16 (value - minimum), the labels as R8 or R16 and each
cut field's brick atlas (whole quanta) as R16 (value + 32768); the shader
turns each texel back into the float the CPU holds. So the image must be the
one R32F textures give (NormalizedTexturesOff), pixel for pixel, when the
shader interpolates (HardwareFilteringOff), and the CPU path's image within
the mapper tests' tolerance when the texture unit does (the default,
test_volume_cut_gpu_filtering.py); any other CT stays R32F. Rendered with
whatever OpenGL VTK gives offscreen (Mesa llvmpipe here).
"""

import numpy as np
import pytest
import slicer_volumecutting as vc
import vtk
from test_volume_cut_mapper import add_cut_volume, read_window, render_window
from vtk.util import numpy_support

from VolumeCuttingLib.data import analyticscene as A

GPU = vc.vtkVolumeCutVolumeMapper.GPUPath
CPU = vc.vtkVolumeCutVolumeMapper.CPUPath
WIDTH = 48


@pytest.fixture(scope="module")
def scene():
    return A.default_scene(32)


@pytest.fixture(scope="module")
def program_cache(tmp_path_factory):
    """One folder of program binaries for the module: each program is compiled once."""
    return tmp_path_factory.mktemp("programs")


def cube_values(scene, scale, offset):
    """The analytic cube (0, 500, 1000) scaled and shifted, with an integer ripple of +-5 everywhere (k, j, i)."""
    n = scene.dimensions
    values = numpy_support.vtk_to_numpy(scene.intensities().GetPointData().GetScalars()).reshape(n, n, n).astype(float)
    k, j, i = np.meshgrid(np.arange(n), np.arange(n), np.arange(n), indexing="ij")
    ripple = (7 * i + 3 * j + 5 * k) % 11 - 5
    return scale * values + offset + ripple, scale * 500.0 + offset


def image_of(values, dtype=None):
    values = np.asarray(values, dtype=dtype)
    n = values.shape[0]
    image = vtk.vtkImageData()
    image.SetDimensions(n, n, n)
    image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(values.ravel(), deep=True))
    return image


def cut_view(scene, ct, iso, program_cache, labels=None, width=WIDTH, cut=None):
    """A window showing the cube of ``ct`` (vtkImageData) at ``iso``, cut by ``cut`` (default: the scene's cut).

    Segments 1 and 2 of ``labels`` are shown if given.
    """
    window, renderer = render_window(width)
    renderer.SetActiveCamera(A.make_camera(scene, 1.5, width, width))
    mapper, _ = add_cut_volume(scene, ct, cut or scene.cut_field(1), renderer)
    caster = mapper.GetRayCaster()
    caster.SetIsoValue(iso)
    if labels is not None:
        caster.SetLabelMap(labels)
        first, second = int(labels.GetPointData().GetScalars().GetRange()[0]), int(labels.GetPointData().GetScalars().GetRange()[1])
        caster.SetSegmentAppearance(first, (0.9, 0.9, 0.8), 1.0, iso)
        caster.SetSegmentAppearance(second, (0.8, 0.3, 0.2), 1.0, iso)
    mapper.SetProgramCacheDirectory(str(program_cache))
    return window, mapper


def draw(window, mapper, path, width=WIDTH):
    mapper.SetRequestedRenderPath(path)
    window.Render()
    assert mapper.GetLastRenderPath() == path, mapper.GetGPUFallbackReason()
    return read_window(window, width)


def assert_like_cpu(window, mapper, gpu_image):
    """The mapper tests' stated tolerance: depth within 1e-4, colour within 2 levels but for 0.5 % of the pixels.

    Where the rippled CT's silhouette is grazed, a ray can stay above the
    iso-value for less than a refined sub-interval (here 0.01 mm against
    0.016 mm): whether a sub-sample falls in it turns on micrometres (the
    GPU's samples shifted by 3e-6 mm miss it too), float against double. Such
    a rim pixel may be covered on one path only, at most 0.1 % of them.
    """
    assert_images_agree(draw(window, mapper, CPU), gpu_image)


def assert_images_agree(cpu_image, gpu_image):
    """assert_like_cpu's tolerance for two (depth, colour) images already drawn."""
    cpu_depth, cpu_color = cpu_image
    gpu_depth, gpu_color = gpu_image
    assert np.any(cpu_depth < 1.0)
    both = (cpu_depth < 1.0) & (gpu_depth < 1.0)
    assert np.count_nonzero((cpu_depth < 1.0) != (gpu_depth < 1.0)) <= 0.001 * cpu_depth.size
    assert np.max(np.abs(cpu_depth - gpu_depth)[both]) < 1e-4
    assert np.mean(np.max(np.abs(cpu_color - gpu_color), axis=2) > 2) < 0.005


def assert_same_image(expected, drawn):
    for a, b in zip(expected, drawn):
        assert np.array_equal(a, b)


def both_formats(window, mapper):
    """The GPU image with NormalizedTextures on, then off, interpolated by the shader (HardwareFiltering off, so
    that the 16-bit texels must give the very floats): images, CT bytes per voxel, program features."""
    gpu = mapper.GetOpenGLRayCaster()
    gpu.HardwareFilteringOff()
    results = []
    for normalized in (True, False):
        gpu.SetNormalizedTextures(normalized)
        image = draw(window, mapper, GPU)
        results.append((image, gpu.GetAnatomyTextureBytesPerVoxel(), gpu.GetProgramFeatures(), gpu.GetTextureMemorySize()))
    gpu.NormalizedTexturesOn()
    gpu.HardwareFilteringOn()
    return results


def filtering_allowed(gpu):
    """Whether this context's texture unit interpolates finely enough to filter (llvmpipe does, 8-bit GPUs do not)."""
    return 0.0 <= gpu.GetFilterWeightError() <= gpu.GetMaximumFilterWeightError()


def assert_filtered_like_cpu(window, mapper):
    """The default GPU image, the 16-bit CT interpolated by the texture unit where allowed, within the CPU path's tolerance."""
    image = draw(window, mapper, GPU)
    gpu = mapper.GetOpenGLRayCaster()
    assert gpu.GetAnatomyHardwareFiltered() == filtering_allowed(gpu)
    assert_like_cpu(window, mapper, image)


# (type, scale, offset): HU-like values for the wide types, what fits for the narrow ones;
# unsigned short far from 0 so that the minimum subtracted matters.
INTEGER_CTS = [
    (np.int16, 1.5, -1024.0),
    (np.uint16, 1.5, 40000.0),
    (np.int32, 1.5, -1024.0),
    (np.int8, 0.2, -100.0),
    (np.uint8, 0.2, 20.0),
    (np.float32, 1.5, -1024.0),
    (np.float64, 1.5, -1024.0),
]


@pytest.mark.parametrize("dtype, scale, offset", INTEGER_CTS, ids=[t[0].__name__ for t in INTEGER_CTS])
def test_an_integer_ct_travels_as_16_bits_and_draws_what_floats_draw(scene, program_cache, dtype, scale, offset):
    values, iso = cube_values(scene, scale, offset)
    window, mapper = cut_view(scene, image_of(values, dtype), iso, program_cache)
    (unorm, unorm_bytes, unorm_features, unorm_memory), (floats, float_bytes, float_features, float_memory) = both_formats(
        window, mapper)
    assert unorm_bytes == 2 and unorm_features.endswith(" ct16 cut16")
    assert float_bytes == 4 and "ct16" not in float_features and "cut16" not in float_features
    # Two bytes a voxel of the CT, two a texel of the cut field's atlas.
    atlas_texels = mapper.GetOpenGLRayCaster().GetCutAtlasTextureSize()
    assert float_memory - unorm_memory == 2 * scene.dimensions**3 + 2 * atlas_texels
    assert_same_image(floats, unorm)
    assert_like_cpu(window, mapper, unorm)
    assert_filtered_like_cpu(window, mapper)


def test_the_16_bit_ct_composites_what_floats_composite(scene, program_cache):
    values, iso = cube_values(scene, 1.5, -1024.0)
    window, mapper = cut_view(scene, image_of(values, np.int16), iso, program_cache)
    color = vtk.vtkColorTransferFunction()
    color.AddRGBPoint(-1024.0, 1.0, 1.0, 1.0)
    color.AddRGBPoint(600.0, 1.0, 0.9, 0.8)
    opacity = vtk.vtkPiecewiseFunction()
    opacity.AddPoint(-600.0, 0.0)
    opacity.AddPoint(600.0, 0.4)
    volume = window.GetRenderers().GetFirstRenderer().GetVolumes().GetItemAsObject(0)
    volume.GetProperty().SetColor(color)
    volume.GetProperty().SetScalarOpacity(opacity)
    mapper.SetBlendMode(vtk.vtkVolumeMapper.COMPOSITE_BLEND)
    (unorm, unorm_bytes, unorm_features, _), (floats, float_bytes, _, _) = both_formats(window, mapper)
    assert (unorm_bytes, float_bytes) == (2, 4) and unorm_features == "cuts=1 composite ct16 cut16"
    assert np.any(unorm[1][..., 3] > 0)
    assert_same_image(floats, unorm)


@pytest.mark.parametrize("span, bytes_per_voxel", [(65535, 2), (65536, 4)])
def test_16_bits_hold_at_most_65536_values(scene, program_cache, span, bytes_per_voxel):
    """The lowest and highest values span+1 values apart, in corners away from the cube."""
    values, iso = cube_values(scene, 1.5, -1024.0)
    values[0, 0, 0] = -32768.0
    values[-1, -1, -1] = -32768.0 + span
    window, mapper = cut_view(scene, image_of(values, np.int32), iso, program_cache)
    (first, first_bytes, _, _), (floats, _, _, _) = both_formats(window, mapper)
    assert first_bytes == bytes_per_voxel
    assert_same_image(floats, first)
    assert_like_cpu(window, mapper, first)


@pytest.mark.parametrize("largest, bytes_per_voxel", [(2, 1), (300, 2)])
def test_labels_travel_as_8_or_16_bits(scene, program_cache, largest, bytes_per_voxel):
    """A shell (label 1) around a core (label ``largest``): R8 while labels fit in a byte, R16 above."""
    n = scene.dimensions
    index = np.arange(n) - (n - 1) / 2.0
    depth = scene.half_size_voxels - np.max(np.abs(np.stack(np.meshgrid(index, index, index, indexing="ij"))), axis=0)
    labels = image_of(np.where(depth >= 3.0, largest, 1), np.uint16)
    values, iso = cube_values(scene, 1.5, -1024.0)
    window, mapper = cut_view(scene, image_of(values, np.int16), iso, program_cache, labels=labels)
    gpu = mapper.GetOpenGLRayCaster()
    gpu.HardwareFilteringOff()
    unorm = draw(window, mapper, GPU)
    assert gpu.GetLabelTextureBytesPerVoxel() == bytes_per_voxel
    assert gpu.GetAnatomyTextureBytesPerVoxel() == 2
    memory = gpu.GetTextureMemorySize()
    gpu.NormalizedTexturesOff()
    floats = draw(window, mapper, GPU)
    assert gpu.GetLabelTextureBytesPerVoxel() == 4
    assert gpu.GetTextureMemorySize() - memory == (2 + 4 - bytes_per_voxel) * n**3 + 2 * gpu.GetCutAtlasTextureSize()
    assert_same_image(floats, unorm)
    # Both segments are in the picture (the core through the cut).
    colors = unorm[1][unorm[1][..., 3] > 0]
    assert np.any(colors[:, 0] > 1.5 * colors[:, 2]) and np.any(colors[:, 0] < 1.5 * colors[:, 2])
    gpu.NormalizedTexturesOn()
    assert_like_cpu(window, mapper, draw(window, mapper, GPU))
    gpu.HardwareFilteringOn()
    assert_filtered_like_cpu(window, mapper)


def test_a_ct_with_fractional_values_stays_32_bit_float(scene, program_cache):
    values, iso = cube_values(scene, 1.5, -1024.0)
    window, mapper = cut_view(scene, image_of(values, np.float32), iso, program_cache)
    gpu = mapper.GetOpenGLRayCaster()
    draw(window, mapper, GPU)
    assert gpu.GetAnatomyTextureBytesPerVoxel() == 2
    # The same mapper given values a tenth apart: the CT goes back to R32F.
    n = scene.dimensions
    tenths = 0.1 * (np.arange(n**3).reshape(n, n, n) % 7)
    mapper.SetInputData(image_of(values + tenths, np.float32))
    drawn = draw(window, mapper, GPU)
    assert gpu.GetAnatomyTextureBytesPerVoxel() == 4 and "ct16" not in gpu.GetProgramFeatures()
    assert_like_cpu(window, mapper, drawn)
    gpu.NormalizedTexturesOff()
    assert_same_image(drawn, draw(window, mapper, GPU))
    gpu.NormalizedTexturesOn()
    # One fractional voxel, or one NaN, is enough.
    for odd in (0.5, np.nan):
        one = values.copy()
        one[-1, 0, -1] = odd
        mapper.SetInputData(image_of(one, np.float32))
        draw(window, mapper, GPU)
        assert gpu.GetAnatomyTextureBytesPerVoxel() == 4


def test_integers_shifted_by_a_common_fraction_are_16_bits_too(scene, program_cache):
    """Values minimum + k (k integer) are what R16 holds: a rescale intercept of 0.25 costs nothing."""
    values, iso = cube_values(scene, 1.5, -1024.25)
    window, mapper = cut_view(scene, image_of(values, np.float32), iso, program_cache)
    (unorm, unorm_bytes, _, _), (floats, float_bytes, _, _) = both_formats(window, mapper)
    assert (unorm_bytes, float_bytes) == (2, 4)
    assert_same_image(floats, unorm)
    assert_like_cpu(window, mapper, unorm)
    assert_filtered_like_cpu(window, mapper)


@pytest.mark.parametrize("with_label_map", [False, True])
def test_fractions_travel_as_16_bits_within_the_stated_tolerance(scene, program_cache, with_label_map):
    """Fractions are not integers: RGBA16 holds each within 1/131070, and the image stays within the mapper tests' tolerance."""
    from test_volume_cut_mapper import sphere_segment

    n = scene.dimensions
    fraction, binary = sphere_segment(n, tuple(scene.center / scene.spacing + [0.3, -0.2, 0.1]), 9.0)
    values, iso = cube_values(scene, 1.5, -1024.0)
    window, mapper = cut_view(scene, image_of(values, np.int16), iso, program_cache)
    caster = mapper.GetRayCaster()
    if with_label_map:
        caster.SetLabelMap(binary)
    caster.SetSegmentFraction(1, fraction)
    caster.SetSegmentAppearance(1, (0.2, 0.6, 0.9), 1.0, float("nan"))
    gpu = mapper.GetOpenGLRayCaster()
    gpu.HardwareFilteringOff()
    unorm = draw(window, mapper, GPU)
    assert gpu.GetFractionTextureBytesPerVoxel() == 8
    memory = gpu.GetTextureMemorySize()
    gpu.NormalizedTexturesOff()
    floats = draw(window, mapper, GPU)
    assert gpu.GetFractionTextureBytesPerVoxel() == 16
    assert gpu.GetTextureMemorySize() - memory == (2 + (3 if with_label_map else 0) + 8) * n**3 + 2 * gpu.GetCutAtlasTextureSize()
    gpu.NormalizedTexturesOn()
    assert np.any(unorm[0] < 1.0)
    assert np.array_equal(unorm[0] < 1.0, floats[0] < 1.0)
    assert np.max(np.abs(unorm[0] - floats[0])) < 1e-4
    assert np.mean(np.max(np.abs(unorm[1] - floats[1]), axis=2) > 2) < 0.005
    print("RGBA16 against RGBA32F fractions: depth differs by at most", np.max(np.abs(unorm[0] - floats[0])),
          "on", np.count_nonzero(unorm[0] != floats[0]), "pixels; colour by at most", np.max(np.abs(unorm[1] - floats[1])))
    assert_like_cpu(window, mapper, draw(window, mapper, GPU))
    gpu.HardwareFilteringOn()
    assert_filtered_like_cpu(window, mapper)
    assert gpu.GetFractionsHardwareFiltered() == filtering_allowed(gpu)


def test_a_cut_fields_atlas_travels_as_16_bits_exactly_before_and_after_a_stroke(scene, program_cache):
    """A fractional CT stays float, so the memory saved is the atlas's alone: two bytes a texel."""
    values, iso = cube_values(scene, 1.5, -1024.0)
    n = scene.dimensions
    fractional = values + 0.1 * (np.arange(n**3).reshape(n, n, n) % 7)
    cut = scene.cut_field(1)
    window, mapper = cut_view(scene, image_of(fractional, np.float32), iso, program_cache, cut=cut)
    gpu = mapper.GetOpenGLRayCaster()
    for stroke in range(2):
        (unorm, unorm_features, unorm_memory, unorm_atlas), (floats, float_features, float_memory, float_atlas) = [
            (draw(window, mapper, GPU), gpu.GetProgramFeatures(), gpu.GetTextureMemorySize(), gpu.GetCutAtlasTextureBytesPerVoxel())
            for normalized in (True, False) if gpu.SetNormalizedTextures(normalized) is None
        ]
        gpu.NormalizedTexturesOn()
        assert (unorm_atlas, float_atlas) == (2, 4)
        assert unorm_features == "cuts=1 iso cut16" and float_features == "cuts=1 iso"
        assert gpu.GetCutAtlasTextureSize() > 0 and float_memory - unorm_memory == 2 * gpu.GetCutAtlasTextureSize()
        assert_same_image(floats, unorm)
        assert_like_cpu(window, mapper, unorm)
        # A burr stroke through the visible top face: only its bricks travel, as shorts.
        top = scene.center + np.array([0.1, -0.1, 1.0]) * scene.half_size
        cut.CutCapsule(list(top), list(top + [0.5, 0.3, -0.4]), 0.8)


def test_the_cut_atlas_draws_the_cut_the_cpu_draws_at_every_stored_distance(scene, program_cache):
    """Distances of every sign and size the field stores: a mismatch anywhere moves the cut surface."""
    values, iso = cube_values(scene, 1.5, -1024.0)
    cut = scene.cut_field(1)
    window, mapper = cut_view(scene, image_of(values, np.int16), iso, program_cache, cut=cut)
    gpu = mapper.GetOpenGLRayCaster()
    rng = np.random.default_rng(7)
    for _ in range(6):
        start = scene.center + rng.uniform(-1.0, 1.0, 3) * scene.half_size
        cut.CutCapsule(list(start), list(start + rng.uniform(-1.0, 1.0, 3)), rng.uniform(0.3, 1.2))
    drawn = draw(window, mapper, GPU)
    assert gpu.GetCutAtlasTextureBytesPerVoxel() == 2
    assert_like_cpu(window, mapper, drawn)
