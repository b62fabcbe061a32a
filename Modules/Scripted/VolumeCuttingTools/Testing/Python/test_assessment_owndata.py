"""A session on the user's own scan is recorded so that ``vc assess`` grades it on their segmentation.

A small own-data case is written in the test with Slicer's writers, as a
user would bring it: a CT (NRRD, x axis flipped, 0.5 mm voxels) of a bone
block in air with a nerve running through it, and a labelmap with a colour
table naming them "Temporal bone" and "Facial nerve". It is loaded through
``owndata`` as the main job loads it, the roles given by name as on the main
job's command line (``--cuttable "temporal bone" --protected facial_nerve``),
and one stroke is drilled toward the nerve through the logic with the main
job's recorder and scan descriptor. ``vc assess`` then grades the saved
recording: its regions and structures at risk are the user's segments (and
their distance bands), the closest approach is the one the geometry gives by
hand, and the recording carries the nerve monitor's readings, which agree
with the distances recomputed from the poses. A segmentation file changed
after the session is refused, the file named.
"""

import json

import numpy as np
import pytest

from test_owndata import write_volume

from VolumeCuttingLib.assessment import __main__ as cli
from VolumeCuttingLib.assessment import metrics, scans
from VolumeCuttingLib.config import toolconfig
from VolumeCuttingLib.cutting import recording as recordings
from VolumeCuttingLib.jobs import mainjob
from VolumeCuttingLib.scene.application import HeadlessSlicer

# 40 x 36 x 32 voxels of 0.5 mm, i running to the patient's left (x = 12 - 0.5 i).
IJK_TO_RAS = np.array([[-0.5, 0.0, 0.0, 12.0], [0.0, 0.5, 0.0, -9.0], [0.0, 0.0, 0.5, -8.0], [0.0, 0.0, 0.0, 1.0]])
SHAPE = (32, 36, 40)  # k, j, i
NERVE_RADIUS = 1.0  # mm, along the y axis through x = 2, z = 0
NERVE_X = 2.0
TABLE = "0 Background 0 0 0 0\n1 Temporal bone 230 200 120 255\n2 Facial nerve 244 214 49 255\n"
BURR_RADIUS = 1.0
VOXEL = 0.5
# The burr's centre comes in along -x at y = 0, z = 0 down to x = 5. The nerve's outermost voxels there have their
# centres at x = 2 + 1 = 3 (x = 12 - 0.5 i), so its voxel surface is at 3.25 mm: the burr's surface comes to
# 5 - 1 - 3.25 = 0.75 mm of it.
STROKE = [[x, 0.0, 0.0] for x in np.arange(10.0, 4.99, -0.25)]
CLOSEST_MM = 5.0 - BURR_RADIUS - (NERVE_X + NERVE_RADIUS + VOXEL / 2)


def case_arrays():
    """The CT and its labels: bone from x = -6 to 11 mm, the nerve a cylinder along y inside it."""
    k, j, i = np.indices(SHAPE)
    ras = np.stack([i, j, k, np.ones(SHAPE)], axis=-1) @ IJK_TO_RAS.T
    x, y, z = ras[..., 0], ras[..., 1], ras[..., 2]
    bone = (x > -6.0) & (x < 11.0) & (np.abs(y) < 7.0) & (np.abs(z) < 6.0)
    nerve = np.hypot(x - NERVE_X, z) <= NERVE_RADIUS
    labels = np.where(nerve & bone, 2, np.where(bone, 1, 0)).astype(np.uint8)
    ct = np.where(bone, 1300, -1000).astype(np.int16)
    ct[labels == 2] = 60
    return ct, labels


def own_case(folder):
    """The CT and its labelmap as files, the labels named by a colour table beside it."""
    ct, labels = case_arrays()
    (folder / "labels.ctbl").write_text(TABLE)
    return write_volume(folder / "ct.nrrd", ct, IJK_TO_RAS), write_volume(folder / "labels.nrrd", labels, IJK_TO_RAS, labelmap=True)


