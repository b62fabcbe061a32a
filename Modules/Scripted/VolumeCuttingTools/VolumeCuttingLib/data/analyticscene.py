"""The mapper's accuracy scene: a cube of bone with spherical and cylindrical cuts.

Everything here is known exactly, so rendered images are compared with a ray
tracing of the true geometry, not with earlier images:

- the CT is a cube of "bone" whose profile across each face is a linear ramp
  two voxels wide (a blurred CT edge). Its faces pass through voxel centres, so
  that the data itself holds the sharp cube: a CT of a cube at an arbitrary
  offset has rounded edges in the samples, whatever renders them;
- the cuts are spheres and cylinders (capsules whose caps lie outside the cube)
  at sub-voxel positions, across the cube's edges and corners and into a face.
  They are cut into a real vtkVolumeCutField.

Metrics, the same for any renderer that gives a window depth per pixel:
- each pixel's visible point (from its depth) is classified by the nearest
  exact surface: background, cube face, or cut;
- edge position error: for every pixel whose class differs from the exact
  image, the distance (pixels) from its centre to the nearest exact border,
  found on the exact image supersampled ``supersampling`` times;
- normal error: angle between the renderer's normal (its own, or one from its
  depth map) and the exact normal, on pixels at least 3 pixels from any border.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import vtk
from vtk.util import numpy_support

BACKGROUND, CUBE, CUT = 0, 1, 2


@dataclass
class Sphere:
    center: tuple
    radius: float


@dataclass
class Cylinder:
    """An infinite cylinder inside the volume: a capsule whose caps lie outside the cube."""

    point: tuple
    direction: tuple
    radius: float


@dataclass
class CubeScene:
    dimensions: int = 64
    spacing: float = 0.5
    half_size_voxels: int = 14  # cube faces at centre +- this many voxels (voxel centres)
    ramp_voxels: float = 2.0
    bone: float = 1000.0
    spheres: list = field(default_factory=list)
    cylinders: list = field(default_factory=list)

    # -- geometry -----------------------------------------------------------
    @property
    def center(self) -> np.ndarray:
        c = (self.dimensions // 2) * self.spacing
        return np.array([c, c, c])

    @property
    def half_size(self) -> float:
        return self.half_size_voxels * self.spacing

    def ijk_to_ras(self) -> vtk.vtkMatrix4x4:
        matrix = vtk.vtkMatrix4x4()
        for axis in range(3):
            matrix.SetElement(axis, axis, self.spacing)
        return matrix

    def cube_distance(self, points: np.ndarray) -> np.ndarray:
        """Exact signed distance (mm) to the cube, negative inside."""
        q = np.abs(points - self.center) - self.half_size
        outside = np.linalg.norm(np.maximum(q, 0.0), axis=-1)
        inside = np.minimum(np.max(q, axis=-1), 0.0)
        return outside + inside

    def intensities(self) -> vtk.vtkImageData:
        n = self.dimensions
        # Separable: the box distance from per-axis offsets, broadcast (float32).
        q = (np.abs(np.arange(n, dtype=np.float32) * self.spacing - np.float32(self.center[0])) - np.float32(self.half_size))
        qz, qy, qx = q[:, None, None], q[None, :, None], q[None, None, :]
        outside = np.sqrt(np.maximum(qx, 0) ** 2 + np.maximum(qy, 0) ** 2 + np.maximum(qz, 0) ** 2)
        inside = np.minimum(np.maximum(np.maximum(qx, qy), qz), 0)
        width = np.float32(self.ramp_voxels * self.spacing)
        values = np.float32(self.bone) * np.clip(np.float32(0.5) - (outside + inside) / width, 0, 1)
        return ct_image(values)

    def iso_value(self) -> float:
        return 0.5 * self.bone

    def cut_field(self, factor: int = 2):
        import slicer_volumecutting as vc

        cut = vc.vtkVolumeCutField()
        cut.SetMaximumStrokeLength(1.0e6)
        if not cut.Initialize([self.dimensions] * 3, self.ijk_to_ras(), factor):
            raise RuntimeError("cut field initialisation failed")
        self.apply_cuts(cut)
        return cut

    @staticmethod
    def masked_intensities(intensities: vtk.vtkImageData, cut) -> vtk.vtkImageData:
        """Today's Slicer approach: the CT with voxels removed by at least half set to 0 (air)."""
        fraction = vtk.vtkImageData()
        cut.ExportRemovedFraction(fraction)
        values = numpy_support.vtk_to_numpy(intensities.GetPointData().GetScalars()).copy()
        values[numpy_support.vtk_to_numpy(fraction.GetPointData().GetScalars()) >= 0.5] = 0.0
        masked = vtk.vtkImageData()
        masked.SetDimensions(intensities.GetDimensions())
        masked.GetPointData().SetScalars(numpy_support.numpy_to_vtk(values, deep=True))
        return masked

    def apply_cuts(self, cut) -> None:
        for sphere in self.spheres:
            cut.CutCapsule(sphere.center, sphere.center, sphere.radius)
        for cylinder in self.cylinders:
            reach = 2.0 * self.dimensions * self.spacing
            direction = np.asarray(cylinder.direction, float)
            direction /= np.linalg.norm(direction)
            p0 = np.asarray(cylinder.point) - reach * direction
            p1 = np.asarray(cylinder.point) + reach * direction
            cut.CutCapsule(list(p0), list(p1), cylinder.radius)

    # -- exact ray tracing ----------------------------------------------------
    def trace(self, origins: np.ndarray, directions: np.ndarray):
        """First visible point of each ray: (t, class, normal); t = inf for none.

        The visible solid is the cube minus the union of the cuts; the first
        visible point is the cube's entry or the exit of a cut, whichever is
        the first one inside the cube and outside every cut.
        """
        count = origins.shape[0]
        lo = self.center - self.half_size
        hi = self.center + self.half_size
        with np.errstate(divide="ignore", invalid="ignore"):
            inverse = 1.0 / directions
            t0 = (lo - origins) * inverse
            t1 = (hi - origins) * inverse
        tmin = np.minimum(t0, t1)
        tmax = np.maximum(t0, t1)
        cube_in = np.max(tmin, axis=1)
        cube_out = np.min(tmax, axis=1)
        entry_axis = np.argmax(tmin, axis=1)
        hits_cube = cube_in < cube_out

        intervals = []  # (enter, exit, exit normal function)
        for sphere in self.spheres:
            c = np.asarray(sphere.center, float)
            oc = origins - c
            b = np.einsum("ij,ij->i", oc, directions)
            cc = np.einsum("ij,ij->i", oc, oc) - sphere.radius**2
            disc = b * b - cc
            root = np.sqrt(np.maximum(disc, 0.0))
            enter = np.where(disc > 0, -b - root, np.inf)
            leave = np.where(disc > 0, -b + root, -np.inf)
            intervals.append((enter, leave, ("sphere", c, sphere.radius)))
        for cylinder in self.cylinders:
            a = np.asarray(cylinder.direction, float)
            a /= np.linalg.norm(a)
            p = np.asarray(cylinder.point, float)
            op = origins - p
            d_perp = directions - np.outer(directions @ a, a)
            o_perp = op - np.outer(op @ a, a)
            qa = np.einsum("ij,ij->i", d_perp, d_perp)
            qb = np.einsum("ij,ij->i", d_perp, o_perp)
            qc = np.einsum("ij,ij->i", o_perp, o_perp) - cylinder.radius**2
            disc = qb * qb - qa * qc
            root = np.sqrt(np.maximum(disc, 0.0))
            with np.errstate(divide="ignore", invalid="ignore"):
                enter = np.where((disc > 0) & (qa > 1e-15), (-qb - root) / qa, np.inf)
                leave = np.where((disc > 0) & (qa > 1e-15), (-qb + root) / qa, -np.inf)
            # A ray along the axis inside the cylinder is removed throughout.
            inside_parallel = (qa <= 1e-15) & (qc < 0)
            enter = np.where(inside_parallel, -np.inf, enter)
            leave = np.where(inside_parallel, np.inf, leave)
            intervals.append((enter, leave, ("cylinder", p, a)))

        def removed(t):
            result = np.zeros(count, bool)
            for enter, leave, _ in intervals:
                result |= (t > enter) & (t < leave)
            return result

        best_t = np.full(count, np.inf)
        best_class = np.zeros(count, np.int32)
        best_source = np.full(count, -1)
        candidate = np.where(hits_cube & ~removed(cube_in), cube_in, np.inf)
        better = candidate < best_t
        best_t[better] = candidate[better]
        best_class[better] = CUBE
        for n, (enter, leave, _) in enumerate(intervals):
            ok = hits_cube & (leave >= cube_in) & (leave < cube_out)
            # The exit of one cut may lie inside another: then it is not visible.
            others = np.zeros(count, bool)
            for m, (e2, l2, _) in enumerate(intervals):
                if m != n:
                    others |= (leave > e2) & (leave < l2)
            candidate = np.where(ok & ~others, leave, np.inf)
            better = candidate < best_t
            best_t[better] = candidate[better]
            best_class[better] = CUT
            best_source[better] = n

        points = origins + directions * np.where(np.isfinite(best_t), best_t, 0.0)[:, None]
        normals = np.zeros((count, 3))
        cube_hit = best_class == CUBE
        normals[cube_hit, entry_axis[cube_hit]] = -np.sign(directions[cube_hit, entry_axis[cube_hit]])
        for n, (_, _, shape) in enumerate(intervals):
            sel = best_source == n
            if not np.any(sel):
                continue
            if shape[0] == "sphere":
                vector = shape[1] - points[sel]
            else:
                rel = points[sel] - shape[1]
                vector = -(rel - np.outer(rel @ shape[2], shape[2]))
            normals[sel] = vector / np.linalg.norm(vector, axis=1)[:, None]
        return best_t, best_class, normals

    def surface_distances(self, points: np.ndarray) -> np.ndarray:
        """Unsigned distances (mm) of points to each exact surface: the cube, then each sphere, then each cylinder."""
        distances = [np.abs(self.cube_distance(points))]
        for sphere in self.spheres:
            distances.append(np.abs(np.linalg.norm(points - np.asarray(sphere.center), axis=1) - sphere.radius))
        for cylinder in self.cylinders:
            a = np.asarray(cylinder.direction, float)
            a /= np.linalg.norm(a)
            rel = points - np.asarray(cylinder.point)
            radial = np.linalg.norm(rel - np.outer(rel @ a, a), axis=1)
            distances.append(np.abs(radial - cylinder.radius))
        return np.stack(distances, axis=1)

    def classify_points(self, points: np.ndarray, valid: np.ndarray) -> np.ndarray:
        """Class of rendered surface points by the nearest exact surface."""
        nearest = np.argmin(self.surface_distances(points), axis=1)
        classes = np.where(nearest == 0, CUBE, CUT).astype(np.int32)
        return np.where(valid, classes, BACKGROUND)

    def crease_distance(self, points: np.ndarray) -> np.ndarray:
        """How far (mm) surface points are from the scene's creases: the cube's
        edges, and where two exact surfaces meet (a point this near two
        surfaces). The CT and the cut fields are sampled: they round a crease
        over about a voxel, where no normal can be the exact one."""
        second_surface = np.sort(self.surface_distances(points), axis=1)[:, 1]
        second_face = np.sort(np.abs(np.abs(points - self.center) - self.half_size), axis=1)[:, 1]
        return np.minimum(second_surface, second_face)


