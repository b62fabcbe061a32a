"""Tests of the procedural temporal-bone phantom (VolumeCuttingLib.data.phantom)."""

import math

import numpy as np
import pytest

from VolumeCuttingLib.data import phantom as ph

EXPECTED_EXACT = {
    "TegmenPlate",
    "MastoidAirCells",
    "SigmoidSinus",
    "Malleus",
    "Incus",
    "Stapes",
    "SemicircularCanals",
    "FacialNerve",
}


def rotation(axis, angle):
    """Rotation matrix about ``axis`` by ``angle`` radians (Rodrigues)."""
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    cross = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + math.sin(angle) * cross + (1.0 - math.cos(angle)) * cross @ cross


OBLIQUE = rotation([1.0, 2.0, 3.0], 0.5)


@pytest.fixture(scope="module")
def clean():
    """Noise-free 64^3 phantom at 0.5 mm."""
    return ph.generate_phantom((64, 64, 64), (0.5, 0.5, 0.5), noise_sigma=0.0, seed=3)


@pytest.fixture(scope="module")
def noisy():
    """The same grid with 25 HU noise."""
    return ph.generate_phantom((64, 64, 64), (0.5, 0.5, 0.5), noise_sigma=25.0, seed=3)


@pytest.fixture(scope="module")
def oblique():
    """Oblique, anisotropic, off-centre, left-handed noise-free phantom."""
    direction = OBLIQUE @ np.diag([1.0, 1.0, -1.0])
    return ph.generate_phantom((56, 48, 40), (0.6, 0.55, 0.8), origin=(12.0, -7.5, 30.0), direction=direction,
                               noise_sigma=0.0)


def volume_tolerance(segment, spacing):
    """Allowed |labelmap volume - exact volume|: a quarter voxel layer over the surface.

    Voxel-centre classification misplaces at most a half-diagonal layer; in
    practice it errs by far less except for flat faces aligned with the grid
    (the tegmen slab), which need about 0.2 of a voxel layer.
    """
    return 0.25 * segment.surface_area_mm2 * max(spacing)


def grid_volume(primitive, samples=1_000_000):
    """Midpoint-rule volume of a primitive over its bounding box, from its inside test only."""
    lower, upper = primitive.bounds
    extent = upper - lower
    counts = np.maximum(np.ceil(extent / (np.prod(extent) / samples) ** (1 / 3)).astype(int), 1)
    cell = extent / counts
    axes = [lower[a] + (np.arange(counts[a]) + 0.5) * cell[a] for a in range(3)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)
    return np.count_nonzero(primitive.contains(grid)) * np.prod(cell)


PRIMITIVES = {
    "sphere": ph.Sphere([1.0, -2.0, 0.5], 2.5),
    "ellipsoid": ph.Ellipsoid([0.5, 1.0, -1.0], [3.0, 1.2, 2.0], rotation([1.0, -1.0, 2.0], 0.7)),
    "capsule": ph.Capsule([-2.0, 0.0, 1.0], [2.0, 1.5, -1.0], 1.1),
    "cylinder": ph.Cylinder([-1.0, -2.0, 0.0], [1.5, 2.0, 1.0], 1.3),
    "box": ph.Box([0.0, 0.5, 0.0], [2.0, 0.4, 1.5], rotation([0.0, 1.0, 1.0], 0.4)),
    "torus": ph.Torus([0.0, 0.0, 0.0], [1.0, 1.0, 0.0], 3.0, 0.8),
    "torus_arc": ph.TorusArc([0.0, 0.0, 0.0], [0.0, 1.0, 1.0], [1.0, 0.0, 0.0], 3.0, 0.7, 2.0),
}


# --------------------------------------------------------------------------- primitives


@pytest.mark.parametrize("name", sorted(PRIMITIVES))
def test_primitive_volume_formula_matches_inside_test(name):
    primitive = PRIMITIVES[name]
    assert grid_volume(primitive) == pytest.approx(primitive.volume_mm3, rel=3e-3)


