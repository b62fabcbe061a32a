"""Grading a recorded drilling session: final product, safety, efficiency and visibility metrics, and a score.

The session is replayed on the scan's label image (``scans.Scan``), pose by
pose: a spherical burr of the tool's radius swept from each pose to the next
removes the cuttable voxels whose centres it passes within its radius
(protected structures are never removed, as in the product), restore strokes
put them back, undo and redo take a stroke back and forth. Replaying on the
labels rather than through the logic keeps the assessment Slicer-free and
lets it know, at each pose, what material remains, which the visibility
metric needs: the burr is hidden when the ray from the recorded camera to
the side of the burr facing it crosses an opaque voxel of the operative field
(the poses' box grown by the burr and 4 mm) that is still there.

Distances are from the burr's surface to a structure's surface: the distance
from the burr centre to the nearest surface-voxel centre of the structure,
less half a voxel (where the voxelised surface lies) and the burr radius;
negative inside. Where the recording holds the nerve monitor's readings
(version 3), a structure's distance at a pose is the monitor's (the last
reading kept at or before the pose in its stroke, within the recording's
step of the live value; the monitor measures to the smoothed surface the
view draws), and the recomputed one where the monitor did not read (not
ready, or beyond its range, where its reading is only a lower bound); the
JSON says how many poses each came from and how far the two differ. Each pose stands for the interval since the previous pose
of its stroke (the first of a stroke for none): times within 1 and 2 mm,
the largest force there (where a device recorded forces),
contact time and hidden time add those intervals up; idle time is the
session's time between strokes.

Regions are the cuttable segments and, per protected structure, the bands of
cuttable material 0-1, 1-2 and 2-4 mm from it.
"""

from __future__ import annotations

import datetime
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..cutting import recording as recordings
from . import scans as scanlib

FORMAT = "VolumeCuttingAssessment"
VERSION = 1
BANDS_MM = ((0.0, 1.0), (1.0, 2.0), (2.0, 4.0))
NEAR_MM = (1.0, 2.0)
LARGE_BURR_RADIUS_MM = 2.0
LARGE_BURR_TYPE = "cutting"
# Overall score: a weighted mean of the parts that could be computed (0-1 each).
SCORE_WEIGHTS = {"safety": 0.40, "final_product": 0.25, "visibility": 0.20, "efficiency": 0.15}
# Safety part: the mean of four terms, each 1 when the trainee did nothing wrong.
SAFE_DISTANCE_MM = 2.0  # min distance term: distance / this, capped at 1
NEAR_TIME_SCALE_S = 5.0  # exp(-time within 1 mm / this)
LARGE_BURR_TIME_SCALE_S = 2.0  # exp(-time of a large cutting burr within 2 mm / this)
# Version 1 recordings have no times: their burr is taken to move at this speed, pausing between strokes.
UNTIMED_SPEED_MM_S = 5.0
UNTIMED_PAUSE_S = 0.5
# Readings this close below the nerve monitor's exact limit (range less the burr's radius) interpolate towards
# the plateau beyond it: they count as lower bounds too.
MONITOR_RANGE_MARGIN_MM = 0.25


class AssessmentError(ValueError):
    """A session that cannot be graded; the message says why (the file, the field, both grids)."""


def band_name(structure: str, band) -> str:
    return f"{structure}_band_{band[0]:g}-{band[1]:g}mm"


