"""A careful and a careless mastoidectomy on each shipped scan, as complete recordings, to validate the grading.

The careful one is the shipped mastoidectomy (the saucer of ``drilling.
MastoidectomyPlan`` with a cutting burr, its last layers polished with a 3 mm
diamond burr; on the head CT the recording in Resources/Sessions), at 5 mm/s,
seen from outside along the approach as ``mainjob.cavity_camera`` looks.

The careless one is what graders fault: a 6 mm cutting burr at 20 mm/s
plunging from the entry straight toward each structure at risk until it
touches it, then undercutting sideways beneath the cortex, while the camera
looks at the field from 60 degrees above the approach, never brought over
the hole: the burr works where it cannot be seen.

    python -m VolumeCuttingLib.assessment.sessions --scan phantom|headct --out DIR
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from ..cutting import drilling
from ..cutting import recording as recordings
from . import scans as scanlib

CAREFUL_SPEED_MM_S = 5.0
CARELESS_SPEED_MM_S = 20.0
CAMERA_RATE_HZ = 10.0
CARELESS_BURR = {"name": "Cutting burr 6 mm", "burr_type": "Cutting", "radius_mm": 3.0}
DIAMOND_3MM = {"name": "Diamond burr 3 mm", "burr_type": "Diamond", "radius_mm": 1.5}
CARELESS_CAMERA_TILT_DEG = 60.0
APPROACH = np.array([-1.0, 0.0, 0.0])  # into the bone, from the patient's right


def plan_for(scan: scanlib.Scan) -> drilling.MastoidectomyPlan:
    """The main job's mastoidectomy plan on that scan."""
    if scan.entry is None:
        raise scanlib.ScanError(f"scan '{scan.name}' has no mastoidectomy entry")
    if scan.name == "phantom":
        return drilling.MastoidectomyPlan(entry=scan.entry, surface_radius=7.0, depth=8.0, burr_radius=2.0)
    return drilling.MastoidectomyPlan(entry=scan.entry)


def camera_frames(plan: drilling.MastoidectomyPlan, until_s: float, rate_hz: float = CAMERA_RATE_HZ, tilt_deg: float = 0.0) -> list:
    """A still camera looking into the planned cavity along its approach (``mainjob.cavity_camera``), one frame per 1/rate s.

    ``tilt_deg`` swings it that far toward the top of the head: a view the
    trainee never brought over the hole.
    """
    into = np.asarray(plan.direction, dtype=float) / np.linalg.norm(plan.direction)
    center = np.asarray(plan.entry, dtype=float) + 0.5 * plan.depth * into
    distance = 0.5 * 6.0 * plan.surface_radius / np.tan(np.radians(15.0))
    tilt = np.radians(tilt_deg)
    position = center + distance * (-np.cos(tilt) * into + np.sin(tilt) * np.array([0.0, 0.0, 1.0]))
    return [[t, *position, *center, 0.0, 0.0, 1.0, 30.0] for t in np.arange(0.0, until_s + 1.0 / rate_hz, 1.0 / rate_hz)]


def _finish(recording: dict, plan, tools: dict, scan: scanlib.Scan, speed: float, trainee: str, pause_s: float,
            tilt_deg: float = 0.0) -> dict:
    timed = recordings.timed(recording, tools, speed, pause_s, scan=scan.descriptor(), trainee=trainee,
                             started="2026-11-27T09:00:00+00:00")
    last = timed["strokes"][-1]["times"][-1]
    timed["camera"] = {"fields": list(recordings.CAMERA_FIELDS),
                       "frames": [[round(float(v), 6) for v in frame] for frame in camera_frames(plan, last, tilt_deg=tilt_deg)]}
    return timed


def careful(scan: scanlib.Scan) -> dict:
    """The shipped mastoidectomy on ``scan``, complete (see the module docstring)."""
    plan = plan_for(scan)
    if scan.name == "headct":
        untimed = recordings.load(recordings.head_ct_mastoidectomy_path())
        cutting = {"name": "Cutting burr 5 mm", "burr_type": "Cutting", "radius_mm": 2.5}
    else:
        untimed = recordings.record_mastoidectomy(plan, finishing_radius=DIAMOND_3MM["radius_mm"],
                                                  description="The main job's mastoidectomy on the phantom.")
        cutting = {"name": "Cutting burr 4 mm", "burr_type": "Cutting", "radius_mm": plan.burr_radius}
    return _finish(untimed, plan, {"cutting": cutting, "diamond": DIAMOND_3MM}, scan, CAREFUL_SPEED_MM_S, "careful", 0.5)


def _line(start, end, step=0.5) -> list:
    count = max(int(np.ceil(np.linalg.norm(end - start) / step)), 1)
    return [[round(float(v), 4) for v in start + (end - start) * f] for f in np.linspace(0.0, 1.0, count + 1)]


def careless(scan: scanlib.Scan, structures=None) -> dict:
    """A 6 mm cutting burr plunging to each structure at risk and undercutting the cortex (see the module docstring)."""
    plan = plan_for(scan)
    radius = CARELESS_BURR["radius_mm"]
    entry = np.asarray(plan.entry, dtype=float)
    into = APPROACH
    across = np.cross(into, [0.0, 0.0, 1.0])
    rotation = [round(float(v), 9) for v in recordings.frame_along(into).ravel()]
    strokes = []
    # Plunges: from outside the bone toward the structure's surface point nearest the entry, until the burr touches it.
    structures = structures or [name for name in scan.protected
                                if len(scan.surface_points(name)) and
                                np.linalg.norm(scan.surface_points(name) - entry, axis=1).min() < 25.0]
    for name in structures:
        surface = scan.surface_points(name)
        target = surface[np.argmin(np.linalg.norm(surface - entry, axis=1))]
        start = entry - 2.0 * into
        toward = (target - start) / np.linalg.norm(target - start)
        stop = target - (radius - 0.3) * toward  # 0.3 mm into it
        strokes.append({"tool": "cutting", "action": "cut", "rotation": rotation, "positions": _line(start, stop)})
    # Undercut: in through the cortex, then sideways beneath it, both ways.
    depth = entry + (radius + 3.0) * into
    strokes.append({"tool": "cutting", "action": "cut", "rotation": rotation, "positions": _line(entry - 2.0 * into, depth)})
    for side in (1.0, -1.0):
        strokes.append({"tool": "cutting", "action": "cut", "rotation": rotation,
                        "positions": _line(depth, depth + side * 10.0 * across) + _line(depth + side * 10.0 * across,
                                                                                           depth + side * 10.0 * across + np.array([0, 0, 6.0]))[1:]})
    untimed = {"format": recordings.FORMAT, "version": 1, "frame": "RAS", "units": "mm", "strokes": strokes,
               "description": "A careless drilling: a 6 mm cutting burr plunging toward the structures at risk and undercutting the cortex."}
    return _finish(untimed, plan, {"cutting": CARELESS_BURR}, scan, CARELESS_SPEED_MM_S, "careless", 0.2, CARELESS_CAMERA_TILT_DEG)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scan", choices=("phantom", "headct"), required=True)
    parser.add_argument("--out", type=Path, required=True)
    args = parser.parse_args(argv)
    scan = scanlib.by_name(args.scan)
    for name, make in (("careful", careful), ("careless", careless)):
        path = recordings.save(make(scan), args.out / f"{args.scan}-{name}.json")
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
