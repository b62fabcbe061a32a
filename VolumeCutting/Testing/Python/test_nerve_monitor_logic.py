"""The module logic's nerve monitor: protected segments by default, readings at every pose, events and table.

The block of ``test_haptic_session`` holds a nerve canal (protected) deep in
bone; a 4 mm burr (radius 2 mm) moves along the canal's axis towards its
blunt end, whose smoothed surface lies halfway between the last voxel inside
(x = 3.0 mm) and the first outside (3.5 mm): the distance from the burr's
surface is 3.25 - x - 2 mm for a burr centred at x on the axis.
"""

from __future__ import annotations

import numpy as np
import slicer
import vtk

from test_haptic_session import add_burr, block_scene
from VolumeCuttingLib.feedback import drillsound, nervemonitor

NERVE_END_X = 3.25
BURR_RADIUS = 2.0


def pose(x):
    matrix = vtk.vtkMatrix4x4()
    matrix.SetElement(0, 3, float(x))
    return matrix


def test_the_logic_monitors_the_protected_nerve_as_the_tool_moves():
    application, logic, cut = block_scene()
    add_burr(application.scene, cut)
    assert list(logic.GetMonitoredSegmentIDs(cut)) == ["Nerve"]
    monitor = nervemonitor.monitor_for(logic, cut)
    assert monitor is not None and monitor.IsBuilt()
    assert monitor.GetStructureName(0) == "Nerve"
    changes = {"n": 0}
    logic.AddObserver(slicer.vtkSlicerVolumeCuttingLogic.NerveMonitorLevelChangedEvent,
                      lambda caller, event: changes.__setitem__("n", changes["n"] + 1))
    levels = []
    distances = []
    sounds = []
    for x in np.arange(-6.0, 1.6, 0.25):
        assert logic.MoveActiveTool(cut, pose(x), slicer.vtkSlicerVolumeCuttingLogic.ToolMove)
        reading = nervemonitor.readings(monitor)["Nerve"]
        # What the drill sound mixes in: a level it knows, the rate the monitor fires at.
        sound_level, sound_rate = nervemonitor.sound_input(monitor)
        assert sound_level in drillsound.MONITOR_LEVELS and sound_rate == reading["firing_rate_hz"]
        assert nervemonitor.nearest_mm(monitor) == reading["distance_mm"]  # the only structure is the nearest
        sounds.append(sound_level)
        expected = NERVE_END_X - x - BURR_RADIUS
        assert abs(reading["distance_mm"] - expected) < 0.1, (x, reading)
        distances.append(reading["distance_mm"])
        levels.append(reading["level"])
    assert np.all(np.diff(distances) < 0)
    assert levels[0] == "silent" and levels[-1] == "contact"
    assert [level for n, level in enumerate(sounds) if n == 0 or level != sounds[n - 1]] == list(drillsound.MONITOR_LEVELS)
    assert nervemonitor.sound_input(None) == ("silent", 0.0)
    assert nervemonitor.nearest_mm(None) == float("inf")
    assert [level for n, level in enumerate(levels) if n == 0 or level != levels[n - 1]] == list(nervemonitor.LEVEL_NAMES)
    # One event per change of level (the first reading, from "not ready", included).
    assert changes["n"] == len(nervemonitor.LEVEL_NAMES)
    rows = nervemonitor.table_rows(logic.GetNerveMonitorTableNode(cut))
    assert rows and {row["name"] for row in rows} == {"Nerve"}
    assert {row["level"] for row in rows} == set(nervemonitor.LEVEL_NAMES)
    assert all(b["time_s"] >= a["time_s"] for a, b in zip(rows, rows[1:]))
    loudest = nervemonitor.loudest(nervemonitor.readings(monitor))
    assert loudest[0] == "Nerve" and loudest[1]["level"] == "contact"


def test_the_user_picks_the_monitored_segments_and_bad_thresholds_are_refused():
    application, logic, cut = block_scene()
    add_burr(application.scene, cut)
    monitor = nervemonitor.monitor_for(logic, cut, ["Bone", "Nerve"])
    assert [monitor.GetStructureName(n) for n in range(monitor.GetNumberOfStructures())] == ["Bone", "Nerve"]
    try:
        nervemonitor.set_thresholds(monitor, 2.0, 4.0, 1.0)
    except ValueError as error:
        assert "out of order" in str(error)
    else:
        raise AssertionError("thresholds out of order were accepted")
    assert nervemonitor.thresholds(monitor) == {"silent_above_mm": 4.0, "sparse_clicks_above_mm": 2.0, "bursts_above_mm": 1.0}
    # Back to the protected segments.
    monitor = nervemonitor.monitor_for(logic, cut, [])
    assert monitor.GetNumberOfStructures() == 1 and monitor.GetStructureName(0) == "Nerve"
    logic.SetNerveMonitoring(False)
    assert logic.GetNerveMonitor(cut) is None


def test_a_recording_summarises_and_plots(tmp_path):
    recording = nervemonitor.MonitorRecording({"silent_above_mm": 4.0, "sparse_clicks_above_mm": 2.0, "bursts_above_mm": 1.0})
    for n, distance in enumerate([5.0, 3.0, 1.5, 0.5, -0.1, 0.5]):
        level = ("silent" if distance > 4 else "sparse clicks" if distance > 2 else "bursts" if distance > 1
                 else "continuous" if distance > 0 else "contact")
        recording.add(0.1 * n, {"Nerve": {"distance_mm": distance, "level": level, "firing_rate_hz": 0.0}})
    summary = recording.summary()["structures"]["Nerve"]
    assert summary["nearest_mm"] == -0.1 and summary["highest_level"] == "contact" and summary["level_changes"] == 5
    path = recording.plot(tmp_path / "nerve_monitor.png")
    assert path.is_file() and path.stat().st_size > 10000
