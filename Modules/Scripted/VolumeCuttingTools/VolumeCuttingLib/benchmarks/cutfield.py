"""Benchmark area ``cutfield``: accuracy, stroke time and memory of the sub-voxel cut field.

Each figure of ``vtkVolumeCutField`` is set against whole-voxel removal
(``vtkBinaryVoxelCutter``) on the same grid and strokes; accuracies against
exact volumes and surfaces (a sphere's closed form, a union of capsules
integrated along lines).
"""

from __future__ import annotations

import time

import numpy as np
import slicer
import vtk

from .harness import grid_matrix, machine_description, measurement



def _sphere_points(center, radius, count, seed=11):
    rng = np.random.default_rng(seed)
    z = rng.uniform(-1.0, 1.0, count)
    phi = rng.uniform(0.0, 2.0 * np.pi, count)
    r = np.sqrt(1.0 - z * z)
    normals = np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)
    return np.asarray(center) + radius * normals, normals


def _field_surface_error(field, center, radius, voxel):
    points, _ = _sphere_points(center, radius, 2000)
    offsets = np.array([abs(field.GetSignedDistance(p)) for p in points]) / voxel
    return float(np.sqrt(np.mean(offsets ** 2))), float(offsets.max())


def _binary_surface_error(cutter, center, radius, voxel):
    """Offset of the staircase boundary along the normal from the exact surface."""
    points, normals = _sphere_points(center, radius, 500)
    steps = np.linspace(-1.5, 1.5, 301) * voxel
    offsets = []
    for point, normal in zip(points, normals):
        removed = [cutter.IsRemoved(point + t * normal) for t in steps]
        crossing = next((steps[n] for n in range(1, len(steps)) if removed[n - 1] and not removed[n]), steps[-1])
        offsets.append(abs(crossing) / voxel)
    offsets = np.array(offsets)
    return float(np.sqrt(np.mean(offsets ** 2))), float(offsets.max())


def _union_of_capsules_volume(starts, ends, radii, lines=700):
    """Exact-to-quadrature volume of a union of capsules.

    For lines parallel to x on a lines x lines grid over the union's y-z
    extent, each capsule's crossing is one interval (the hull of its two end
    spheres' and its cylinder's crossings, the capsule being convex); the
    union's length on a line is the merged length of those intervals, and the
    volume is its midpoint-rule integral over y and z.
    """
    lower = np.minimum(starts, ends).min(axis=0) - radii.max()
    upper = np.maximum(starts, ends).max(axis=0) + radii.max()
    ys = lower[1] + (np.arange(lines) + 0.5) * (upper[1] - lower[1]) / lines
    zs = lower[2] + (np.arange(lines) + 0.5) * (upper[2] - lower[2]) / lines
    y, z = np.meshgrid(ys, zs, indexing="ij")
    y, z = y.ravel(), z.ravel()
    first = np.full((y.size, len(radii)), np.inf)
    last = np.full((y.size, len(radii)), -np.inf)

    def hull(t0, t1, ok, index):
        first[:, index] = np.where(ok, np.minimum(first[:, index], t0), first[:, index])
        last[:, index] = np.where(ok, np.maximum(last[:, index], t1), last[:, index])

    for index, (a, b, r) in enumerate(zip(starts, ends, radii)):
        for center in (a, b):
            # (x - cx)^2 + (y - cy)^2 + (z - cz)^2 <= r^2
            rest = r * r - (y - center[1]) ** 2 - (z - center[2]) ** 2
            ok = rest >= 0.0
            root = np.sqrt(np.where(ok, rest, 0.0))
            hull(center[0] - root, center[0] + root, ok, index)
        axis = b - a
        length = np.linalg.norm(axis)
        u = axis / length
        # Points (t, y, z): w = (t - ax, y - ay, z - az); |w|^2 - (w.u)^2 <= r^2, 0 <= w.u <= length.
        wy, wz = y - a[1], z - a[2]
        qa = 1.0 - u[0] ** 2
        qb = 2.0 * (-(wy * u[1] + wz * u[2]) * u[0])
        qc = wy ** 2 + wz ** 2 - (wy * u[1] + wz * u[2]) ** 2 - r * r
        disc = qb * qb - 4.0 * qa * qc
        ok = disc >= 0.0
        root = np.sqrt(np.where(ok, disc, 0.0))
        s0 = (-qb - root) / (2.0 * qa)
        s1 = (-qb + root) / (2.0 * qa)
        base = wy * u[1] + wz * u[2]  # w.u at s = 0
        if abs(u[0]) > 1e-12:
            c0 = (0.0 - base) / u[0]
            c1 = (length - base) / u[0]
            lo, hi = np.minimum(c0, c1), np.maximum(c0, c1)
            s0, s1 = np.maximum(s0, lo), np.minimum(s1, hi)
        else:
            ok &= (base >= 0.0) & (base <= length)
        ok &= s0 <= s1
        hull(s0 + a[0], s1 + a[0], ok, index)
    order = np.argsort(first, axis=1)
    first = np.take_along_axis(first, order, axis=1)
    last = np.take_along_axis(last, order, axis=1)
    valid = np.isfinite(first)
    first = np.where(valid, first, 0.0)
    last = np.where(valid, last, 0.0)
    reach = np.maximum.accumulate(np.where(valid, last, -np.inf), axis=1)
    previous = np.concatenate([np.full((y.size, 1), -np.inf), reach[:, :-1]], axis=1)
    covered = np.where(valid, np.maximum(0.0, last - np.maximum(first, previous)), 0.0).sum(axis=1)
    cell = (upper[1] - lower[1]) / lines * (upper[2] - lower[2]) / lines
    return float(covered.sum() * cell)


