"""Adaptive multivolume ray casting: CPU reference and OpenGL path against exact geometry.

Every image is compared with a ray tracing of the true scene (VolumeCuttingLib
.analyticscene) or with the other implementation, never with a stored image.
The OpenGL path runs on whatever context VTK gives offscreen (Mesa llvmpipe
through EGL on CI), so images are kept small.
"""

import math

import numpy as np
import pytest
import slicer_volumecutting as vc
import vtk
from vtkmodules.util import numpy_support

from VolumeCuttingLib.data import analyticscene as A


class ErrorLog:
    """Collects the errors (and warnings) an object reports instead of printing them."""

    def __init__(self, obj, warnings=False):
        self.messages = []
        obj.AddObserver(vtk.vtkCommand.ErrorEvent, self._collect)
        if warnings:
            obj.AddObserver(vtk.vtkCommand.WarningEvent, self._collect)

    def _collect(self, caller, event, calldata=None):
        self.messages.append(str(calldata))

    _collect.CallDataType = vtk.VTK_STRING


def image_array(getter, height, width, components):
    image = vtk.vtkImageData()
    getter(image)
    values = numpy_support.vtk_to_numpy(image.GetPointData().GetScalars())
    return values.reshape(height, width, components) if components > 1 else values.reshape(height, width)


def cast(scene, intensities, cut, width, pixels_per_voxel=8.0, camera=None, configure=None):
    caster = vc.vtkVolumeCutRayCaster()
    caster.SetAnatomy(intensities, scene.ijk_to_ras())
    caster.SetIsoValue(scene.iso_value())
    if cut is not None:
        caster.AddCutField(cut)
    if configure:
        configure(caster)
    camera = camera or A.make_camera(scene, pixels_per_voxel, width, width)
    matrix = A.world_to_ndc(camera, width, width)
    assert caster.Render(matrix, width, width)
    return caster, matrix


def classes_from_depth(scene, matrix, depth):
    points = A.depth_to_points(matrix, depth.astype(float))
    valid = depth < 1.0
    classes = scene.classify_points(np.nan_to_num(points.reshape(-1, 3)), valid.ravel()).reshape(depth.shape)
    return points, classes


def test_cpu_reference_places_cut_edges_and_silhouettes_exactly(scene, intensities):
    width = 160
    cut = scene.cut_field(2)
    caster, matrix = cast(scene, intensities, cut, width)
    depth = image_array(caster.GetDepthImage, width, width, 1)
    normals = image_array(caster.GetNormalImage, width, width, 3).astype(float)
    reference = A.exact_reference(scene, matrix, width, width, supersampling=4)
    # The view must hold what is measured: background, cube faces and cuts.
    assert set(np.unique(reference.classes)) == {A.BACKGROUND, A.CUBE, A.CUT}
    _, classes = classes_from_depth(scene, matrix, depth)
    edges = A.edge_errors(reference, classes)
    assert edges.size < 0.01 * width * width
    assert edges.max(initial=0.0) <= 0.5  # pixels, at 8 pixels per voxel
    angles = A.normal_errors(reference, normals, classes)
    assert np.median(angles) <= 2.0
    assert np.percentile(angles, 95) <= 5.0
    # The border kinds are reported: cut surfaces by their field, faces as objects.
    sources = image_array(caster.GetSourceImage, width, width, 1)
    assert np.any(sources == vc.vtkVolumeCutRayCaster.SourceCutField)
    assert np.any(sources == vc.vtkVolumeCutRayCaster.SourceObject)


def test_whole_voxel_masking_misses_the_edges_the_field_places(scene, intensities):
    """The same metric detects the staircase of masking by whole voxels (the baseline)."""
    width = 160
    cut = scene.cut_field(2)
    masked = A.CubeScene.masked_intensities(intensities, cut)
    caster, matrix = cast(scene, masked, None, width)
    depth = image_array(caster.GetDepthImage, width, width, 1)
    reference = A.exact_reference(scene, matrix, width, width, supersampling=4)
    _, classes = classes_from_depth(scene, matrix, depth)
    assert A.edge_errors(reference, classes).max(initial=0.0) > 1.0


def render_window(width, height=None):
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(width, height or width)
    renderer = vtk.vtkRenderer()
    window.AddRenderer(renderer)
    return window, renderer


def render_on_both_paths(window, mapper, width):
    """The window's depth and colour drawn by the CPU path, then by the GPU path, keyed by path."""
    images = {}
    for path in (vc.vtkVolumeCutVolumeMapper.CPUPath, vc.vtkVolumeCutVolumeMapper.GPUPath):
        mapper.SetRequestedRenderPath(path)
        window.Render()
        assert mapper.GetLastRenderPath() == path, mapper.GetGPUFallbackReason()
        images[path] = read_window(window, width)
    return images


def add_cut_volume(scene, intensities, cut, renderer):
    mapper = vc.vtkVolumeCutVolumeMapper()
    mapper.SetInputData(intensities)
    mapper.GetRayCaster().SetIsoValue(scene.iso_value())
    if cut is not None:
        mapper.GetRayCaster().AddCutField(cut)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetUserMatrix(scene.ijk_to_ras())
    renderer.AddVolume(volume)
    return mapper, volume


def read_window(window, width, height=None):
    height = height or width
    depth = vtk.vtkFloatArray()
    window.GetZbufferData(0, 0, width - 1, height - 1, depth)
    rgba = vtk.vtkUnsignedCharArray()
    window.GetRGBACharPixelData(0, 0, width - 1, height - 1, 1, rgba)
    return (
        numpy_support.vtk_to_numpy(depth).reshape(height, width),
        numpy_support.vtk_to_numpy(rgba).reshape(height, width, 4).astype(int),
    )


def test_gpu_and_cpu_paths_draw_the_same_image(scene, intensities):
    width = 96
    cut = scene.cut_field(2)
    window, renderer = render_window(width)
    renderer.SetActiveCamera(A.make_camera(scene, 8.0, width, width))
    mapper, _ = add_cut_volume(scene, intensities, cut, renderer)
    images = render_on_both_paths(window, mapper, width)
    cpu_depth, cpu_color = images[vc.vtkVolumeCutVolumeMapper.CPUPath]
    gpu_depth, gpu_color = images[vc.vtkVolumeCutVolumeMapper.GPUPath]
    # Stated tolerance: depth within 1e-4 of the window range, colour within
    # 2/255 on 99.5 % of pixels (float vs double arithmetic).
    assert np.array_equal(cpu_depth < 1.0, gpu_depth < 1.0)
    assert np.max(np.abs(cpu_depth - gpu_depth)) < 1e-4
    assert np.mean(np.max(np.abs(cpu_color - gpu_color), axis=2) > 2) < 0.005
    # And the OpenGL path is exact on its own.
    matrix = A.world_to_ndc(renderer.GetActiveCamera(), width, width)
    reference = A.exact_reference(scene, matrix, width, width, supersampling=4)
    _, classes = classes_from_depth(scene, matrix, gpu_depth)
    assert A.edge_errors(reference, classes).max(initial=0.0) <= 0.5


