"""Recorded drilling sessions: the pose streams of tools, saved as JSON and replayed through the logic.

A recording is what a mouse, a haptic device or a script produced: strokes,
each a tool (by a key that names a tool preset), an action (cut or restore)
and the tool's poses (RAS, mm; one rotation per stroke, the tool's +z along
its shaft towards the handpiece, as ``vtkMRMLVolumeCutToolNode`` defines it).
Replaying it moves each tool node through ``vtkSlicerVolumeCuttingLogic.
MoveActiveTool`` inside ``BeginStroke`` / ``EndStroke``, exactly as a live
session does, so tests, demos and session review all run the product's path.

Version 2 makes a recording complete enough to grade the session
(``VolumeCuttingLib.assessment``): the scan it was drilled on (its name, how
to rebuild it and its voxel grid), the tools (burr type and radius, since a
large cutting burr near a nerve is a fault of its own), a time per pose, the
camera of every rendered frame (what the trainee could see), events (drill
on/off, tool changes, undo/redo, contacts), the force on the tool per pose
where a haptic device measured one, and the removed volume per segment over
time; and a sha256 of its content, checked on reading, so a truncated or
edited file is refused rather than graded. Version 3 adds the virtual nerve
monitor's readings (``MONITOR_FIELDS``): per stroke, for each monitored
structure, its distance (mm) and level at the poses where the reading
changed (the level, or the distance by more than ``MONITOR_STEP_MM``), and
at each stroke's first pose. Versions 1 and 2 are still read.

    python -m VolumeCuttingLib.cutting.recording --head-ct OUT.json   # record the shipped mastoidectomy
"""

from __future__ import annotations

import argparse
import datetime
import hashlib
import json
import sys
import time
from pathlib import Path

import numpy as np

from ..scene.resources import find_resource

FORMAT = "VolumeCuttingRecording"
VERSION = 3
READABLE_VERSIONS = (1, 2, 3)
EVENT_TYPES = ("drill_on", "drill_off", "tool_change", "undo", "redo", "contact")
CAMERA_FIELDS = ("t", "position", "focal_point", "view_up", "view_angle")
# A nerve-monitor reading: the pose of its stroke it was taken at, the
# structure (an index into the recording's monitor structures), the distance
# from the tool's surface to the structure's surface (mm, None while not
# ready) and the level (vtkVolumeCutNerveMonitor: 0 silent .. 4 contact, -1 not ready).
MONITOR_FIELDS = ("pose", "structure", "distance_mm", "level")
# A reading is kept when it moved by more than this since the last one kept:
# at 1 kHz most ticks change the distance by microns, and the metrics
# (1 and 2 mm bands, the minimum) need no finer step.
MONITOR_STEP_MM = 0.05
MONITOR_LEVELS = range(-1, 5)
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
    # Untimed, as before: ``timed`` turns it into a complete recording.
    return {"format": FORMAT, "version": 1, "description": description, "frame": "RAS", "units": "mm", "strokes": strokes}


def content_sha256(recording: dict) -> str:
    """The sha256 of a recording's content: its canonical JSON without the ``sha256`` field.

    Python writes floats as their shortest round-tripping text, so the sum of
    a loaded recording equals the sum of the one that was saved.
    """
    content = {key: value for key, value in recording.items() if key != "sha256"}
    return hashlib.sha256(json.dumps(content, sort_keys=True, separators=(",", ":")).encode()).hexdigest()


