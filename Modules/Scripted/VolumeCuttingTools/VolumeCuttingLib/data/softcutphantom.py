"""A CT whose skin is an analytic sphere over a bone shell, for SoftCut's accuracy.

The skin is the sphere of radius ``skin_radius`` (mm) about ``center``; under
it lies soft tissue, then a bone shell between ``bone_inner`` and
``bone_outer``, then brain-like tissue. Every boundary is blurred by a smooth
step of width ``blur`` voxels (a CT's point-spread function), so the CT's
iso-surface half-way between two tissues lies on the analytic sphere to a
small fraction of a voxel.

A resection outlined by the circle at distance ``r`` from the axis through
the top of the sphere (+S) and carved ``d`` mm deep has an exact volume:

* local normals: the wall follows the sphere's normals, a cone through the
  centre, so the resection is a spherical sector's shell,
  ``2 pi / 3 (1 - cos theta) (R^3 - (R - d)^3)`` with ``sin theta = r / R``
  (``exact_volume_local_normal``);
* the average normal: the wall is the cylinder of radius r about the axis,
  and the depth is measured to the skin inside the outline
  (``exact_volume_average_normal``, by quadrature).

Where the depth reaches the bone (d > R - bone_outer), bone is never carved
and the resection stops at the bone.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

AIR_HU = -1000.0
SOFT_TISSUE_HU = 40.0
BONE_HU = 1200.0
BRAIN_HU = 35.0
SKIN_ISO_HU = 0.5 * (AIR_HU + SOFT_TISSUE_HU)  # the analytic sphere
BONE_THRESHOLD_HU = 0.5 * (SOFT_TISSUE_HU + BONE_HU)


@dataclass
class SpherePhantom:
    ct: np.ndarray                 # (k, j, i) float32, HU
    ijk_to_ras: np.ndarray         # 4x4
    center: np.ndarray             # RAS, mm
    skin_radius: float
    bone_outer: float
    bone_inner: float

    @property
    def dimensions(self):
        return tuple(int(n) for n in self.ct.shape[::-1])

    @property
    def spacing(self):
        return tuple(float(np.linalg.norm(self.ijk_to_ras[:3, axis])) for axis in range(3))

    def voxel_centers_ras(self):
        """RAS of every voxel centre, (k, j, i, 3)."""
        k, j, i = np.meshgrid(*(np.arange(n, dtype=np.float64) for n in self.ct.shape), indexing="ij")
        ijk = np.stack([i, j, k, np.ones_like(i)], axis=-1)
        return (ijk @ self.ijk_to_ras.T)[..., :3]

    def radius_of_voxels(self):
        return np.linalg.norm(self.voxel_centers_ras() - self.center, axis=-1)

    def bone_voxels(self, threshold=BONE_THRESHOLD_HU):
        """Voxels whose CT lies above the soft-tissue range (bone and the bone's partial-volume surface)."""
        return self.ct > threshold

    def interior_bone_voxels(self, threshold=BONE_THRESHOLD_HU):
        """Bone through and through: the voxel and its 26 neighbours above the soft-tissue range."""
        bone = self.bone_voxels(threshold)
        interior = bone.copy()
        for dk in (-1, 0, 1):
            for dj in (-1, 0, 1):
                for di in (-1, 0, 1):
                    interior &= np.roll(bone, (dk, dj, di), axis=(0, 1, 2))
        interior[[0, -1], :, :] = interior[:, [0, -1], :] = interior[:, :, [0, -1]] = False
        return interior

    def bone_fraction(self, voxels_kji, samples=4):
        """The part (0..1) of each voxel's cube inside the analytic bone shell, by samples^3 points."""
        voxels = np.asarray(voxels_kji, dtype=float).reshape(-1, 3)
        offsets = (np.arange(samples) + 0.5) / samples - 0.5
        grid = np.stack(np.meshgrid(offsets, offsets, offsets, indexing="ij"), axis=-1).reshape(-1, 3)
        fractions = np.zeros(len(voxels))
        for offset in grid:
            ijk = voxels[:, ::-1] + offset
            ras = ijk @ self.ijk_to_ras[:3, :3].T + self.ijk_to_ras[:3, 3]
            r = np.linalg.norm(ras - self.center, axis=1)
            fractions += (r >= self.bone_inner) & (r <= self.bone_outer)
        return fractions / len(grid)


def smooth_step(x, width):
    """1 well inside (x > 0), 0 well outside; half at x = 0."""
    return 0.5 * (1.0 + np.tanh(x / width))


def make_sphere_phantom(dimensions=None, spacing=(1.0, 1.0, 1.0), skin_radius=40.0, bone_outer=31.0, bone_inner=27.0,
                        blur=0.6, noise=0.0, seed=0, flip_x=False) -> SpherePhantom:
    """The phantom, centred in the grid (by default just large enough for the skin and 8 mm of air
    around it); ``flip_x`` makes i run towards patient right (as many CTs)."""
    spacing = np.asarray(spacing, dtype=float)
    if dimensions is None:
        dimensions = np.ceil(2.0 * (skin_radius + 8.0) / spacing).astype(int) + 1
    dims = np.asarray(dimensions, dtype=int)
    ijk_to_ras = np.eye(4)
    ijk_to_ras[:3, :3] = np.diag(spacing)
    if flip_x:
        ijk_to_ras[0, 0] = -spacing[0]
    # The grid's centre at the RAS origin.
    ijk_to_ras[:3, 3] = -ijk_to_ras[:3, :3] @ ((dims - 1) / 2.0)
    center = np.zeros(3)
    phantom = SpherePhantom(np.zeros(dims[::-1], np.float32), ijk_to_ras, center, skin_radius, bone_outer, bone_inner)
    r = phantom.radius_of_voxels()
    width = blur * float(spacing.max())
    skin = smooth_step(skin_radius - r, width)
    bone = smooth_step(bone_outer - r, width) - smooth_step(bone_inner - r, width)
    brain = smooth_step(bone_inner - r, width)
    ct = AIR_HU + (SOFT_TISSUE_HU - AIR_HU) * skin + (BONE_HU - SOFT_TISSUE_HU) * bone + (BRAIN_HU - SOFT_TISSUE_HU) * brain
    if noise > 0.0:
        ct = ct + np.random.default_rng(seed).normal(0.0, noise, ct.shape)
    phantom.ct = ct.astype(np.float32)
    return phantom


def circle_outline(phantom: SpherePhantom, radius: float, count: int = 72, axis=(0.0, 0.0, 1.0), start_angle=0.0) -> np.ndarray:
    """Points (RAS) on the skin along the circle at distance ``radius`` from the axis through the centre."""
    axis = np.asarray(axis, dtype=float)
    axis /= np.linalg.norm(axis)
    helper = np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(axis, helper)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(axis, e1)
    height = math.sqrt(phantom.skin_radius ** 2 - radius ** 2)
    angles = start_angle + 2.0 * math.pi * np.arange(count) / count
    return np.array([phantom.center + height * axis + radius * (math.cos(a) * e1 + math.sin(a) * e2) for a in angles])


def exact_volume_local_normal(skin_radius: float, radius: float, depth: float, bone_outer: float = 0.0) -> float:
    """Resected volume (mm^3) with local normals: a spherical sector's shell, stopped at the bone."""
    theta = math.asin(radius / skin_radius)
    inner = max(skin_radius - depth, bone_outer)
    return 2.0 * math.pi / 3.0 * (1.0 - math.cos(theta)) * (skin_radius ** 3 - inner ** 3)


def exact_volume_average_normal(skin_radius: float, radius: float, depth: float, bone_outer: float = 0.0, steps: int = 2000) -> float:
    """Resected volume (mm^3) with the average normal: inside the cylinder of the outline, within
    ``depth`` of the skin inside the outline, outside the bone; by quadrature over (rho, z)."""
    R = skin_radius
    z_rim = math.sqrt(R * R - radius * radius)
    rho = (np.arange(steps) + 0.5) * radius / steps
    volume = 0.0
    z = np.linspace(-R, R, 2 * steps + 1)
    dz = z[1] - z[0]
    zc = 0.5 * (z[1:] + z[:-1])
    for value in rho:
        r3 = np.sqrt(value * value + zc * zc)
        inside = (r3 < R) & (zc > 0.0) & (r3 > bone_outer)
        # Depth under the skin inside the outline: along the radius while its
        # foot lies inside the outline, else to the outline's rim.
        foot_rho = value * R / np.maximum(r3, 1e-12)
        to_rim = np.sqrt((value - radius) ** 2 + (zc - z_rim) ** 2)
        distance = np.where(foot_rho <= radius, R - r3, to_rim)
        volume += 2.0 * math.pi * value * (radius / steps) * dz * np.count_nonzero(inside & (distance < depth))
    return float(volume)


def add_volume_node(scene, phantom: SpherePhantom, name="SpherePhantom"):
    """The phantom's CT as a scalar volume node (float HU)."""
    from ..scene import nodes

    return nodes.create_scalar_volume_node(scene, phantom.ct, phantom.ijk_to_ras, name)