@dataclass
class Replay:
    """What the label-image replay of one recording gives, pose by pose."""

    positions: np.ndarray  # (N, 3) burr centres, RAS mm
    times: np.ndarray  # (N,) s
    intervals: np.ndarray  # (N,) s since the previous pose of the stroke
    radii: np.ndarray
    large: np.ndarray  # a large cutting burr
    stroke_of: np.ndarray
    first_of_stroke: np.ndarray
    cutting: np.ndarray  # a cut stroke (not a restore)
    removed_voxels: np.ndarray  # (N,) voxels this pose removed (less those it restored)
    hidden: np.ndarray | None  # (N,) the burr was hidden from the camera (None: no camera recorded)
    region_series: np.ndarray  # (N, regions) removed volume per region after each pose, mm3
    final_removed: np.ndarray  # bool, crop shaped
    forces: np.ndarray | None = None  # (N,) force on the tool, N, where recorded (NaN elsewhere); None: none recorded
    distances: dict = field(default_factory=dict)  # structure -> (N,) burr surface to structure surface, mm
    recomputed: dict = field(default_factory=dict)  # structure -> (N,) the distance recomputed from the poses, mm
    monitored: dict = field(default_factory=dict)  # structure -> (N,) the nerve monitor's recorded distance, NaN where none
    undo: int = 0
    redo: int = 0


class Crop:
    """The part of the scan the sessions can reach, with region masks and distance bands."""

    def __init__(self, scan: scanlib.Scan, positions: np.ndarray, radius: float):
        self.scan = scan
        spacing = scan.spacing
        margin = radius + BANDS_MM[-1][1] + 2.0 * spacing.max()
        ijk = scan.ras_to_ijk(np.concatenate([positions - margin, positions + margin]))
        dims = np.array(scan.dimensions)
        self.low = np.clip(np.floor(ijk.min(axis=0)).astype(int), 0, dims)
        self.high = np.clip(np.ceil(ijk.max(axis=0)).astype(int) + 1, 0, dims)
        if np.any(self.high <= self.low):
            raise AssessmentError(f"the session's poses lie outside the scan ({scanlib.describe_grid(scan.grid())})")
        self.slices = tuple(slice(self.low[a], self.high[a]) for a in (2, 1, 0))
        self.labels = scan.labels[self.slices]
        self.cuttable = scan.lookup(scan.cuttable)[self.labels]
        self.opaque_table = scan.lookup(scan.opaque)
        self.regions, self.masks = [], []
        for name in scan.cuttable:
            self.regions.append(name)
            self.masks.append(self.labels == scan.label(name))
        for structure in scan.protected:
            distance = self.surface_distance(structure)
            for band in BANDS_MM:
                self.regions.append(band_name(structure, band))
                self.masks.append(self.cuttable & (distance >= band[0]) & (distance < band[1]))
        self.membership = np.stack(self.masks, axis=-1).reshape(-1, len(self.masks)) if self.masks else np.zeros((self.labels.size, 0), bool)

    def surface_distance(self, structure: str) -> np.ndarray:
        """Distance (mm) from each crop voxel centre to the structure's surface, from a Euclidean distance transform."""
        import vtk
        from vtkmodules.util import numpy_support

        mask = self.labels == self.scan.label(structure)
        # The structure may lie just outside the crop: transform a box grown by the widest band.
        grow = np.ceil(BANDS_MM[-1][1] / self.scan.spacing).astype(int) + 1
        low = np.maximum(self.low - grow, 0)
        high = np.minimum(self.high + grow, self.scan.dimensions)
        big = self.scan.labels[low[2]:high[2], low[1]:high[1], low[0]:high[0]] == self.scan.label(structure)
        if not big.any():
            return np.full(mask.shape, np.inf)
        image = vtk.vtkImageData()
        image.SetDimensions(*(high - low))
        image.SetSpacing(*self.scan.spacing)
        image.GetPointData().SetScalars(numpy_support.numpy_to_vtk((~big).astype(np.float32).ravel() * 1e12, deep=True))
        transform = vtk.vtkImageEuclideanDistance()
        transform.SetInputData(image)
        transform.ConsiderAnisotropyOn()
        transform.InitializeOn()
        transform.SetAlgorithmToSaito()
        transform.Update()
        squared = numpy_support.vtk_to_numpy(transform.GetOutput().GetPointData().GetScalars()).reshape(big.shape)
        distance = np.sqrt(squared) - 0.5 * float(self.scan.spacing.mean())
        start = self.low - low
        stop = start + (self.high - self.low)
        return distance[start[2]:stop[2], start[1]:stop[1], start[0]:stop[0]]


