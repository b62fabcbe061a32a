"""A carved floor in soft tissue shows no isolated dark pixels (issue 28, finding 10b).

SoftCut carves a region given as sampled signed distances whose value is a
depth along the plan's normal, not the distance to the floor along every
direction: above a floor it can be larger. The ray marcher jumps across a
cavity by a sample's removed depth; where that overshot the floor, the ray
landed inside the tissue and was shaded with the CT's gradient there (noise
in homogeneous tissue), a dark or bright speck among the floor's pixels.
Here a noisy slab of soft tissue (40 HU, iso-value -500 as SoftCut's skin)
has a box carved 6 mm deep whose depth component is twice the distance to
the floor, seen obliquely from above on the CPU reference and the GLSL path:
no pixel of the floor may be darker than the median of its eight neighbours
by more than 15/255.
"""

import numpy as np
import pytest
import slicer_volumecutting as vc
import vtk
from vtkmodules.util import numpy_support

from test_cavity_shading import render_as_the_application, scaled_ijk_to_ras, volume_image
from VolumeCuttingLib.data.analyticscene import depth_to_points, world_to_ndc

SPACING = 0.5
DIMENSIONS = 48
TOP = 18.0  # mm: the tissue's top face
FLOOR = 12.0  # mm: the carved floor
HALF_WIDTH = 7.0  # mm: the carved box's half width in x and y
CENTRE = np.array([(DIMENSIONS - 1) / 2 * SPACING, (DIMENSIONS - 1) / 2 * SPACING, FLOOR])
WIDTH = 160
DARKER = 15  # of 255


def tissue():
    """Soft tissue (40 HU, noise 15 HU, fixed seed) under z = TOP with a two-voxel partial-volume ramp, air above."""
    index = np.arange(DIMENSIONS) * SPACING
    z = np.meshgrid(index, index, index, indexing="ij")[0]
    inside = np.clip(0.5 + (TOP - z) / (2.0 * SPACING), 0.0, 1.0)
    return volume_image(-1000.0 + 1040.0 * inside + np.random.default_rng(28).normal(0.0, 15.0, z.shape))


def carved_box():
    """The box over the floor, as SoftCut gives a region: the largest of a depth component (twice the height over
    the floor, negative above it) and the walls' distances."""
    index = np.arange(DIMENSIONS) * SPACING
    z, y, x = np.meshgrid(index, index, index, indexing="ij")
    depth = 2.0 * (FLOOR - z)
    walls = np.maximum(np.abs(x - CENTRE[0]), np.abs(y - CENTRE[1])) - HALF_WIDTH
    distances = volume_image(np.maximum(depth, walls))
    cut = vc.vtkVolumeCutField()
    assert cut.Initialize([DIMENSIONS] * 3, scaled_ijk_to_ras(SPACING), 2)
    assert cut.CutSampledRegion(distances)
    return cut


def render_floor(path):
    """Brightness (0..255, rows from the bottom) of the carved box seen from above at 30 degrees, and the floor's
    pixels."""
    def from_above(camera):
        direction = np.array([0.0, -np.sin(np.radians(30.0)), np.cos(np.radians(30.0))])
        camera.SetFocalPoint(*CENTRE)
        camera.SetPosition(*(CENTRE + 80.0 * direction))
        camera.SetViewUp(0.0, 1.0, 0.0)
        camera.OrthogonalizeViewUp()
        camera.SetViewAngle(20.0)
        camera.SetClippingRange(40.0, 140.0)

    brightness, window, camera = render_as_the_application(tissue(), SPACING, -500.0, carved_box(), path, from_above,
                                                           WIDTH)
    depth = vtk.vtkFloatArray()
    window.GetZbufferData(0, 0, WIDTH - 1, WIDTH - 1, depth)
    depth = numpy_support.vtk_to_numpy(depth).reshape(WIDTH, WIDTH).astype(float)
    # The floor's pixels: the world points under the depth image on the floor, away from the walls.
    points = depth_to_points(world_to_ndc(camera, WIDTH, WIDTH), depth)
    inner = np.max(np.abs(points[..., :2] - CENTRE[:2]), axis=-1) < HALF_WIDTH - 1.0
    floor = (np.abs(points[..., 2] - FLOOR) < 0.3) & inner
    return brightness, floor


def isolated_dark(brightness, mask):
    """Pixels of mask darker than the median of their eight neighbours by more than DARKER."""
    padded = np.pad(brightness, 1, mode="edge")
    neighbours = np.stack([padded[1 + dy:WIDTH + 1 + dy, 1 + dx:WIDTH + 1 + dx]
                           for dy in (-1, 0, 1) for dx in (-1, 0, 1) if (dy, dx) != (0, 0)])
    return mask & (brightness < np.median(neighbours, axis=0) - DARKER)


@pytest.mark.parametrize("path", [vc.vtkVolumeCutVolumeMapper.CPUPath, vc.vtkVolumeCutVolumeMapper.GPUPath],
                         ids=["cpu", "gpu"])
def test_a_carved_floor_has_no_isolated_dark_pixels(path):
    brightness, floor = render_floor(path)
    assert np.count_nonzero(floor) > 0.1 * WIDTH * WIDTH, "the floor should fill much of the view"
    specks = isolated_dark(brightness, floor)
    count = np.count_nonzero(specks)
    assert count == 0, f"{count} isolated dark pixels among {np.count_nonzero(floor)} of the floor"
