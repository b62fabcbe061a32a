"""A scan opens whole in the 3D view: the camera distance fits its box in perspective, whatever its shape.

A temporal-bone block whose tissue fills its box opened as a close-up of its near face (issue 28, finding 2):
the distance was 2.2 times the box's largest side, measured to the box's centre, so the near face, half a
side closer, overflowed the 30-degree view.
"""

import itertools
import math

import numpy as np
import pytest

views = pytest.importorskip("VolumeCuttingLib.webapp.views")


def _projected(bounds, direction, view_up, distance):
    """Each corner's (horizontal, vertical) tangent off the view axis from the eye."""
    forward = np.asarray(direction, float) / np.linalg.norm(direction)
    up = np.asarray(view_up, float) - np.dot(view_up, forward) * forward
    up /= np.linalg.norm(up)
    right = np.cross(forward, up)
    center = np.array([(bounds[2 * a] + bounds[2 * a + 1]) / 2 for a in range(3)])
    eye = center + distance * forward
    tangents = []
    for corner in itertools.product(*((bounds[2 * a], bounds[2 * a + 1]) for a in range(3))):
        ray = np.array(corner) - eye
        depth = -np.dot(ray, forward)
        tangents.append((abs(np.dot(ray, right)) / depth, abs(np.dot(ray, up)) / depth))
    return tangents


@pytest.mark.parametrize("bounds, direction, aspect", [
    ((-24.3, 24.3, -24.3, 24.3, -24.0, 24.0), (1, 0, 0), 1.33),        # the 0.19 mm temporal-bone block
    ((0, 245, 0, 245, 0, 162), (1, 0, 0), 1.33),                        # the head CT
    ((-180, 180, -180, 180, 0, 332), (0.3, -0.9, 0.3), 0.75),          # a patient-scale CT, an oblique look, a tall view
])
def test_every_corner_is_inside_the_view_and_one_touches_its_margin(bounds, direction, aspect):
    margin = 0.05
    distance = views.fitting_distance(bounds, direction, (0, 0, 1), 30.0, aspect, margin)
    tan_vertical = math.tan(math.radians(15.0)) * (1 - margin)
    tangents = _projected(bounds, direction, (0, 0, 1), distance)
    worst = max(max(h / (tan_vertical * aspect), v / tan_vertical) for h, v in tangents)
    assert worst == pytest.approx(1.0, abs=1e-9)


def test_a_box_filled_to_its_faces_no_longer_overflows_the_view():
    bounds = (-24.3, 24.3, -24.3, 24.3, -24.0, 24.0)
    old_distance = 2.2 * 48.6
    tan_vertical = math.tan(math.radians(15.0))
    overflow = max(v for _, v in _projected(bounds, (1, 0, 0), (0, 0, 1), old_distance)) / tan_vertical
    assert overflow > 1.0, "the old distance showed the whole block: this test would prove nothing"
    fitted = views.fitting_distance(bounds, (1, 0, 0), (0, 0, 1), 30.0, 1.33)
    assert max(v for _, v in _projected(bounds, (1, 0, 0), (0, 0, 1), fitted)) / tan_vertical < 1.0