@pytest.mark.parametrize("path", ["CPUPath", "GPUPath"])
def test_depth_composites_with_other_actors(scene, intensities, path):
    width = 64
    window, renderer = render_window(width)
    camera = A.make_camera(scene, 2.0, width, width)
    renderer.SetActiveCamera(camera)
    mapper, _ = add_cut_volume(scene, intensities, scene.cut_field(1), renderer)
    mapper.SetRequestedRenderPath(getattr(vc.vtkVolumeCutVolumeMapper, path))
    window.Render()
    alone, _ = read_window(window, width)
    # A red ball between the camera and the cube, covering part of it.
    source = vtk.vtkSphereSource()
    focal = np.array(camera.GetFocalPoint())
    toward = np.array(camera.GetPosition()) - focal
    source.SetCenter(*(focal + 0.3 * toward))
    source.SetRadius(0.02 * np.linalg.norm(toward))
    source.SetThetaResolution(32)
    source.SetPhiResolution(32)
    ball = vtk.vtkActor()
    ball.SetMapper(vtk.vtkPolyDataMapper())
    ball.GetMapper().SetInputConnection(source.GetOutputPort())
    ball.GetProperty().SetColor(1.0, 0.0, 0.0)
    ball.GetProperty().SetAmbient(1.0)
    ball.GetProperty().SetDiffuse(0.0)
    renderer.AddActor(ball)
    window.Render()
    depth, color = read_window(window, width)
    covered = depth < alone - 1e-3
    assert covered.sum() > 20
    # The ball's colour, never the bone's (the volume is not drawn over it).
    assert np.all(color[covered][:, 1] < 60) and np.all(color[covered][:, 0] > color[covered][:, 1] + 60)
    # Where the ball is not, the cube's surface depth is kept.
    assert np.allclose(depth[~covered], alone[~covered], atol=1e-5)


def test_localized_update_recasts_only_the_stroke(scene, intensities):
    width = 128
    cut = scene.cut_field(2)
    caster, matrix = cast(scene, intensities, cut, width, pixels_per_voxel=4.0)
    assert not caster.GetLastRenderWasLocalized()
    # One burr stroke on the visible top face.
    top = scene.center + np.array([0.2, -0.2, 1.0]) * scene.half_size
    cut.CutCapsule(list(top), list(top + [0.4, 0.0, 0.0]), 1.0)
    assert caster.Render(matrix, width, width)
    assert caster.GetLastRenderWasLocalized()
    # Whole bricks (2 mm here, with the interpolation's reach) are recast.
    assert 0 < caster.GetNumberOfRaysCast() < 0.3 * width * width
    localized = image_array(caster.GetColorImage, width, width, 4)
    fresh, _ = cast(scene, intensities, cut, width, pixels_per_voxel=4.0)
    assert np.array_equal(localized, image_array(fresh.GetColorImage, width, width, 4))
    # Nothing changed: nothing is cast.
    assert caster.Render(matrix, width, width)
    assert caster.GetNumberOfRaysCast() == 0


def test_clip_plane_opens_the_cube(scene, intensities):
    width = 64
    camera = vtk.vtkCamera()
    center = scene.center
    camera.SetFocalPoint(*center)
    camera.SetPosition(*(center + [0.0, 0.0, 100.0]))
    camera.SetViewUp(0.0, 1.0, 0.0)
    camera.SetClippingRange(50.0, 200.0)
    planes = vtk.vtkPlaneCollection()
    plane = vtk.vtkPlane()
    plane.SetOrigin(*(center + [0.0, 0.0, 0.1]))
    plane.SetNormal(0.0, 0.0, -1.0)  # keep below the plane: the top half is clipped away
    planes.AddItem(plane)
    caster, matrix = cast(scene, intensities, None, width, camera=camera, configure=lambda c: c.SetClippingPlanes(planes))
    depth = image_array(caster.GetDepthImage, width, width, 1)
    sources = image_array(caster.GetSourceImage, width, width, 1)
    middle = width // 2
    assert sources[middle, middle] == vc.vtkVolumeCutRayCaster.SourceClipPlane
    point = A.depth_to_points(matrix, depth.astype(float))[middle, middle]
    assert point[2] == pytest.approx(center[2] + 0.1, abs=1e-3)


def test_composite_mode_sees_through_the_removed_region(scene, intensities):
    width = 48
    cut = vc.vtkVolumeCutField()
    cut.Initialize([scene.dimensions] * 3, scene.ijk_to_ras(), 2)
    center = scene.center
    top = center + [0.0, 0.0, scene.half_size]
    cut.CutCapsule(list(top), list(top), 3.0)
    camera = vtk.vtkCamera()
    camera.SetFocalPoint(*center)
    camera.SetPosition(*(center + [0.0, 0.0, 100.0]))
    camera.SetViewUp(0.0, 1.0, 0.0)
    camera.SetClippingRange(50.0, 200.0)
    color = vtk.vtkColorTransferFunction()
    color.AddRGBPoint(0.0, 1.0, 1.0, 1.0)
    color.AddRGBPoint(1000.0, 1.0, 0.9, 0.8)
    opacity = vtk.vtkPiecewiseFunction()
    opacity.AddPoint(0.0, 0.0)
    opacity.AddPoint(400.0, 0.0)
    opacity.AddPoint(1000.0, 0.5)

    def composite(caster):
        caster.SetBlendMode(vc.vtkVolumeCutRayCaster.CompositeBlend)
        caster.SetTransferFunctions(color, opacity)

    caster, matrix = cast(scene, intensities, cut, width, camera=camera, configure=composite)
    depth = image_array(caster.GetDepthImage, width, width, 1)
    middle = width // 2
    point = A.depth_to_points(matrix, depth.astype(float))[middle, middle]
    # The first material along the central ray is the bottom of the spherical pit.
    off_axis = math.hypot(point[0] - top[0], point[1] - top[1])
    assert point[2] == pytest.approx(top[2] - math.sqrt(9.0 - off_axis**2), abs=0.01)
    sources = image_array(caster.GetSourceImage, width, width, 1)
    assert sources[middle, middle] == vc.vtkVolumeCutRayCaster.SourceCutField