def ct_image(values: np.ndarray) -> vtk.vtkImageData:
    """A CT (float32 scalars named "CT") from an array indexed [k, j, i], at unit spacing."""
    nk, nj, ni = values.shape
    image = vtk.vtkImageData()
    image.SetDimensions(ni, nj, nk)
    array = numpy_support.numpy_to_vtk(np.ascontiguousarray(values, dtype=np.float32).ravel(), deep=True)
    array.SetName("CT")
    image.GetPointData().SetScalars(array)
    return image


def default_scene(dimensions: int = 64) -> CubeScene:
    """The issue's scene: cuts across a corner, two edges and into a face.

    Larger ``dimensions`` scale the whole scene (cube, cuts) with the grid, at
    the same voxel size, for performance measurements.
    """
    scale = dimensions / 64.0
    scene = CubeScene(dimensions=dimensions, half_size_voxels=int(round(14 * scale)))
    c = scene.center
    h = scene.half_size
    s = scene.spacing * scale
    scene.spheres = [
        Sphere(tuple(c + [h - 0.37 * s, h - 0.61 * s, h + 0.23 * s]), 5.3 * s),  # a corner
        Sphere(tuple(c + [h + 0.81 * s, 0.17 * s, h - 1.93 * s]), 4.1 * s),  # an edge
    ]
    scene.cylinders = [
        Cylinder(tuple(c + [-4.31 * s, h + 0.42 * s, h - 0.27 * s]), (1.0, 0.0, 0.0), 3.2 * s),  # along an edge
        Cylinder(tuple(c + [5.13 * s, -3.71 * s, h]), (0.2, 0.3, 1.0), 3.6 * s),  # a hole into the top face
    ]
    return scene


