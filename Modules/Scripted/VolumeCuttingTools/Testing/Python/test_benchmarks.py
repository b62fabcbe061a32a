"""The benchmarks' analytic references must themselves be right."""

import numpy as np
import pytest

from VolumeCuttingLib.benchmarks.cutfield import _union_of_capsules_volume
from VolumeCuttingLib.benchmarks.harness import machine_description, measurement


def test_union_reference_on_known_volumes():
    # One capsule.
    a, b, r = np.array([[0.0, 0.0, 0.0]]), np.array([[3.0, 1.0, 2.0]]), np.array([1.5])
    exact = np.pi * r[0] ** 2 * np.linalg.norm(b - a) + 4.0 / 3.0 * np.pi * r[0] ** 3
    assert _union_of_capsules_volume(a, b, r) == pytest.approx(exact, rel=1e-4)
    # Two disjoint spheres (degenerate capsules).
    a = np.array([[0.0, 0.0, 0.0], [10.0, 0.0, 0.0]])
    assert _union_of_capsules_volume(a, a + 1e-6, np.array([1.0, 2.0])) == pytest.approx(4.0 / 3.0 * np.pi * 9.0, rel=1e-4)
    # Two unit spheres one radius apart: their lens is counted once.
    a = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    lens = np.pi / 12.0 * 5.0
    assert _union_of_capsules_volume(a, a + [0.0, 0.0, 1e-6], np.array([1.0, 1.0])) == pytest.approx(8.0 / 3.0 * np.pi - lens, rel=1e-4)


def test_measurement_records_the_ratio_and_machine():
    machine = machine_description("llvmpipe (LLVM 15)")
    assert machine["gpu"] is None and machine["cores"] >= 1
    row = measurement("x", 2.0, "ms", "baseline", 4.0, 3, machine)
    assert row["ratio"] == 0.5 and row["baseline_value"] == 4.0 and row["machine"] is machine
