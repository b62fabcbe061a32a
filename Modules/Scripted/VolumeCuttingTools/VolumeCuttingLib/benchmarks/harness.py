"""Benchmark harness: what every area shares (machine, measurements, timing, results files).

Each measurement is compared with a baseline measured in the same process, on
the same data, right after it (these machines are noisy; a ratio from one run
is what can be trusted). A result file holds a list of measurements::

    {"name", "value", "unit", "baseline_name", "baseline_value", "ratio",
     "repeats", "machine": {"cpu_model", "cores", "gpu", "renderer"}}

``value`` and ``baseline_value`` are medians over ``repeats`` runs; ``ratio`` is
value / baseline_value. The areas (one module each in this package) import
this module and no other area, so that any one of them can run alone.
"""

from __future__ import annotations

import json
import os
import platform
import statistics
import time
from pathlib import Path

import numpy as np
import vtk


def machine_description(renderer: str | None = None) -> dict:
    cpu_model = platform.processor() or "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu_model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return {
        "cpu_model": cpu_model,
        "cores": os.cpu_count(),
        # No GPU on these machines unless the renderer names one.
        "gpu": None if renderer is None or "llvmpipe" in renderer.lower() else renderer,
        "renderer": renderer,
    }


def timed(function, repeats: int):
    """Median wall time (s) of ``function()`` over ``repeats`` runs, and its last result."""
    times = []
    result = None
    for _ in range(repeats):
        start = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - start)
    return statistics.median(times), result


def measurement(name, value, unit, baseline_name, baseline_value, repeats, machine):
    return {
        "name": name,
        "value": round(value, 6),
        "unit": unit,
        "baseline_name": baseline_name,
        "baseline_value": round(baseline_value, 6),
        "ratio": round(value / baseline_value, 4) if baseline_value > 0 else None,
        "repeats": repeats,
        "machine": machine,
    }



def grid_matrix(spacing, dims):
    """IJK-to-RAS matrix of an axis-aligned grid with isotropic ``spacing`` (mm) at the origin."""
    matrix = vtk.vtkMatrix4x4()
    for axis in range(3):
        matrix.SetElement(axis, axis, spacing)
    return matrix


def millisecond_summary(times_s):
    """First, median, 99th percentile and largest of times in seconds, in milliseconds."""
    milliseconds = np.array(times_s) * 1e3
    return {
        "first": milliseconds[0],
        "median": statistics.median(milliseconds),
        "p99": float(np.percentile(milliseconds, 99)),
        "max": milliseconds.max(),
    }


def finish_frame(window):
    # Reading a pixel waits for the GPU to finish the frame.
    window.GetRGBACharPixelData(0, 0, 0, 0, 1, vtk.vtkUnsignedCharArray())


def write_results(results: list[dict], path: Path) -> Path:
    """One area's measurements as the JSON file the results folder holds."""
    path.write_text(json.dumps(results, indent=2) + "\n")
    return path
