"""An uncut CT surface seen head-on shows no contour rings: normals true to an analytic ball at every pixel.

The phantom the application opens with showed concentric rings at the
default zoom, one per voxel layer its surface crosses (issue 28, finding 10):
its CT, like every CT, ramps each surface over about a voxel (partial
volume), and the central differences of the trilinear interpolant swing with
the voxel's phase across such a ramp. A surface almost parallel to a voxel
plane (a ball's pole, seen along an axis) turns these swings into rings.

Here a ball whose voxels hold the share of their box inside it (the
phantom's partial volume, iso-value at a sixth of the ramp as the bone
surface's 300 HU between soft tissue and cortex) is looked at along the
i axis, one voxel over 6 pixels: the shaded normal at each pixel of the cap
must stay within 4 degrees of the analytic (p - centre) / r (plain central
differences: 10.0, Sobel differences: 2.9), and the
brightness along radial lines from the pole must fall without the rings'
ups and downs (both paths; regained brightness 24.8 / 255 before, 0.3 after).
"""

import numpy as np
import pytest
import slicer_volumecutting as vc
import vtk
from vtkmodules.util import numpy_support

from VolumeCuttingLib.data import analyticscene as A

DIMENSIONS = 40
# Off the grid's symmetry, so that the cap crosses voxel layers at all phases.
CENTRE = np.array([19.3, 19.6, 19.1])
RADIUS = 15.0
ISO = 1000.0 / 6.0
SUBSAMPLES = 6
WIDTH = 160
PIXELS_PER_VOXEL = 6.0


def box_filtered_ball():
    """CT 1000 inside the ball, each voxel the share of its box inside (SUBSAMPLES^3 points), as the phantom's."""
    grid = np.arange(DIMENSIONS, dtype=float)
    z, y, x = np.meshgrid(grid, grid, grid, indexing="ij")
    offsets = (np.arange(SUBSAMPLES) + 0.5) / SUBSAMPLES - 0.5
    inside = np.zeros(x.shape)
    for dz in offsets:
        for dy in offsets:
            for dx in offsets:
                inside += (x + dx - CENTRE[0]) ** 2 + (y + dy - CENTRE[1]) ** 2 + (z + dz - CENTRE[2]) ** 2 < RADIUS**2
    values = 1000.0 * inside / SUBSAMPLES**3
    return A.ct_image(values)


def head_on_camera():
    camera = vtk.vtkCamera()
    distance = 0.5 * (WIDTH / PIXELS_PER_VOXEL) / np.tan(np.radians(15.0))
    pole = CENTRE + np.array([RADIUS, 0.0, 0.0])
    camera.SetViewAngle(30.0)
    camera.SetFocalPoint(*pole)
    camera.SetPosition(*(pole + np.array([distance, 0.0, 0.0])))
    camera.SetViewUp(0.0, 0.0, 1.0)
    camera.SetClippingRange(0.5 * distance, distance + 2.0 * RADIUS)
    return camera


def render(path):
    """Colour (rows from the bottom), world hit points and (CPU only) shaded normals."""
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(WIDTH, WIDTH)
    renderer = vtk.vtkRenderer()
    window.AddRenderer(renderer)
    camera = head_on_camera()
    renderer.SetActiveCamera(camera)
    mapper = vc.vtkVolumeCutVolumeMapper()
    mapper.SetInputData(box_filtered_ball())
    mapper.SetRequestedRenderPath(path)
    mapper.GetRayCaster().SetIsoValue(ISO)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    renderer.AddVolume(volume)
    window.Render()
    assert mapper.GetLastRenderPath() == path, mapper.GetGPUFallbackReason()
    rgba = vtk.vtkUnsignedCharArray()
    window.GetRGBACharPixelData(0, 0, WIDTH - 1, WIDTH - 1, 1, rgba)
    rgb = numpy_support.vtk_to_numpy(rgba).reshape(WIDTH, WIDTH, 4)[..., :3].astype(float)
    depth = vtk.vtkFloatArray()
    window.GetZbufferData(0, 0, WIDTH - 1, WIDTH - 1, depth)
    depth = numpy_support.vtk_to_numpy(depth).reshape(WIDTH, WIDTH).astype(float)
    points = A.depth_to_points(A.world_to_ndc(camera, WIDTH, WIDTH), depth)
    normals = None
    if path == vc.vtkVolumeCutVolumeMapper.CPUPath:
        image = vtk.vtkImageData()
        mapper.GetRayCaster().GetNormalImage(image)
        normals = numpy_support.vtk_to_numpy(image.GetPointData().GetScalars()).reshape(WIDTH, WIDTH, 3).astype(float)
    return rgb, points, normals


def ring_contrast(rgb):
    """Mean over 16 radial lines from the view's centre (the pole) of the brightness the line regains on its way
    out (of 255): 0 where the headlight's shading falls monotonically, as on a smooth ball."""
    brightness = rgb.mean(axis=2)
    centre = (WIDTH - 1) / 2.0
    radii = np.arange(0.0, 0.45 * WIDTH)
    regained = []
    for angle in np.linspace(0.0, 2.0 * np.pi, 16, endpoint=False):
        rows = np.rint(centre + radii * np.sin(angle)).astype(int)
        columns = np.rint(centre + radii * np.cos(angle)).astype(int)
        steps = np.diff(brightness[rows, columns])
        regained.append(steps[steps > 0].sum())
    return float(np.mean(regained))


def test_the_cap_of_a_partial_volume_ball_is_shaded_with_true_normals():
    rgb, points, normals = render(vc.vtkVolumeCutVolumeMapper.CPUPath)
    valid = np.all(np.isfinite(points), axis=2)
    # The cap the view shows: within 0.6 radii of the pole's axis.
    filled = np.where(valid[..., None], points, 0.0)
    off_axis = np.hypot(filled[..., 1] - CENTRE[1], filled[..., 2] - CENTRE[2])
    cap = valid & (off_axis < 0.6 * RADIUS)
    assert cap.sum() > 0.3 * WIDTH * WIDTH
    analytic = filled[cap] - CENTRE
    analytic /= np.linalg.norm(analytic, axis=1)[:, None]
    cosine = np.abs(np.sum(analytic * normals[cap], axis=1)) / np.linalg.norm(normals[cap], axis=1)
    angles = np.degrees(np.arccos(np.clip(cosine, 0.0, 1.0)))
    assert np.max(angles) <= 4.0, f"normal error max {np.max(angles):.2f} deg, median {np.median(angles):.2f} deg"
    contrast = ring_contrast(rgb)
    assert contrast <= 4.0, f"rings: brightness regained along a radial line {contrast:.1f} / 255"


def test_the_gpu_path_shades_the_cap_without_rings():
    rgb, points, _ = render(vc.vtkVolumeCutVolumeMapper.GPUPath)
    assert np.all(np.isfinite(points[WIDTH // 2, WIDTH // 2]))
    contrast = ring_contrast(rgb)
    assert contrast <= 4.0, f"rings: brightness regained along a radial line {contrast:.1f} / 255"
