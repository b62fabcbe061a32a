"""Drilling from Python with the OpenIGTLink bridge streaming, one line of JSON: for before/after comparisons.

    python -m VolumeCuttingLib.benchmarks.collaborationdrilling LABEL [PASSES]

Runs ``collaborationigtl._strokes`` (the mastoidectomy plan's passes on the
phantom, drilled through the logic as the web application's mouse does, on a
scene streamed to one client and on a second scene without a bridge, pass by
pass in turn) and prints the per-pose times and the image updates' cost. Run
the same command with two installations (say the base commit's and a change's)
alternately, in the same minutes: a p99 of a few hundred poses on a shared
machine varies from run to run as much as a change may move it.
"""

from __future__ import annotations

import json
import sys

import numpy as np

from . import collaborationigtl


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if not argv or len(argv) > 2 or (len(argv) == 2 and not argv[1].isdigit()):
        print(__doc__.splitlines()[2].strip(), file=sys.stderr)
        return 2
    label, passes = argv[0], int(argv[1]) if len(argv) == 2 else 16
    _, logic, cut, plan = collaborationigtl._scene()
    _, plain_logic, plain_cut, _ = collaborationigtl._scene()
    result = collaborationigtl._strokes((logic, cut), (plain_logic, plain_cut), plan, passes=passes)
    streamed = np.array(result["pose_times"][True]) * 1e3
    alone = np.array(result["pose_times"][False]) * 1e3
    compute = np.array(result["compute_s"]) * 1e3 if result["compute_s"] else np.zeros((1, 2))
    print(json.dumps({
        "label": label, "poses": len(streamed),
        "streamed_p50_ms": round(float(np.percentile(streamed, 50)), 3),
        "streamed_p99_ms": round(float(np.percentile(streamed, 99)), 3),
        "alone_p50_ms": round(float(np.percentile(alone, 50)), 3),
        "alone_p99_ms": round(float(np.percentile(alone, 99)), 3),
        "image_updates": len(result["updates"]),
        "update_wall_ms_median": round(float(np.median(compute[:, 0])), 1),
        "update_cpu_ms_median": round(float(np.median(compute[:, 1])), 1),
        "update_bytes_median": float(np.median([u["bytes"] for u in result["updates"]])) if result["updates"] else 0.0,
    }))
    return 0


if __name__ == "__main__":
    sys.exit(main())
