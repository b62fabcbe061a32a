"""A recorded session (version 2) replays through the product's logic to the same cut, bit for bit.

A session on a small phantom is drilled through ``recording.replay`` with a
``SessionRecorder`` listening (strokes with their times, undo and redo
between strokes, contacts, removed volume per segment after each stroke),
saved, read back, checked, and replayed in a fresh scene: the removed
fraction of every voxel is identical. The label-image assessment of the same
recording agrees with the logic's removed volume.
"""

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
