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

The phantom the application opens with is held to the same standard on its own voxel grid: its cap shows no more
rings than an analytic ellipsoid with a band-limited edge (the phantom's CT now has a scanner's blur).
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


def camera_along_x(pole, pixels_per_unit, height, depth):
    """A 30 degree camera on the +x side looking at ``pole`` (the view's centre), ``pixels_per_unit`` at the pole."""
    camera = vtk.vtkCamera()
    distance = 0.5 * (height / pixels_per_unit) / np.tan(np.radians(15.0))
    camera.SetViewAngle(30.0)
    camera.SetFocalPoint(*pole)
    camera.SetPosition(*(pole + np.array([distance, 0.0, 0.0])))
    camera.SetViewUp(0.0, 0.0, 1.0)
    camera.SetClippingRange(0.5 * distance, distance + depth)
    return camera


def head_on_camera():
    return camera_along_x(CENTRE + np.array([RADIUS, 0.0, 0.0]), PIXELS_PER_VOXEL, WIDTH, 2.0 * RADIUS)


def draw(image, camera, iso, width, height, path):
    """The window after the product's mapper drew ``image``'s iso-surface on ``path``; its mapper; its colours
    (rows from the bottom)."""
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(width, height)
    renderer = vtk.vtkRenderer()
    window.AddRenderer(renderer)
    renderer.SetActiveCamera(camera)
    mapper = vc.vtkVolumeCutVolumeMapper()
    mapper.SetInputData(image)
    mapper.SetRequestedRenderPath(path)
    mapper.GetRayCaster().SetIsoValue(iso)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    renderer.AddVolume(volume)
    window.Render()
    assert mapper.GetLastRenderPath() == path, mapper.GetGPUFallbackReason()
    rgba = vtk.vtkUnsignedCharArray()
    window.GetRGBACharPixelData(0, 0, width - 1, height - 1, 1, rgba)
    rgb = numpy_support.vtk_to_numpy(rgba).reshape(height, width, 4)[..., :3].astype(float)
    return window, mapper, rgb


def render(path):
    """Colour (rows from the bottom), world hit points and (CPU only) shaded normals."""
    camera = head_on_camera()
    window, mapper, rgb = draw(box_filtered_ball(), camera, ISO, WIDTH, WIDTH, path)
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


# --- The phantom the web application opens with (issue 28, finding 10) --------------------------------------
#
# The cap of its bone ellipsoid, seen from the patient's right as the application first shows it (about 11 pixels
# per mm: 4.4 per 0.4 mm voxel), on the application's own voxel grid: a block of the phantom around the cortex's
# lateral pole, generated with the same grid phase, scale and noise. Its rings are compared with those of an
# analytic reference: the same ellipsoid from its exact signed distance, edge blurred by a Gaussian of half a voxel
# (0.2 mm), with the very same noise. Such a reference shows no rings to the eye at this zoom (0.6 / 255 moved beyond
# the net change along a radial line, on both paths), while one blurred by 0.15 mm already shows faint rings (8.2),
# and so did the phantom with only each voxel's average over 3 x 3 x 3 points (36.1; 0.3 with the scanner's blur).
# The phantom may exceed the reference by 2 / 255.
APP_PIXELS_PER_MM = 11.0
CAP_WIDTH, CAP_HEIGHT = 240, 200
CAP_REFERENCE_SIGMA_MM = 0.2
INVISIBLE_EXCESS = 2.0