def test_thin_bone_shows_red_and_translucent(scene, intensities):
    width = 48
    cut = vc.vtkVolumeCutField()
    cut.SetMaximumStrokeLength(1000.0)
    cut.Initialize([scene.dimensions] * 3, scene.ijk_to_ras(), 2)
    center = scene.center
    h = scene.half_size
    # Hollow the cube from below, leaving a 0.4 mm roof under the top face.
    cut.CutCapsule(list(center + [0.0, 0.0, h - 0.4 - 4.0]), list(center + [0.0, 0.0, -2.0 * h]), 4.0)
    camera = vtk.vtkCamera()
    camera.SetFocalPoint(*center)
    camera.SetPosition(*(center + [0.0, 0.0, 100.0]))
    camera.SetViewUp(0.0, 1.0, 0.0)
    camera.SetClippingRange(50.0, 200.0)

    def thin(caster):
        caster.ThinBoneShadingOn()
        caster.SetThinBoneThickness(1.5)

    caster, _ = cast(scene, intensities, cut, width, camera=camera, configure=thin)
    rgba = image_array(caster.GetColorImage, width, width, 4)
    middle = width // 2
    roof = rgba[middle, middle]
    assert roof[0] > 1.5 * roof[1]  # red
    corner_of_face = rgba[middle + 5, middle + 5]  # thick bone away from the hollow
    assert corner_of_face[0] < 1.2 * corner_of_face[1]
    assert roof[3] < 0.999  # what lies behind shows through
    plain, _ = cast(scene, intensities, cut, width, camera=camera)
    unshaded = image_array(plain.GetColorImage, width, width, 4)[middle, middle]
    assert unshaded[0] < 1.2 * unshaded[1]


def test_bad_input_gives_clear_errors_and_keeps_rendering(scene, intensities):
    width = 32
    caster = vc.vtkVolumeCutRayCaster()
    log = ErrorLog(caster)
    matrix = A.world_to_ndc(A.make_camera(scene, 1.0, width, width), width, width)
    assert not caster.Render(matrix, width, width)
    assert "no anatomy" in log.messages[-1]

    flat = vtk.vtkImageData()
    flat.SetDimensions(10, 10, 1)
    flat.AllocateScalars(vtk.VTK_FLOAT, 1)
    caster.SetAnatomy(flat, None)
    assert not caster.Render(matrix, width, width)
    assert "at least 2 voxels" in log.messages[-1]

    # A cut field on another grid is refused with a message; the anatomy still renders.
    caster.SetAnatomy(intensities, scene.ijk_to_ras())
    caster.SetIsoValue(scene.iso_value())
    other = vc.vtkVolumeCutField()
    other.Initialize([scene.dimensions + 1] * 3, scene.ijk_to_ras(), 2)
    other.CutCapsule(list(scene.center), list(scene.center), 5.0)
    caster.AddCutField(other)
    assert caster.Render(matrix, width, width)
    assert any("not made on the anatomy's voxel grid" in m for m in log.messages)
    depth = image_array(caster.GetDepthImage, width, width, 1)
    assert np.any(depth < 1.0)

    # An empty cut field changes nothing.
    caster.RemoveAllCutFields()
    empty = vc.vtkVolumeCutField()
    empty.Initialize([scene.dimensions] * 3, scene.ijk_to_ras(), 2)
    caster.AddCutField(empty)
    assert caster.Render(matrix, width, width)
    assert np.array_equal(image_array(caster.GetDepthImage, width, width, 1), depth)

    # A label map of the wrong size is refused; rendering goes on without labels.
    labels = vtk.vtkImageData()
    labels.SetDimensions(5, 5, 5)
    labels.AllocateScalars(vtk.VTK_UNSIGNED_SHORT, 1)
    caster.SetLabelMap(labels)
    assert caster.Render(matrix, width, width)
    assert "label map must have the anatomy's dimensions" in log.messages[-1]

    # NaN intensities neither crash nor show.
    values = numpy_support.vtk_to_numpy(intensities.GetPointData().GetScalars()).copy()
    values[: values.size // 2] = np.nan
    nan_image = vtk.vtkImageData()
    nan_image.SetDimensions(intensities.GetDimensions())
    nan_image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(values, deep=True))
    caster.SetLabelMap(None)
    caster.SetAnatomy(nan_image, scene.ijk_to_ras())
    assert caster.Render(matrix, width, width)


def test_hundreds_of_segments_render_with_their_colours(scene, intensities):
    width = 48
    n = scene.dimensions
    labels = np.zeros((n, n, n), np.uint16)
    # 300 slabs along x, each its own segment.
    labels[:, :, :] = (np.arange(n) % 300 + 1)[None, None, :]
    labels[:, :, : n // 2] = 7
    label_image = vtk.vtkImageData()
    label_image.SetDimensions(n, n, n)
    label_image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(labels.ravel(), deep=True))

    def segments(caster):
        caster.SetLabelMap(label_image)
        for label in range(1, 301):
            color = (1.0, 0.0, 0.0) if label == 7 else (0.0, 0.0, 1.0)
            caster.SetSegmentAppearance(label, color, 1.0, scene.iso_value())

    caster, _ = cast(scene, intensities, None, width, pixels_per_voxel=1.0, configure=segments)
    assert caster.GetNumberOfSegmentAppearances() == 300
    rgba = image_array(caster.GetColorImage, width, width, 4)
    hit = rgba[..., 3] > 0.5
    red = hit & (rgba[..., 0] > rgba[..., 2])
    blue = hit & (rgba[..., 2] > rgba[..., 0])
    assert red.sum() > 20 and blue.sum() > 20