def _poses(recording: dict):
    """Per pose: position, time, interval, radius, large, stroke, first of stroke, cutting."""
    if recording.get("version", 1) < 2:
        raise AssessmentError("internal: untimed recordings are timed before grading")
    rows = []
    for index, stroke in enumerate(recording["strokes"]):
        tool = recordings.tool_of(recording, stroke["tool"])
        positions = np.asarray(stroke["positions"], dtype=float)
        times = np.asarray(stroke["times"], dtype=float)
        large = tool["burr_type"].lower() == LARGE_BURR_TYPE and tool["radius_mm"] >= LARGE_BURR_RADIUS_MM
        for n in range(len(positions)):
            rows.append((positions[n], times[n], times[n] - times[n - 1] if n else 0.0, float(tool["radius_mm"]), large,
                         index, n == 0, stroke["action"] == "cut"))
    columns = list(zip(*rows))
    return (np.array(columns[0]), np.array(columns[1]), np.array(columns[2]), np.array(columns[3]),
            np.array(columns[4], dtype=bool), np.array(columns[5]), np.array(columns[6], dtype=bool), np.array(columns[7], dtype=bool))


_OFFSETS = {}


def _box_offsets(shape) -> np.ndarray:
    """The (i, j, k) offsets of every voxel of a box of that shape, in the crop's flat order (k slowest), cached."""
    offsets = _OFFSETS.get(shape)
    if offsets is None:
        k, j, i = np.indices(shape[::-1])
        offsets = _OFFSETS[shape] = np.stack([i.ravel(), j.ravel(), k.ravel()], axis=1)
    return offsets


def _capsule_voxels(crop: Crop, start, end, radius) -> np.ndarray:
    """Flat crop indices of voxels whose centres lie within ``radius`` of the segment start-end."""
    scan = crop.scan
    reach = radius / scan.spacing.min() + 1.0
    ijk = scan.ras_to_ijk(np.array([start, end])) - crop.low
    low = np.maximum(np.floor(ijk.min(axis=0) - reach).astype(int), 0)
    high = np.minimum(np.ceil(ijk.max(axis=0) + reach).astype(int) + 1, crop.high - crop.low)
    if np.any(high <= low):
        return np.zeros(0, dtype=np.int64)
    local = _box_offsets(tuple(int(n) for n in high - low)) + low
    # Offsets from the segment's start in RAS: one matrix product, the translation cancels.
    relative = (local - (scan.ras_to_ijk(start) - crop.low)) @ scan.ijk_to_ras[:3, :3].T
    axis = np.asarray(end, dtype=float) - start
    length2 = float(axis @ axis)
    if length2 > 0.0:
        t = np.clip(relative @ axis / length2, 0.0, 1.0)
        relative = relative - t[:, None] * axis
    chosen = local[np.einsum("ij,ij->i", relative, relative) <= radius * radius]
    shape = crop.labels.shape
    return (chosen[:, 2] * shape[1] + chosen[:, 1]) * shape[2] + chosen[:, 0]


def _camera_at(frames: np.ndarray, time: float):
    index = max(int(np.searchsorted(frames[:, 0], time, side="right")) - 1, 0)
    return frames[index, 1:4]


def _hidden(crop: Crop, present: np.ndarray, camera, center, radius) -> bool:
    """Whether opaque material still there lies between the camera and the side of the burr facing it.

    Only the operative field (the crop) can hide the burr: what lies beyond
    it in the scan, a head holder, the far side of the head, is not between
    a surgeon's microscope and the field.
    """
    scan = crop.scan
    toward = center - camera
    distance = float(np.linalg.norm(toward))
    # Stop a voxel short of the burr: the voxels it is cutting now touch it.
    stop = distance - radius - float(scan.spacing.max())
    if stop <= 0.0:
        return False
    step = 0.5 * float(scan.spacing.min())
    samples = camera + np.arange(0.0, stop, step)[:, None] * (toward / distance)
    ijk = np.rint(scan.ras_to_ijk(samples)).astype(int)
    local = ijk[np.all((ijk >= crop.low) & (ijk < crop.high), axis=1)] - crop.low
    return bool(present[local[:, 2], local[:, 1], local[:, 0]].any())