def phantom_cap_block():
    """The block of the application's phantom around the cortex's lateral pole; the cortex ellipsoid; the pole."""
    from VolumeCuttingLib.data import phantom as ph
    from VolumeCuttingLib.webapp.session import PHANTOM_DIMENSIONS, PHANTOM_SPACING

    spacing = np.asarray(PHANTOM_SPACING, dtype=float)
    full_origin = -spacing * (np.asarray(PHANTOM_DIMENSIONS) - 1) / 2.0
    scale = ph._auto_scale(PHANTOM_DIMENSIONS, spacing, np.eye(3))
    cortex = ph.TemporalBoneAnatomy(scale=scale).segment("MastoidCortex").primitives[0]
    pole = cortex.center + np.array([cortex.radii[0], 0.0, 0.0])
    # 8 mm into the bone to 2 mm out of it; 12 mm either side along y and 10 mm along z: the whole view.
    lower = np.floor((pole - (8.0, 12.0, 10.0) - full_origin) / spacing)
    upper = np.ceil((pole + (2.0, 12.0, 10.0) - full_origin) / spacing)
    block = ph.generate_phantom(dimensions=tuple(int(n) for n in upper - lower + 1), spacing=spacing,
                                origin=full_origin + lower * spacing, scale=scale, anatomy_center_ras=(0.0, 0.0, 0.0),
                                ct_dtype="int16")
    return block, cortex, pole


def analytic_cap(block, cortex):
    """The block's CT replaced by the cortex ellipsoid alone, its edge the exact signed distance through a Gaussian
    of CAP_REFERENCE_SIGMA_MM, plus the block's own noise."""
    from math import erf

    from VolumeCuttingLib.data import phantom as ph

    ni, nj, nk = block.dimensions
    k, j, i = np.meshgrid(np.arange(nk), np.arange(nj), np.arange(ni), indexing="ij")
    distance = cortex.signed_distance(block.ijk_to_ras_points(np.stack([i, j, k], axis=-1)))
    occupancy = 0.5 * (1.0 - np.vectorize(erf)(distance / (CAP_REFERENCE_SIGMA_MM * np.sqrt(2.0))))
    clean = ph.HU_SOFT_TISSUE + (ph.HU_CORTICAL_BONE - ph.HU_SOFT_TISSUE) * occupancy
    noise = block.ct.astype(float) - block.ct_noise_free
    return np.rint(clean + noise)


def render_cap(values, block, pole, path):
    """Brightness (0-255, rows from the bottom) of the cap seen along -x with the pole at the view's centre."""
    image = A.ct_image(values)
    image.SetSpacing(*block.spacing)
    image.SetOrigin(*block.origin)
    camera = camera_along_x(pole, APP_PIXELS_PER_MM, CAP_HEIGHT, 20.0)
    # The application's bone surface (session.SURFACE_ISO_HU).
    _, _, rgb = draw(image, camera, 300.0, CAP_WIDTH, CAP_HEIGHT, path)
    return rgb.mean(axis=2)


def excess_variation(brightness):
    """Mean over 16 radial lines from the view's centre to 0.45 of its height of the brightness the line moves
    beyond its net change (total variation - |end - start|, of 255): 0 where the shading falls steadily from the pole,
    as on a smooth ellipsoid under a headlight; each ring adds twice its contrast."""
    centre = (np.array(brightness.shape) - 1) / 2.0
    radii = np.arange(0.0, 0.45 * min(brightness.shape))
    excess = []
    for angle in np.linspace(0.0, 2.0 * np.pi, 16, endpoint=False):
        rows = np.rint(centre[0] + radii * np.sin(angle)).astype(int)
        columns = np.rint(centre[1] + radii * np.cos(angle)).astype(int)
        line = brightness[rows, columns]
        excess.append(np.abs(np.diff(line)).sum() - abs(line[-1] - line[0]))
    return float(np.mean(excess))


@pytest.mark.parametrize("path", ["CPUPath", "GPUPath"])
def test_the_phantom_cap_shows_no_more_rings_than_a_smooth_analytic_ellipsoid(path):
    path = getattr(vc.vtkVolumeCutVolumeMapper, path)
    block, cortex, pole = phantom_cap_block()
    phantom_rings = excess_variation(render_cap(block.ct.astype(float), block, pole, path))
    reference_rings = excess_variation(render_cap(analytic_cap(block, cortex), block, pole, path))
    assert reference_rings < 8.0, f"the analytic reference itself shows rings: {reference_rings:.1f} / 255"
    assert phantom_rings <= reference_rings + INVISIBLE_EXCESS, (
        f"the phantom's cap shows rings: brightness moves {phantom_rings:.1f} / 255 beyond its net change along a "
        f"radial line, the analytic reference {reference_rings:.1f} / 255")