def save(recording: dict, path) -> Path:
    """Write a recording; version 2 recordings get the sha256 of their content (checked by ``load``)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if recording.get("version", 1) >= 2:
        recording = dict(recording, sha256=content_sha256(recording))
    # Written beside and renamed: a crash while writing leaves the old file whole.
    scratch = path.with_name(path.name + ".part")
    scratch.write_text(json.dumps(recording, separators=(",", ":")) + "\n")
    scratch.replace(path)
    return path


def _finite_list(value, length=None) -> bool:
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return False
    return array.ndim == 1 and (length is None or len(array) == length) and bool(np.all(np.isfinite(array)))


def load(path) -> dict:
    """Read and check a recording; RecordingError names the file and what is wrong (the stroke, the field)."""
    path = Path(path)
    try:
        recording = json.loads(path.read_text())
    except FileNotFoundError:
        raise RecordingError(f"{path}: no such recording") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
        raise RecordingError(f"{path}: not a readable recording, truncated or corrupt ({error})") from None
    check(recording, path)
    return recording


def check(recording, path="recording", require_checksum=True) -> None:
    """Raise RecordingError unless ``recording`` is a whole, consistent recording of a readable version.

    A file must carry its sha256 (``load`` requires it); a recording built in
    memory (a session just recorded) may not have one yet, and is checked
    against it when it has.
    """
    if not isinstance(recording, dict) or recording.get("format") != FORMAT or recording.get("version") not in READABLE_VERSIONS:
        raise RecordingError(f"{path}: not a {FORMAT} file of version {' or '.join(map(str, READABLE_VERSIONS))}")
    version = recording["version"]
    if version >= 2:
        stored = recording.get("sha256")
        if stored is None and not require_checksum:
            pass
        elif not isinstance(stored, str):
            raise RecordingError(f"{path}: it has no sha256 of its content (a version {version} recording must)")
        elif stored != content_sha256(recording):
            raise RecordingError(f"{path}: its content does not match its sha256: the file is corrupt or was edited")
    strokes = recording.get("strokes")
    if not isinstance(strokes, list) or not strokes:
        raise RecordingError(f"{path}: it holds no strokes (an empty session)")
    tools = recording.get("tools", {})
    if version >= 2 and not isinstance(tools, dict):
        raise RecordingError(f"{path}: 'tools' must map tool keys to their burr type and radius")
    for key, tool in tools.items():
        if not isinstance(tool, dict) or not isinstance(tool.get("burr_type"), str) or not _finite_list([tool.get("radius_mm")], 1) \
                or tool["radius_mm"] <= 0.0:
            raise RecordingError(f"{path}: tool '{key}' needs a 'burr_type' and a positive 'radius_mm'")
    previous_time = -np.inf
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
        if version >= 2:
            if tools and stroke["tool"] not in tools:
                raise RecordingError(f"{where}: tool '{stroke['tool']}' is not among the recording's tools")
            times = stroke.get("times")
            if not _finite_list(times, len(positions)):
                raise RecordingError(f"{where}: 'times' must be one finite time (s) per position")
            times = np.asarray(times, dtype=float)
            if np.any(np.diff(times) < 0.0) or times[0] < previous_time:
                raise RecordingError(f"{where}: its times go backwards")
            previous_time = times[-1]
            if "forces" in stroke and not _finite_list(stroke["forces"], len(positions)):
                raise RecordingError(f"{where}: 'forces' must be one finite force (N) per position")
            if "monitor" in stroke:
                _check_monitor_readings(stroke["monitor"], len(positions), len(recording.get("monitor", {}).get("structures", [])), where)
    if version >= 2:
        for index, event in enumerate(recording.get("events", [])):
            if not isinstance(event, dict) or event.get("type") not in EVENT_TYPES or not _finite_list([event.get("t")], 1):
                raise RecordingError(f"{path}: event {index} needs a time 't' and a type among {', '.join(EVENT_TYPES)}")
        monitor = recording.get("monitor")
        if monitor is not None and (not isinstance(monitor, dict) or not isinstance(monitor.get("structures"), list)
                                    or not all(isinstance(name, str) for name in monitor["structures"])):
            raise RecordingError(f"{path}: 'monitor' must name its structures (a list of segment names)")
        frames = recording.get("camera", {}).get("frames", [])
        for index, frame in enumerate(frames):
            if not _finite_list(frame, 11):
                raise RecordingError(f"{path}: camera frame {index} must be 11 numbers: t, position, focal point, view up, view angle")


def _check_monitor_readings(readings, poses: int, structures: int, where: str) -> None:
    if not isinstance(readings, list):
        raise RecordingError(f"{where}: 'monitor' must be a list of readings [{', '.join(MONITOR_FIELDS)}]")
    for reading in readings:
        if not isinstance(reading, list) or len(reading) != 4 or not all(isinstance(v, int) for v in (reading[0], reading[1], reading[3])) \
                or not 0 <= reading[0] < poses or not 0 <= reading[1] < structures or reading[3] not in MONITOR_LEVELS \
                or not (reading[2] is None if reading[3] == -1 else _finite_list([reading[2]], 1)):
            raise RecordingError(f"{where}: monitor reading {reading!r} is not [pose of the stroke, structure index, "
                                 f"distance mm (null when not ready), level -1..4]")


class MonitorCompactor:
    """Keeps the nerve monitor's readings of a stroke that matter.

    The first of each structure, then those that changed level or moved by
    more than ``MONITOR_STEP_MM`` since the last one kept.
    """

    def __init__(self, step_mm: float = MONITOR_STEP_MM):
        self.step_mm = step_mm
        self._last = {}

    def restart(self) -> None:
        """A new stroke: its first readings are all kept, so that a stroke reads on its own."""
        self._last = {}

    def keep(self, pose: int, structure: int, distance, level: int):
        """The reading as recorded ``[pose, structure, distance, level]`` when it is kept, else None."""
        distance = None if distance is None or not np.isfinite(distance) or level < 0 else round(float(distance), 4)
        level = -1 if distance is None else int(level)
        last = self._last.get(structure)
        if last is not None and last[1] == level and (distance is None or abs(distance - last[0]) <= self.step_mm):
            return None
        self._last[structure] = (distance, level)
        return [int(pose), int(structure), distance, level]


def monitor_readings(monitor) -> list:
    """The readings of a ``vtkVolumeCutNerveMonitor`` now: (structure name, distance mm or None, level) per structure."""
    if monitor is None:
        return []
    result = []
    for index in range(monitor.GetNumberOfStructures()):
        distance = monitor.GetDistance(index)
        level = int(monitor.GetLevel(index))
        result.append((monitor.GetStructureName(index), None if level < 0 or not np.isfinite(distance) else float(distance), level))
    return result


def monitor_header(monitor, structures) -> dict:
    """What a recording says of its monitor: the structures' names, the thresholds, the range and the step readings are kept at."""
    header = {"structures": list(structures), "fields": list(MONITOR_FIELDS), "step_mm": MONITOR_STEP_MM}
    if monitor is not None:
        header.update(range_mm=float(monitor.GetRange()), thresholds_mm=[float(monitor.GetSilentThreshold()),
                      float(monitor.GetSparseThreshold()), float(monitor.GetBurstThreshold())])
    return header