def test_gpu_path_falls_back_to_the_cpu_with_a_reason():
    width = 32
    window, renderer = render_window(width)
    big = vtk.vtkImageData()
    big.SetDimensions(20000, 8, 8)  # longer than any GPU's 3D texture side
    big.SetSpacing(0.002, 2.5, 2.5)
    big.AllocateScalars(vtk.VTK_FLOAT, 1)
    big.GetPointData().GetScalars().Fill(1000.0)
    mapper = vc.vtkVolumeCutVolumeMapper()
    mapper.SetInputData(big)
    mapper.GetRayCaster().SetIsoValue(500.0)
    log = ErrorLog(mapper, warnings=True)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    renderer.AddVolume(volume)
    renderer.ResetCamera()
    window.Render()
    # Automatic: the CPU draws, and the log says why (a software rasterizer
    # such as llvmpipe, or a volume beyond the 3D texture limit).
    assert mapper.GetLastRenderPath() == vc.vtkVolumeCutVolumeMapper.CPUPath
    reason = mapper.GetGPUFallbackReason()
    assert "3D texture limit" in reason or "software rasterizer" in reason
    assert sum("Rendering cuts on the CPU" in m for m in log.messages) == 1
    depth, _ = read_window(window, width)
    assert np.any(depth < 1.0)
    window.Render()
    assert sum("Rendering cuts on the CPU" in m for m in log.messages) == 1  # once, not every frame
    # The GPU path asked for explicitly: the CPU image all the same, with the reason.
    mapper.SetRequestedRenderPath(vc.vtkVolumeCutVolumeMapper.CPUPath)
    window.Render()
    cpu_image = read_window(window, width)
    mapper.SetRequestedRenderPath(vc.vtkVolumeCutVolumeMapper.GPUPath)
    window.Render()
    assert mapper.GetLastRenderPath() == vc.vtkVolumeCutVolumeMapper.CPUPath
    assert "exceeds this GPU's 3D texture limit" in mapper.GetGPUFallbackReason()
    assert "GPU path was requested" in log.messages[-1] and "3D texture limit" in log.messages[-1]
    for expected, drawn in zip(cpu_image, read_window(window, width)):
        assert np.array_equal(expected, drawn)
    # Without input: nothing drawn, no crash (the renderer may not even call it).
    empty_mapper = vc.vtkVolumeCutVolumeMapper()
    empty_volume = vtk.vtkVolume()
    empty_volume.SetMapper(empty_mapper)
    renderer.AddVolume(empty_volume)
    window.Render()
    assert empty_mapper.GetLastRenderPath() == 0
    assert math.isfinite(mapper.GetLastFrameTime())


@pytest.mark.parametrize("path", ["CPUPath", "GPUPath"])
def test_stereo_draws_each_eye_with_its_own_camera(scene, intensities, path):
    """Split-viewport stereo: both eyes show the cut cube, from slightly different places."""
    width = 64
    window, renderer = render_window(2 * width, width)
    window.SetStereoCapableWindow(1)
    window.SetStereoTypeToSplitViewportHorizontal()
    window.StereoRenderOn()
    camera = A.make_camera(scene, 2.0, width, width)
    camera.SetEyeAngle(6.0)
    renderer.SetActiveCamera(camera)
    mapper, _ = add_cut_volume(scene, intensities, scene.cut_field(1), renderer)
    mapper.SetRequestedRenderPath(getattr(vc.vtkVolumeCutVolumeMapper, path))
    window.Render()
    assert mapper.GetLastRenderPath() == getattr(vc.vtkVolumeCutVolumeMapper, path)
    rgba = vtk.vtkUnsignedCharArray()
    window.GetRGBACharPixelData(0, 0, 2 * width - 1, width - 1, 1, rgba)
    pixels = numpy_support.vtk_to_numpy(rgba).reshape(width, 2 * width, 4).astype(int)
    left, right = pixels[:, :width, :3], pixels[:, width:, :3]
    background = pixels[0, 0, :3]
    for eye in (left, right):
        assert (np.abs(eye - background).sum(axis=2) > 30).mean() > 0.2
    assert np.abs(left - right).sum(axis=2).astype(bool).mean() > 0.01  # parallax


def sphere_segment(n, center, radius, supersampling=4):
    """Fractional (partial-volume) and binary labelmaps of a ball on a unit grid."""
    offsets = (np.arange(supersampling) + 0.5) / supersampling - 0.5
    index = np.arange(n, dtype=float)
    fraction = np.zeros((n, n, n))
    for dz in offsets:
        for dy in offsets:
            for dx in offsets:
                z = (index + dz - center[2])[:, None, None]
                y = (index + dy - center[1])[None, :, None]
                x = (index + dx - center[0])[None, None, :]
                fraction += (x * x + y * y + z * z) <= radius * radius
    fraction /= supersampling**3
    binary = np.zeros((n, n, n), np.uint16)
    z, y, x = np.meshgrid(index - center[2], index - center[1], index - center[0], indexing="ij")
    binary[(x * x + y * y + z * z) <= radius * radius] = 1

    def image(values, vtk_type):
        result = vtk.vtkImageData()
        result.SetDimensions(n, n, n)
        result.GetPointData().SetScalars(numpy_support.numpy_to_vtk(values.ravel(), deep=True, array_type=vtk_type))
        return result

    return image(fraction.astype(np.float32), vtk.VTK_FLOAT), image(binary, vtk.VTK_UNSIGNED_SHORT)


def look_down_z(camera, center, half_height):
    """``camera`` in parallel projection looking down z at ``center`` from 50 mm, showing 2 * half_height mm."""
    camera.ParallelProjectionOn()
    camera.SetParallelScale(half_height)
    camera.SetFocalPoint(*center)
    camera.SetPosition(center[0], center[1], center[2] + 50.0)
    camera.SetViewUp(0.0, 1.0, 0.0)
    camera.SetClippingRange(20.0, 80.0)
    return camera


def test_fractional_labelmaps_place_segment_surfaces_at_sub_voxel_accuracy():
    n, center, radius = 32, (15.3, 15.6, 15.2), 9.0
    fraction, binary = sphere_segment(n, center, radius)
    ct = vtk.vtkImageData()
    ct.SetDimensions(n, n, n)
    ct.AllocateScalars(vtk.VTK_FLOAT, 1)
    ct.GetPointData().GetScalars().Fill(0.0)
    camera = look_down_z(vtk.vtkCamera(), center, 11.0)
    width = 64
    matrix = A.world_to_ndc(camera, width, width)
    errors = {}
    for kind in ("fraction", "binary"):
        caster = vc.vtkVolumeCutRayCaster()
        caster.SetAnatomy(ct, None)
        if kind == "fraction":
            caster.SetSegmentFraction(3, fraction, 0.0, 1.0)
        else:
            caster.SetLabelMap(binary)
        caster.SetSegmentAppearance(3 if kind == "fraction" else 1, (0.9, 0.8, 0.2), 1.0, float("nan"))
        assert caster.Render(matrix, width, width)
        depth = image_array(caster.GetDepthImage, width, width, 1)
        points = A.depth_to_points(matrix, depth.astype(float))
        r_xy = np.hypot(points[..., 0] - center[0], points[..., 1] - center[1])
        inner = (depth < 1.0) & (r_xy < 0.8 * radius)
        exact = center[2] + np.sqrt(radius**2 - r_xy[inner] ** 2)
        errors[kind] = float(np.sqrt(np.mean((points[..., 2][inner] - exact) ** 2)))
    assert errors["fraction"] < 0.1  # voxels
    assert errors["fraction"] < 0.5 * errors["binary"]