# -- cameras and rays ------------------------------------------------------------
def make_camera(scene: CubeScene, pixels_per_voxel: float, width: int, height: int) -> vtk.vtkCamera:
    """A perspective camera looking at the cut corner, zoomed to the given scale."""
    camera = vtk.vtkCamera()
    focal = scene.center + np.array([0.55, 0.35, 0.75]) * scene.half_size
    direction = np.array([1.0, 0.8, 1.25])
    direction /= np.linalg.norm(direction)
    camera.SetViewAngle(30.0)
    visible_height = height / pixels_per_voxel * scene.spacing
    distance = 0.5 * visible_height / np.tan(np.radians(15.0))
    camera.SetFocalPoint(*focal)
    camera.SetPosition(*(focal + distance * direction))
    camera.SetViewUp(0.0, 0.0, 1.0)
    camera.OrthogonalizeViewUp()
    camera.SetClippingRange(0.5 * distance, distance + 4.0 * scene.dimensions * scene.spacing)
    return camera


def world_to_ndc(camera: vtk.vtkCamera, width: int, height: int) -> vtk.vtkMatrix4x4:
    matrix = vtk.vtkMatrix4x4()
    matrix.DeepCopy(camera.GetCompositeProjectionTransformMatrix(width / height, -1.0, 1.0))
    return matrix