def tool_of(recording: dict, key: str) -> dict:
    """The burr type and radius of a recording's tool key (RecordingError if the recording does not say)."""
    tool = recording.get("tools", {}).get(key)
    if tool is None:
        raise RecordingError(f"the recording does not say what tool '{key}' is (burr type and radius): give its tools")
    return tool


def timed(recording: dict, tools: dict, speed_mm_s: float = 5.0, pause_s: float = 0.5, start_s: float = 0.0,
          scan: dict | None = None, camera_frames=None, started: str | None = None, trainee: str | None = None) -> dict:
    """A version 2 recording of an untimed one: the burr moving at ``speed_mm_s`` along each stroke, ``pause_s`` between strokes.

    ``tools`` says each key's burr type and radius; ``scan`` the scan (name,
    rebuild parameters, grid); ``camera_frames`` rows of
    ``CAMERA_FIELDS`` (flattened, 11 numbers). Events mark the drill going on
    and off around each stroke and the tool changes.
    """
    if speed_mm_s <= 0.0:
        raise ValueError("the burr speed must be positive")
    strokes, events = [], []
    now = float(start_s)
    previous_tool = None
    for stroke in recording["strokes"]:
        positions = np.asarray(stroke["positions"], dtype=float)
        steps = np.linalg.norm(np.diff(positions, axis=0), axis=1)
        times = now + np.concatenate([[0.0], np.cumsum(steps)]) / speed_mm_s
        if stroke["tool"] != previous_tool:
            events.append({"t": round(now, 6), "type": "tool_change", "tool": stroke["tool"]})
            previous_tool = stroke["tool"]
        events.append({"t": round(now, 6), "type": "drill_on"})
        events.append({"t": round(float(times[-1]), 6), "type": "drill_off"})
        strokes.append(dict(stroke, times=[round(float(t), 6) for t in times]))
        now = float(times[-1]) + pause_s
    result = {key: value for key, value in recording.items() if key not in ("strokes", "sha256")}
    result.update({
        "version": VERSION, "strokes": strokes, "events": events, "tools": tools,
        "started": started or datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "trainee": trainee,
    })
    if scan is not None:
        result["scan"] = scan
    if camera_frames is not None:
        result["camera"] = {"fields": list(CAMERA_FIELDS), "frames": [[round(float(v), 6) for v in frame] for frame in camera_frames]}
    return result