@pytest.mark.parametrize("with_label_map", [False, True])
def test_gpu_path_draws_fractional_segments_like_the_cpu(scene, intensities, with_label_map):
    width = 48
    n = scene.dimensions
    fraction, binary = sphere_segment(n, tuple(scene.center / scene.spacing + [0.3, -0.2, 0.1]), 9.0)
    window, renderer = render_window(width)
    renderer.SetActiveCamera(A.make_camera(scene, 1.0, width, width))
    mapper, _ = add_cut_volume(scene, intensities, scene.cut_field(1), renderer)
    caster = mapper.GetRayCaster()
    if with_label_map:
        caster.SetLabelMap(binary)  # label 1 everywhere the ball is; the fraction overrides it
    caster.SetSegmentFraction(1, fraction)
    caster.SetSegmentAppearance(1, (0.2, 0.6, 0.9), 1.0, float("nan"))
    images = render_on_both_paths(window, mapper, width)
    cpu_depth, cpu_color = images[vc.vtkVolumeCutVolumeMapper.CPUPath]
    gpu_depth, gpu_color = images[vc.vtkVolumeCutVolumeMapper.GPUPath]
    assert np.any(cpu_depth < 1.0)
    assert np.array_equal(cpu_depth < 1.0, gpu_depth < 1.0)
    assert np.max(np.abs(cpu_depth - gpu_depth)) < 1e-4
    assert np.mean(np.max(np.abs(cpu_color - gpu_color), axis=2) > 2) < 0.005


@pytest.mark.parametrize("path", ["CPUPath", "GPUPath"])
def test_a_lost_context_is_rebuilt_without_a_crash(scene, intensities, path):
    """The window's context goes away (Finalize releases every GPU resource) and comes back."""
    width = 32
    window, renderer = render_window(width)
    renderer.SetActiveCamera(A.make_camera(scene, 2.0, width, width))
    mapper, _ = add_cut_volume(scene, intensities, scene.cut_field(1), renderer)
    mapper.SetRequestedRenderPath(getattr(vc.vtkVolumeCutVolumeMapper, path))
    window.Render()
    before, _ = read_window(window, width)
    window.Finalize()
    window.Render()
    after, _ = read_window(window, width)
    assert mapper.GetLastRenderPath() == getattr(vc.vtkVolumeCutVolumeMapper, path)
    assert np.any(before < 1.0)
    assert np.allclose(before, after, atol=1e-6)


def partial_volume_ball(n=40, center=(19.6, 20.3, 19.8), radius=11.0, ramp=2.5):
    """A bone ball as CT sees it (1500 HU, a linear ramp to -1000 HU over ``ramp`` voxels
    outside ``radius``) and labels: 1 where the CT is at or above 300 HU, 2 on the ramp's
    outer voxels (a halo of another segment around the bone, as segmentations have)."""
    index = np.arange(n, dtype=float)
    z, y, x = np.meshgrid(index - center[2], index - center[1], index - center[0], indexing="ij")
    r = np.sqrt(x * x + y * y + z * z)
    ct = np.clip(1500.0 - 2500.0 * (r - radius) / ramp, -1000.0, 1500.0).astype(np.float32)
    labels = np.zeros(ct.shape, np.uint16)
    labels[ct >= 300.0] = 1
    labels[(ct < 300.0) & (ct > -900.0)] = 2

    def image(values):
        result = vtk.vtkImageData()
        result.SetDimensions(n, n, n)
        result.GetPointData().SetScalars(numpy_support.numpy_to_vtk(values.ravel(), deep=True))
        return result

    return image(ct), image(labels)


def test_surface_shows_the_segment_of_the_material_behind_it():
    """The 300 HU surface crosses voxels of the halo segment; it is coloured as the bone under it."""
    ct, labels = partial_volume_ball()
    width = 64
    window, renderer = render_window(width)
    camera = vtk.vtkCamera()
    camera.SetFocalPoint(20.0, 20.0, 20.0)
    camera.SetPosition(20.0, -60.0, 35.0)
    camera.SetViewUp(0.0, 0.0, 1.0)
    renderer.SetActiveCamera(camera)
    renderer.ResetCameraClippingRange()
    mapper = vc.vtkVolumeCutVolumeMapper()
    mapper.SetInputData(ct)
    caster = mapper.GetRayCaster()
    caster.SetLabelMap(labels)
    caster.SetSegmentAppearance(1, (0.9, 0.2, 0.2), 1.0, 300.0)
    caster.SetSegmentAppearance(2, (0.2, 0.9, 0.2), 1.0, 300.0)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    renderer.AddVolume(volume)
    images = render_on_both_paths(window, mapper, width)
    owners = image_array(caster.GetSegmentImage, width, width, 1)
    surface = owners > 0
    assert surface.sum() > 0.15 * width * width
    assert np.all(owners[surface] == 1)
    cpu_depth, cpu_color = images[vc.vtkVolumeCutVolumeMapper.CPUPath]
    gpu_depth, gpu_color = images[vc.vtkVolumeCutVolumeMapper.GPUPath]
    covered = cpu_depth < 1.0
    assert np.all(cpu_color[covered][:, 0] > cpu_color[covered][:, 1])  # red bone, no green halo
    assert np.array_equal(covered, gpu_depth < 1.0)
    assert np.max(np.abs(cpu_depth - gpu_depth)) < 1e-4
    assert np.mean(np.max(np.abs(cpu_color - gpu_color), axis=2) > 2) < 0.005


def shell_and_core(scene):
    """Labels of the cube: a 3-voxel shell (segment 1, cortex) around a core (segment 2, cancellous bone)."""
    n = scene.dimensions
    index = np.arange(n) - (n - 1) / 2.0
    depth = scene.half_size_voxels - np.max(np.abs(np.stack(np.meshgrid(index, index, index, indexing="ij"))), axis=0)
    labels = np.where(depth >= 3.0, 2, 1).astype(np.uint16)
    image = vtk.vtkImageData()
    image.SetDimensions(n, n, n)
    image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(labels.ravel(), deep=True))
    return image


