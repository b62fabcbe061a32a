"""The assessment of recorded sessions (VolumeCuttingLib.assessment) and the complete recording format.

Every metric is checked against values computed by hand on an analytic
scene: a box of bone (2-18 x 2-18 x 2-12 mm) on a 0.5 mm grid with a
protected nerve, a cylinder of radius 1.1 mm along x at y = 10, z = 15 mm,
whose surface is therefore at z = 13.9 mm above the box. A spherical burr of
radius r swept along a segment of length L removes a capsule of
pi r^2 L + 4/3 pi r^3; voxels count by their centres, so volumes agree
within a few per cent and distances within half a voxel (0.25 mm).

Then a careful and a careless session on the phantom (seconds) and on the
head CT (realdata): every safety metric and the score separate them. Bad
input (corrupt, truncated, empty, another scan) is refused with a message
naming the file, and nothing is written.
"""

import json
import math
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from VolumeCuttingLib.assessment import __main__ as cli
from VolumeCuttingLib.assessment import metrics, report, scans, sessions
from VolumeCuttingLib.cutting import recording as recordings

NERVE_RADIUS = 1.1
NERVE_Z = 15.0
HALF_VOXEL = 0.25
CAMERA_ABOVE = [0.0, 5.0, 5.0, 60.0, 5.0, 5.0, 0.0, 0.0, 1.0, 0.0, 30.0]  # t, position, focal point, view up, angle


@pytest.fixture(scope="module")
def scene():
    return scans.analytic_scan(nerve_radius=NERVE_RADIUS)


def capsule(radius, length):
    return math.pi * radius ** 2 * length + 4.0 / 3.0 * math.pi * radius ** 3


def line(start, end, count):
    return [list(map(float, np.asarray(start) + (np.asarray(end) - start) * f)) for f in np.linspace(0.0, 1.0, count)]


def session(scene, strokes, tools=None, speed=4.0, pause=1.0, camera=(CAMERA_ABOVE,), events=()):
    """A complete recording on the analytic scene: strokes are (tool, positions[, action])."""
    tools = tools or {"burr": {"burr_type": "Diamond", "radius_mm": 1.5}}
    untimed = {"format": recordings.FORMAT, "version": 1, "frame": "RAS", "units": "mm", "strokes": [
        {"tool": s[0], "action": s[2] if len(s) > 2 else "cut", "rotation": [1.0, 0, 0, 0, 1.0, 0, 0, 0, 1.0], "positions": s[1]}
        for s in strokes]}
    timed = recordings.timed(untimed, tools, speed, pause, scan=scene.descriptor(), camera_frames=list(camera) or None,
                             started="2026-11-27T10:00:00+00:00", trainee="test")
    timed["events"] += [dict(e) for e in events]
    if not camera:
        timed.pop("camera", None)
    timed["sha256"] = recordings.content_sha256(timed)
    return timed


# ---------------------------------------------------------------------------
# Metrics against hand-computed values
# ---------------------------------------------------------------------------

def test_removed_volume_path_length_time_and_rate_of_one_stroke(scene):
    # r = 1.5 mm along 8 mm at z = 6.27, wholly inside the bone, at 4 mm/s (off the voxel centres' lattice,
    # where a radius of exactly 3 voxels would count the lattice points on its rim, 3 % more).
    graded = metrics.assess(session(scene, [("burr", line([5, 6.13, 6.27], [13, 6.13, 6.27], 17))]), scene)
    m = graded.metrics
    expected = capsule(1.5, 8.0)
    assert m["final.removed_mm3"] == pytest.approx(expected, rel=0.03)
    assert m["final.removed_mm3.Bone"] == pytest.approx(m["final.removed_mm3"])
    assert m["efficiency.path_length_mm"] == pytest.approx(8.0)
    assert m["efficiency.duration_s"] == pytest.approx(2.0)
    assert m["efficiency.drilling_time_s"] == pytest.approx(2.0)
    assert m["efficiency.strokes"] == 1
    assert m["efficiency.idle_time_s"] == pytest.approx(0.0)
    assert m["efficiency.removal_rate_mm3_s"] == pytest.approx(m["final.removed_mm3"] / 2.0)
    # The nerve's axis is hypot(10 - 6.13, 15 - 6.27) = 9.55 mm from the burr's: 9.55 - 1.1 - 1.5 = 6.95 mm between them.
    assert m["safety.min_distance_mm.Nerve"] == pytest.approx(math.hypot(10 - 6.13, 15 - 6.27) - NERVE_RADIUS - 1.5, abs=HALF_VOXEL)
    assert all(m[f"final.removed_mm3.{metrics.band_name('Nerve', band)}"] == 0.0 for band in metrics.BANDS_MM)
    assert m["safety.time_within_2mm_s.Nerve"] == 0.0 and m["safety.contacts"] == 0
    assert graded.to_dict()["format"] == "VolumeCuttingAssessment" and graded.to_dict()["session"]["duration_s"] == 2.0