def replay(recording: dict, crop: Crop) -> Replay:
    """Replay a (timed) recording on the crop's labels; see the module docstring."""
    positions, times, intervals, radii, large, stroke_of, first, cutting = _poses(recording)
    scan = crop.scan
    removable = crop.cuttable.ravel()
    removed = np.zeros(crop.labels.size, dtype=bool)
    present = crop.opaque_table[crop.labels].copy()  # opaque material that remains, for the visibility rays
    present_flat = present.reshape(-1)
    opaque_flat = crop.opaque_table[crop.labels].ravel()
    voxel = scan.voxel_volume_mm3
    region_totals = np.zeros(crop.membership.shape[1])
    series = np.zeros((len(positions), crop.membership.shape[1]))
    removed_voxels = np.zeros(len(positions))
    frames = np.asarray(recording.get("camera", {}).get("frames", []), dtype=float).reshape(-1, 11)
    hidden = np.zeros(len(positions), dtype=bool) if len(frames) else None
    done, undone = [], []  # strokes' (removed, restored) flat indices, for undo and redo
    counts = {"undo": 0, "redo": 0}

    def apply(took, gave):
        removed[took] = True
        present_flat[took] = False
        removed[gave] = False
        present_flat[gave] = opaque_flat[gave]
        return crop.membership[took].sum(axis=0) - crop.membership[gave].sum(axis=0)

    def edit(kind):
        nonlocal region_totals
        source, target = (done, undone) if kind == "undo" else (undone, done)
        if not source:
            return
        took, gave = source.pop()
        delta = apply(gave, took) if kind == "undo" else apply(took, gave)
        region_totals = region_totals + delta * voxel
        target.append((took, gave))
        counts[kind] += 1

    edits = recordings.edits_before_strokes(recording)
    stroke_took, stroke_gave = [], []
    for n in range(len(positions)):
        stroke = stroke_of[n]
        if first[n]:
            for kind in edits[stroke]:
                edit(kind)
            stroke_took, stroke_gave = [], []
        if hidden is not None and cutting[n]:
            hidden[n] = _hidden(crop, present, _camera_at(frames, times[n]), positions[n], radii[n])
        start = positions[n - 1] if not first[n] else positions[n]
        swept = _capsule_voxels(crop, start, positions[n], radii[n])
        if cutting[n]:
            took = swept[removable[swept] & ~removed[swept]]
            gave = np.zeros(0, dtype=np.int64)
        else:
            took = np.zeros(0, dtype=np.int64)
            gave = swept[removed[swept]]
        region_totals = region_totals + apply(took, gave) * voxel
        stroke_took.append(took)
        stroke_gave.append(gave)
        removed_voxels[n] = len(took) - len(gave)
        series[n] = region_totals
        if n + 1 == len(positions) or first[n + 1]:
            done.append((np.concatenate(stroke_took), np.concatenate(stroke_gave)))
            undone.clear()
    for kind in edits[-1]:
        edit(kind)
    if edits[-1]:
        series[-1] = region_totals
    result = Replay(positions, times, intervals, radii, large, stroke_of, first, cutting, removed_voxels, hidden, series,
                    removed.reshape(crop.labels.shape), undo=counts["undo"], redo=counts["redo"])
    forces = [np.asarray(stroke["forces"], dtype=float) if "forces" in stroke else np.full(len(stroke["positions"]), np.nan)
              for stroke in recording["strokes"]]
    result.forces = np.concatenate(forces) if any("forces" in stroke for stroke in recording["strokes"]) else None
    result.recomputed = {structure: structure_distances(scan, structure, positions) - radii for structure in scan.protected}
    result.monitored = monitor_distances(recording, scan.protected, radii)
    result.distances = {structure: np.where(np.isfinite(result.monitored[structure]), result.monitored[structure], recomputed)
                        if structure in result.monitored else recomputed for structure, recomputed in result.recomputed.items()}
    return result