def cutfield(repeats: int) -> list[dict]:
    machine = machine_description()
    results = []
    voxel = 0.5
    dims = [48, 48, 48]
    center = [11.87, 12.21, 11.63]
    for radius_voxels in (3.0, 5.0):
        radius = radius_voxels * voxel
        field = slicer.vtkVolumeCutField()
        field.Initialize(dims, grid_matrix(voxel, dims), 2)
        field.CutCapsule(center, center, radius)
        cutter = slicer.vtkBinaryVoxelCutter()
        cutter.Initialize(dims, grid_matrix(voxel, dims))
        cutter.CutCapsule(center, center, radius)
        exact = 4.0 / 3.0 * np.pi * radius ** 3
        results.append(measurement(
            f"sphere r={radius_voxels:g} voxels, sub-voxel factor 2: removed volume relative error",
            100 * abs(field.ComputeRemovedVolume() - exact) / exact, "%",
            "whole-voxel removal (voxel centres inside the tool), same grid",
            100 * abs(cutter.ComputeRemovedVolume() - exact) / exact, 1, machine))
        rms, worst = _field_surface_error(field, center, radius, voxel)
        binary_rms, binary_worst = _binary_surface_error(cutter, center, radius, voxel)
        results.append(measurement(
            f"sphere r={radius_voxels:g} voxels: cut-surface position error RMS", rms, "voxel",
            "whole-voxel staircase boundary, RMS along the normal", binary_rms, 1, machine))
        results.append(measurement(
            f"sphere r={radius_voxels:g} voxels: cut-surface position error max", worst, "voxel",
            "whole-voxel staircase boundary, max along the normal", binary_worst, 1, machine))

    # 1000 small strokes against one stroke over the same path.
    a, b = np.array([5.1, 12.3, 11.7]), np.array([18.9, 11.2, 12.9])
    one = slicer.vtkVolumeCutField()
    one.Initialize(dims, grid_matrix(voxel, dims), 2)
    one.CutCapsule(a, b, 2.0)
    many = slicer.vtkVolumeCutField()
    many.Initialize(dims, grid_matrix(voxel, dims), 2)
    many.BeginStroke()
    path = [a + t * (b - a) for t in np.linspace(0.0, 1.0, 1001)]
    for p0, p1 in zip(path[:-1], path[1:]):
        many.CutCapsule(p0, p1, 2.0)
    many.EndStroke()
    binary_one = slicer.vtkBinaryVoxelCutter()
    binary_one.Initialize(dims, grid_matrix(voxel, dims))
    binary_one.CutCapsule(a, b, 2.0)
    binary_many = slicer.vtkBinaryVoxelCutter()
    binary_many.Initialize(dims, grid_matrix(voxel, dims))
    for p0, p1 in zip(path[:-1], path[1:]):
        binary_many.CutCapsule(p0, p1, 2.0)
    rng = np.random.default_rng(5)
    probes = rng.uniform([2, 8, 8], [22, 16, 16], size=(5000, 3))
    difference = max(abs(one.GetSignedDistance(p) - many.GetSignedDistance(p)) for p in probes) / voxel
    # Whole voxels: a probe whose voxel differs between the two is a surface
    # moved by (at least) one voxel.
    binary_difference = max(float(binary_one.IsRemoved(p) != binary_many.IsRemoved(p)) for p in probes)
    results.append(measurement(
        "1000 strokes vs one stroke over the same path: largest surface difference", difference, "voxel",
        "whole-voxel removal, same strokes: largest surface difference (0 or 1 voxel)", binary_difference, 1, machine))

    # Union of 100 random overlapping capsules (radius 3 to 5 voxels): the
    # reference volume integrates, over a fine grid of lines along x, the
    # exact length of each line inside the union (closed-form intervals).
    rng = np.random.default_rng(2026)
    capsule_dims = [64, 64, 64]
    starts = rng.uniform(6.0, 26.0, size=(100, 3))
    directions = rng.normal(size=(100, 3))
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    ends = starts + directions * rng.uniform(0.5, 4.0, size=(100, 1))
    radii = rng.uniform(3.0, 5.0, size=100) * voxel
    union_field = slicer.vtkVolumeCutField()
    union_field.Initialize(capsule_dims, grid_matrix(voxel, capsule_dims), 2)
    union_cutter = slicer.vtkBinaryVoxelCutter()
    union_cutter.Initialize(capsule_dims, grid_matrix(voxel, capsule_dims))
    for p0, p1, r in zip(starts, ends, radii):
        union_field.CutCapsule(p0, p1, r)
        union_cutter.CutCapsule(p0, p1, r)
    exact_union = _union_of_capsules_volume(starts, ends, radii, lines=700)
    results.append(measurement(
        "union of 100 random overlapping capsules (radius 3-5 voxels), factor 2: removed volume relative error",
        100 * abs(union_field.ComputeRemovedVolume() - exact_union) / exact_union, "%",
        "whole-voxel removal of the same capsules",
        100 * abs(union_cutter.ComputeRemovedVolume() - exact_union) / exact_union, 1, machine))

    # Stroke time: a 5 mm burr moving 0.5 mm per stroke on 0.33 mm voxels at
    # factor 2, in a 512^3 CT, on one core (the calling thread).
    big = [512, 512, 512]
    spacing = 0.33
    field = slicer.vtkVolumeCutField()
    field.Initialize(big, grid_matrix(spacing, big), 2)
    cutter = slicer.vtkBinaryVoxelCutter()
    cutter.Initialize(big, grid_matrix(spacing, big))
    # A helix of 20 mm radius through the middle of the CT: steps of 0.5 mm,
    # half of them through bone already cut (as when a surgeon goes over an area).
    center_mm = np.array([84.0, 84.0, 84.0])
    angles = np.arange(2001) * 0.5 / 20.0
    poses = [center_mm + np.array([20.0 * np.cos(t), 20.0 * np.sin(t), 0.2 * t]) for t in angles]
    field_times, cutter_times = [], []
    # One user stroke of 2000 device poses: one undo step, as the haptic loop drives it.
    field.BeginStroke()
    for p0, p1 in zip(poses[:-1], poses[1:]):
        t0 = time.perf_counter()
        field.CutCapsule(p0, p1, 2.5)
        t1 = time.perf_counter()
        cutter.CutCapsule(p0, p1, 2.5)
        t2 = time.perf_counter()
        field_times.append(t1 - t0)
        cutter_times.append(t2 - t1)
    end_start = time.perf_counter()
    field.EndStroke()
    end_stroke_ms = 1000 * (time.perf_counter() - end_start)
    for label, q in (("p50", 50), ("p99", 99)):
        results.append(measurement(
            f"stroke of a 5 mm spherical burr moving 0.5 mm, 0.33 mm voxels, factor 2, one core: {label}",
            1000 * float(np.percentile(field_times, q)), "ms",
            "whole-voxel removal of the same stroke at the CT's resolution",
            1000 * float(np.percentile(cutter_times, q)), len(field_times), machine))

    # The same helix with each narrower instruction set the processor has:
    # what a processor without the wider vectors (or a build without them) gets.
    in_use = slicer.vtkVolumeCutField.GetInstructionSet()
    for instruction_set in range(in_use):
        if not slicer.vtkVolumeCutField.SetInstructionSet(instruction_set):
            continue
        narrow = slicer.vtkVolumeCutField()
        narrow.Initialize(big, grid_matrix(spacing, big), 2)
        narrow_times = []
        narrow.BeginStroke()
        for p0, p1 in zip(poses[:-1], poses[1:]):
            t0 = time.perf_counter()
            narrow.CutCapsule(p0, p1, 2.5)
            narrow_times.append(time.perf_counter() - t0)
        narrow.EndStroke()
        name = slicer.vtkVolumeCutField.GetInstructionSetAsString(instruction_set)
        for label, q in (("p50", 50), ("p99", 99)):
            results.append(measurement(
                f"the same burr stroke with the {name} instruction set instead of {slicer.vtkVolumeCutField.GetInstructionSetAsString(in_use)}: {label}",
                1000 * float(np.percentile(narrow_times, q)), "ms",
                f"the stroke with {slicer.vtkVolumeCutField.GetInstructionSetAsString(in_use)} (above)",
                1000 * float(np.percentile(field_times, q)), len(narrow_times), machine))
    slicer.vtkVolumeCutField.SetInstructionSet(in_use)

    results.append(measurement(
        "closing that 2000-pose stroke into one undo step (EndStroke)", end_stroke_ms, "ms",
        "one pose of the stroke, p50 (above)", 1000 * float(np.percentile(field_times, 50)), 1, machine))

    # A cylindrical burr (2.5 mm radius, 5 mm long, axis along z) on the first
    # 500 poses of the same helix: a swept tool, not the burr's closed form.
    cylinder = slicer.vtkVolumeCutCylinderTool()
    cylinder.SetRadius(2.5)
    cylinder.SetLength(5.0)
    sweep_field = slicer.vtkVolumeCutField()
    sweep_field.Initialize(big, grid_matrix(spacing, big), 2)
    matrices = []
    for pose in poses[:501]:
        matrix = vtk.vtkMatrix4x4()
        for axis in range(3):
            matrix.SetElement(axis, 3, float(pose[axis]))
        matrices.append(matrix)
    sweep_times = []
    sweep_field.BeginStroke()
    for m0, m1 in zip(matrices[:-1], matrices[1:]):
        t0 = time.perf_counter()
        sweep_field.CutToolSweep(cylinder, m0, m1)
        sweep_times.append(time.perf_counter() - t0)
    sweep_field.EndStroke()
    for label, q in (("p50", 50), ("p99", 99)):
        results.append(measurement(
            f"stroke of a 2.5 x 5 mm cylindrical burr moving 0.5 mm, same grid, one core: {label}",
            1000 * float(np.percentile(sweep_times, q)), "ms",
            "the 5 mm spherical burr's stroke (above)",
            1000 * float(np.percentile(field_times[:500], q)), len(sweep_times), machine))

    # Memory of a mastoidectomy-sized cut (about 10 cm^3) in that 512^3 CT.
    memory_field = slicer.vtkVolumeCutField()
    memory_field.Initialize(big, grid_matrix(spacing, big), 2)
    origin = np.array([70.0, 70.0, 70.0])
    for z in np.arange(0.0, 12.0, 2.0):
        for y in np.arange(0.0, 28.0, 2.0):
            memory_field.CutCapsule(origin + [0.0, y, z], origin + [30.0, y, z], 2.5)
    removed_cm3 = memory_field.ComputeRemovedVolume() / 1000.0
    results.append(measurement(
        f"cut-field memory for a {removed_cm3:.1f} cm^3 cut in a 512^3 CT at factor 2",
        memory_field.GetBrickMemorySize() / 2 ** 20, "MiB",
        "dense 16-bit field of the same resolution (1024^3 samples)",
        memory_field.GetDenseMemorySize() / 2 ** 20, 1, machine))
    return results