def test_distances_and_times_near_the_nerve(scene):
    # A vertical stroke toward the nerve: burr (r = 1.5) centre at z, surface distance 13.9 - 1.5 - z.
    # Distances 4.4 3.4 2.4 1.7 1.3 0.6 mm: each clear of the 1 and 2 mm thresholds by more than the tolerance.
    heights = [8.0, 9.0, 10.0, 10.7, 11.1, 11.8]
    positions = [[10.0, 10.0, z] for z in heights]
    graded = metrics.assess(session(scene, [("burr", positions)], speed=1.0), scene)
    m = graded.metrics
    distances = [13.9 - 1.5 - z for z in heights]
    intervals = [0.0] + list(np.diff(heights))  # 1 mm/s: each interval is the step in mm
    assert graded.trainee.distances["Nerve"] == pytest.approx(distances, abs=HALF_VOXEL)
    assert m["safety.min_distance_mm.Nerve"] == pytest.approx(min(distances), abs=HALF_VOXEL)
    assert m["safety.time_within_2mm_s.Nerve"] == pytest.approx(sum(t for t, d in zip(intervals, distances) if d < 2.0))
    assert m["safety.time_within_1mm_s.Nerve"] == pytest.approx(sum(t for t, d in zip(intervals, distances) if d < 1.0))
    assert m["safety.contacts.Nerve"] == 0
    # Removed bone 1-2 mm from the nerve: the burr reaches z = 11.8 + 1.5 = 13.3 > 11.9 (the 2 mm band's floor).
    assert m[f"final.removed_mm3.{metrics.band_name('Nerve', (1.0, 2.0))}"] > 0.0
    # The bone ends at z = 12, 1.9 mm below the nerve: nothing in the 0-1 mm band exists to remove.
    assert m[f"final.removed_mm3.{metrics.band_name('Nerve', (0.0, 1.0))}"] == 0.0


