"""A drilled pit seen head-on reads as a cavity, not as the bump of the same shape (issue 28).

Lit from the eye, a hemispherical pit in a flat block and a hemispherical
bump on it shade alike: a bright centre facing the light, sides turning
dark. Ambient occlusion at its 6 mm radius does not see a burr's pit (2 mm
radius): from the floor its points look out through the opening. So the
journeys' drilled grooves looked like raised pills. Here a noisy flat block
of bone at 0.25 mm, a 4 mm burr's pit and the bump of the same shape, drawn
head-on as the application draws them (ambient occlusion on): the pit's
floor must be clearly darker than the flat top and than the bump's top, a
deeper pit darker than a shallower one, and the CPU reference and the GLSL
path (here llvmpipe) must draw the same image.
"""

import numpy as np
import slicer_volumecutting as vc
import vtk
from vtkmodules.util import numpy_support

SPACING = 0.25
DIMENSIONS = 64
TOP = 10.0  # mm: the block's top face, z = TOP
BURR_RADIUS = 2.0
CENTRE = np.array([(DIMENSIONS - 1) / 2 * SPACING, (DIMENSIONS - 1) / 2 * SPACING, TOP])
WIDTH = 120
FIELD_MM = 12.0
CPU = vc.vtkVolumeCutVolumeMapper.CPUPath
GPU = vc.vtkVolumeCutVolumeMapper.GPUPath


def volume_image(values):
    """A float image of values (z, y, x) with unit spacing, as the mapper's input."""
    image = vtk.vtkImageData()
    image.SetDimensions(*values.shape[::-1])
    image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(values.astype(np.float32).ravel(), deep=True))
    return image


def scaled_ijk_to_ras(spacing):
    matrix = vtk.vtkMatrix4x4()
    for axis in range(3):
        matrix.SetElement(axis, axis, spacing)
    return matrix


def render_as_the_application(ct, spacing, iso, cut, path, place_camera, width=WIDTH, occlusion=True):
    """Brightness (0..255, rows from the bottom) of one path's still frame of ct at iso with ambient occlusion on,
    as vtkMRMLVolumeCutNode's default (off where asked), and a cut field (or None); place_camera(camera) sets the
    view. Also the window and the camera, for the depth image."""
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(width, width)
    renderer = vtk.vtkRenderer()
    window.AddRenderer(renderer)
    place_camera(renderer.GetActiveCamera())
    mapper = vc.vtkVolumeCutVolumeMapper()
    mapper.SetInputData(ct)
    mapper.SetRequestedRenderPath(path)
    caster = mapper.GetRayCaster()
    caster.SetIsoValue(iso)
    caster.SetAmbientOcclusion(occlusion)
    if cut is not None:
        caster.AddCutField(cut)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetUserMatrix(scaled_ijk_to_ras(spacing))
    renderer.AddVolume(volume)
    window.Render()
    assert mapper.GetLastRenderPath() == path, mapper.GetGPUFallbackReason()
    rgba = vtk.vtkUnsignedCharArray()
    window.GetRGBACharPixelData(0, 0, width - 1, width - 1, 1, rgba)
    brightness = numpy_support.vtk_to_numpy(rgba).reshape(width, width, 4)[..., :3].astype(float).mean(axis=2)
    return brightness, window, renderer.GetActiveCamera()


def block(bump_centre_depth=None):
    """Bone 1000 under z = TOP (a two-voxel partial-volume ramp, fixed-seed noise), with a ball of the burr's
    radius added whose centre lies this deep under the top (a bump), as a scan."""
    index = np.arange(DIMENSIONS) * SPACING
    z, y, x = np.meshgrid(index, index, index, indexing="ij")
    inside = TOP - z  # mm into the material
    if bump_centre_depth is not None:
        radius = np.sqrt((x - CENTRE[0]) ** 2 + (y - CENTRE[1]) ** 2 + (z - CENTRE[2] + bump_centre_depth) ** 2)
        inside = np.maximum(inside, BURR_RADIUS - radius)
    values = 1000.0 * np.clip(0.5 + inside / (2.0 * SPACING), 0.0, 1.0)
    return volume_image(values + np.random.default_rng(28).normal(0.0, 15.0, values.shape))


def render_head_on(path, pit_centre_height=None, bump_centre_depth=None):
    """Brightness (0..255, rows from the top) of the block seen along -z, with a burr's pit whose centre lies
    this high over the top (0: a hemisphere) or a bump."""
    def head_on(camera):
        camera.ParallelProjectionOn()
        camera.SetParallelScale(FIELD_MM / 2.0)
        camera.SetFocalPoint(*CENTRE)
        camera.SetPosition(*(CENTRE + [0.0, 0.0, 60.0]))
        camera.SetViewUp(0.0, 1.0, 0.0)
        camera.SetClippingRange(20.0, 120.0)

    cut = None
    if pit_centre_height is not None:
        cut = vc.vtkVolumeCutField()
        assert cut.Initialize([DIMENSIONS] * 3, scaled_ijk_to_ras(SPACING), 2)
        centre = list(CENTRE + [0.0, 0.0, pit_centre_height])
        assert cut.CutCapsule(centre, centre, BURR_RADIUS)
    return render_as_the_application(block(bump_centre_depth), SPACING, 500.0, cut, path, head_on)[0][::-1]


def from_axis_mm():
    rows, columns = np.mgrid[0:WIDTH, 0:WIDTH]
    return np.hypot(columns - (WIDTH - 1) / 2, rows - (WIDTH - 1) / 2) * FIELD_MM / WIDTH


def test_a_pit_reads_darker_than_the_bump_of_its_shape():
    r = from_axis_mm()
    centre, flat = r < 0.4, r > 4.0
    pit = render_head_on(CPU, pit_centre_height=0.0)
    shallow = render_head_on(CPU, pit_centre_height=1.0)  # 1 mm deep, as the journeys' first stroke
    bump = render_head_on(CPU, bump_centre_depth=0.0)
    figures = (f"flat top {pit[flat].mean():.1f}, pit floor {pit[centre].mean():.1f}, "
               f"1 mm pit floor {shallow[centre].mean():.1f}, bump top {bump[centre].mean():.1f}")
    print(figures)
    # Head-on the floor and the bump's top face the light as the flat top
    # does: only a depth cue sets them apart.
    assert pit[centre].mean() < 0.7 * pit[flat].mean(), figures
    assert shallow[centre].mean() < 0.85 * shallow[flat].mean(), figures
    assert pit[centre].mean() < shallow[centre].mean() - 10.0, figures
    assert bump[centre].mean() > 0.9 * bump[flat].mean(), figures
    assert pit[centre].mean() < 0.7 * bump[centre].mean(), figures
    # Away from the cut nothing changes.
    assert np.array_equal(pit[r > 3.0], render_head_on(CPU)[r > 3.0])


def test_cpu_and_gpu_shade_the_pit_alike():
    cpu = render_head_on(CPU, pit_centre_height=0.5)
    gpu = render_head_on(GPU, pit_centre_height=0.5)
    differs = np.abs(cpu - gpu) > 2
    assert np.mean(differs) < 0.005, f"{100 * np.mean(differs):.2f} % of pixels differ by more than 2/255"