@pytest.mark.parametrize("name", sorted(PRIMITIVES))
def test_primitive_bounds_are_tight_and_conservative(name):
    primitive = PRIMITIVES[name]
    lower, upper = primitive.bounds
    margin = 0.5 * (upper - lower)
    points = np.random.default_rng(0).uniform(lower - margin, upper + margin, size=(400_000, 3))
    inside = points[primitive.contains(points)]
    assert np.all(inside >= lower) and np.all(inside <= upper)
    # The box touches the solid on every face (to the sampling resolution).
    assert np.all(inside.min(axis=0) - lower < 0.1 * (upper - lower))
    assert np.all(upper - inside.max(axis=0) < 0.1 * (upper - lower))
    center, radius = primitive.bounding_sphere
    assert np.all(np.linalg.norm(inside - center, axis=1) <= radius)


@pytest.mark.parametrize("name", sorted(PRIMITIVES))
def test_primitive_signed_distance_is_exact(name):
    """Sign matches contains(), the function is 1-Lipschitz, zero on the surface, and no surface is closer."""
    primitive = PRIMITIVES[name]
    rng = np.random.default_rng(1)
    lower, upper = primitive.bounds
    points = rng.uniform(lower - 1.0, upper + 1.0, size=(1500, 3))
    distance = primitive.signed_distance(points)
    inside = primitive.contains(points)
    assert np.all(inside[distance < -1e-9]) and not np.any(inside[distance > 1e-9])

    # 1-Lipschitz and zero on the surface => |d| <= true distance to the surface.
    other = points + rng.normal(scale=0.3, size=points.shape)
    assert np.all(np.abs(primitive.signed_distance(other) - distance)
                  <= np.linalg.norm(other - points, axis=1) + 1e-9)

    # Surface points found by bisecting the inside test between an inside and an outside point.
    outside_points, inside_points = points[~inside][:200], points[inside][:200]
    count = min(len(outside_points), len(inside_points))
    a, b = inside_points[:count].copy(), outside_points[:count].copy()
    for _ in range(50):
        middle = 0.5 * (a + b)
        middle_inside = primitive.contains(middle)
        a[middle_inside], b[~middle_inside] = middle[middle_inside], middle[~middle_inside]
    assert np.abs(primitive.signed_distance(a)).max() < 1e-9

    # The open ball of radius |d| never crosses the surface => true distance >= |d|.
    directions = rng.normal(size=(64, 3))
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    for point, value, point_inside in zip(points[:300], distance[:300], inside[:300]):
        radii = np.abs(value) * (1.0 - 1e-6) * rng.uniform(0.0, 1.0, size=(64, 1)) ** (1 / 3)
        radii[:16] = np.abs(value) * (1.0 - 1e-6)  # also probe the sphere itself
        assert np.all(primitive.contains(point + radii * directions) == point_inside)


def test_ellipsoid_distance_lower_bound_is_a_lower_bound():
    ellipsoid = PRIMITIVES["ellipsoid"]
    points = np.random.default_rng(2).uniform(-5.0, 5.0, size=(5000, 3))
    points[0] = ellipsoid.center  # the degenerate centre point
    assert np.all(ellipsoid.distance_lower_bound(points) <= np.abs(ellipsoid.signed_distance(points)) + 1e-12)
    assert ellipsoid.signed_distance(ellipsoid.center[None])[0] == pytest.approx(-1.2, abs=1e-9)


def test_primitive_validation():
    with pytest.raises(ValueError, match="radius"):
        ph.Sphere([0, 0, 0], -1.0)
    with pytest.raises(ValueError, match="orthonormal"):
        ph.Ellipsoid([0, 0, 0], [1, 2, 3], [[1, 0, 0], [0, 2, 0], [0, 0, 1]])
    with pytest.raises(ValueError, match="minor_radius"):
        ph.Torus([0, 0, 0], [0, 0, 1], 1.0, 2.0)
    with pytest.raises(ValueError, match="sweep_angle"):
        ph.TorusArc([0, 0, 0], [0, 0, 1], [1, 0, 0], 3.0, 0.5, 4.0)
    with pytest.raises(ValueError, match="finite"):
        ph.Capsule([0, 0, float("nan")], [1, 0, 0], 1.0)


# --------------------------------------------------------------------------- anatomy and segments


