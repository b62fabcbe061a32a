"""The virtual nerve monitor (seed 003) as plain Python data, without Qt.

The desktop widget and the web application show the same readings: per
monitored structure (by name) the distance (mm) from the tool's surface to
the structure's smoothed surface, the level (silent, sparse clicks, bursts,
continuous, contact) and the firing rate (spikes/s) that rises with
proximity. The readings come from ``vtkVolumeCutNerveMonitor``, which the
module logic updates at every pose of the mouse and at every haptic tick
(``vtkSlicerVolumeCuttingLogic.GetNerveMonitor``).

:class:`MonitorRecording` keeps readings over time, summarises them and
plots distance per structure against time over the threshold bands
(``nerve_monitor.png`` of the main job).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import slicer

LEVEL_NAMES = ("silent", "sparse clicks", "bursts", "continuous", "contact")
NOT_READY = "not ready"
# Band colours from calm to alarm, as a monitor's display would show them.
LEVEL_COLOURS = {
    "silent": "#e8f0e8",
    "sparse clicks": "#fff4c2",
    "bursts": "#ffd59a",
    "continuous": "#ffab91",
    "contact": "#ef5350",
}
NOT_READY_COLOUR = "#9e9e9e"


def level_name(level: int) -> str:
    """The name of a ``vtkVolumeCutNerveMonitor`` level (``"not ready"`` for -1)."""
    return slicer.vtkVolumeCutNerveMonitor.GetLevelAsString(int(level))


def thresholds(monitor) -> dict:
    """The monitor's thresholds (mm) between the levels."""
    return {
        "silent_above_mm": monitor.GetSilentThreshold(),
        "sparse_clicks_above_mm": monitor.GetSparseThreshold(),
        "bursts_above_mm": monitor.GetBurstThreshold(),
    }


def set_thresholds(monitor, silent: float, sparse: float, bursts: float) -> None:
    """Set the thresholds (mm); ``ValueError`` naming them when out of order (the monitor keeps its own)."""
    if not monitor.SetThresholds(float(silent), float(sparse), float(bursts)):
        raise ValueError(f"nerve monitor thresholds out of order: silent {silent} mm, sparse clicks {sparse} mm, "
                         f"bursts {bursts} mm (they must decrease and stay above 0)")


def readings(monitor) -> dict:
    """The monitor's current readings: ``{structure name: {distance_mm, clearance_mm, level, firing_rate_hz}}``.

    ``distance_mm`` is the distance to the structure's smoothed surface while
    the tool is clear of what the shield keeps, the clearance (0 or less,
    level ``"contact"``) once it touches it; ``clearance_mm`` the distance to
    what the shield keeps (the smoothed interior and the voxel cubes). Both
    are ``None`` while the structure's field is being built (level ``"not ready"``).
    """
    result = {}
    for index in range(monitor.GetNumberOfStructures()):
        distance = monitor.GetDistance(index)
        clearance = monitor.GetClearance(index)
        result[monitor.GetStructureName(index)] = {
            "distance_mm": None if math.isnan(distance) else round(float(distance), 4),
            "clearance_mm": None if math.isnan(clearance) else round(float(clearance), 4),
            "level": level_name(monitor.GetLevel(index)),
            "firing_rate_hz": round(float(monitor.GetFiringRate(index)), 2),
        }
    return result


def loudest(current: dict) -> tuple[str, dict] | None:
    """The structure with the highest level (the nearest among equals), or None if none is ready."""
    ready = [(name, reading) for name, reading in current.items() if reading["distance_mm"] is not None]
    if not ready:
        return None
    return max(ready, key=lambda item: (LEVEL_NAMES.index(item[1]["level"]), -item[1]["distance_mm"]))


# The drill sound's names for the monitor's levels (``drillsound.MONITOR_LEVELS``).
SOUND_LEVELS = {"silent": "silent", "sparse clicks": "sparse", "bursts": "bursts", "continuous": "continuous",
                "contact": "contact"}


def sound_input(monitor) -> tuple[str, float]:
    """What the drill sound mixes in: the loudest structure's level and firing rate (silent until one is ready)."""
    top = loudest(readings(monitor)) if monitor is not None else None
    if top is None:
        return "silent", 0.0
    reading = top[1]
    return SOUND_LEVELS[reading["level"]], float(reading["firing_rate_hz"])


def nearest_mm(monitor) -> float:
    """The smallest distance (mm) from the tool's surface to a monitored structure; inf while none is ready."""
    distances = [r["distance_mm"] for r in readings(monitor).values() if r["distance_mm"] is not None] if monitor else []
    return min(distances, default=math.inf)