def _matrix(m: vtk.vtkMatrix4x4) -> np.ndarray:
    return np.array([[m.GetElement(r, c) for c in range(4)] for r in range(4)])


def pixel_rays(matrix: vtk.vtkMatrix4x4, width: int, height: int, supersampling: int = 1):
    """Rays (origins, unit directions) through pixel centres, row 0 at the bottom."""
    inverse = np.linalg.inv(_matrix(matrix))
    w, h = width * supersampling, height * supersampling
    xs = (np.arange(w) + 0.5) / w * 2.0 - 1.0
    ys = (np.arange(h) + 0.5) / h * 2.0 - 1.0
    x, y = np.meshgrid(xs, ys)
    near = np.stack([x.ravel(), y.ravel(), -np.ones(x.size), np.ones(x.size)])
    far = near.copy()
    far[2] = 1.0
    near_w = inverse @ near
    far_w = inverse @ far
    near_w = (near_w[:3] / near_w[3]).T
    far_w = (far_w[:3] / far_w[3]).T
    directions = far_w - near_w
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    return near_w, directions


def depth_to_points(matrix: vtk.vtkMatrix4x4, depth: np.ndarray) -> np.ndarray:
    """World points of a window depth image (height x width); NaN where empty."""
    height, width = depth.shape
    inverse = np.linalg.inv(_matrix(matrix))
    xs = (np.arange(width) + 0.5) / width * 2.0 - 1.0
    ys = (np.arange(height) + 0.5) / height * 2.0 - 1.0
    x, y = np.meshgrid(xs, ys)
    ndc = np.stack([x.ravel(), y.ravel(), 2.0 * depth.ravel() - 1.0, np.ones(x.size)])
    world = inverse @ ndc
    points = (world[:3] / world[3]).T.reshape(height, width, 3)
    points[depth >= 1.0] = np.nan
    return points


def normals_from_points(points: np.ndarray, view_directions: np.ndarray) -> np.ndarray:
    """Normals of a depth map's surface by central differences, facing the viewer."""
    dx = np.full_like(points, np.nan)
    dy = np.full_like(points, np.nan)
    dx[:, 1:-1] = points[:, 2:] - points[:, :-2]
    dy[1:-1, :] = points[2:, :] - points[:-2, :]
    n = np.cross(dx, dy)
    n /= np.linalg.norm(n, axis=2)[..., None]
    flip = np.einsum("ijk,ijk->ij", n, view_directions) > 0
    n[flip] *= -1.0
    return n


@dataclass
class Reference:
    width: int
    height: int
    supersampling: int
    classes: np.ndarray  # height x width
    normals: np.ndarray  # height x width x 3
    view_directions: np.ndarray  # height x width x 3
    border_points: np.ndarray  # (n, 2) pixel coordinates of exact borders, to 1/(2 supersampling) px