def test_exact_segments_are_the_unclipped_ones():
    anatomy = ph.TemporalBoneAnatomy()
    exact = {segment.name for segment in anatomy.segments if segment.has_exact_geometry}
    assert exact == EXPECTED_EXACT
    # Their region really is the union of their primitives (the bounding-volume proof holds).
    points = np.random.default_rng(4).uniform(*anatomy.interest_bounds, size=(300_000, 3))
    for name in EXPECTED_EXACT:
        segment = anatomy.segment(name)
        assert np.array_equal(segment.contains(points), segment.shape_contains(points)), name
    # Segments without a closed form say so instead of returning a wrong number.
    with pytest.raises(ValueError, match="estimate_volume_mm3"):
        anatomy.segment("MastoidBone").volume_mm3
    with pytest.raises(ValueError, match="no closed form"):
        anatomy.segment("MiddleEar").signed_distance([[0.0, 0.0, 0.0]])


def test_segments_partition_space_by_precedence():
    anatomy = ph.TemporalBoneAnatomy(center_ras=(5.0, -3.0, 2.0), scale=0.8)
    points = np.random.default_rng(5).uniform(*anatomy.interest_bounds, size=(200_000, 3))
    labels = anatomy.label_at(points)
    memberships = np.array([segment.contains(points) for segment in anatomy.segments])
    assert memberships.sum(axis=0).max() == 1  # no overlaps
    assert np.array_equal(memberships.any(axis=0), labels > 0)
    for segment in anatomy.segments:
        assert np.array_equal(memberships[segment.label - 1], labels == segment.label)
        # Precedence: a point is in a segment iff it is in its shape and in no later shape.
        later = np.zeros(len(points), dtype=bool)
        for higher in anatomy.segments[segment.label:]:
            later |= higher.shape_contains(points)
        assert np.array_equal(memberships[segment.label - 1], segment.shape_contains(points) & ~later)
    # Air cells carve the mastoid bone.
    cell_centers = np.array([sphere.center for sphere in anatomy.segment("MastoidAirCells").primitives])
    assert np.all(anatomy.segment("MastoidBone").shape_contains(cell_centers))
    assert not np.any(anatomy.segment("MastoidBone").contains(cell_centers))
    assert np.all(anatomy.label_at(cell_centers) == anatomy.segment("MastoidAirCells").label)


def test_exact_volumes_match_fine_grid_estimates():
    anatomy = ph.TemporalBoneAnatomy(scale=0.9)
    for name in sorted(EXPECTED_EXACT):
        segment = anatomy.segment(name)
        assert segment.estimate_volume_mm3(samples_per_primitive=150_000) == pytest.approx(
            segment.volume_mm3, rel=0.01), name


def test_segment_signed_distance_of_union():
    segment = ph.TemporalBoneAnatomy().segment("MastoidAirCells")
    centers = np.array([sphere.center for sphere in segment.primitives])
    radii = np.array([sphere.radius for sphere in segment.primitives])
    assert np.allclose(segment.signed_distance(centers), -radii)
    probe = centers[0] + np.array([radii[0] + 0.25, 0.0, 0.0])
    assert segment.signed_distance(probe[None])[0] == pytest.approx(0.25)


# --------------------------------------------------------------------------- generated volumes


def test_shapes_dtypes_and_geometry(clean):
    assert clean.ct.shape == clean.labelmap.shape == (64, 64, 64)
    assert clean.ct.dtype == np.float32 and clean.labelmap.dtype == np.uint8
    assert clean.ijk_to_ras.shape == (4, 4)
    assert np.allclose(clean.ijk_to_ras[:3, :3], 0.5 * np.eye(3))
    # The default grid is centred on the RAS origin.
    assert np.allclose(clean.ijk_to_ras_points([31.5, 31.5, 31.5]), 0.0)
    assert clean.segment_names == [segment.name for segment in clean.segments]
    assert len(clean.segment_colors) == len(clean.segment_names)
    assert all(0.0 <= c <= 1.0 for color in clean.segment_colors for c in color)
    assert set(np.unique(clean.labelmap)) <= set(range(len(clean.segment_names) + 1))
    as_int = ph.generate_phantom((16, 16, 16), (2.0, 2.0, 2.0), ct_dtype="int16", noise_sigma=5.0)
    assert as_int.ct.dtype == np.int16


def test_auto_scale_keeps_anatomy_inside_grid(oblique):
    lower, upper = oblique.anatomy.interest_bounds
    corners = np.array([[x, y, z] for x in (lower[0], upper[0]) for y in (lower[1], upper[1])
                        for z in (lower[2], upper[2])])
    ijk = oblique.ras_to_ijk_points(corners)
    size = np.array(oblique.dimensions)
    assert np.all(ijk >= 0.5 - 1e-9) and np.all(ijk <= size - 1.5 + 1e-9)
    assert np.any(np.isclose(ijk, 0.5) | np.isclose(ijk, size - 1.5))  # and as large as possible


