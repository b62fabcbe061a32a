"""Bone drawn at a CT iso-value beside tissue that is hidden or has no segment: a smooth surface, not voxel terraces.

A label map classifies voxel centres while the CT averages each voxel's
material, so the first voxel outside a bone is often above the iso-value.
Such partial-volume voxels, and hidden voxels below it, used to decide the
bone's border by label weights, half a voxel from its last voxel, and the
bone showed the voxels' terraces (issue 28, finding 10: the temporal-bone
phantom, whose soft tissue is hidden, is the application's first picture).
Figures: how far the drawn surface strays from a sphere (the spread of its
points' distances to the ball's centre, in voxels: a terrace is a flat piece
of a sphere), and the share of neighbouring pixel pairs inside the object
whose brightness differs by more than 6/255, both against the same ball in
air, where no voxel outside the bone reaches the iso-value.
"""

import numpy as np
import pytest
import slicer_volumecutting as vc
import vtk
from vtkmodules.util import numpy_support

SIZE = 48
RADIUS = 15.3  # voxels: the surface crosses voxels at every offset
BONE_HU, SOFT_HU, AIR_HU = 1700.0, 40.0, -1000.0
ISO = 300.0
WIDTH = 240
BONE, SOFT = 1, 2


def ball_volume(outside_hu):
    """CT of a bone ball (partial volume from 4^3 sub-samples a voxel) and its label map (bone at voxel centres)."""
    sub = (np.arange(4) + 0.5) / 4.0 - 0.5
    axis = np.arange(SIZE, dtype=float) - (SIZE - 1) / 2.0 + 0.17
    fraction = np.zeros((SIZE, SIZE, SIZE))
    for dz in sub:
        for dy in sub:
            for dx in sub:
                z, y, x = np.meshgrid(axis + dz, axis + dy, axis + dx, indexing="ij")
                fraction += (x * x + y * y + z * z <= RADIUS * RADIUS)
    fraction /= sub.size**3
    ct = outside_hu + (BONE_HU - outside_hu) * fraction
    z, y, x = np.meshgrid(axis, axis, axis, indexing="ij")
    labels = np.where(x * x + y * y + z * z <= RADIUS * RADIUS, BONE, SOFT).astype(np.uint16)
    return ct.astype(np.float32), labels


def image(array):
    data = vtk.vtkImageData()
    data.SetDimensions(SIZE, SIZE, SIZE)
    data.SetSpacing(0.5, 0.5, 0.5)
    data.GetPointData().SetScalars(numpy_support.numpy_to_vtk(np.ascontiguousarray(array).ravel(), deep=True))
    return data


def make_camera():
    camera = vtk.vtkCamera()
    center = np.full(3, 0.5 * (SIZE - 1) * 0.5)
    camera.SetFocalPoint(*center)
    camera.SetPosition(*(center + np.array([36.0, 5.0, 3.0])))
    camera.SetViewUp(0.0, 0.0, 1.0)
    camera.SetViewAngle(30.0)
    camera.SetClippingRange(20.0, 100.0)
    return camera


def world_to_ndc(camera=None):
    camera = camera or make_camera()
    matrix = vtk.vtkMatrix4x4()
    matrix.DeepCopy(camera.GetCompositeProjectionTransformMatrix(1.0, -1.0, 1.0))
    return matrix


def configure(caster, ct, labels, soft_label):
    caster.SetAnatomy(image(ct), None)
    caster.SetIsoValue(ISO)
    caster.SetLabelMap(image(np.where(labels == SOFT, soft_label, labels).astype(np.uint16)))
    caster.SetSegmentAppearance(BONE, (0.94, 0.84, 0.57), 1.0, ISO)


def step_share(rgba, segments):
    """Share of horizontal and vertical pixel pairs, both well inside the object, that differ by more than 6/255."""
    grey = 255.0 * rgba[..., :3].mean(axis=2)
    inside = segments > 0
    for _ in range(4):
        eroded = inside.copy()
        eroded[1:] &= inside[:-1]
        eroded[:-1] &= inside[1:]
        eroded[:, 1:] &= inside[:, :-1]
        eroded[:, :-1] &= inside[:, 1:]
        inside = eroded
    pairs = steps = 0
    for axis in (0, 1):
        difference = np.abs(np.diff(grey, axis=axis))
        both = inside[1:, :] & inside[:-1, :] if axis == 0 else inside[:, 1:] & inside[:, :-1]
        pairs += int(both.sum())
        steps += int(np.count_nonzero(difference[both] > 6.0))
    assert pairs > 0.3 * WIDTH * WIDTH
    return steps / pairs


def buffer(getter, components=1):
    data = vtk.vtkImageData()
    getter(data)
    values = numpy_support.vtk_to_numpy(data.GetPointData().GetScalars())
    return values.reshape(WIDTH, WIDTH, components) if components > 1 else values.reshape(WIDTH, WIDTH)