def test_segments_of_one_material_share_their_surface_colour_and_cuts_tell_them_apart(scene, intensities):
    width = 64
    cut = vc.vtkVolumeCutField()
    cut.Initialize([scene.dimensions] * 3, scene.ijk_to_ras(), 2)
    top = scene.center + [0.0, 0.0, scene.half_size]
    cut.CutCapsule(list(top), list(top), 5.0)  # a pit through the shell into the core
    window, renderer = render_window(width)
    camera = vtk.vtkCamera()
    camera.SetFocalPoint(*scene.center)
    camera.SetPosition(*(scene.center + [25.0, -30.0, 60.0]))
    camera.SetViewUp(0.0, 0.0, 1.0)
    renderer.SetActiveCamera(camera)
    renderer.ResetCameraClippingRange()
    mapper, _ = add_cut_volume(scene, intensities, cut, renderer)
    caster = mapper.GetRayCaster()
    caster.SetLabelMap(shell_and_core(scene))
    cortex, cancellous = (0.9, 0.9, 0.8), (0.8, 0.3, 0.2)
    caster.SetSegmentAppearance(1, cortex, 1.0, scene.iso_value())
    caster.SetSegmentAppearance(2, cancellous, 1.0, scene.iso_value())
    caster.SetSegmentSurfaceColor(2, cortex)
    images = render_on_both_paths(window, mapper, width)
    sources = image_array(caster.GetSourceImage, width, width, 1)
    owners = image_array(caster.GetSegmentImage, width, width, 1)
    rgba = image_array(caster.GetColorImage, width, width, 4)
    outer = sources == vc.vtkVolumeCutRayCaster.SourceObject
    exposed = sources == vc.vtkVolumeCutRayCaster.SourceCutField
    assert outer.sum() > 500 and exposed.sum() > 50
    # Uncut: one bone, whichever segment owns it; cut: each its own colour.
    redness = rgba[..., 0] / np.maximum(rgba[..., 2], 1e-6)  # 1.1 for the cortex's colour, 4 for the core's
    assert np.all(redness[outer] < 1.5)
    assert np.any(exposed & (owners == 1)) and np.any(exposed & (owners == 2))
    assert np.all(redness[exposed & (owners == 2)] > 2.0)
    assert np.all(redness[exposed & (owners == 1)] < 1.5)
    cpu_depth, cpu_color = images[vc.vtkVolumeCutVolumeMapper.CPUPath]
    gpu_depth, gpu_color = images[vc.vtkVolumeCutVolumeMapper.GPUPath]
    # (a ray grazing the cube's far edge may end on either side of it)
    assert np.mean(np.abs(cpu_depth - gpu_depth) > 1e-4) < 0.005
    assert np.mean(np.max(np.abs(cpu_color - gpu_color), axis=2) > 2) < 0.005
    log = ErrorLog(caster)
    caster.SetSegmentSurfaceColor(9, cortex)  # no such segment
    assert "has no appearance" in log.messages[-1]


def test_ambient_occlusion_darkens_a_cavity_not_a_flat_face(scene, intensities):
    width = 64
    cut = vc.vtkVolumeCutField()
    cut.Initialize([scene.dimensions] * 3, scene.ijk_to_ras(), 2)
    top = scene.center + [0.0, 0.0, scene.half_size]
    cut.CutCapsule(list(top), list(top), 4.0)
    camera = vtk.vtkCamera()
    camera.SetFocalPoint(*scene.center)
    camera.SetPosition(*(scene.center + [0.0, 0.0, 100.0]))
    camera.SetViewUp(0.0, 1.0, 0.0)
    camera.SetClippingRange(50.0, 200.0)
    matrix = A.world_to_ndc(camera, width, width)
    images = {}
    for occlusion in (False, True):
        caster = vc.vtkVolumeCutRayCaster()
        caster.SetAnatomy(intensities, scene.ijk_to_ras())
        caster.SetIsoValue(scene.iso_value())
        caster.AddCutField(cut)
        caster.SetAmbientOcclusion(occlusion)
        caster.SetAmbientOcclusionRadius(6.0)
        assert caster.Render(matrix, width, width)
        images[occlusion] = image_array(caster.GetColorImage, width, width, 4)
    middle = width // 2
    plain, occluded = images[False], images[True]
    # The pit's floor is darker, the flat top away from the pit is not.
    assert occluded[middle, middle, 0] < 0.8 * plain[middle, middle, 0]
    assert occluded[middle + 20, middle + 20, 0] == pytest.approx(plain[middle + 20, middle + 20, 0], rel=1e-6)

    # A stroke next to the pit: the localized update recasts the pixels whose
    # occlusion looks into it, and equals a full render.
    cut.CutCapsule(list(top + [8.0, 0.0, 0.0]), list(top + [8.5, 0.0, 0.0]), 1.0)
    assert caster.Render(matrix, width, width)
    assert caster.GetLastRenderWasLocalized()
    fresh = vc.vtkVolumeCutRayCaster()
    fresh.SetAnatomy(intensities, scene.ijk_to_ras())
    fresh.SetIsoValue(scene.iso_value())
    fresh.AddCutField(cut)
    fresh.SetAmbientOcclusion(True)
    fresh.SetAmbientOcclusionRadius(6.0)
    assert fresh.Render(matrix, width, width)
    assert np.array_equal(image_array(caster.GetColorImage, width, width, 4), image_array(fresh.GetColorImage, width, width, 4))


def test_gpu_path_draws_ambient_occlusion_like_the_cpu(scene, intensities):
    width = 48
    window, renderer = render_window(width)
    renderer.SetActiveCamera(A.make_camera(scene, 1.0, width, width))
    mapper, _ = add_cut_volume(scene, intensities, scene.cut_field(2), renderer)
    mapper.GetRayCaster().SetAmbientOcclusion(True)
    images = render_on_both_paths(window, mapper, width)
    cpu_depth, cpu_color = images[vc.vtkVolumeCutVolumeMapper.CPUPath]
    gpu_depth, gpu_color = images[vc.vtkVolumeCutVolumeMapper.GPUPath]
    assert np.max(np.abs(cpu_depth - gpu_depth)) < 1e-4
    assert np.mean(np.max(np.abs(cpu_color - gpu_color), axis=2) > 2) < 0.005


def test_binary_segments_are_smoothed_between_slices(scene, intensities):
    """A ball stored as whole voxels on thick slices: smoothing brings its surface near the exact sphere, CPU and GPU alike."""
    n, center, radius = 32, (15.3, 15.6, 15.2), 9.0
    _, binary = sphere_segment(n, center, radius)
    ct = vtk.vtkImageData()
    ct.SetDimensions(n, n, n)
    ct.AllocateScalars(vtk.VTK_FLOAT, 1)
    ct.GetPointData().GetScalars().Fill(0.0)
    ct.SetSpacing(0.7, 0.7, 2.5)
    world_center = np.array(center) * [0.7, 0.7, 2.5]
    ellipsoid_radii = radius * np.array([0.7, 0.7, 2.5])
    camera = vtk.vtkCamera()
    camera.ParallelProjectionOn()
    camera.SetParallelScale(1.1 * ellipsoid_radii[2])
    camera.SetFocalPoint(*world_center)
    camera.SetPosition(*(world_center + [60.0, 0.0, 0.0]))
    camera.SetViewUp(0.0, 0.0, 1.0)
    camera.SetClippingRange(20.0, 100.0)
    width = 64
    errors = {}
    for smoothing in (0.0, 1.0):
        window, renderer = render_window(width)
        renderer.SetActiveCamera(camera)
        mapper = vc.vtkVolumeCutVolumeMapper()
        mapper.SetInputData(ct)
        caster = mapper.GetRayCaster()
        caster.SetLabelMap(binary)
        caster.SetSegmentAppearance(1, (0.9, 0.8, 0.2), 1.0, float("nan"))
        caster.SetLabelSmoothing(smoothing)
        volume = vtk.vtkVolume()
        volume.SetMapper(mapper)
        renderer.AddVolume(volume)
        images = render_on_both_paths(window, mapper, width)
        cpu_depth, gpu_depth = images[vc.vtkVolumeCutVolumeMapper.CPUPath][0], images[vc.vtkVolumeCutVolumeMapper.GPUPath][0]
        assert np.array_equal(cpu_depth < 1.0, gpu_depth < 1.0)
        assert np.max(np.abs(cpu_depth - gpu_depth)) < 1e-4
        matrix = A.world_to_ndc(camera, width, width)
        points = A.depth_to_points(matrix, cpu_depth.astype(float))
        # The ellipsoid the stretched ball is: its x at the rendered (y, z).
        u = (points[..., 1] - world_center[1]) / ellipsoid_radii[1]
        w = (points[..., 2] - world_center[2]) / ellipsoid_radii[2]
        inner = (cpu_depth < 1.0) & (u * u + w * w < 0.6)
        exact = world_center[0] + ellipsoid_radii[0] * np.sqrt(1.0 - u[inner] ** 2 - w[inner] ** 2)
        errors[smoothing] = float(np.sqrt(np.mean((points[..., 0][inner] - exact) ** 2)))
    assert errors[1.0] < 0.8 * errors[0.0]