def test_determinism():
    first = ph.generate_phantom((24, 20, 16), (1.0, 1.2, 1.5), seed=7, noise_sigma=30.0)
    second = ph.generate_phantom((24, 20, 16), (1.0, 1.2, 1.5), seed=7, noise_sigma=30.0)
    third = ph.generate_phantom((24, 20, 16), (1.0, 1.2, 1.5), seed=8, noise_sigma=30.0)
    assert first.ct.tobytes() == second.ct.tobytes()
    assert first.labelmap.tobytes() == second.labelmap.tobytes()
    assert not np.array_equal(first.ct, third.ct)
    assert np.array_equal(first.labelmap, third.labelmap)
    assert np.array_equal(first.ct_noise_free, third.ct_noise_free)


def test_labelmap_classifies_voxel_centres(oblique):
    ni, nj, nk = oblique.dimensions
    k, j, i = np.meshgrid(np.arange(nk), np.arange(nj), np.arange(ni), indexing="ij")
    centres = oblique.ijk_to_ras_points(np.stack([i, j, k], axis=-1))
    assert np.array_equal(oblique.labelmap, oblique.anatomy.label_at(centres))
    for segment in oblique.segments:
        assert np.array_equal(oblique.labelmap == segment.label, segment.contains(centres))


def test_scanned_values_near_surfaces_equal_the_scanner_model_everywhere(oblique):
    """Computing the scanner's blur only near surfaces must equal computing it at every voxel (to 0.001 HU)."""
    ni, nj, nk = oblique.dimensions
    rng = np.random.default_rng(6)
    # All voxels whose centre label differs from a neighbour, plus random ones.
    labels = oblique.labelmap
    edge = np.zeros_like(labels, dtype=bool)
    for axis in range(3):
        change = np.diff(labels, axis=axis) != 0
        index = [slice(None)] * 3
        index[axis] = slice(1, None)
        edge[tuple(index)] |= change
        index[axis] = slice(None, -1)
        edge[tuple(index)] |= change
    kji = np.vstack([np.argwhere(edge), rng.integers(0, [nk, nj, ni], size=(3000, 3))])
    centres = oblique.ijk_to_ras_points(kji[:, ::-1].astype(float))
    expected = oblique.anatomy._scanned_hu(centres, oblique.resolution_sigma_mm)
    actual = oblique.ct_noise_free[kji[:, 0], kji[:, 1], kji[:, 2]]
    assert np.allclose(actual, expected, rtol=0.0, atol=1e-3)


def test_the_scanner_resolution_is_one_voxel_of_blur_on_top_of_the_voxel_average(clean):
    # Default FWHM: the largest spacing (0.5 mm), sigma 0.212 mm; the voxel's box adds 0.5^2 / 12 mm^2.
    assert clean.psf_fwhm_mm == 0.5
    assert clean.resolution_sigma_mm == pytest.approx(math.sqrt((0.5 / 2.3548) ** 2 + 0.5**2 / 12.0), rel=1e-4)
    sharp = ph.generate_phantom((16, 16, 16), (0.4, 0.4, 0.5), noise_sigma=0.0, psf_fwhm_mm=0.0)
    assert sharp.resolution_sigma_mm == pytest.approx(math.sqrt((0.16 + 0.16 + 0.25) / 3.0 / 12.0))


