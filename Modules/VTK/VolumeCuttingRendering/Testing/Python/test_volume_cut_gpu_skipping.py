"""GPU empty-space skipping at parity with the CPU path.

In iso-surface mode the OpenGL path skips what the CPU reference skips: it
walks the cells where no visible object can be and lands on the ray's sample
grid before the first that may hold one, jumps the cube of empty blocks
around a sample, jumps the removed depth deep in a cavity, and refines an
interval only where the trilinear CT reaches the iso-value along it. Each
scene below is one where a wrong skip loses something: small specks and a
thin shell that lie between samples, a surface just past a long empty run, a
cavity floor just beyond the removed depth, rays that enter where the walk
starts in a cell that may hold an object, wires whose CT peaks between the
cell walls a ray crosses. Each must draw the CPU's image
(the mapper tests' tolerance), and each must stop doing so when the skipping
is deliberately broken (the broken code is injected before main() with
SetExtraFragmentDeclarations): otherwise the scene would not test it.
Rendered with whatever OpenGL VTK gives offscreen (Mesa llvmpipe here).
"""

import numpy as np
import pytest
import slicer_volumecutting as vc
import vtk
from test_volume_cut_mapper import read_window, render_window
from vtk.util import numpy_support

from VolumeCuttingLib.data import analyticscene as A

GPU = vc.vtkVolumeCutVolumeMapper.GPUPath
CPU = vc.vtkVolumeCutVolumeMapper.CPUPath
WIDTH = 64
SPACING = 0.5
BONE = 1000.0
ISO = 500.0

# Deliberately broken skipping, injected before main(): each redefines a
# function main() calls by a wrong one built on it.
WALK_ONE_CELL_TOO_FAR = """
float walkTooFar(vec3 p, float t, float tEnd)
{
  // Lands past the cell the walk stops at (a cell is at most sqrt(3) voxels across).
  return min(exitEmptyCells(p, t, tEnd) + 1.8 / length(rayDirection), tEnd);
}
#define exitEmptyCells(p, t, tEnd) walkTooFar(p, t, tEnd)
"""
WALK_PAST_THE_START_CELL = """
float walkPastStart(vec3 p, float t, float tEnd)
{
  // Starts the walk in the next cell, as if the cell the ray is in were empty.
  float wallT = 1e30;
  for (int axis = 0; axis < 3; ++axis)
  {
    if (abs(rayDirection[axis]) >= 1e-12)
    {
      float wall = rayDirection[axis] > 0.0 ? floor(p[axis]) + 1.0 : floor(p[axis]);
      wallT = min(wallT, t + (wall - p[axis]) / rayDirection[axis]);
    }
  }
  float next = min(wallT + 1e-4, tEnd);
  return exitEmptyCells(p + (next - t) * rayDirection, next, tEnd);
}
#define exitEmptyCells(p, t, tEnd) walkPastStart(p, t, tEnd)
"""
NO_REFINEMENT = """
bool neverRefined(inout Sample a, inout Sample b, float voxelsPerMillimetre)
{
  // As if the CT never reached the iso-value between two samples that agree.
  if (a.object != 0 || b.object != 0)
  {
    evaluateCuts(a);
    evaluateCuts(b);
  }
  return leafInterval(a, b);
}
#define surfaceInterval(a, b, v) neverRefined(a, b, v)
"""
BLOCK_JUMP_TOO_FAR = """
float jumpTooFar(vec3 p, float t)
{
  // One block beyond the empty cube around p's block.
  return blockExit(p, t) + float(BLOCK) / length(rayDirection);
}
#define blockExit(p, t) jumpTooFar(p, t)
"""
CAVITY_JUMP_TOO_FAR = """
float cavityTooFar(Sample s)
{
  // Past everything behind the floor: a jump that lands in visible material
  // is refused (the ray marches on), one that leaves the object is not.
  return removedDepthExit(s) + 1.0e4;
}
#define removedDepthExit(s) cavityTooFar(s)
"""


def volume_of(values):
    """vtkImageData of ``values`` (k, j, i), float32."""
    nz, ny, nx = values.shape
    image = vtk.vtkImageData()
    image.SetDimensions(nx, ny, nz)
    image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(np.ascontiguousarray(values, dtype=np.float32).ravel(), deep=True))
    return image


def grid(n):
    """Voxel coordinates (k, j, i) of an n^3 grid, broadcastable."""
    index = np.arange(n, dtype=np.float64)
    return index[:, None, None], index[None, :, None], index[None, None, :]


def specks(n=48, count=90, seed=7):
    """Small blobs at sub-voxel positions: iso-surfaces about a voxel across, most between samples."""
    rng = np.random.default_rng(seed)
    k, j, i = grid(n)
    values = np.zeros((n, n, n))
    for centre in rng.uniform(6.0, n - 7.0, size=(count, 3)):
        distance = np.sqrt((i - centre[0]) ** 2 + (j - centre[1]) ** 2 + (k - centre[2]) ** 2)
        values = np.maximum(values, BONE * np.clip(1.0 - distance / rng.uniform(1.6, 2.6), 0.0, 1.0))
    return values