def from_haptic_ticks(proxies, forces, drilling, rate_hz: float, tool_key: str, tool: dict, rotation,
                      scan: dict | None = None, description: str = "", started: str | None = None,
                      monitor: dict | None = None) -> dict:
    """A recording of a haptic session, tick by tick (``vtkHapticRecorder``: proxy, force, drilling).

    Each run of ticks with the drill on is a stroke at the device's rate:
    positions are the proxy's (where the tool is held on the bone, RAS mm),
    times the tick index over ``rate_hz``, forces the magnitude of the force
    sent (N). Ticks with the drill off move no stroke; their time is idle.
    ``monitor``: the nerve monitor's readings per tick, ``monitor_header``'s
    dict with ``distances`` and ``levels`` (ticks x structures) added; kept
    as a live session keeps them (``MonitorCompactor``).
    """
    proxies = np.asarray(proxies, dtype=float).reshape(-1, 3)
    forces = np.asarray(forces, dtype=float)
    forces = np.linalg.norm(forces, axis=1) if forces.ndim == 2 else forces.ravel()  # vectors or magnitudes
    drilling = np.asarray(drilling, dtype=bool).ravel()
    if not (len(proxies) == len(forces) == len(drilling)):
        raise RecordingError("the haptic ticks' proxies, forces and drilling flags differ in number")
    if rate_hz <= 0.0:
        raise RecordingError("the haptic rate must be positive")
    edges = np.flatnonzero(np.diff(np.concatenate([[0], drilling.astype(np.int8), [0]])))
    strokes, events = [], [{"t": 0.0, "type": "tool_change", "tool": tool_key}]
    rotation = [float(v) for v in np.asarray(rotation, dtype=float).ravel()]
    if monitor is not None:
        distances = np.asarray(monitor["distances"], dtype=float).reshape(len(proxies), -1)
        levels = np.asarray(monitor["levels"], dtype=int).reshape(len(proxies), -1)
        compactor = MonitorCompactor(monitor.get("step_mm", MONITOR_STEP_MM))
    for first, stop in zip(edges[0::2], edges[1::2]):
        times = np.arange(first, stop) / rate_hz
        events += [{"t": float(times[0]), "type": "drill_on"}, {"t": float(times[-1]), "type": "drill_off"}]
        strokes.append({"tool": tool_key, "action": "cut", "rotation": rotation, "positions": proxies[first:stop].tolist(),
                        "times": times.tolist(), "forces": forces[first:stop].tolist()})
        if monitor is not None:
            compactor.restart()
            kept = (compactor.keep(tick - first, index, distances[tick, index], levels[tick, index])
                    for tick in range(first, stop) for index in range(distances.shape[1]))
            strokes[-1]["monitor"] = [reading for reading in kept if reading is not None]
    recording = {"format": FORMAT, "version": VERSION, "description": description, "frame": "RAS", "units": "mm",
                 "started": started or datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
                 "trainee": None, "tools": {tool_key: tool}, "strokes": strokes, "events": events}
    if monitor is not None:
        recording["monitor"] = {key: value for key, value in monitor.items() if key not in ("distances", "levels")}
    if scan is not None:
        recording["scan"] = scan
    return recording