def test_partial_volume_at_skin_surface(clean):
    """Voxels across the skin hold the air/soft-tissue mix of a blurred edge: Phi(-d / sigma) of the exact distance."""
    skin = clean.segment("SoftTissue").primitives[0]
    sigma = clean.resolution_sigma_mm
    ijk = np.argwhere(clean.labelmap <= 1)[:, ::-1]  # air or soft tissue at the centre
    centres = clean.ijk_to_ras_points(ijk)
    near = np.abs(skin.distance_lower_bound(centres)) < 2.0
    ijk, centres = ijk[near], centres[near]
    distance = skin.signed_distance(centres)
    values = clean.ct_noise_free[ijk[:, 2], ijk[:, 1], ijk[:, 0]]
    soft_fraction = (values - ph.HU_AIR) / (ph.HU_SOFT_TISSUE - ph.HU_AIR)
    # Only the skin within reach of the blur (the bone lies beneath it where the head leaves the grid).
    lonely = np.ones(len(centres), dtype=bool)
    for segment in clean.segments[1:]:
        for primitive in segment.primitives:
            lonely &= primitive.distance_lower_bound(centres) > 6.0 * sigma
    assert lonely.sum() > 1000
    expected = np.array([0.5 * math.erfc(d / (sigma * math.sqrt(2.0))) for d in distance[lonely]])
    np.testing.assert_allclose(soft_fraction[lonely], expected, rtol=0.0, atol=1e-4)
    on_surface = lonely & (np.abs(distance) < 0.05 * 0.5)
    assert on_surface.sum() > 20
    assert np.all((soft_fraction[on_surface] > 0.45) & (soft_fraction[on_surface] < 0.55))
    # Farther than five sigma the voxel is pure.
    pure_air = lonely & (distance > 5.0 * sigma)
    pure_soft = lonely & (distance < -5.0 * sigma)
    assert pure_air.any() and pure_soft.any()
    assert np.all(np.abs(values[pure_air] - ph.HU_AIR) < 1e-3)
    assert np.all(np.abs(values[pure_soft] - ph.HU_SOFT_TISSUE) < 1e-3)


def test_values_stay_within_material_range(clean):
    assert clean.ct_noise_free.min() >= ph.HU_AIR
    assert clean.ct_noise_free.max() <= ph.HU_DENSE_BONE
    mixed = ~np.isin(clean.ct_noise_free, clean.anatomy.hu_table)
    assert mixed.mean() > 0.01  # partial-volume values exist...
    assert mixed.mean() < 0.5  # ...but only at edges


def test_noise_statistics(clean, noisy):
    noise = noisy.ct.astype(np.float64) - clean.ct.astype(np.float64)
    homogeneous = (clean.labelmap == clean.segment("MastoidBone").label) & (
        clean.ct_noise_free == ph.HU_TRABECULAR_BONE)
    assert homogeneous.sum() > 10_000
    samples = noise[homogeneous]
    assert samples.std() == pytest.approx(25.0, rel=0.03)
    assert abs(samples.mean()) < 3 * 25.0 / math.sqrt(samples.size)
    assert np.array_equal(clean.labelmap, noisy.labelmap)


@pytest.mark.parametrize("fixture_name", ["clean", "oblique"])
def test_labelmap_volumes_match_exact_volumes(fixture_name, request):
    phantom = request.getfixturevalue(fixture_name)
    for name in sorted(EXPECTED_EXACT):
        segment = phantom.segment(name)
        error = phantom.labelmap_volume_mm3(name) - segment.volume_mm3
        assert abs(error) <= volume_tolerance(segment, phantom.spacing), name


def test_mistaken_volume_fails_the_volume_check():
    """The tolerance is tight enough to catch a capsule without caps or a radius off by one voxel.

    Uses a 0.4 mm patch around the natural-size sigmoid sinus.
    """
    canonical = ph.TemporalBoneAnatomy()
    sinus_center = np.mean(canonical.segment("SigmoidSinus").bounds, axis=0)
    patch = ph.generate_phantom((32, 32, 76), (0.4, 0.4, 0.4), noise_sigma=0.0, scale=1.0,
                                anatomy_center_ras=-sinus_center)
    sinus = patch.segment("SigmoidSinus")
    capsule = sinus.primitives[0]
    assert np.all(np.abs(patch.ras_to_ijk_points(np.array(sinus.bounds)) - 15.5 - [0, 0, 22]) < [15, 15, 37])
    measured = patch.labelmap_volume_mm3("SigmoidSinus")
    tolerance = volume_tolerance(sinus, patch.spacing)
    assert abs(measured - sinus.volume_mm3) <= tolerance
    without_caps = math.pi * capsule.radius**2 * capsule.length
    one_voxel_wider = ph.Capsule(capsule.point0, capsule.point1, capsule.radius + 0.4).volume_mm3
    assert abs(measured - without_caps) > tolerance
    assert abs(measured - one_voxel_wider) > tolerance