def test_recorded_nerve_monitor_readings_are_used_where_present(scene):
    # The same approach as above (recomputed distances 4.4 3.4 2.4 1.7 1.3 0.6 mm), with monitor readings kept as a
    # recorder keeps them: at pose 0, then when they moved by more than the step. Said by hand: the monitor reads
    # 2.2 mm at pose 1 (held at pose 2), 0.9 mm from pose 3 on (held at pose 4), 0.4 mm at pose 5. Pose 0 reads 6.4 mm:
    # with an 8 mm range and a 1.5 mm burr, readings from 8 - 1.5 - 0.25 = 6.25 mm on are lower bounds, so pose 0
    # keeps its recomputed 4.4 mm. A structure of the monitor that the scan does not know is ignored.
    heights = [8.0, 9.0, 10.0, 10.7, 11.1, 11.8]
    recomputed = np.array([13.9 - 1.5 - z for z in heights])
    recording = session(scene, [("burr", [[10.0, 10.0, z] for z in heights])], speed=1.0)
    recording["monitor"] = recordings.monitor_header(None, ["nerve", "Elsewhere"])
    recording["monitor"]["range_mm"] = 8.0
    recording["strokes"][0]["monitor"] = [[0, 0, 6.4, 0], [0, 1, 3.0, 1], [1, 0, 2.2, 1], [3, 0, 0.9, 3], [5, 0, 0.4, 3],
                                          [5, 1, 0.1, 3]]
    recording["sha256"] = recordings.content_sha256(recording)
    recordings.check(recording)
    graded = metrics.assess(recording, scene)
    m = graded.metrics
    distances = graded.trainee.distances["Nerve"]
    assert distances[0] == pytest.approx(recomputed[0], abs=HALF_VOXEL)
    assert distances[1:].tolist() == [2.2, 2.2, 0.9, 0.9, 0.4]
    assert m["safety.min_distance_mm.Nerve"] == 0.4 and m["safety.min_distance_mm"] == 0.4
    # Intervals 0, 1, 1, 0.7, 0.4, 0.7 s: within 2 mm are poses 3-5 (pose 1-2 read 2.2), within 1 mm the same.
    assert m["safety.time_within_2mm_s.Nerve"] == pytest.approx(0.7 + 0.4 + 0.7)
    assert m["safety.time_within_1mm_s.Nerve"] == pytest.approx(0.7 + 0.4 + 0.7)
    assert m["safety.monitor_poses.Nerve"] == 5
    held = np.array([2.2, 2.2, 0.9, 0.9, 0.4])
    assert m["safety.monitor_minus_poses_max_abs_mm.Nerve"] == pytest.approx(np.abs(held - recomputed[1:]).max(), abs=HALF_VOXEL)
    # Not ready at pose 4 (a null distance, level -1): that pose falls back on the recomputed distance.
    recording["strokes"][0]["monitor"].insert(4, [4, 0, None, -1])
    recording["sha256"] = recordings.content_sha256(recording)
    fallback = metrics.assess(recording, scene).trainee.distances["Nerve"]
    assert fallback[4] == pytest.approx(recomputed[4], abs=HALF_VOXEL) and fallback[3] == 0.9
    # A reading of a structure the monitor does not list, of a pose the stroke does not have, of no level, is refused.
    for bad in ([9, 0, 1.0, 1], [0, 2, 1.0, 1], [0, 0, 1.0, 7], [0, 0, None, 2]):
        broken = json.loads(json.dumps(recording))
        broken["strokes"][0]["monitor"].append(bad)
        broken.pop("sha256")
        with pytest.raises(recordings.RecordingError, match="monitor reading"):
            recordings.check(broken, require_checksum=False)


def test_monitor_readings_are_kept_when_they_change(scene):
    # A compactor keeps the first reading of a stroke, a level change, and a distance that moved by more than the step.
    compactor = recordings.MonitorCompactor(step_mm=0.05)
    readings = [(0, 3.0, 1), (1, 2.98, 1), (2, 2.96, 1), (3, 2.94, 1), (4, 1.9, 2), (5, None, -1), (6, 1.9, 2)]
    kept = [compactor.keep(pose, 0, distance, level) for pose, distance, level in readings]
    assert [k[0] for k in kept if k] == [0, 3, 4, 5, 6]
    compactor.restart()
    assert compactor.keep(7, 0, 1.9, 2) == [7, 0, 1.9, 2]


def test_the_largest_force_near_the_nerve(scene):
    # The same approach with a force per pose (N), falling as the burr nears: within 2 mm are the last three poses.
    heights = [8.0, 9.0, 10.0, 10.7, 11.1, 11.8]
    recording = session(scene, [("burr", [[10.0, 10.0, z] for z in heights])], speed=1.0)
    recording["strokes"][0]["forces"] = [6.0, 5.0, 4.0, 3.0, 2.0, 1.0]
    recording["sha256"] = recordings.content_sha256(recording)
    m = metrics.assess(recording, scene).metrics
    assert m["safety.max_force_within_2mm_n.Nerve"] == 3.0
    assert m["safety.max_force_within_1mm_n.Nerve"] == 1.0
    # Without recorded forces there is no force metric rather than a zero.
    assert not any("force" in key for key in metrics.assess(session(scene, [("burr", [[10.0, 10.0, 8.0]])]), scene).metrics)


