"""A recorded session (version 2) replays through the product's logic to the same cut, bit for bit.

A session on a small phantom is drilled through ``recording.replay`` with a
``SessionRecorder`` listening (strokes with their times, undo and redo
between strokes, contacts, removed volume per segment after each stroke),
saved, read back, checked, and replayed in a fresh scene: the removed
fraction of every voxel is identical. The label-image assessment of the same
recording agrees with the logic's removed volume.
"""

import json

import numpy as np
import pytest

from VolumeCuttingLib.assessment import metrics, scans
from VolumeCuttingLib.config import toolconfig
from VolumeCuttingLib.cutting import drilling
from VolumeCuttingLib.cutting import recording as recordings
from VolumeCuttingLib.data import phantom
from VolumeCuttingLib.scene.application import HeadlessSlicer
from VolumeCuttingLib.scene.nodes import array_from_volume_node

DIMENSIONS, SPACING = (64, 64, 48), (0.5, 0.5, 0.5)


def drilling_scene():
    application = HeadlessSlicer()
    logic = application.volume_cutting_logic
    volume, segmentation = phantom.create_phantom_nodes(
        application.scene, phantom.generate_phantom(dimensions=DIMENSIONS, spacing=SPACING, seed=0))
    cut = logic.AddVolumeCutNode(volume, segmentation)
    ids = set(segmentation.GetSegmentation().GetSegmentIDs())
    cut.SetCuttableSegmentIDs([s for s in phantom.CUTTABLE_SEGMENTS if s in ids])
    cut.SetProtectedSegmentIDs([s for s in phantom.PROTECTED_SEGMENTS if s in ids])
    presets = {preset.name: preset for preset in toolconfig.load_presets()}
    tools = {key: toolconfig.create_tool_node(application.scene, toolconfig.from_preset(presets[name]), name)
             for key, name in (("cutting", "Cutting burr 4 mm"), ("diamond", "Diamond burr 3 mm"))}
    return application, logic, cut, tools


def test_a_recorded_session_replays_bit_for_bit_and_the_assessment_agrees(tmp_path):
    scan = scans.phantom_scan(DIMENSIONS, SPACING, 0)
    plan = drilling.MastoidectomyPlan(entry=scan.entry, surface_radius=4.0, depth=3.0, burr_radius=2.0, layer_step=1.5)
    tools = {"cutting": {"name": "Cutting burr 4 mm", "burr_type": "Cutting", "radius_mm": 2.0},
             "diamond": {"name": "Diamond burr 3 mm", "burr_type": "Diamond", "radius_mm": 1.5}}
    source = recordings.timed(recordings.record_mastoidectomy(plan, finishing_layers=1), tools, speed_mm_s=20.0,
                              pause_s=0.2, scan=scan.descriptor())
    # Take the third stroke back, put it back, and take the last one back after the session.
    third_end = source["strokes"][2]["times"][-1]
    source["events"] += [{"t": third_end + 0.05, "type": "undo"}, {"t": third_end + 0.1, "type": "redo"},
                         {"t": source["strokes"][-1]["times"][-1] + 0.1, "type": "undo"}]

    _, logic, cut, tool_nodes = drilling_scene()
    recorder = recordings.SessionRecorder(tools, scan=scan.descriptor(), trainee="replay test")
    recorder.camera([60.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 1.0], 30.0)
    replayed = recordings.replay(logic, cut, source, tool_nodes, recorder=recorder)
    assert replayed["refused_poses"] == 0
    first = array_from_volume_node(logic.ExportRemovedFractionToVolume(cut, None)).copy()
    removed_by_logic = logic.GetRemovedVolume(cut)
    assert removed_by_logic > 50.0

    path = recordings.save(recorder.recording, tmp_path / "session.json")
    loaded = recordings.load(path)
    assert loaded["version"] == recordings.VERSION and len(loaded["strokes"]) == len(source["strokes"])
    assert [e["type"] for e in loaded["events"] if e["type"] in ("undo", "redo")] == ["undo", "redo", "undo"]
    samples = np.array(loaded["removed"]["samples"])
    assert len(samples) == len(source["strokes"]) and np.all(np.diff(samples[:, 0]) >= 0.0)
    # The per-segment samples after each stroke add up to the logic's removed volume before the last undo.
    assert samples[-1, 1:].sum() >= removed_by_logic - 1e-6

    _, logic_again, cut_again, tool_nodes_again = drilling_scene()
    recordings.replay(logic_again, cut_again, loaded, tool_nodes_again)
    second = array_from_volume_node(logic_again.ExportRemovedFractionToVolume(cut_again, None))
    assert first.shape == second.shape and np.array_equal(first, second)
    assert logic_again.GetRemovedVolume(cut_again) == removed_by_logic

    # The edits matter: without them the same strokes leave another cut.
    unedited = dict(loaded, events=[e for e in loaded["events"] if e["type"] not in ("undo", "redo")])
    _, logic_third, cut_third, tool_nodes_third = drilling_scene()
    recordings.replay(logic_third, cut_third, unedited, tool_nodes_third)
    assert not np.array_equal(first, array_from_volume_node(logic_third.ExportRemovedFractionToVolume(cut_third, None)))

    # The assessment replays the same session on the labels: voxel counting against the logic's sub-voxel cut.
    graded = metrics.assess(loaded, scan)
    print(f"removed: logic {removed_by_logic:.2f} mm3, assessment {graded.metrics['final.removed_mm3']:.2f} mm3")
    assert graded.metrics["final.removed_mm3"] == pytest.approx(removed_by_logic, rel=0.05)
    assert graded.metrics["efficiency.undo"] == 2 and graded.metrics["efficiency.redo"] == 1