def shell(n=48, radius=17.3, half_thickness=0.55):
    """A spherical shell about a voxel thick: its rim is only ever grazed."""
    k, j, i = grid(n)
    centre = 0.5 * (n - 1) + np.array([0.31, -0.22, 0.17])
    r = np.sqrt((i - centre[0]) ** 2 + (j - centre[1]) ** 2 + (k - centre[2]) ** 2)
    return BONE * np.clip(1.0 - np.abs(r - radius) / (2.0 * half_thickness), 0.0, 1.0)


def wires(n=40, count=25, peak=900.0, seed=5):
    """Columns of single bright voxels along k: beside one, the trilinear CT peaks between the cell walls a
    ray crosses, above the iso-value where the walls' values stay under it."""
    rng = np.random.default_rng(seed)
    values = np.zeros((n, n, n))
    for i, j in rng.integers(6, n - 6, size=(count, 2)):
        values[6 : n - 6, j, i] = peak
    return values


def slab(n=48, face=29.37):
    """Bone beyond x = face (a 2-voxel ramp), and specks before it: long empty runs, then a surface."""
    k, j, i = grid(n)
    values = BONE * np.clip(0.5 + (i - face) / 2.0, 0.0, 1.0) * np.ones((n, n, n))
    return np.maximum(values, specks(n, count=20, seed=3) * (i < face - 4.0))


def camera_on(centre_voxels, direction, pixels_per_voxel=1.5, width=WIDTH, view_angle=30.0):
    """A perspective camera looking at ``centre_voxels`` from ``direction`` (world, mm = SPACING per voxel)."""
    direction = np.asarray(direction, float)
    direction /= np.linalg.norm(direction)
    focal = np.asarray(centre_voxels, float) * SPACING
    visible = width / pixels_per_voxel * SPACING
    distance = 0.5 * visible / np.tan(np.radians(0.5 * view_angle))
    camera = vtk.vtkCamera()
    camera.SetViewAngle(view_angle)
    camera.SetFocalPoint(*focal)
    camera.SetPosition(*(focal + distance * direction))
    up = (0.0, 0.0, 1.0) if abs(direction[2]) < 0.9 else (0.0, 1.0, 0.0)
    camera.SetViewUp(*up)
    camera.OrthogonalizeViewUp()
    camera.SetClippingRange(0.2 * distance, distance + 200.0)
    return camera


class View:
    """A window with one volume (iso-surface mode) drawn by the mapper on either path."""

    def __init__(self, values, camera, cut=None, planes=None, program_cache=None):
        self.window, renderer = render_window(WIDTH)
        renderer.SetActiveCamera(camera)
        self.mapper = vc.vtkVolumeCutVolumeMapper()
        self.mapper.SetInputData(volume_of(values))
        self.mapper.GetRayCaster().SetIsoValue(ISO)
        if cut is not None:
            self.mapper.GetRayCaster().AddCutField(cut)
        if planes is not None:
            self.mapper.SetClippingPlanes(planes)
        if program_cache is not None:
            self.mapper.SetProgramCacheDirectory(str(program_cache))
        volume = vtk.vtkVolume()
        volume.SetMapper(self.mapper)
        matrix = vtk.vtkMatrix4x4()
        for axis in range(3):
            matrix.SetElement(axis, axis, SPACING)
        volume.SetUserMatrix(matrix)
        renderer.AddVolume(volume)

    def draw(self, path, broken=""):
        self.mapper.GetOpenGLRayCaster().SetExtraFragmentDeclarations(broken)
        self.mapper.SetRequestedRenderPath(path)
        self.window.Render()
        assert self.mapper.GetLastRenderPath() == path, self.mapper.GetGPUFallbackReason()
        return read_window(self.window, WIDTH)


def mismatch(cpu, gpu):
    """How the GPU image departs from the CPU's: pixels covered on one path only, the largest depth
    difference where both are covered, the share of pixels whose colour differs by more than 2/255."""
    cpu_depth, cpu_color = cpu
    gpu_depth, gpu_color = gpu
    both = (cpu_depth < 1.0) & (gpu_depth < 1.0)
    return {
        "coverage": int(np.count_nonzero((cpu_depth < 1.0) != (gpu_depth < 1.0))),
        "depth": float(np.max(np.abs(cpu_depth - gpu_depth)[both], initial=0.0)),
        "colour": float(np.mean(np.max(np.abs(cpu_color - gpu_color), axis=2) > 2)),
    }


def like_cpu(difference):
    """The mapper tests' tolerance (float against double arithmetic): depth within 1e-4, colour within
    2/255 on 99.5 % of pixels; of specks grazed at their rim, at most 0.1 % of pixels covered on one path only."""
    return difference["coverage"] <= 0.001 * WIDTH * WIDTH and difference["depth"] < 1e-4 and difference["colour"] < 0.005