def test_a_haptic_session_tick_by_tick(scene):
    # At 1 kHz: 10 ticks with the drill off, 20 on rising toward the nerve, 5 off, 10 on; forces in N along -z.
    rate = 1000.0
    heights = np.concatenate([np.full(10, 8.0), np.linspace(8.0, 11.8, 20), np.full(5, 11.8), np.linspace(11.8, 9.0, 10)])
    proxies = np.stack([np.full(45, 10.0), np.full(45, 10.0), heights], axis=1)
    forces = np.zeros((45, 3))
    forces[:, 2] = -np.linspace(0.5, 5.0, 45)
    drilling = np.r_[np.zeros(10), np.ones(20), np.zeros(5), np.ones(10)].astype(bool)
    recording = recordings.from_haptic_ticks(proxies, forces, drilling, rate, "burr", {"burr_type": "Diamond", "radius_mm": 1.5},
                                             np.eye(3), scan=scene.descriptor())
    recording["sha256"] = recordings.content_sha256(recording)
    recordings.check(recording)
    assert [len(s["positions"]) for s in recording["strokes"]] == [20, 10]
    assert recording["strokes"][1]["times"][0] == pytest.approx(35 / rate)
    m = metrics.assess(recording, scene).metrics
    assert m["efficiency.strokes"] == 2 and m["efficiency.idle_time_s"] == pytest.approx(6 / rate)  # the drill off from tick 29 to 35
    assert m["efficiency.path_length_mm"] == pytest.approx(3.8 + 2.8)
    # Within 2 mm of the nerve (burr centre above 13.9 - 1.5 - 2 = 10.4 mm): the largest force sent there.
    distance = 13.9 - 1.5 - heights
    near = drilling & (distance < 2.0 - HALF_VOXEL)
    maybe = drilling & (distance < 2.0 + HALF_VOXEL)
    magnitudes = np.linalg.norm(forces, axis=1)
    assert magnitudes[near].max() <= m["safety.max_force_within_2mm_n.Nerve"] <= magnitudes[maybe].max()


def test_a_haptic_session_keeps_the_monitor_readings_that_changed(scene):
    # 200 ticks at 1 kHz, the drill on throughout, the burr rising 0.01 mm a tick from z = 9 mm: the monitor's
    # distance (taken here as the analytic one, 13.9 - 1.5 - z) falls 0.01 mm a tick, so with a 0.05 mm step one tick
    # in six is kept (the first, then each that moved by more than 0.05 mm), plus the level changes at 2 and 1 mm.
    rate = 1000.0
    heights = 9.0 + 0.01 * np.arange(200)
    proxies = np.stack([np.full(200, 10.0), np.full(200, 10.0), heights], axis=1)
    distances = (13.9 - 1.5 - heights)[:, None]
    levels = np.digitize(-distances, [-4.0, -2.0, -1.0, 0.0])  # 0 silent .. 4 contact, as the monitor's thresholds
    header = dict(recordings.monitor_header(None, ["Nerve"]), range_mm=8.0, distances=distances, levels=levels)
    recording = recordings.from_haptic_ticks(proxies, np.ones(200), np.ones(200, bool), rate, "burr",
                                             {"burr_type": "Diamond", "radius_mm": 1.5}, np.eye(3), scan=scene.descriptor(),
                                             monitor=header)
    recording["sha256"] = recordings.content_sha256(recording)
    recordings.check(recording)
    kept = recording["strokes"][0]["monitor"]
    assert "distances" not in recording["monitor"] and recording["monitor"]["structures"] == ["Nerve"]
    assert len(kept) == pytest.approx(200 / 6, abs=4) and kept[0] == [0, 0, 3.4, 1]
    # Held between kept ticks, the readings stay within the step of every tick's own reading.
    graded = metrics.assess(recording, scene)
    assert np.abs(graded.trainee.distances["Nerve"] - distances[:, 0]).max() <= recordings.MONITOR_STEP_MM + 1e-9
    within = graded.metrics["safety.time_within_1mm_s.Nerve"]
    assert within == pytest.approx(float(np.sum(distances[1:, 0] < 1.0)) / rate, abs=6 / rate)