def record_own_session(folder):
    ct_path, labels_path = own_case(folder)
    application = HeadlessSlicer()
    logic = application.volume_cutting_logic
    own = mainjob.OwnData(ct=ct_path, segmentation=labels_path, cuttable=["temporal bone"], protected=["facial_nerve"])
    volume, segmentation, _ = mainjob.load_anatomy(application, False, 0, own)
    cut_node = logic.AddVolumeCutNode(volume, segmentation)
    mainjob.assign_roles(cut_node, segmentation, logic, False, own)
    tool = toolconfig.create_tool_node(application.scene, toolconfig.ToolParameters(shape="Sphere", burr_type="Cutting",
                                                                                   diameter=2.0 * BURR_RADIUS), "burr")
    recorder = recordings.SessionRecorder({"burr": {"name": "burr", "burr_type": "Cutting", "radius_mm": BURR_RADIUS}},
                                          scan=mainjob.scan_descriptor(volume, False, 0, own, cut_node))
    session = {"format": recordings.FORMAT, "version": 1, "strokes": [
        {"tool": "burr", "action": "cut", "rotation": recordings.frame_along([-1.0, 0.0, 0.0]).ravel().tolist(),
         "positions": STROKE}]}
    counts = recordings.replay(logic, cut_node, session, {"burr": tool}, recorder=recorder)
    assert counts["poses"] == len(STROKE) and logic.GetRemovedVolume(cut_node) > 10.0
    return recordings.save(recorder.recording, folder / "session.json"), labels_path


def test_a_session_on_an_own_scan_is_graded_on_the_users_segments(tmp_path):
    path, labels_path = record_own_session(tmp_path)
    recording = recordings.load(path)
    descriptor = recording["scan"]
    assert descriptor["name"] == "own" and descriptor["parameters"]["cuttable"] == ["Temporal bone"]
    assert descriptor["parameters"]["protected"] == ["Facial nerve"]
    assert descriptor["grid"]["dimensions"] == [40, 36, 32]
    # The monitor watched the user's protected segment and its readings went with every pose where they changed.
    assert recording["monitor"]["structures"] == ["Facial nerve"]
    assert 1 < len(recording["strokes"][0]["monitor"]) <= len(STROKE)

    out = tmp_path / "report"
    assert cli.main([str(path), "--out", str(out)]) == 0
    graded = json.loads((out / "assessment.json").read_text())
    m = graded["metrics"]
    assert graded["session"]["scan"] == "own"
    assert m["final.removed_mm3.Temporal bone"] > 10.0
    assert f"final.removed_mm3.{metrics.band_name('Facial nerve', (1.0, 2.0))}" in m
    assert m["safety.contacts.Facial nerve"] == 0 and m["safety.monitor_poses.Facial nerve"] > 0
    print(f"own scan: closest approach {m['safety.min_distance_mm.Facial nerve']:.3f} mm (by hand {CLOSEST_MM} mm), "
          f"recorded readings against the poses: largest difference {m['safety.monitor_minus_poses_max_abs_mm.Facial nerve']:.3f} mm "
          f"over {m['safety.monitor_poses.Facial nerve']} poses")
    # By hand: the closest approach is 0.75 mm; the grading takes the monitor's reading there.
    assert m["safety.min_distance_mm.Facial nerve"] == pytest.approx(CLOSEST_MM, abs=0.05)
    assert m["safety.monitor_minus_poses_max_abs_mm.Facial nerve"] <= VOXEL / 2 + recordings.MONITOR_STEP_MM
    assert m["safety.time_within_2mm_s.Facial nerve"] > 0.0

    # The scan rebuilt from the files is the user's: their names, their roles, their voxels.
    scan = scans.from_descriptor(descriptor)
    assert scan.cuttable == ("Temporal bone",) and scan.protected == ("Facial nerve",)
    labels = case_arrays()[1]
    assert np.array_equal(scan.labels == scan.label("Facial nerve"), labels == 2)
    assert np.array_equal(scan.labels == scan.label("Temporal bone"), labels == 1)

    # A segmentation that changed since the session is refused, named; nothing is written.
    labels_path.write_bytes(labels_path.read_bytes() + b"\n")
    again = tmp_path / "again"
    assert cli.main([str(path), "--out", str(again)]) == 2 and not again.exists()
    with pytest.raises(scans.ScanError, match="changed since the session") as error:
        scans.from_descriptor(descriptor)
    assert str(labels_path.resolve()) in str(error.value)