def test_non_exact_segment_volume_estimate_matches_labelmap(clean):
    segment = clean.segment("MastoidBone")
    estimate = segment.estimate_volume_mm3(samples_per_primitive=200_000)
    assert clean.labelmap_volume_mm3("MastoidBone") == pytest.approx(estimate, rel=0.02)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(direction=[[1, 0, 0], [0, 1, 0], [0, 0.1, 1]]), "orthonormal"),
        (dict(direction=2 * np.eye(3)), "orthonormal"),
        (dict(direction=np.eye(2)), "3x3"),
        (dict(spacing=(1.0, float("nan"), 1.0)), "finite"),
        (dict(spacing=(1.0, 0.0, 1.0)), "positive"),
        (dict(spacing=(1.0, 1.0)), "spacing"),
        (dict(dimensions=(16, 0, 16)), "positive"),
        (dict(dimensions=(16, 16.5, 16)), "integers"),
        (dict(dimensions=(1024, 1024, 1024)), "exceeds"),
        (dict(dimensions=(2, 2, 2)), "too small"),
        (dict(origin=(0.0, float("inf"), 0.0)), "finite"),
        (dict(noise_sigma=-1.0), "noise_sigma"),
        (dict(noise_sigma=float("nan")), "noise_sigma"),
        (dict(seed=-3), "seed"),
        (dict(scale=0.0), "scale"),
        (dict(psf_fwhm_mm=-0.5), "psf_fwhm_mm"),
        (dict(psf_fwhm_mm=float("inf")), "psf_fwhm_mm"),
        (dict(ct_dtype="uint8"), "ct_dtype"),
    ],
)
def test_bad_input_raises_value_error(kwargs, message):
    arguments = dict(dimensions=(16, 16, 16), spacing=(1.0, 1.0, 1.0))
    arguments.update(kwargs)
    with pytest.raises(ValueError, match=message):
        ph.generate_phantom(**arguments)


# --------------------------------------------------------------------------- MRML nodes


def test_mrml_nodes_round_trip_oblique_anisotropic(oblique):
    slicer = pytest.importorskip("slicer")
    from VolumeCuttingLib.scene import nodes

    scene = slicer.vtkMRMLScene()
    volume_node, segmentation_node = ph.create_phantom_nodes(scene, oblique, name="Phantom")

    assert np.allclose(nodes.volume_node_ijk_to_ras(volume_node), oblique.ijk_to_ras, atol=1e-12)
    assert np.allclose(volume_node.GetSpacing(), oblique.spacing)
    assert np.allclose(volume_node.GetOrigin(), oblique.origin)
    assert volume_node.GetImageData().GetDimensions() == oblique.dimensions
    assert volume_node.GetDisplayNode() is not None
    read_back = nodes.array_from_volume_node(volume_node)
    assert read_back.dtype == oblique.ct.dtype and np.array_equal(read_back, oblique.ct)

    # RAS of a known voxel centre, computed by hand from spacing, direction and origin.
    ijk = np.array([3.0, 5.0, 7.0])
    expected = np.asarray(oblique.origin) + oblique.direction @ (np.asarray(oblique.spacing) * ijk)
    from vtkmodules.vtkCommonMath import vtkMatrix4x4

    matrix = vtkMatrix4x4()
    volume_node.GetIJKToRASMatrix(matrix)
    assert np.allclose(matrix.MultiplyPoint((*ijk, 1.0))[:3], expected)
    assert oblique.labelmap[7, 5, 3] == oblique.anatomy.label_at(expected[None])[0]

    segmentation = segmentation_node.GetSegmentation()
    assert segmentation.GetNumberOfSegments() == len(oblique.segments)
    for segment_info in oblique.segments:
        segment = segmentation.GetSegment(segment_info.name)
        assert segment.GetName() == segment_info.name
        assert np.allclose(segment.GetColor(), segment_info.color)
        labelmap = slicer.vtkOrientedImageData()
        segmentation_node.GetBinaryLabelmapRepresentation(segment_info.name, labelmap)
        image_to_world = vtkMatrix4x4()
        labelmap.GetImageToWorldMatrix(image_to_world)
        assert np.allclose(nodes.vtk_matrix_to_numpy(image_to_world), oblique.ijk_to_ras, atol=1e-9)
        mask = np.zeros(oblique.labelmap.shape, dtype=bool)
        if labelmap.GetPointData().GetScalars() is not None:
            extent = labelmap.GetExtent()
            values = nodes.array_from_image_data(labelmap)
            mask[extent[4]:extent[5] + 1, extent[2]:extent[3] + 1, extent[0]:extent[1] + 1] = values > 0
        assert np.array_equal(mask, oblique.labelmap == segment_info.label), segment_info.name