def assert_parity(view, breakages):
    """The GPU draws the CPU's image; each broken skipping in ``breakages`` makes it differ."""
    cpu = view.draw(CPU)
    assert np.mean(cpu[0] < 1.0) > 0.02, "the view must show the scene"
    gpu = view.draw(GPU)
    difference = mismatch(cpu, gpu)
    assert like_cpu(difference), difference
    for name, code in breakages.items():
        broken = mismatch(cpu, view.draw(GPU, code))
        assert not like_cpu(broken), f"the scene does not see a {name}: {broken}"
    # The skipping off (the GPU path before it) draws the same image too.
    view.mapper.GetOpenGLRayCaster().EmptySpaceSkippingOff()
    difference = mismatch(cpu, view.draw(GPU))
    view.mapper.GetOpenGLRayCaster().EmptySpaceSkippingOn()
    assert like_cpu(difference), difference


@pytest.fixture(scope="module")
def program_cache(tmp_path_factory):
    """One folder of program binaries for the module: each program is compiled once."""
    return tmp_path_factory.mktemp("programs")


@pytest.mark.parametrize("direction", [(1.0, 0.7, 0.45), (-0.3, 1.0, -0.8)])
def test_specks_between_samples_are_drawn_alike(direction, program_cache):
    n = 48
    view = View(specks(n), camera_on([0.5 * (n - 1)] * 3, direction, pixels_per_voxel=1.6), program_cache=program_cache)
    assert_parity(view, {"walk one cell too far": WALK_ONE_CELL_TOO_FAR, "missing refinement": NO_REFINEMENT})


def test_a_thin_shell_is_grazed_alike_and_opened_by_a_plane(program_cache):
    n = 48
    planes = vtk.vtkPlaneCollection()
    plane = vtk.vtkPlane()
    # Rays enter at the plane, many of them inside the shell's wall: the walk
    # starts in a cell that may hold the object.
    plane.SetOrigin(*(np.array([0.5 * (n - 1) + 3.1] * 3) * SPACING))
    plane.SetNormal(-0.8, -0.5, -0.33)
    planes.AddItem(plane)
    view = View(shell(n), camera_on([0.5 * (n - 1)] * 3, (0.8, 0.5, 0.33), pixels_per_voxel=1.2), planes=planes,
        program_cache=program_cache)
    assert_parity(
        view,
        {
            "walk one cell too far": WALK_ONE_CELL_TOO_FAR,
            "walk past the cell it starts in": WALK_PAST_THE_START_CELL,
            "missing refinement": NO_REFINEMENT,
        },
    )


def test_a_surface_just_past_a_long_empty_run(program_cache):
    n = 48
    # Grazing the slab's face: rays cross many empty cells and blocks, then the surface.
    view = View(slab(n), camera_on([30.0, 0.5 * (n - 1), 0.5 * (n - 1)], (-0.35, -1.0, 0.3), pixels_per_voxel=1.4),
        program_cache=program_cache)
    assert_parity(
        view,
        {
            "walk one cell too far": WALK_ONE_CELL_TOO_FAR,
            "walk past the cell it starts in": WALK_PAST_THE_START_CELL,
            "block jump one block too far": BLOCK_JUMP_TOO_FAR,
        },
    )


def test_a_cavity_floor_just_beyond_the_removed_depth(program_cache):
    # The analytic cube with pits drilled into its top face: deep in a pit the
    # ray jumps its removed depth and must still land before the floor (a
    # landing in visible material is refused, so the breakage jumps past
    # the cube).
    scene = A.CubeScene(dimensions=40, half_size_voxels=12)
    c, h, s = scene.center, scene.half_size, scene.spacing
    scene.spheres = [A.Sphere(tuple(c + [1.3 * s, -2.1 * s, h + 0.7 * s]), 6.2 * s), A.Sphere(tuple(c + [-6.4 * s, 5.9 * s, h - 0.4 * s]), 4.3 * s)]
    scene.cylinders = [A.Cylinder(tuple(c + [6.2 * s, 6.1 * s, h]), (0.1, -0.2, 1.0), 2.9 * s)]
    values = numpy_support.vtk_to_numpy(scene.intensities().GetPointData().GetScalars()).reshape((scene.dimensions,) * 3)
    camera = camera_on(c / s + [0.0, 0.0, 12.0], (0.25, -0.35, 1.0), pixels_per_voxel=2.2)
    view = View(values, camera, cut=scene.cut_field(2), program_cache=program_cache)
    assert_parity(view, {"cavity jump too far": CAVITY_JUMP_TOO_FAR})


@pytest.mark.parametrize("direction", [(1.0, -1.0, 0.1), (1.0, 0.98, -0.2)])
def test_peaks_between_cell_walls_are_refined_alike(direction, program_cache):
    # Samples 1.5 voxels apart: the wires are found by refinement, which the
    # exact test asks for only where the CT reaches the iso-value between two
    # samples. A test that looks at the cell pieces' ends only (not where the
    # cubic along a piece peaks) drew 26 and 83 pixels differently here.
    n = 40
    view = View(wires(n), camera_on([0.5 * (n - 1)] * 3, direction, pixels_per_voxel=1.6), program_cache=program_cache)
    view.mapper.GetRayCaster().SetSampleDistance(1.5)
    assert_parity(view, {"missing refinement": NO_REFINEMENT})