def test_bands_hold_the_removed_bone_at_their_distances(scene):
    # A stroke along the box's top under the nerve; count by hand which removed voxel centres lie in each band.
    graded = metrics.assess(session(scene, [("burr", line([4, 10, 11], [16, 10, 11], 25))]), scene)
    removed = graded.trainee.final_removed
    k, j, i = np.nonzero(removed)
    centers = (np.stack([i, j, k], axis=1) + graded.crop.low) * 0.5
    distance = np.hypot(centers[:, 1] - 10.0, centers[:, 2] - NERVE_Z) - NERVE_RADIUS
    for band in metrics.BANDS_MM:
        by_hand = np.count_nonzero((distance >= band[0]) & (distance < band[1])) * 0.125
        measured = graded.metrics[f"final.removed_mm3.{metrics.band_name('Nerve', band)}"]
        # Voxels within half a voxel of a band's edge may fall on either side.
        edge = np.count_nonzero(np.abs(distance - band[0]) < HALF_VOXEL) + np.count_nonzero(np.abs(distance - band[1]) < HALF_VOXEL)
        assert abs(measured - by_hand) <= edge * 0.125 + 1e-9, band
    assert sum(graded.metrics[f"final.removed_mm3.{metrics.band_name('Nerve', b)}"] for b in metrics.BANDS_MM) > 0.0


def test_contacts_count_each_entry_into_a_structure(scene):
    # Two dips into the nerve (burr r = 1.5 at z = 12.8: 0.4 mm deep), each from below it.
    up_down = [[10.0, 10.0, 9.0], [10.0, 10.0, 12.8], [10.0, 10.0, 9.0]]
    graded = metrics.assess(session(scene, [("burr", up_down), ("burr", up_down)], speed=1.0), scene)
    m = graded.metrics
    assert m["safety.contacts.Nerve"] == 2 and m["safety.contacts"] == 2
    assert m["safety.min_distance_mm"] == pytest.approx(13.9 - 1.5 - 12.8, abs=HALF_VOXEL)
    assert m["safety.contact_time_s.Nerve"] == pytest.approx(2 * 3.8)  # each arrival interval at 1 mm/s
    # The nerve is never removed.
    assert not np.any(graded.trainee.final_removed & (graded.crop.labels == scene.label("Nerve")))


def test_a_large_cutting_burr_near_the_nerve(scene):
    near = [[10.0, 10.0, 9.0], [10.0, 10.0, 10.5]]  # r = 2: surface distance 13.9 - 2 - 10.5 = 1.4 mm at the end
    tools = {"large": {"burr_type": "Cutting", "radius_mm": 2.0}, "diamond": {"burr_type": "Diamond", "radius_mm": 2.0},
             "small": {"burr_type": "Cutting", "radius_mm": 1.9}}
    recording = session(scene, [("large", near), ("diamond", near), ("small", near)], tools=tools, speed=1.5)
    m = metrics.assess(recording, scene).metrics
    assert m["safety.large_burr_within_2mm_poses"] == 1
    assert m["safety.large_burr_within_2mm_s"] == pytest.approx(1.0)  # 1.5 mm at 1.5 mm/s


def test_idle_time_undo_redo_and_restore(scene):
    stroke = line([5, 6.13, 6.27], [13, 6.13, 6.27], 17)
    one = capsule(1.5, 8.0)
    # Cut, pause 1 s, cut elsewhere; undo the second between, redo it: as if it had stayed.
    other = line([5, 12.13, 6.27], [13, 12.13, 6.27], 17)
    events = [{"t": 2.4, "type": "undo"}, {"t": 2.6, "type": "redo"}, {"t": 2.8, "type": "undo"}]
    # Stroke times: 0-2 s, 3-5 s, 6-8 s; the undo at 2.4 s undoes the first, redo restores it, the undo at 2.8 s undoes it again.
    graded = metrics.assess(session(scene, [("burr", stroke), ("burr", other), ("burr", stroke, "restore")], events=events), scene)
    m = graded.metrics
    assert m["efficiency.undo"] == 2 and m["efficiency.redo"] == 1
    assert m["efficiency.idle_time_s"] == pytest.approx(2.0)  # two 1 s pauses
    assert m["efficiency.duration_s"] == pytest.approx(8.0)
    # Left: the second stroke only (the first was undone, the restore found nothing of it left).
    assert m["final.removed_mm3"] == pytest.approx(one, rel=0.03)
    assert graded.trainee.final_removed.sum() * 0.125 == pytest.approx(m["final.removed_mm3"])


