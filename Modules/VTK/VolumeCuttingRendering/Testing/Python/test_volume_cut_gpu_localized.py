"""The GPU path keeps its last image and, after a stroke, recasts only the rectangle over the modified bricks.

Each localized frame is compared with a full recast of the same state by the
same mapper (LocalizedUpdates off), in the window, bit for bit. The OpenGL
context is whatever VTK gives offscreen (Mesa llvmpipe through EGL here).
"""

import numpy as np
import pytest
import slicer_volumecutting as vc
import vtk
from test_volume_cut_mapper import add_cut_volume, read_window, render_window

from VolumeCuttingLib.data import analyticscene as A

GPU = vc.vtkVolumeCutVolumeMapper.GPUPath
WIDTH = 128


def gpu_view(scene, intensities, pixels_per_voxel=4.0, width=WIDTH):
    cut = scene.cut_field(2)
    window, renderer = render_window(width)
    renderer.SetActiveCamera(A.make_camera(scene, pixels_per_voxel, width, width))
    mapper, _ = add_cut_volume(scene, intensities, cut, renderer)
    mapper.SetRequestedRenderPath(GPU)
    return window, renderer, mapper, cut


def render(window, mapper):
    window.Render()
    assert mapper.GetLastRenderPath() == GPU, mapper.GetGPUFallbackReason()
    return mapper.GetOpenGLRayCaster()


def full_recast(window, mapper, width=WIDTH):
    """The window's image when the GPU recasts every pixel of the same state."""
    gpu = mapper.GetOpenGLRayCaster()
    gpu.LocalizedUpdatesOff()
    render(window, mapper)
    assert not gpu.GetLastRenderWasLocalized() and gpu.GetNumberOfPixelsRecast() == width * width
    image = read_window(window, width)
    gpu.LocalizedUpdatesOn()
    return image


def stroke_pixels(camera, points, width=WIDTH):
    matrix = A.world_to_ndc(camera, width, width)
    m = np.array([[matrix.GetElement(r, c) for c in range(4)] for r in range(4)])
    clip = m @ np.vstack([np.array(points).T, np.ones(len(points))])
    return (clip[:2] / clip[3] + 1.0) * 0.5 * width


SHADINGS = {
    "plain": lambda caster: None,
    # Shadings that look around the surface point: the scissored program
    # still gives the full recast's pixels (their reach, which widens the
    # rectangle, is not isolated here: on this cube a brick's rectangle
    # already holds every pixel they change).
    "ambient occlusion": lambda caster: (caster.SetAmbientOcclusion(True), caster.SetAmbientOcclusionRadius(1.0)),
    "thin bone": lambda caster: (caster.SetThinBoneShading(True), caster.SetThinBoneThickness(1.0)),
}


@pytest.mark.parametrize("shading", SHADINGS)
def test_a_stroke_recasts_its_rectangle_and_the_window_equals_a_full_recast(scene, intensities, shading):
    window, renderer, mapper, cut = gpu_view(scene, intensities)
    SHADINGS[shading](mapper.GetRayCaster())
    gpu = render(window, mapper)
    assert not gpu.GetLastRenderWasLocalized() and gpu.GetNumberOfPixelsRecast() == WIDTH * WIDTH
    before = read_window(window, WIDTH)
    # Nothing changed: the kept image is drawn again, no ray is cast.
    render(window, mapper)
    assert gpu.GetLastRenderWasLocalized() and gpu.GetNumberOfPixelsRecast() == 0
    for a, b in zip(before, read_window(window, WIDTH)):
        assert np.array_equal(a, b)

    # One burr stroke on the visible top face.
    top = scene.center + np.array([0.2, -0.2, 1.0]) * scene.half_size
    end = top + [0.4, 0.0, 0.0]
    cut.CutCapsule(list(top), list(end), 1.0)
    render(window, mapper)
    assert gpu.GetLastRenderWasLocalized()
    # Whole bricks (2 mm here) with the interpolation's reach, and the shading's.
    share = 0.3 if shading == "plain" else 0.6
    assert 0 < gpu.GetNumberOfPixelsRecast() < share * WIDTH * WIDTH
    x0, y0, x1, y1 = gpu.GetUpdatedRegion()
    assert gpu.GetNumberOfPixelsRecast() == (x1 - x0 + 1) * (y1 - y0 + 1)
    xs, ys = stroke_pixels(renderer.GetActiveCamera(), [top, end])
    assert np.all((xs >= x0) & (xs <= x1 + 1) & (ys >= y0) & (ys <= y1 + 1))
    localized = read_window(window, WIDTH)
    # The stroke shows, and only inside the rectangle.
    changed = np.any(localized[1] != before[1], axis=2) | (localized[0] != before[0])
    assert changed.any()
    inside = np.zeros_like(changed)
    inside[y0 : y1 + 1, x0 : x1 + 1] = True
    assert not np.any(changed & ~inside)
    for a, b in zip(localized, full_recast(window, mapper)):
        assert np.array_equal(a, b)


