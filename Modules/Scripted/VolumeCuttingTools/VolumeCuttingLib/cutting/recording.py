"""Recorded drilling sessions: the pose streams of tools, saved as JSON and replayed through the logic.

A recording is what a mouse, a haptic device or a script produced: strokes,
each a tool (by a key that names a tool preset), an action (cut or restore)
and the tool's poses (RAS, mm; one rotation per stroke, the tool's +z along
its shaft towards the handpiece, as ``vtkMRMLVolumeCutToolNode`` defines it).
Replaying it moves each tool node through ``vtkSlicerVolumeCuttingLogic.
MoveActiveTool`` inside ``BeginStroke`` / ``EndStroke``, exactly as a live
session does, so tests, demos and session review all run the product's path.

    python -m VolumeCuttingLib.cutting.recording --head-ct OUT.json   # record the shipped mastoidectomy
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from ..scene.resources import find_resource

FORMAT = "VolumeCuttingRecording"
VERSION = 1
HEAD_CT_MASTOIDECTOMY = "HeadCTMastoidectomy.json"


class RecordingError(ValueError):
    """A recording file that cannot be used; the message names the file and what is wrong."""


def frame_along(direction) -> np.ndarray:
    """A rotation whose +z points back along ``direction`` (the shaft, towards the handpiece)."""
    z = -np.asarray(direction, dtype=float)
    z /= np.linalg.norm(z)
    helper = np.array([0.0, 0.0, 1.0]) if abs(z[2]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    return np.stack([x, y, z], axis=1)


def record_mastoidectomy(plan, cutting_tool="cutting", finishing_tool="diamond", finishing_layers=2, finishing_radius=1.5,
                         description="") -> dict:
    """A cortical mastoidectomy as a recording: the plan's saucer with the
    cutting burr, its last layers polished with a smaller diamond burr.

    ``plan`` is a ``drilling.MastoidectomyPlan``; the tool keys name the
    tools the replay is given.
    """
    rotation = frame_along(plan.direction)
    layers = {}
    for poses in plan.strokes():
        # Strokes of one layer share the burr depth along the approach direction.
        depth = round(float(np.dot(poses[0] - plan.entry, plan.direction / np.linalg.norm(plan.direction))), 6)
        layers.setdefault(depth, []).append(poses)
    depths = sorted(layers)
    strokes = []
    for index, depth in enumerate(depths):
        finishing = index >= len(depths) - finishing_layers
        for poses in layers[depth]:
            if finishing:
                # The smaller burr reaches as deep as the cutting burr did.
                shift = (plan.burr_radius - finishing_radius) * plan.direction / np.linalg.norm(plan.direction)
                poses = poses + shift
            strokes.append({
                "tool": finishing_tool if finishing else cutting_tool,
                "action": "cut",
                "rotation": [round(float(v), 9) for v in rotation.ravel()],
                "positions": [[round(float(v), 4) for v in position] for position in poses],
            })
    return {"format": FORMAT, "version": VERSION, "description": description, "frame": "RAS", "units": "mm", "strokes": strokes}


def save(recording: dict, path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(recording, separators=(",", ":")) + "\n")
    return path


def load(path) -> dict:
    """Read and check a recording; RecordingError names the file and the stroke at fault."""
    path = Path(path)
    try:
        recording = json.loads(path.read_text())
    except FileNotFoundError:
        raise RecordingError(f"{path}: no such recording") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
        raise RecordingError(f"{path}: not a readable recording ({error})") from None
    if not isinstance(recording, dict) or recording.get("format") != FORMAT or recording.get("version") != VERSION:
        raise RecordingError(f"{path}: not a {FORMAT} file of version {VERSION}")
    strokes = recording.get("strokes")
    if not isinstance(strokes, list) or not strokes:
        raise RecordingError(f"{path}: it holds no strokes")
    for index, stroke in enumerate(strokes):
        where = f"{path}: stroke {index}"
        if not isinstance(stroke, dict) or not isinstance(stroke.get("tool"), str) or stroke.get("action") not in ("cut", "restore"):
            raise RecordingError(f"{where} needs a tool key and an action 'cut' or 'restore'")
        rotation = np.asarray(stroke.get("rotation"), dtype=float) if isinstance(stroke.get("rotation"), list) else None
        if rotation is None or rotation.shape != (9,) or not np.all(np.isfinite(rotation)):
            raise RecordingError(f"{where}: 'rotation' must be 9 finite numbers (a 3x3 rotation, row by row)")
        matrix = rotation.reshape(3, 3)
        if not np.allclose(matrix.T @ matrix, np.eye(3), atol=1e-6) or np.linalg.det(matrix) <= 0.0:
            raise RecordingError(f"{where}: 'rotation' is not a rotation")
        try:
            positions = np.asarray(stroke.get("positions"), dtype=float)
        except (TypeError, ValueError):
            positions = np.zeros((0, 0))
        if positions.ndim != 2 or positions.shape[1] != 3 or len(positions) == 0 or not np.all(np.isfinite(positions)):
            raise RecordingError(f"{where}: 'positions' must be a non-empty list of finite [R, A, S] points")
    return recording


def head_ct_mastoidectomy_path() -> Path:
    """The recorded mastoidectomy on the shipped head CT."""
    return find_resource("Sessions", HEAD_CT_MASTOIDECTOMY)


def replay(logic, cut_node, recording: dict, tool_nodes: dict) -> dict:
    """Drill the recording with the given tool nodes (by the recording's tool keys).

    Each stroke makes its tool the cut node's active tool and moves it
    through its poses with ``MoveActiveTool``. Returns counts and per-pose
    timings (first, p50, p99 and max, ms).
    """
    import vtk

    missing = sorted({stroke["tool"] for stroke in recording["strokes"]} - set(tool_nodes))
    if missing:
        raise RecordingError(f"the recording uses tools {', '.join(missing)} that were not given")
    matrix = vtk.vtkMatrix4x4()
    times = []
    refused = 0
    for stroke in recording["strokes"]:
        cut_node.SetAndObserveActiveToolNodeID(tool_nodes[stroke["tool"]].GetID())
        rotation = np.asarray(stroke["rotation"], dtype=float).reshape(3, 3)
        for row in range(3):
            for column in range(3):
                matrix.SetElement(row, column, rotation[row, column])
        if not logic.BeginStroke(cut_node):
            raise RuntimeError("the cut node has no cut field (see the log)")
        action = logic.ToolCut if stroke["action"] == "cut" else logic.ToolRestore
        for position in stroke["positions"]:
            for row in range(3):
                matrix.SetElement(row, 3, position[row])
            start = time.perf_counter()
            accepted = logic.MoveActiveTool(cut_node, matrix, action)
            times.append(1000.0 * (time.perf_counter() - start))
            refused += not accepted
        logic.EndStroke(cut_node)
    values = np.array(times) if times else np.zeros(1)
    return {
        "strokes": len(recording["strokes"]),
        "poses": len(times),
        "refused_poses": refused,
        "tools": sorted({stroke["tool"] for stroke in recording["strokes"]}),
        "pose_time_ms_first": round(float(values[0]), 4),
        "pose_time_ms_p50": round(float(np.percentile(values, 50)), 4),
        "pose_time_ms_p99": round(float(np.percentile(values, 99)), 4),
        "pose_time_ms_max": round(float(values.max()), 4),
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--head-ct", type=Path, required=True, help="write the shipped head-CT mastoidectomy recording here")
    args = parser.parse_args(argv)
    from . import drilling
    from ..data import headct
    from ..scene.application import HeadlessSlicer

    application = HeadlessSlicer()
    volume = headct.load_volume_node(application.scene, name="HeadCT")
    plan = drilling.MastoidectomyPlan(entry=drilling.lateral_entry(volume, *headct.RIGHT_MASTOID_YZ))
    recording = record_mastoidectomy(
        plan, description="Cortical mastoidectomy of the right mastoid of Debian's invesalius-examples head CT: "
        "saucerised layers with a 5 mm cutting burr ('cutting'), the last two polished with a 3 mm diamond burr ('diamond').")
    save(recording, args.head_ct)
    poses = sum(len(stroke["positions"]) for stroke in recording["strokes"])
    print(f"{args.head_ct}: {len(recording['strokes'])} strokes, {poses} poses")
    return 0


if __name__ == "__main__":
    sys.exit(main())