def test_interactive_frames_are_reduced_and_the_still_frame_is_the_full_image(scene, intensities):
    width, height = 90, 70  # not multiples of the sample distance: the last block reaches past the edge
    camera = A.make_camera(scene, 4.0, width, height)
    cut = scene.cut_field(2)
    # The image a view that never moved draws.
    window, renderer = render_window(width, height)
    renderer.SetActiveCamera(camera)
    mapper, _ = add_cut_volume(scene, intensities, cut, renderer)
    mapper.SetRequestedRenderPath(vc.vtkVolumeCutVolumeMapper.CPUPath)
    # Moving frames leave ambient occlusion out; the refined one must not.
    mapper.GetRayCaster().SetAmbientOcclusion(True)
    window.Render()
    assert mapper.GetLastImageSampleDistance() == 1
    full = read_window(window, width, height)

    moving, moving_renderer = render_window(width, height)
    moving_camera = vtk.vtkCamera()
    moving_camera.DeepCopy(camera)
    moving_renderer.SetActiveCamera(moving_camera)
    moving_mapper, _ = add_cut_volume(scene, intensities, cut, moving_renderer)
    moving_mapper.SetRequestedRenderPath(vc.vtkVolumeCutVolumeMapper.CPUPath)
    moving_mapper.SetMaximumImageSampleDistance(4)
    moving_mapper.GetRayCaster().SetAmbientOcclusion(True)
    # The camera moves: the window asks for 1000 frames per second, more
    # than any full frame gives, so every frame is the coarsest.
    moving.SetDesiredUpdateRate(1000.0)
    for angle in (5.0, -5.0):
        moving_camera.Azimuth(angle)
        moving.Render()
        assert moving_mapper.GetLastImageSampleDistance() == 4
        assert moving_mapper.GetRayCaster().GetNumberOfRaysCast() <= math.ceil(width / 4) * math.ceil(height / 4)
    reduced = read_window(moving, width, height)
    # Magnified, not shifted: the reduced image covers the same pixels as the
    # full one but for the blocks along the silhouette.
    covered_full, covered_reduced = full[0] < 1.0, reduced[0] < 1.0
    assert np.mean(covered_full != covered_reduced) < 0.08
    assert not np.array_equal(full[1], reduced[1])
    # The motion stops: the window's rate drops back and the next frame is the full image.
    moving.SetDesiredUpdateRate(0.0001)
    moving.Render()
    assert moving_mapper.GetLastImageSampleDistance() == 1
    assert moving_mapper.GetRayCaster().GetNumberOfRaysCast() == width * height
    refined = read_window(moving, width, height)
    assert np.array_equal(refined[0], full[0])
    assert np.array_equal(refined[1], full[1])


def test_interactive_frames_fit_the_time_the_window_allows(scene, intensities):
    width = 128
    window, renderer = render_window(width)
    renderer.SetActiveCamera(A.make_camera(scene, 4.0, width, width))
    mapper, _ = add_cut_volume(scene, intensities, scene.cut_field(1), renderer)
    mapper.SetRequestedRenderPath(vc.vtkVolumeCutVolumeMapper.CPUPath)
    caster = mapper.GetRayCaster()
    window.Render()  # shaders and textures made
    renderer.GetActiveCamera().Azimuth(3.0)
    window.Render()
    # A rate the last full frame meets leaves the image at full resolution.
    window.SetDesiredUpdateRate(0.5 / mapper.GetLastFrameTime())
    renderer.GetActiveCamera().Azimuth(3.0)
    window.Render()
    assert mapper.GetLastImageSampleDistance() == 1
    full_frame = mapper.GetLastFrameTime()
    assert mapper.GetRestOfFrameTime() > 0.0  # the window's own work was timed
    # A full frame's rays do not tell what a reduced frame's cost (they share
    # the memory they read): the first reduced frame is the coarsest.
    window.SetDesiredUpdateRate(1000.0)
    costs = []  # each reduced frame's work besides the rays, and its cost per ray
    for _ in range(4):  # the first also makes the magnified image's shader variant
        renderer.GetActiveCamera().Azimuth(3.0)
        window.Render()
        assert mapper.GetLastImageSampleDistance() == 16
        assert 0.0 < caster.GetLastRayCastingTime() <= mapper.GetLastFrameTime()
        costs.append((mapper.GetLastFrameTime() - caster.GetLastRayCastingTime(),
                      caster.GetLastRayCastingTime() / caster.GetNumberOfRaysCast()))

    def rays(distance):
        return math.ceil(width / distance) ** 2

    def predicted(distance):  # the dearest of the last three reduced frames
        return max(fixed + per_ray * rays(distance) for fixed, per_ray in costs[-3:])

    # The next ones are sized from them, at a rate that a full frame does not meet.
    rest = mapper.GetRestOfFrameTime()
    rate = 4.0 / full_frame
    window.SetDesiredUpdateRate(rate)
    renderer.GetActiveCamera().Azimuth(3.0)
    window.Render()
    # The rest of the window's frame is taken off the time allowed first
    # (the mapper keeps at least a fifth of it), and a fifth of it is spared.
    allowed = max(0.2 / rate, 1.0 / rate - rest)
    expected = next((d for d in range(2, 16) if predicted(d) <= 0.8 * allowed), 16)
    assert mapper.GetLastImageSampleDistance() == expected
    assert expected >= 2