def test_the_camera_moving_forces_a_full_frame(scene, intensities):
    window, renderer, mapper, cut = gpu_view(scene, intensities)
    gpu = render(window, mapper)
    top = scene.center + np.array([0.2, -0.2, 1.0]) * scene.half_size
    cut.CutCapsule(list(top), list(top + [0.4, 0.0, 0.0]), 1.0)
    renderer.GetActiveCamera().Azimuth(3.0)
    render(window, mapper)
    assert not gpu.GetLastRenderWasLocalized() and gpu.GetNumberOfPixelsRecast() == WIDTH * WIDTH
    moved = read_window(window, WIDTH)
    for a, b in zip(moved, full_recast(window, mapper)):
        assert np.array_equal(a, b)
    # A resize too.
    window.SetSize(WIDTH + 8, WIDTH)
    render(window, mapper)
    assert not gpu.GetLastRenderWasLocalized() and gpu.GetNumberOfPixelsRecast() == (WIDTH + 8) * WIDTH


def test_a_stroke_outside_the_view_recasts_nothing(scene, intensities):
    # Zoomed in on the cut corner (4 voxels across): another corner of the
    # cube is far out of view, beyond its bricks (8 voxels with the margin).
    window, renderer, mapper, cut = gpu_view(scene, intensities, pixels_per_voxel=16.0, width=64)
    gpu = render(window, mapper)
    before = read_window(window, 64)
    corner = scene.center + np.array([-0.9, 0.9, 0.9]) * scene.half_size
    xs, ys = stroke_pixels(renderer.GetActiveCamera(), [corner], width=64)
    assert np.all((xs < -100) | (xs > 64 + 100) | (ys < -100) | (ys > 64 + 100))
    uploaded = gpu.GetTotalNumberOfBricksUploaded()
    cut.CutCapsule(list(corner), list(corner + [0.4, 0.0, 0.0]), 1.0)
    render(window, mapper)
    assert gpu.GetTotalNumberOfBricksUploaded() > uploaded  # the field did change
    assert gpu.GetLastRenderWasLocalized() and gpu.GetNumberOfPixelsRecast() == 0
    after = read_window(window, 64)
    for a, b in zip(before, after):
        assert np.array_equal(a, b)
    for a, b in zip(after, full_recast(window, mapper, width=64)):
        assert np.array_equal(a, b)


def test_opaque_geometry_appearing_forces_a_full_frame(scene, intensities):
    # A tool drawn as a surface (an opaque prop) changes the depth the rays
    # stop at: the kept image, cast against the old depth, is not reused.
    window, renderer, mapper, cut = gpu_view(scene, intensities)
    gpu = render(window, mapper)
    render(window, mapper)
    assert gpu.GetLastRenderWasLocalized() and gpu.GetNumberOfPixelsRecast() == 0
    ball = vtk.vtkSphereSource()
    ball.SetCenter(*(scene.center + np.array([0.0, 0.0, 1.0]) * scene.half_size))
    ball.SetRadius(0.3 * scene.half_size)
    polydata_mapper = vtk.vtkPolyDataMapper()
    polydata_mapper.SetInputConnection(ball.GetOutputPort())
    actor = vtk.vtkActor()
    actor.SetMapper(polydata_mapper)
    renderer.AddActor(actor)
    render(window, mapper)
    assert not gpu.GetLastRenderWasLocalized() and gpu.GetNumberOfPixelsRecast() == WIDTH * WIDTH
    with_ball = read_window(window, WIDTH)
    # Unchanged again: reused, and equal to a full recast.
    render(window, mapper)
    assert gpu.GetLastRenderWasLocalized() and gpu.GetNumberOfPixelsRecast() == 0
    for a, b in zip(with_ball, full_recast(window, mapper)):
        assert np.array_equal(a, b)