def test_visibility_counts_what_was_removed_out_of_sight(scene):
    # The camera looks straight down at x = y = 5. A shaft down that line is seen all along;
    # then the burr undercuts sideways at z = 6 beneath intact bone: out of sight beyond the shaft's rim.
    shaft = line([5, 5, 13], [5, 5, 6], 15)
    undercut = line([5, 5, 6], [13, 5, 6], 17)
    graded = metrics.assess(session(scene, [("burr", shaft), ("burr", undercut)]), scene)
    hidden = graded.trainee.hidden
    x = np.array([p[0] for p in shaft + undercut])
    assert not hidden[:len(shaft)].any()
    # Seen while the burr's top is under the shaft's opening (x - 5 < 1.5 less the voxel stop), hidden past its rim.
    assert not hidden[len(shaft):][x[len(shaft):] <= 5.5].any()
    assert hidden[len(shaft):][x[len(shaft):] >= 8.0].all()
    per_pose = graded.trainee.removed_voxels * 0.125
    m = graded.metrics
    assert m["visibility.hidden_removed_mm3"] == pytest.approx(per_pose[hidden].sum())
    # By hand: at least the undercut from x = 8 on (a cylinder 5 mm long) and at most all of it past x = 5.5.
    assert math.pi * 1.5 ** 2 * 5.0 * 0.95 <= m["visibility.hidden_removed_mm3"] <= capsule(1.5, 7.5) * 1.05
    assert m["visibility.hidden_time_s"] == pytest.approx(hidden.sum() * 0.125)  # 0.5 mm steps at 4 mm/s
    # A recording without a camera has no visibility metrics and the score leaves that part out.
    blind = metrics.assess(session(scene, [("burr", shaft)], camera=()), scene)
    assert "visibility.hidden_removed_mm3" not in blind.metrics and blind.parts["visibility"] is None


def test_final_product_against_a_reference_shifted_by_hand(scene):
    r, length, shift = 1.5, 8.0, 2.0
    reference = session(scene, [("burr", line([5, 6.13, 6.27], [13, 6.13, 6.27], 17))])
    trainee = session(scene, [("burr", line([5 + shift, 6.13, 6.27], [13 + shift, 6.13, 6.27], 17))])
    m = metrics.assess(trainee, scene, reference).metrics
    # Two collinear capsules offset by d share a capsule of length L - d.
    shared = capsule(r, length - shift)
    assert m["final.dice"] == pytest.approx(shared / capsule(r, length), abs=0.03)
    assert m["final.over_mm3"] == pytest.approx(math.pi * r * r * shift, rel=0.08)
    assert m["final.under_mm3"] == pytest.approx(math.pi * r * r * shift, rel=0.08)
    assert m["final.over_mm3.Bone"] == pytest.approx(m["final.over_mm3"])
    same = metrics.assess(reference, scene, reference).metrics
    assert same["final.dice"] == 1.0 and same["final.over_mm3"] == 0.0 and same["score.final_product"] == 100.0


def test_score_weights_and_contract(scene):
    assert sum(metrics.SCORE_WEIGHTS.values()) == pytest.approx(1.0)
    safe = session(scene, [("burr", line([5, 6.13, 6.27], [13, 6.13, 6.27], 17))])
    graded = metrics.assess(safe, scene, safe)
    parts = graded.parts
    assert graded.score == pytest.approx(100.0 * sum(metrics.SCORE_WEIGHTS[p] * v for p, v in parts.items()), abs=1e-3)
    document = json.loads(json.dumps(graded.to_dict()))
    assert set(document) == {"format", "version", "session", "score", "metrics", "reference"}
    assert set(document["session"]) == {"scan", "recording", "sha256", "started", "duration_s", "trainee"}
    assert all(isinstance(v, (int, float)) for v in document["metrics"].values())
    assert document["session"]["sha256"] == safe["sha256"] and document["reference"]["sha256"] == safe["sha256"]


# ---------------------------------------------------------------------------
# The recording format and bad input
# ---------------------------------------------------------------------------