# The meter the web application and the desktop widget show: a row per structure.
FULL_SCALE_MM = 8.0  # the meter's bar spans 0-8 mm (the monitor is silent beyond its thresholds)
DISTANCE_STEP_MM = 0.05  # a smaller change of distance is not sent to the page


def meter_rows(current: dict) -> list[dict]:
    """The meter's rows from :func:`readings`: name, mm (None: not ready), bar (0-1), level, colour."""
    rows = []
    for name, reading in current.items():
        level = reading["level"]
        distance = None if level == NOT_READY else reading["distance_mm"]
        rows.append({
            "name": name,
            "mm": None if distance is None else round(float(distance), 2),
            "bar": 0.0 if distance is None else round(min(max(float(distance), 0.0), FULL_SCALE_MM) / FULL_SCALE_MM, 3),
            "level": level,
            "colour": LEVEL_COLOURS.get(level, NOT_READY_COLOUR),
        })
    return rows


def rows_differ(shown: list[dict], rows: list[dict], step_mm: float = DISTANCE_STEP_MM) -> bool:
    """Whether ``rows`` must be sent: another structure, level or readiness, or a distance moved by > ``step_mm``."""
    if len(shown) != len(rows):
        return True
    for old, new in zip(shown, rows):
        if old["name"] != new["name"] or old["level"] != new["level"] or (old["mm"] is None) != (new["mm"] is None):
            return True
        if new["mm"] is not None and abs(new["mm"] - old["mm"]) > step_mm:
            return True
    return False



def monitor_for(logic, cut_node, segment_ids=None, wait: bool = True):
    """The cut node's monitor from the module logic, watching ``segment_ids`` (None: the protected segments).

    ``wait`` waits for the distance fields (built on a worker); else the
    readings say ``"not ready"`` until they are. None when nothing is monitored.
    """
    if segment_ids is not None:
        logic.SetMonitoredSegmentIDs(cut_node, [str(segment_id) for segment_id in segment_ids])
    monitor = logic.GetNerveMonitor(cut_node)
    if monitor is not None and wait:
        logic.WaitForNerveMonitor(cut_node)
    return monitor


def table_rows(table_node) -> list:
    """The rows of the logic's nerve-monitor table as dicts (time_s, segment, name, distance_mm, level)."""
    table = table_node.GetTable()
    rows = []
    for row in range(table.GetNumberOfRows()):
        rows.append({
            "time_s": float(table.GetValue(row, 0).ToString()),
            "segment": table.GetValue(row, 1).ToString(),
            "name": table.GetValue(row, 2).ToString(),
            "distance_mm": float(table.GetValue(row, 3).ToString()),
            "level": table.GetValue(row, 4).ToString(),
        })
    return rows


def recording_along(monitor, centres, radius: float, period_s: float) -> "MonitorRecording":
    """Readings for a burr of ``radius`` at each of ``centres`` (RAS, one per ``period_s``), as a recording."""
    import numpy as np
    from vtkmodules.util import numpy_support
    import vtk

    points = vtk.vtkPoints()
    points.SetData(numpy_support.numpy_to_vtk(np.ascontiguousarray(centres, dtype=float).reshape(-1, 3), deep=1))
    distances = vtk.vtkDoubleArray()
    monitor.MeasureAlong(points, float(radius), distances, None)
    values = numpy_support.vtk_to_numpy(distances).reshape(len(centres), -1)
    names = [monitor.GetStructureName(index) for index in range(monitor.GetNumberOfStructures())]
    recording = MonitorRecording(thresholds(monitor))
    for tick, row in enumerate(values):
        recording.add(tick * period_s, {name: {
            "distance_mm": None if math.isnan(row[index]) else float(row[index]),
            "level": level_name(monitor.GetLevelOfDistance(float(row[index]))),
            "firing_rate_hz": float(monitor.GetFiringRateOfDistance(float(row[index]))),
        } for index, name in enumerate(names)})
    return recording