def test_the_nerve_monitor_is_recorded_with_the_poses_and_agrees_with_the_poses(tmp_path):
    """A stroke from the bone's surface toward the nearest protected structure, stopping 0.6 mm short of it.

    The logic's monitor reads at every pose; the recording keeps the readings
    that changed by more than ``MONITOR_STEP_MM`` (or changed level). The
    assessment grades with them, and they agree with the distances it
    recomputes from the poses within half a voxel and the step (the monitor
    measures to the smoothed surface the view draws, the recomputation to the
    voxel surface). Replaying the recording reproduces the cut bit for bit.
    """
    scan = scans.phantom_scan(DIMENSIONS, SPACING, 0)
    radius = 1.5
    nearest = {name: scan.surface_points(name)[np.argmin(np.linalg.norm(scan.surface_points(name) - scan.entry, axis=1))]
               for name in scan.protected}
    target_name = min(nearest, key=lambda name: np.linalg.norm(nearest[name] - scan.entry))
    target = nearest[target_name]
    direction = (target - scan.entry) / np.linalg.norm(target - scan.entry)
    stop = np.linalg.norm(target - scan.entry) - radius - 0.6
    positions = [scan.entry + direction * d for d in np.arange(-1.0, stop, 0.1)]
    tools = {"diamond": {"name": "Diamond burr 3 mm", "burr_type": "Diamond", "radius_mm": radius}}
    source = recordings.timed({"format": recordings.FORMAT, "version": 1, "strokes": [
        {"tool": "diamond", "action": "cut", "rotation": recordings.frame_along(direction).ravel().tolist(),
         "positions": [[round(float(v), 4) for v in p] for p in positions]}]}, tools, speed_mm_s=2.0, scan=scan.descriptor())

    _, logic, cut, tool_nodes = drilling_scene()
    recorder = recordings.SessionRecorder(tools, scan=scan.descriptor())
    recordings.replay(logic, cut, source, {"diamond": tool_nodes["diamond"]}, recorder=recorder)
    first = array_from_volume_node(logic.ExportRemovedFractionToVolume(cut, None)).copy()
    path = recordings.save(recorder.recording, tmp_path / "session.json")
    loaded = recordings.load(path)
    readings = loaded["strokes"][0]["monitor"]
    structures = loaded["monitor"]["structures"]
    assert sorted(structures) == sorted(scan.protected) and loaded["monitor"]["range_mm"] > 0.0
    kept = len(readings)
    every = len(positions) * len(structures)
    without = dict(loaded)
    without.pop("monitor")
    without["strokes"] = [{k: v for k, v in s.items() if k != "monitor"} for s in loaded["strokes"]]
    print(f"monitor readings kept: {kept} of {every}; file {path.stat().st_size} bytes, "
          f"{len(json.dumps(without, separators=(',', ':')))} without readings")
    assert 0 < kept < every

    graded = metrics.assess(loaded, scan)
    m = graded.metrics
    tolerance = 0.5 * max(SPACING) + recordings.MONITOR_STEP_MM
    assert m[f"safety.monitor_poses.{target_name}"] > len(positions) // 2
    assert m[f"safety.monitor_minus_poses_max_abs_mm.{target_name}"] <= tolerance
    recomputed = graded.trainee.recomputed[target_name]
    print(f"{target_name}: min distance monitor {m[f'safety.min_distance_mm.{target_name}']:.3f} mm, "
          f"recomputed {recomputed.min():.3f} mm; largest difference "
          f"{m[f'safety.monitor_minus_poses_max_abs_mm.{target_name}']:.3f} mm, "
          f"mean {m[f'safety.monitor_minus_poses_mean_mm.{target_name}']:.3f} mm")
    assert m[f"safety.min_distance_mm.{target_name}"] == pytest.approx(recomputed.min(), abs=tolerance)
    assert m[f"safety.min_distance_mm.{target_name}"] == pytest.approx(0.6, abs=tolerance)
    # Times within 1 and 2 mm: the poses whose two distances fall on either side of a threshold are within the tolerance of it.
    intervals = graded.trainee.intervals
    for near in metrics.NEAR_MM:
        by_poses = float(intervals[recomputed < near].sum())
        ambiguous = float(intervals[np.abs(recomputed - near) <= tolerance].sum())
        assert abs(m[f"safety.time_within_{near:g}mm_s.{target_name}"] - by_poses) <= ambiguous + 1e-9

    # The readings change nothing of the cut: replayed, it is the same bit for bit.
    _, logic_again, cut_again, tool_nodes_again = drilling_scene()
    recordings.replay(logic_again, cut_again, loaded, tool_nodes_again)
    assert np.array_equal(first, array_from_volume_node(logic_again.ExportRemovedFractionToVolume(cut_again, None)))