class SessionRecorder:
    """Records a live session as a recording: strokes with a time per pose, events, camera frames, removed volumes.

    The application calls it where it drives the logic (``replay`` does, when
    given one): ``begin_stroke`` / ``pose`` / ``end_stroke`` around
    ``MoveActiveTool``, ``event`` for undo, redo and drill switches,
    ``camera`` per rendered frame, ``removed`` after each stroke. Times are
    seconds since the recorder started, from ``clock``. ``pose`` takes the
    nerve monitor's readings at that pose (``monitor_readings``); the
    recording keeps those that changed (``MonitorCompactor``).
    """

    def __init__(self, tools: dict, scan: dict | None = None, trainee: str | None = None, description: str = "", clock=time.perf_counter):
        self._clock = clock
        self._origin = clock()
        self.recording = {
            "format": FORMAT, "version": VERSION, "description": description, "frame": "RAS", "units": "mm",
            "started": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"), "trainee": trainee,
            "tools": tools, "strokes": [], "events": [], "camera": {"fields": list(CAMERA_FIELDS), "frames": []},
            "removed": {"segments": [], "samples": []},
        }
        if scan is not None:
            self.recording["scan"] = scan
        self._stroke = None
        self._tool = None
        self._compactor = MonitorCompactor()

    def monitor(self, monitor) -> None:
        """Say which nerve monitor the readings come from (its structures, thresholds and range)."""
        known = self.recording.get("monitor", {}).get("structures", [])
        names = known + [monitor.GetStructureName(i) for i in range(monitor.GetNumberOfStructures())
                         if monitor.GetStructureName(i) not in known]
        self.recording["monitor"] = monitor_header(monitor, names)

    def _structure_index(self, name: str) -> int:
        structures = self.recording.setdefault("monitor", monitor_header(None, []))["structures"]
        if name not in structures:
            structures.append(name)
        return structures.index(name)

    def now(self) -> float:
        return round(self._clock() - self._origin, 6)

    def event(self, kind: str, **details) -> None:
        if kind not in EVENT_TYPES:
            raise ValueError(f"'{kind}' is no recorded event type ({', '.join(EVENT_TYPES)})")
        self.recording["events"].append(dict({"t": self.now(), "type": kind}, **details))

    def begin_stroke(self, tool: str, action: str, rotation) -> None:
        if tool != self._tool:
            self.event("tool_change", tool=tool)
            self._tool = tool
        self.event("drill_on")
        self._stroke = {"tool": tool, "action": action, "rotation": [float(v) for v in np.asarray(rotation, dtype=float).ravel()],
                        "positions": [], "times": []}
        self._compactor.restart()

    def pose(self, position, force_n: float | None = None, readings=()) -> None:
        """A pose of the stroke; ``force_n`` the magnitude of the force on the tool (N), where a device measures it;
        ``readings`` the nerve monitor's (name, distance mm or None, level) per structure there."""
        pose = len(self._stroke["positions"])
        self._stroke["positions"].append([float(v) for v in position])
        self._stroke["times"].append(self.now())
        if force_n is not None:
            self._stroke.setdefault("forces", [0.0] * pose).append(float(force_n))
        elif "forces" in self._stroke:
            self._stroke["forces"].append(0.0)
        for name, distance, level in readings:
            kept = self._compactor.keep(pose, self._structure_index(name), distance, level)
            if kept is not None:
                self._stroke.setdefault("monitor", []).append(kept)

    def end_stroke(self) -> None:
        self.event("drill_off")
        if self._stroke["positions"]:
            self.recording["strokes"].append(self._stroke)
        self._stroke = None

    def camera(self, position, focal_point, view_up, view_angle) -> None:
        self.recording["camera"]["frames"].append(
            [self.now(), *map(float, position), *map(float, focal_point), *map(float, view_up), float(view_angle)])

    def removed(self, volumes_mm3: dict) -> None:
        """The removed volume (mm3) of each segment now."""
        removed = self.recording["removed"]
        if not removed["segments"]:
            removed["segments"] = sorted(volumes_mm3)
        removed["samples"].append([self.now(), *(float(volumes_mm3.get(name, 0.0)) for name in removed["segments"])])


def head_ct_mastoidectomy_path() -> Path:
    """The recorded mastoidectomy on the shipped head CT."""
    return find_resource("Sessions", HEAD_CT_MASTOIDECTOMY)