def _name_key(name: str) -> str:
    return " ".join(str(name).replace("_", " ").lower().split())


def monitor_distances(recording: dict, structures, radii) -> dict:
    """Per structure, the nerve monitor's recorded distance at each pose (mm; NaN where it gave none in range).

    Readings are held from the pose they were kept at to the next one of the
    same structure in the stroke; structures match by name (case, '_' and
    spaces aside). The monitor stores a structure's field only within its
    range of the surface, so a burr of radius r reads exactly below range - r
    (``radii``: per pose); readings from there on are lower bounds (a plateau
    at range - r) and count as none.
    """
    header = recording.get("monitor")
    if not header:
        return {}
    total = sum(len(stroke["positions"]) for stroke in recording["strokes"])
    result = {structure: np.full(total, np.nan) for structure in structures}
    by_key = {_name_key(structure): structure for structure in structures}
    columns = [by_key.get(_name_key(name)) for name in header["structures"]]
    limits = float(header.get("range_mm", np.inf)) - np.asarray(radii, dtype=float) - MONITOR_RANGE_MARGIN_MM
    offset = 0
    for stroke in recording["strokes"]:
        count = len(stroke["positions"])
        readings = sorted(stroke.get("monitor", []), key=lambda reading: reading[0])
        for index, structure in enumerate(columns):
            if structure is None:
                continue
            mine = [reading for reading in readings if reading[1] == index]
            for n, (pose, _, distance, _level) in enumerate(mine):
                stop = mine[n + 1][0] if n + 1 < len(mine) else count
                span = slice(offset + pose, offset + stop)
                held = np.full(stop - pose, np.nan if distance is None else float(distance))
                result[structure][span] = np.where(held < limits[span], held, np.nan)
        offset += count
    return result