@dataclass
class MonitorRecording:
    """Readings of one monitor over time, for a summary and a plot."""

    thresholds_mm: dict = field(default_factory=dict)
    times_s: list = field(default_factory=list)
    distances_mm: dict = field(default_factory=dict)
    levels: dict = field(default_factory=dict)

    def add(self, time_s: float, current: dict) -> None:
        """Add the readings (as :func:`readings` gives them) taken at ``time_s``."""
        self.times_s.append(float(time_s))
        for name, reading in current.items():
            distances = self.distances_mm.setdefault(name, [math.nan] * (len(self.times_s) - 1))
            levels = self.levels.setdefault(name, [NOT_READY] * (len(self.times_s) - 1))
            distance = reading["distance_mm"]
            distances.append(math.nan if distance is None else float(distance))
            levels.append(reading["level"])
        for name in self.distances_mm:
            if len(self.distances_mm[name]) < len(self.times_s):
                self.distances_mm[name].append(math.nan)
                self.levels[name].append(NOT_READY)

    def summary(self) -> dict:
        """Per structure: the nearest distance, its time, the highest level, the time spent in each level."""
        result = {}
        durations = [b - a for a, b in zip(self.times_s, self.times_s[1:])] + [0.0]
        for name, distances in self.distances_mm.items():
            ready = [(d, t) for d, t in zip(distances, self.times_s) if not math.isnan(d)]
            levels = self.levels[name]
            time_in = {}
            for level, duration in zip(levels, durations):
                time_in[level] = time_in.get(level, 0.0) + duration
            highest = max((LEVEL_NAMES.index(level) for level in levels if level in LEVEL_NAMES), default=None)
            nearest = min(ready) if ready else None
            result[name] = {
                "nearest_mm": None if nearest is None else round(nearest[0], 3),
                "nearest_at_s": None if nearest is None else round(nearest[1], 3),
                "highest_level": NOT_READY if highest is None else LEVEL_NAMES[highest],
                "seconds_per_level": {level: round(seconds, 3) for level, seconds in time_in.items()},
                "level_changes": sum(1 for a, b in zip(levels, levels[1:]) if a != b),
            }
        return {"thresholds_mm": dict(self.thresholds_mm), "samples": len(self.times_s), "structures": result}

    def plot(self, path, title: str = "Virtual nerve monitor", shown: int = 6, exact_below_mm: float | None = None) -> Path:
        """Write a PNG: distance per structure over time over the threshold bands (the ``shown`` nearest structures).

        ``exact_below_mm``: the distance beyond which readings are lower bounds
        (the monitor's range less the burr's radius), drawn as a dashed line.
        """
        import matplotlib
        matplotlib.use("Agg")
        from matplotlib import pyplot

        path = Path(path)
        silent = self.thresholds_mm.get("silent_above_mm", 4.0)
        sparse = self.thresholds_mm.get("sparse_clicks_above_mm", 2.0)
        bursts = self.thresholds_mm.get("bursts_above_mm", 1.0)
        nearest = sorted(self.distances_mm, key=lambda name: min((d for d in self.distances_mm[name] if not math.isnan(d)),
                                                                  default=math.inf))[:shown]
        # Up to the farthest reading shown (within 15 mm): far structures stay in view too.
        farthest = max((d for name in nearest for d in self.distances_mm[name] if not math.isnan(d)), default=0.0)
        top = max(silent + 2.0, min(farthest, 15.0) + 0.5)
        figure, axes = pyplot.subplots(figsize=(10.5, 4.8), dpi=110)
        bands = [("contact", -1.0, 0.0), ("continuous", 0.0, bursts), ("bursts", bursts, sparse),
                 ("sparse clicks", sparse, silent), ("silent", silent, top)]
        for level, low, high in bands:
            axes.axhspan(low, high, color=LEVEL_COLOURS[level], zorder=0)
            axes.text(1.005, (max(low, -0.5) + min(high, top)) / 2, level, transform=axes.get_yaxis_transform(),
                      va="center", fontsize=8, color="#444444")
        for name in nearest:
            axes.plot(self.times_s, [min(d, top) for d in self.distances_mm[name]], label=name, linewidth=1.6)
        if exact_below_mm is not None and exact_below_mm < top:
            axes.axhline(exact_below_mm, color="#555555", linestyle="--", linewidth=0.8)
            axes.text(0.005, exact_below_mm + 0.1, "beyond the monitor's range: lower bounds", fontsize=7, color="#555555",
                      transform=axes.get_yaxis_transform())
        axes.set_ylim(-0.5, top)
        if len(self.times_s) > 1:
            axes.set_xlim(self.times_s[0], self.times_s[-1])
        axes.set_xlabel("time (s)")
        axes.set_ylabel("distance from the burr's surface (mm)")
        axes.set_title(title)
        # Beside the plot, where it hides no reading.
        axes.legend(loc="upper left", bbox_to_anchor=(1.12, 1.0), fontsize=8, frameon=False)
        figure.tight_layout()
        figure.savefig(path)
        pyplot.close(figure)
        return path