def edits_before_strokes(recording: dict):
    """Undo/redo events grouped by the stroke they precede (len(strokes): after the last), in time order."""
    strokes = recording["strokes"]
    starts = [stroke["times"][0] if "times" in stroke else None for stroke in strokes]
    edits = [[] for _ in range(len(strokes) + 1)]
    for event in sorted((e for e in recording.get("events", []) if e["type"] in ("undo", "redo")), key=lambda e: e["t"]):
        index = next((i for i, start in enumerate(starts) if start is not None and event["t"] <= start), len(strokes))
        edits[index].append(event["type"])
    return edits


def replay(logic, cut_node, recording: dict, tool_nodes: dict, recorder: SessionRecorder | None = None) -> dict:
    """Drill the recording with the given tool nodes (by the recording's tool keys).

    Each stroke makes its tool the cut node's active tool and moves it
    through its poses with ``MoveActiveTool``; undo and redo (version 2) are
    applied where they happened, between strokes. With a ``recorder``, the
    replay is recorded as a live session is: poses with their times, the
    edits, contacts and the removed volume per segment after each stroke.
    Returns counts and per-pose timings (first, p50, p99 and max, ms).
    """
    import vtk

    missing = sorted({stroke["tool"] for stroke in recording["strokes"]} - set(tool_nodes))
    if missing:
        raise RecordingError(f"the recording uses tools {', '.join(missing)} that were not given")
    matrix = vtk.vtkMatrix4x4()
    times = []
    refused = 0
    edits = edits_before_strokes(recording)
    contact_table = logic.GetContactTableNode(cut_node) if recorder is not None else None
    # The nerve monitor's readings go with the poses; its fields are built first, so that every pose reads.
    monitor = logic.GetNerveMonitor(cut_node) if recorder is not None else None
    if monitor is not None:
        logic.WaitForNerveMonitor(cut_node)
        recorder.monitor(monitor)
    contacts_seen = contact_table.GetNumberOfRows() if contact_table is not None else 0
    segmentation = cut_node.GetSegmentationNode().GetSegmentation() if recorder is not None and cut_node.GetSegmentationNode() else None

    def apply_edits(kinds):
        for kind in kinds:
            done = logic.UndoStroke(cut_node) if kind == "undo" else logic.RedoStroke(cut_node)
            if recorder is not None and done:
                recorder.event(kind)

    def record_after_stroke():
        nonlocal contacts_seen
        if segmentation is not None:
            recorder.removed({segment_id: logic.GetRemovedVolumeInSegment(cut_node, segment_id)
                              for segment_id in segmentation.GetSegmentIDs()})
        for row in range(contacts_seen, contact_table.GetNumberOfRows()):
            recorder.event("contact", segment=contact_table.GetCellText(row, 0), depth_mm=float(contact_table.GetCellText(row, 3)))
        contacts_seen = contact_table.GetNumberOfRows()

    for index, stroke in enumerate(recording["strokes"]):
        apply_edits(edits[index])
        cut_node.SetAndObserveActiveToolNodeID(tool_nodes[stroke["tool"]].GetID())
        rotation = np.asarray(stroke["rotation"], dtype=float).reshape(3, 3)
        for row in range(3):
            for column in range(3):
                matrix.SetElement(row, column, rotation[row, column])
        if not logic.BeginStroke(cut_node):
            raise RuntimeError("the cut node has no cut field (see the log)")
        if recorder is not None:
            recorder.begin_stroke(stroke["tool"], stroke["action"], rotation)
        action = logic.ToolCut if stroke["action"] == "cut" else logic.ToolRestore
        for position in stroke["positions"]:
            for row in range(3):
                matrix.SetElement(row, 3, position[row])
            start = time.perf_counter()
            accepted = logic.MoveActiveTool(cut_node, matrix, action)
            times.append(1000.0 * (time.perf_counter() - start))
            refused += not accepted
            if recorder is not None:
                recorder.pose(position, readings=monitor_readings(monitor))
        logic.EndStroke(cut_node)
        if recorder is not None:
            recorder.end_stroke()
            record_after_stroke()
    apply_edits(edits[-1])
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