def exact_reference(scene: CubeScene, matrix: vtk.vtkMatrix4x4, width: int, height: int, supersampling: int = 4) -> Reference:
    origins, directions = pixel_rays(matrix, width, height)
    _, classes, normals = scene.trace(origins, directions)
    classes = classes.reshape(height, width)
    normals = normals.reshape(height, width, 3)
    # Borders between classes on the supersampled exact image, located between
    # neighbouring fine pixels.
    s = supersampling
    fine_o, fine_d = pixel_rays(matrix, width, height, s)
    fine = np.empty(fine_o.shape[0], np.int32)
    for start in range(0, fine_o.shape[0], 1 << 20):
        _, c, _ = scene.trace(fine_o[start : start + (1 << 20)], fine_d[start : start + (1 << 20)])
        fine[start : start + (1 << 20)] = c
    fine = fine.reshape(height * s, width * s)
    points = []
    horizontal = fine[:, 1:] != fine[:, :-1]
    yy, xx = np.nonzero(horizontal)
    points.append(np.stack([(xx + 1.0) / s, (yy + 0.5) / s], axis=1))
    vertical = fine[1:, :] != fine[:-1, :]
    yy, xx = np.nonzero(vertical)
    points.append(np.stack([(xx + 0.5) / s, (yy + 1.0) / s], axis=1))
    border_points = np.concatenate(points)
    return Reference(width, height, s, classes, normals, directions.reshape(height, width, 3), border_points)


def _nearest_distance(queries: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Distance from each query to the nearest point (brute force, in chunks)."""
    result = np.full(queries.shape[0], np.inf)
    if points.shape[0] == 0:
        return result
    for start in range(0, queries.shape[0], 256):
        q = queries[start : start + 256]
        d2 = np.full(q.shape[0], np.inf)
        for first in range(0, points.shape[0], 8192):
            p = points[first : first + 8192]
            d2 = np.minimum(d2, np.min(np.sum((q[:, None, :] - p[None, :, :]) ** 2, axis=2), axis=1))
        result[start : start + 256] = np.sqrt(d2)
    return result


def near_borders(classes: np.ndarray, margin: int) -> np.ndarray:
    """Pixels within ``margin`` pixels (Chebyshev) of a class border."""
    border = np.zeros(classes.shape, bool)
    border[:, 1:] |= classes[:, 1:] != classes[:, :-1]
    border[:, :-1] |= classes[:, 1:] != classes[:, :-1]
    border[1:, :] |= classes[1:, :] != classes[:-1, :]
    border[:-1, :] |= classes[1:, :] != classes[:-1, :]
    near = border.copy()
    for _ in range(margin):
        grown = near.copy()
        grown[1:, :] |= near[:-1, :]
        grown[:-1, :] |= near[1:, :]
        grown[:, 1:] |= near[:, :-1]
        grown[:, :-1] |= near[:, 1:]
        near = grown
    return near


def edge_errors(reference: Reference, classes: np.ndarray) -> np.ndarray:
    """Distances (px) from the exact borders of the pixels classified wrongly."""
    y, x = np.nonzero(classes != reference.classes)
    return _nearest_distance(np.stack([x + 0.5, y + 0.5], axis=1), reference.border_points)


def normal_errors(reference: Reference, normals: np.ndarray, classes: np.ndarray, margin: int = 3, keep=None) -> np.ndarray:
    """Angles (degrees) between normals and the exact ones, away from borders (and only at pixels in keep, if given)."""
    inside_image = np.zeros(classes.shape, bool)
    inside_image[margin:-margin, margin:-margin] = True
    sel = (classes == reference.classes) & (reference.classes != BACKGROUND) & ~near_borders(reference.classes, margin) & inside_image
    if keep is not None:
        sel &= keep
    a = normals[sel]
    b = reference.normals[sel]
    ok = np.all(np.isfinite(a), axis=1)
    cosine = np.clip(np.einsum("ij,ij->i", a[ok], b[ok]), -1.0, 1.0)
    angles = np.degrees(np.arccos(cosine))
    # A normal that could not be computed counts as wholly wrong.
    return np.concatenate([angles, np.full(int(np.sum(~ok)), 90.0)])


def summarize(values: np.ndarray) -> dict:
    if values.size == 0:
        return {"count": 0, "median": 0.0, "p95": 0.0, "p99": 0.0, "max": 0.0}
    return {
        "count": int(values.size),
        "median": float(np.median(values)),
        "p95": float(np.percentile(values, 95)),
        "p99": float(np.percentile(values, 99)),
        "max": float(np.max(values)),
    }