def structure_distances(scan: scanlib.Scan, structure: str, points: np.ndarray) -> np.ndarray:
    """Distance (mm) from each point to the structure's surface, negative inside (see the module docstring)."""
    surface = scan.surface_points(structure)
    if len(surface) == 0:
        return np.full(len(points), np.inf)
    best = np.full(len(points), np.inf)
    for start in range(0, len(points), 256):
        chunk = points[start:start + 256]
        # Only surface points that can be nearest: within the chunk's box grown by an upper bound of the distance.
        low, high = chunk.min(axis=0), chunk.max(axis=0)
        bound = float(np.linalg.norm(surface[:: max(len(surface) // 64, 1)][:, None, :] - chunk[None, :, :], axis=2).min(axis=0).max())
        near = surface[np.all((surface >= low - bound) & (surface <= high + bound), axis=1)]
        squared = ((chunk[:, None, :] - near[None, :, :]) ** 2).sum(axis=2)
        best[start:start + 256] = np.sqrt(squared.min(axis=1))
    distance = best - 0.5 * float(scan.spacing.mean())
    ijk = np.rint(scan.ras_to_ijk(points)).astype(int)
    inside_grid = np.all((ijk >= 0) & (ijk < np.array(scan.dimensions)), axis=1)
    inside = np.zeros(len(points), dtype=bool)
    inside[inside_grid] = scan.labels[ijk[inside_grid, 2], ijk[inside_grid, 1], ijk[inside_grid, 0]] == scan.label(structure)
    distance[inside] = -best[inside] - 0.5 * float(scan.spacing.mean())
    return distance


def prepare(recording: dict, path: str = "recording") -> dict:
    """A recording ready to grade: checked, and timed at the stated nominal speed when it is a version 1 recording."""
    recordings.check(recording, path, require_checksum=False)
    if recording.get("version", 1) >= 2:
        return recording
    if "tools" not in recording:
        raise AssessmentError(f"{path}: a version 1 recording does not say what its tools are: give them (burr type and radius per key)")
    return recordings.timed(recording, recording["tools"], UNTIMED_SPEED_MM_S, UNTIMED_PAUSE_S,
                            scan=recording.get("scan"), started=recording.get("started"))


@dataclass
class Assessment:
    """The graded session: ``to_dict`` is the JSON of every metric; the replays feed the report's plots."""

    session: dict
    score: float
    metrics: dict
    reference: dict | None
    regions: list
    trainee: Replay
    reference_replay: Replay | None
    crop: Crop
    parts: dict
    camera_direction: np.ndarray | None = None  # the first recorded frame's view direction, for the report's pictures
    reference_camera_direction: np.ndarray | None = None

    def to_dict(self) -> dict:
        return {"format": FORMAT, "version": VERSION, "session": self.session, "score": self.score,
                "metrics": self.metrics, "reference": self.reference}


def _session_info(recording: dict, path, scan: scanlib.Scan, replayed: Replay) -> dict:
    started = recording.get("started")
    if not started and path is not None and Path(path).exists():
        started = datetime.datetime.fromtimestamp(Path(path).stat().st_mtime, datetime.timezone.utc).isoformat(timespec="seconds")
    return {"scan": scan.name, "recording": str(path) if path is not None else "", "sha256": recordings.content_sha256(recording),
            "started": started, "duration_s": round(float(replayed.times[-1] - replayed.times[0]), 6),
            "trainee": recording.get("trainee")}


def _safety(scan, replayed: Replay, recording: dict, metrics: dict) -> float:
    intervals = replayed.intervals
    drilling = replayed.cutting
    total_contacts, overall_min, near_time = 0, np.inf, 0.0
    for structure, distance in replayed.distances.items():
        touching = (distance < 0.0) & drilling
        entered = touching & (replayed.first_of_stroke | ~np.roll(touching, 1))
        contacts = int(entered.sum())
        total_contacts += contacts
        minimum = float(distance[drilling].min()) if drilling.any() else float("inf")
        overall_min = min(overall_min, minimum)
        metrics[f"safety.contacts.{structure}"] = contacts
        if structure in replayed.monitored:
            monitored = np.isfinite(replayed.monitored[structure]) & drilling
            # How the recorded readings agree with the distances recomputed from the poses.
            metrics[f"safety.monitor_poses.{structure}"] = int(monitored.sum())
            difference = replayed.monitored[structure][monitored] - replayed.recomputed[structure][monitored]
            metrics[f"safety.monitor_minus_poses_max_abs_mm.{structure}"] = float(np.abs(difference).max()) if len(difference) else 0.0
            metrics[f"safety.monitor_minus_poses_mean_mm.{structure}"] = float(difference.mean()) if len(difference) else 0.0
        metrics[f"safety.contact_time_s.{structure}"] = float(intervals[touching].sum())
        metrics[f"safety.min_distance_mm.{structure}"] = minimum
        for near in NEAR_MM:
            metrics[f"safety.time_within_{near:g}mm_s.{structure}"] = float(intervals[(distance < near) & drilling].sum())
        near_time += metrics[f"safety.time_within_1mm_s.{structure}"]
        if replayed.forces is not None:
            for near in NEAR_MM:
                pressed = replayed.forces[(distance < near) & drilling & np.isfinite(replayed.forces)]
                metrics[f"safety.max_force_within_{near:g}mm_n.{structure}"] = float(pressed.max()) if len(pressed) else 0.0
    nearest = np.min(np.stack(list(replayed.distances.values())), axis=0) if replayed.distances else np.full(len(intervals), np.inf)
    large_near = replayed.large & drilling & (nearest < NEAR_MM[1])
    metrics["safety.contacts"] = total_contacts
    metrics["safety.min_distance_mm"] = float(overall_min)
    metrics["safety.large_burr_within_2mm_s"] = float(intervals[large_near].sum())
    metrics["safety.large_burr_within_2mm_poses"] = int(large_near.sum())
    logged = {}
    for event in recording.get("events", []):
        if event["type"] == "contact":
            logged[event.get("segment", "?")] = logged.get(event.get("segment", "?"), 0) + 1
    for segment, count in logged.items():
        metrics[f"safety.logged_contacts.{segment}"] = count
    terms = [1.0 / (1.0 + total_contacts),
             float(np.clip(overall_min / SAFE_DISTANCE_MM, 0.0, 1.0)) if np.isfinite(overall_min) else 1.0,
             float(np.exp(-near_time / NEAR_TIME_SCALE_S)),
             float(np.exp(-metrics["safety.large_burr_within_2mm_s"] / LARGE_BURR_TIME_SCALE_S))]
    return float(np.mean(terms))


def _efficiency(scan, replayed: Replay, recording: dict, metrics: dict, reference: Replay | None) -> float | None:
    duration = float(replayed.times[-1] - replayed.times[0])
    steps = np.linalg.norm(np.diff(replayed.positions, axis=0), axis=1)
    path_length = float(steps[~replayed.first_of_stroke[1:]].sum())
    drilling_time = float(replayed.intervals.sum())
    removed = float(replayed.removed_voxels.sum()) * scan.voxel_volume_mm3
    removing_time = float(replayed.intervals[replayed.removed_voxels > 0].sum())
    metrics["efficiency.duration_s"] = duration
    metrics["efficiency.strokes"] = int(replayed.first_of_stroke.sum())
    metrics["efficiency.path_length_mm"] = path_length
    metrics["efficiency.drilling_time_s"] = drilling_time
    metrics["efficiency.removed_mm3"] = removed
    metrics["efficiency.removal_rate_mm3_s"] = removed / drilling_time if drilling_time > 0.0 else 0.0
    metrics["efficiency.idle_time_s"] = duration - drilling_time
    metrics["efficiency.time_removing_nothing_s"] = duration - removing_time
    metrics["efficiency.undo"] = replayed.undo
    metrics["efficiency.redo"] = replayed.redo
    if reference is None:
        return None  # efficiency is relative: without an expert's session it is reported, not scored
    reference_duration = float(reference.times[-1] - reference.times[0])
    reference_path = float(np.linalg.norm(np.diff(reference.positions, axis=0), axis=1)[~reference.first_of_stroke[1:]].sum())
    return float(np.mean([min(1.0, reference_duration / duration) if duration > 0.0 else 1.0,
                          min(1.0, reference_path / path_length) if path_length > 0.0 else 1.0]))


def _visibility(scan, replayed: Replay, metrics: dict) -> float | None:
    if replayed.hidden is None:
        return None
    cut = replayed.removed_voxels * (replayed.removed_voxels > 0)
    hidden_volume = float(cut[replayed.hidden].sum()) * scan.voxel_volume_mm3
    total = float(cut.sum()) * scan.voxel_volume_mm3
    metrics["visibility.hidden_removed_mm3"] = hidden_volume
    metrics["visibility.hidden_removed_fraction"] = hidden_volume / total if total > 0.0 else 0.0
    metrics["visibility.hidden_time_s"] = float(replayed.intervals[replayed.hidden].sum())
    return 1.0 - metrics["visibility.hidden_removed_fraction"]


def _final_product(crop: Crop, replayed: Replay, reference: Replay | None, metrics: dict) -> float | None:
    voxel = crop.scan.voxel_volume_mm3
    trainee = replayed.final_removed.ravel()
    metrics["final.removed_mm3"] = float(trainee.sum()) * voxel
    for index, region in enumerate(crop.regions):
        metrics[f"final.removed_mm3.{region}"] = float(replayed.region_series[-1, index])
    if reference is None:
        return None
    expert = reference.final_removed.ravel()
    both = trainee & expert
    metrics["final.reference_removed_mm3"] = float(expert.sum()) * voxel
    metrics["final.dice"] = 2.0 * float(both.sum()) / float(trainee.sum() + expert.sum()) if (trainee.sum() + expert.sum()) else 1.0
    metrics["final.over_mm3"] = float((trainee & ~expert).sum()) * voxel
    metrics["final.under_mm3"] = float((expert & ~trainee).sum()) * voxel
    for index, region in enumerate(crop.regions):
        inside = crop.membership[:, index]
        a, b = trainee & inside, expert & inside
        metrics[f"final.reference_removed_mm3.{region}"] = float(b.sum()) * voxel
        metrics[f"final.over_mm3.{region}"] = float((a & ~b).sum()) * voxel
        metrics[f"final.under_mm3.{region}"] = float((b & ~a).sum()) * voxel
        metrics[f"final.dice.{region}"] = 2.0 * float((a & b).sum()) / float(a.sum() + b.sum()) if (a.sum() + b.sum()) else 1.0
    return metrics["final.dice"]


def _view_direction(recording: dict | None):
    frames = (recording or {}).get("camera", {}).get("frames", [])
    return np.asarray(frames[0][4:7], dtype=float) - np.asarray(frames[0][1:4], dtype=float) if frames else None


def assess(recording: dict, scan: scanlib.Scan | None = None, reference: dict | None = None,
           recording_path=None, reference_path=None) -> Assessment:
    """Grade ``recording`` (optionally against ``reference``, a recording on the same scan); see the module docstring.

    ``scan`` defaults to the one the recording names; a recording or
    reference made on another scan raises ``scans.ScanError`` with both grids.
    """
    name = str(recording_path) if recording_path is not None else "the recording"
    recording = prepare(recording, name)
    if scan is None:
        scan = scanlib.from_descriptor(recording.get("scan"))
    scanlib.check_fits(scan, recording.get("scan"), name)
    if reference is not None:
        reference_name = str(reference_path) if reference_path is not None else "the reference"
        reference = prepare(reference, reference_name)
        if reference.get("scan") is None and recording.get("scan") is not None:
            raise scanlib.ScanError(f"{reference_name} does not name its scan; the session was made on '{scan.name}'")
        scanlib.check_fits(scan, reference.get("scan"), reference_name)
    missing = [s for s in scan.cuttable + scan.protected if s not in scan.segment_names]
    if missing:
        raise AssessmentError(f"scan '{scan.name}' lacks the segments {', '.join(missing)}")
    every = [np.asarray(p, dtype=float) for r in [recording] + ([reference] if reference else []) for s in r["strokes"] for p in s["positions"]]
    radius = max(recordings.tool_of(r, s["tool"])["radius_mm"] for r in [recording] + ([reference] if reference else []) for s in r["strokes"])
    crop = Crop(scan, np.array(every), radius)
    trainee = replay(recording, crop)
    expert = replay(reference, crop) if reference is not None else None
    metrics = {}
    parts = {"safety": _safety(scan, trainee, recording, metrics),
             "final_product": _final_product(crop, trainee, expert, metrics),
             "visibility": _visibility(scan, trainee, metrics),
             "efficiency": _efficiency(scan, trainee, recording, metrics, expert)}
    available = {part: value for part, value in parts.items() if value is not None}
    weight = sum(SCORE_WEIGHTS[part] for part in available)
    score = 100.0 * sum(SCORE_WEIGHTS[part] * value for part, value in available.items()) / weight
    for part, value in available.items():
        metrics[f"score.{part}"] = 100.0 * value
    metrics = {key: (round(float(value), 6) if isinstance(value, float) and np.isfinite(value) else value)
               for key, value in sorted(metrics.items())}
    for key, value in metrics.items():
        if isinstance(value, float) and not np.isfinite(value):
            metrics[key] = None  # no such structure near: JSON has no infinity
    reference_info = None
    if reference is not None:
        reference_info = {"recording": str(reference_path) if reference_path is not None else "",
                          "sha256": recordings.content_sha256(reference), "started": reference.get("started"),
                          "duration_s": round(float(expert.times[-1] - expert.times[0]), 6)}
    return Assessment(_session_info(recording, recording_path, scan, trainee), round(score, 3), metrics, reference_info,
                      list(crop.regions), trainee, expert, crop, parts, _view_direction(recording), _view_direction(reference))