def surface_points(depth, matrix=None):
    """World points (mm) of the pixels where a surface was drawn."""
    matrix = matrix or world_to_ndc()
    inverse = np.linalg.inv(np.array([[matrix.GetElement(r, c) for c in range(4)] for r in range(4)]))
    rows, columns = np.nonzero(depth < 1.0)
    ndc = np.stack([(columns + 0.5) / WIDTH * 2.0 - 1.0, (rows + 0.5) / WIDTH * 2.0 - 1.0, 2.0 * depth[rows, columns] - 1.0,
                    np.ones(rows.size)])
    world = inverse @ ndc
    return (world[:3] / world[3]).T


def radial_spread(depth, matrix=None):
    """Standard deviation (voxels) of the drawn points' distances to the ball's centre."""
    center = np.full(3, ((SIZE - 1) / 2.0 - 0.17) * 0.5)
    return float(np.std(np.linalg.norm(surface_points(depth, matrix) - center, axis=1) / 0.5))


def cpu_render(ct, labels, soft_label):
    caster = vc.vtkVolumeCutRayCaster()
    configure(caster, ct, labels, soft_label)
    assert caster.Render(world_to_ndc(), WIDTH, WIDTH)
    return buffer(caster.GetColorImage, 4), buffer(caster.GetSegmentImage), buffer(caster.GetDepthImage)


@pytest.fixture(scope="module")
def in_air():
    ct, labels = ball_volume(AIR_HU)
    rgba, segments, depth = cpu_render(ct, labels, 0)
    return step_share(rgba, segments), radial_spread(depth)


@pytest.fixture(scope="module")
def in_soft_tissue():
    return ball_volume(SOFT_HU)


@pytest.mark.parametrize("soft_label", [0, SOFT], ids=["unlabelled", "hidden segment"])
def test_bone_beside_hidden_soft_tissue_is_as_smooth_as_in_air(in_air, in_soft_tissue, soft_label):
    ct, labels = in_soft_tissue
    rgba, segments, depth = cpu_render(ct, labels, soft_label)
    air_steps, air_spread = in_air
    # Before the partial-volume labels: spread 0.27 voxel (unlabelled) and 0.17 (hidden segment), steps 4.4 %
    # and 2.0 %; now 0.09 and 1.9 %; in air 0.05 and 1.3 % (what is left is the trilinear iso-surface's
    # grain on a CT without the scanner's blur, in air as in tissue).
    assert radial_spread(depth) <= air_spread + 0.06
    assert step_share(rgba, segments) <= air_steps + 0.01
    # The surface is the bone's: its colour, nothing of the hidden tissue.
    assert set(np.unique(segments)) <= {0, BONE}


def test_the_gpu_path_draws_the_same_smooth_surface(in_air, in_soft_tissue):
    """The GLSL reads the label map the CPU resolved: the same surface on llvmpipe (or a GPU) as on the CPU."""
    ct, labels = in_soft_tissue
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(WIDTH, WIDTH)
    renderer = vtk.vtkRenderer()
    window.AddRenderer(renderer)
    mapper = vc.vtkVolumeCutVolumeMapper()
    mapper.SetInputData(image(ct))
    configure(mapper.GetRayCaster(), ct, labels, 0)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    renderer.AddVolume(volume)
    camera = make_camera()
    renderer.SetActiveCamera(camera)
    mapper.SetRequestedRenderPath(vc.vtkVolumeCutVolumeMapper.GPUPath)
    window.Render()
    assert mapper.GetLastRenderPath() == vc.vtkVolumeCutVolumeMapper.GPUPath, mapper.GetGPUFallbackReason()
    depth = vtk.vtkFloatArray()
    window.GetZbufferData(0, 0, WIDTH - 1, WIDTH - 1, depth)
    depth = numpy_support.vtk_to_numpy(depth).reshape(WIDTH, WIDTH)
    assert radial_spread(depth, world_to_ndc(camera)) <= in_air[1] + 0.06


def test_a_hidden_bone_beside_a_shown_one_stays_hidden():
    """A bright hidden segment is not a partial-volume rim: its border with the shown bone stays where the labels put it."""
    ct = np.full((SIZE, SIZE, SIZE), AIR_HU, dtype=np.float32)
    labels = np.zeros((SIZE, SIZE, SIZE), dtype=np.uint16)
    ct[8:40, 8:40, 8:40] = BONE_HU
    labels[8:40, 8:40, 8:40] = BONE
    # The near half (x >= 24, towards the camera) is hidden and brighter: not the shown bone's partial volume.
    ct[8:40, 8:40, 24:40] = BONE_HU + 200.0
    labels[8:40, 8:40, 24:40] = SOFT
    _, segments, depth = cpu_render(ct, labels, SOFT)
    assert set(np.unique(segments)) == {0, BONE}
    shown = (segments == BONE) & (depth < 1.0)
    assert np.count_nonzero(shown) > 0.05 * WIDTH * WIDTH
    # The shown bone's face is the labels' border (x halfway between voxels 23 and 24: 11.75 mm), not
    # the hidden half's face at 19.75 mm (nor its rim voxels given to the shown bone).
    x = surface_points(np.where(shown, depth, 1.0))[:, 0]
    assert np.median(x) == pytest.approx(11.75, abs=0.3)