def test_version_2_round_trip_and_version_1_still_read(scene, tmp_path):
    recording = session(scene, [("burr", line([5, 6.13, 6.27], [13, 6.13, 6.27], 5))])
    path = recordings.save(recording, tmp_path / "s.json")
    assert recordings.load(path) == recording
    shipped = recordings.load(recordings.head_ct_mastoidectomy_path())
    assert shipped["version"] == 1 and len(shipped["strokes"]) == 86
    assert recordings.edits_before_strokes(shipped) == [[] for _ in range(87)]  # untimed: nothing to undo, replays as before


@pytest.mark.parametrize("damage, words", [
    (lambda text: text.replace('"positions":[[5.0', '"positions":[[5.5', 1), "does not match its sha256"),
    (lambda text: text[: len(text) // 2], "truncated or corrupt"),
    (lambda text: text.replace('"sha256"', '"sha"', 1), "has no sha256"),
    (lambda text: "", "truncated or corrupt"),
])
def test_corrupt_recordings_are_refused_naming_the_file(scene, tmp_path, damage, words):
    path = recordings.save(session(scene, [("burr", line([5, 6.13, 6.27], [13, 6.13, 6.27], 5))]), tmp_path / "s.json")
    path.write_text(damage(path.read_text()))
    with pytest.raises(recordings.RecordingError, match=words) as error:
        recordings.load(path)
    assert str(path) in str(error.value)


def test_an_empty_session_is_refused(scene, tmp_path):
    recording = session(scene, [("burr", line([5, 6.13, 6.27], [13, 6.13, 6.27], 5))])
    recording["strokes"] = []
    recording["sha256"] = recordings.content_sha256(recording)
    path = tmp_path / "empty.json"
    path.write_text(json.dumps(recording))
    with pytest.raises(recordings.RecordingError, match="empty session"):
        recordings.load(path)
    out = tmp_path / "out"
    assert cli.main([str(path), "--out", str(out)]) == 2 and not out.exists()


def test_a_recording_for_another_scan_is_refused_with_both_grids(scene, tmp_path):
    recording = session(scene, [("burr", line([5, 6.13, 6.27], [13, 6.13, 6.27], 5))])
    other = scans.analytic_scan(dimensions=(40, 40, 44), nerve_radius=NERVE_RADIUS)
    with pytest.raises(scans.ScanError) as error:
        metrics.assess(recording, other)
    message = str(error.value)
    assert "40x40x40 voxels" in message and "40x40x44 voxels" in message
    # A reference on another scan: likewise, through the command line, and nothing is written.
    elsewhere = session(other, [("burr", line([5, 6.13, 6.27], [13, 6.13, 6.27], 5))])
    first = recordings.save(recording, tmp_path / "a.json")
    second = recordings.save(elsewhere, tmp_path / "b.json")
    out = tmp_path / "out"
    assert cli.main([str(first), "--reference", str(second), "--out", str(out)]) == 2
    assert not out.exists() and recordings.load(first) == recording and recordings.load(second) == elsewhere


def test_the_command_line_writes_a_report_and_every_metric(scene, tmp_path):
    trainee = recordings.save(session(scene, [("burr", line([7, 6.13, 6.27], [15, 6.13, 6.27], 17))]), tmp_path / "trainee.json")
    reference = recordings.save(session(scene, [("burr", line([5, 6.13, 6.27], [13, 6.13, 6.27], 17))]), tmp_path / "reference.json")
    out = tmp_path / "report"
    assert cli.main([str(trainee), "--reference", str(reference), "--out", str(out)]) == 0
    document = json.loads((out / "assessment.json").read_text())
    assert document["session"]["recording"] == str(trainee) and document["reference"]["recording"] == str(reference)
    page = (out / "report.html").read_text()
    assert page.count("data:image/png;base64,") == 4 and "Score" in page and "src='http" not in page


# ---------------------------------------------------------------------------
# Careful and careless sessions on the phantom and the head CT
# ---------------------------------------------------------------------------

SEPARATING = {  # metric: the careless value is larger (True) or smaller (False) than the careful one
    "safety.contacts": True, "safety.min_distance_mm": False, "safety.large_burr_within_2mm_s": True,
    "safety.large_burr_within_2mm_poses": True, "visibility.hidden_removed_fraction": True,
}


def check_separated(scan):
    careful, careless = sessions.careful(scan), sessions.careless(scan)
    for recording in (careful, careless):
        recording["sha256"] = recordings.content_sha256(recording)
    started = time.perf_counter()
    good = metrics.assess(careful, scan, careful)
    bad = metrics.assess(careless, scan, careful)
    seconds = time.perf_counter() - started
    for metric, larger in SEPARATING.items():
        assert (bad.metrics[metric] > good.metrics[metric]) == larger, (metric, good.metrics[metric], bad.metrics[metric])
    # Per structure: the careless session comes nearer to each one it plunged at, and longer within 1 and 2 mm.
    for structure in scan.protected:
        if bad.metrics[f"safety.contacts.{structure}"]:
            assert bad.metrics[f"safety.min_distance_mm.{structure}"] < 0.0 < good.metrics[f"safety.min_distance_mm.{structure}"]
            for near in ("1", "2"):
                assert bad.metrics[f"safety.time_within_{near}mm_s.{structure}"] > good.metrics[f"safety.time_within_{near}mm_s.{structure}"]
    assert good.metrics["safety.contacts"] == 0 and good.metrics["safety.large_burr_within_2mm_s"] == 0.0
    assert good.metrics["safety.min_distance_mm"] > 2.0
    assert good.score > 85.0 > 60.0 > bad.score
    assert bad.metrics["score.safety"] < good.metrics["score.safety"] and bad.metrics["score.visibility"] < good.metrics["score.visibility"]
    return good, bad, seconds


def test_careful_and_careless_on_the_phantom(tmp_path):
    good, bad, seconds = check_separated(scans.phantom_scan())
    assert seconds < 20.0
    paths = report.write(bad, tmp_path)
    assert paths["html"].stat().st_size > 10_000


@pytest.mark.realdata
def test_careful_and_careless_on_the_head_ct():
    from VolumeCuttingLib.data import headct

    try:
        headct.fetch()
    except headct.HeadCTUnavailableError as error:
        pytest.skip(f"the head CT cannot be obtained: {error}")
    good, bad, seconds = check_separated(scans.head_ct_scan())
    assert seconds < 30.0


def test_the_command_line_runs_as_vc_assess(scene, tmp_path):
    """``python -m VolumeCuttingLib.assessment`` (what ``Utilities/vc assess`` runs): bad input exits 2 with the file named."""
    broken = tmp_path / "broken.json"
    broken.write_text('{"format": "VolumeCuttingRecording", "version": 2, "strok')
    result = subprocess.run([sys.executable, "-m", "VolumeCuttingLib.assessment", str(broken), "--out", str(tmp_path / "o")],
                            capture_output=True, text=True, cwd=Path(__file__).resolve().parents[2])
    assert result.returncode == 2 and str(broken) in result.stderr and not (tmp_path / "o").exists()


def test_poses_outside_the_scan_are_refused(scene):
    with pytest.raises(metrics.AssessmentError, match="outside the scan"):
        metrics.assess(session(scene, [("burr", [[500.0, 500.0, 500.0], [510.0, 500.0, 500.0]])]), scene)


@pytest.mark.realdata
def test_a_version_1_recording_is_graded_given_its_scan_and_tools(tmp_path, capsys):
    from VolumeCuttingLib.data import headct

    try:
        headct.fetch()
    except headct.HeadCTUnavailableError as error:
        pytest.skip(f"the head CT cannot be obtained: {error}")
    shipped = str(recordings.head_ct_mastoidectomy_path())
    # Without its tools it cannot be graded, and says so.
    assert cli.main([shipped, "--scan", "headct", "--out", str(tmp_path / "no")]) == 2
    assert "does not say what its tools are" in capsys.readouterr().err and not (tmp_path / "no").exists()
    out = tmp_path / "v1"
    assert cli.main([shipped, "--scan", "headct", "--tool", "cutting=Cutting:5", "--tool", "diamond=Diamond:3", "--out", str(out)]) == 0
    document = json.loads((out / "assessment.json").read_text())
    # Timed at the nominal 5 mm/s: its 86 strokes; no camera was recorded, so no visibility part.
    assert document["metrics"]["efficiency.strokes"] == 86 and "visibility.hidden_removed_mm3" not in document["metrics"]
    assert document["metrics"]["safety.contacts"] == 0