def set_transfer_functions(volume, colors, opacities):
    """The volume property's colour points (value, r, g, b) and opacity points (value, opacity per mm)."""
    color = vtk.vtkColorTransferFunction()
    for point in colors:
        color.AddRGBPoint(*point)
    opacity = vtk.vtkPiecewiseFunction()
    for point in opacities:
        opacity.AddPoint(*point)
    volume.GetProperty().SetColor(color)
    volume.GetProperty().SetScalarOpacity(opacity)


def test_gpu_and_cpu_paths_composite_the_same_image():
    """Composite mode on the cut cube: both paths give the same emission-absorption image.

    Inside the cube the CT is uniform and its gradient is zero; both paths
    then light the sample by the ambient term alone (the GPU once normalized
    the zero vector to NaN, which llvmpipe drew as full white: 13 % of the
    pixels differed, by up to 196/255). Tolerance: the paths sample the same
    points except after an empty-space jump (the CPU jumps over several empty
    blocks at once, the GPU block by block), and float against double
    arithmetic; measured 0.4 % of pixels over 2/255, at most 6/255.
    """
    scene = A.default_scene(32)
    width = 64
    window, renderer = render_window(width)
    renderer.SetActiveCamera(A.make_camera(scene, 2.0, width, width))
    mapper, volume = add_cut_volume(scene, scene.intensities(), scene.cut_field(1), renderer)
    mapper.SetBlendMode(vtk.vtkVolumeMapper.COMPOSITE_BLEND)
    set_transfer_functions(volume, [(0.0, 1.0, 1.0, 1.0), (1000.0, 1.0, 0.9, 0.8)], [(400.0, 0.0), (1000.0, 0.5)])
    images = render_on_both_paths(window, mapper, width)
    cpu_color = images[vc.vtkVolumeCutVolumeMapper.CPUPath][1]
    gpu_color = images[vc.vtkVolumeCutVolumeMapper.GPUPath][1]
    assert np.mean(cpu_color[..., 3] > 0) > 0.2
    difference = np.max(np.abs(cpu_color - gpu_color), axis=2)
    assert np.mean(difference > 2) < 0.01
    assert difference.max() <= 12


def slab_view(image, volume, width, centre, half_height):
    """``image`` composited unshaded by ``volume`` in a parallel view down z, centred on (centre, centre)."""
    window, renderer = render_window(width)
    camera = renderer.GetActiveCamera()
    camera.ParallelProjectionOn()
    camera.SetFocalPoint(centre, centre, 0.0)
    camera.SetPosition(centre, centre, 50.0)
    camera.SetParallelScale(half_height)
    camera.SetClippingRange(1.0, 100.0)
    mapper = vc.vtkVolumeCutVolumeMapper()
    mapper.SetInputData(image)
    mapper.SetBlendMode(vtk.vtkVolumeMapper.COMPOSITE_BLEND)
    mapper.GetRayCaster().SetAmbient(1.0)
    mapper.GetRayCaster().SetDiffuse(0.0)
    mapper.GetRayCaster().SetSpecular(0.0)
    volume.SetMapper(mapper)
    renderer.AddVolume(volume)
    return window, mapper, volume


def test_composite_opacity_is_corrected_for_the_thickness_on_both_paths():
    """A uniform slab 1 mm and 3 mm thick, opacity 0.5 per mm: alpha is 1 - 0.5**thickness, colour the transfer function's."""
    n = 16
    width = 32
    for thickness in (1, 3):
        # A CT ramp across the slab (a gradient perpendicular to the view, so
        # the shading is ambient whatever the diffuse term); the colour runs
        # from white to red along it.
        values = (1000.0 + 10.0 * np.arange(n, dtype=np.float32))[None, None, :].repeat(n, 1).repeat(thickness + 1, 0)
        image = vtk.vtkImageData()
        image.SetDimensions(n, n, thickness + 1)
        image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(values.ravel(), deep=True))
        window, mapper, volume = slab_view(image, vtk.vtkVolume(), width, 7.5, 4.0)
        set_transfer_functions(volume, [(1000.0, 1.0, 1.0, 1.0), (1150.0, 1.0, 0.0, 0.0)], [(1000.0, 0.5), (1150.0, 0.5)])
        alpha = 1.0 - 0.5**thickness
        x = 7.5 + (np.arange(width) + 0.5 - width / 2) * 0.25
        green = 255.0 * alpha * np.clip(1.0 - 10.0 * x / 150.0, 0.0, 1.0)
        for _, (_, drawn) in render_on_both_paths(window, mapper, width).items():
            row = drawn[width // 2]
            assert np.all(np.abs(row[:, 3] - 255.0 * alpha) <= 1.5)
            assert np.all(np.abs(row[:, 0] - 255.0 * alpha) <= 1.5)
            assert np.all(np.abs(row[:, 1] - green) <= 1.5)


@pytest.mark.parametrize("spacing_in", ["image", "volume matrix"])
def test_composite_opacity_is_per_millimetre_wherever_the_spacing_is_stored(spacing_in):
    """A uniform slab 4 voxels of 0.5 mm (2 mm) thick, opacity 0.5 per mm: alpha 0.75 on both paths.

    Slicer puts a volume's spacing in the vtkVolume's matrix; VTK's stock GPU
    mapper counts the unit distance in voxels there (alpha 1 - 0.5**4 =
    0.9375 for this slab), which made it look brighter than this mapper.
    """
    n, slab, spacing, width = 16, 4, 0.5, 32
    values = np.full((slab + 1, n, n), 1000.0, np.float32)
    image = vtk.vtkImageData()
    image.SetDimensions(n, n, slab + 1)
    image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(values.ravel(), deep=True))
    volume = vtk.vtkVolume()
    if spacing_in == "image":
        image.SetSpacing(spacing, spacing, spacing)
    else:
        matrix = vtk.vtkMatrix4x4()
        for axis in range(3):
            matrix.SetElement(axis, axis, spacing)
        volume.SetUserMatrix(matrix)
    window, mapper, volume = slab_view(image, volume, width, 7.5 * spacing, 2.0 * spacing)
    set_transfer_functions(volume, [(0.0, 1.0, 1.0, 1.0), (2000.0, 1.0, 1.0, 1.0)], [(0.0, 0.5), (2000.0, 0.5)])
    alpha = 1.0 - 0.5 ** (slab * spacing)
    for _, (_, drawn) in render_on_both_paths(window, mapper, width).items():
        centre_pixels = drawn[width // 4 : 3 * width // 4, width // 4 : 3 * width // 4]
        assert np.all(np.abs(centre_pixels[..., 3] - 255.0 * alpha) <= 1.5)
