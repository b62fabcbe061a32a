"""The main job end to end: real nodes, Slicer's 3D rendering, a bundle that reloads."""

import argparse
import json
import socket
import threading
import time

import numpy as np
import pytest
import vtk
from vtkmodules.util import numpy_support

from VolumeCuttingLib.collaboration import igtloptions
from VolumeCuttingLib.collaboration.igtlclient import RecordingClient
from VolumeCuttingLib.jobs import mainjob
from VolumeCuttingLib.scene.application import HeadlessSlicer


def read_png(path):
    reader = vtk.vtkPNGReader()
    reader.SetFileName(str(path))
    reader.Update()
    image = reader.GetOutput()
    width, height, _ = image.GetDimensions()
    pixels = numpy_support.vtk_to_numpy(image.GetPointData().GetScalars())
    return pixels.reshape(height, width, -1)[:, :, :3].astype(int)


def foreground_fraction(pixels):
    """Share of pixels that differ from the background gradient at their row.

    Slicer's 3D view background is a vertical gradient, so each row's leftmost
    pixel gives that row's background colour.
    """
    background = pixels[:, :1, :]
    return float((np.abs(pixels - background).sum(axis=2) > 30).mean())


def cut_overlay(pixels):
    """Pixels of the slice view where the cut's red outline or fill lies over the grey CT."""
    return (pixels[..., 0] - np.maximum(pixels[..., 1], pixels[..., 2])) > 60


def check_outputs(summary, out_dir):
    assert summary["inputs_ok"], summary["input_messages"]
    pixels = read_png(out_dir / "3d.png")
    assert pixels.shape == (240, 320, 3)
    # The bone must fill a good part of the view, and not all of it.
    assert 0.05 < foreground_fraction(pixels) < 0.95
    # Drawn by the product's mapper, before and after cutting, and zoomed on a cut edge.
    assert summary["rendering"]["path"] in ("CPU", "GPU")
    assert summary["rendering"]["displayable_manager"] == "vtkMRMLVolumeCutDisplayableManager"
    before = read_png(out_dir / "cut_before.png")
    assert before.shape == pixels.shape
    changed = (np.abs(before - pixels).sum(axis=2) > 30).mean()
    assert 0.0005 < changed < 0.5  # the cavity, not the whole view
    zoom = read_png(out_dir / "cut_edge_zoom.png")
    assert foreground_fraction(zoom) > 0.05
    reloaded = HeadlessSlicer()
    reloaded.load_bundle(out_dir / "scene.mrb")
    cut = reloaded.scene.GetFirstNodeByClass("vtkMRMLVolumeCutNode")
    assert cut is not None
    assert list(cut.GetCuttableSegmentIDs()) == summary["cuttable_segment_ids"]
    assert list(cut.GetProtectedSegmentIDs()) == summary["protected_segment_ids"]
    segments = cut.GetSegmentationNode().GetSegmentation()
    assert summary["cuttable_segments"] == [segments.GetSegment(s).GetName() for s in summary["cuttable_segment_ids"]]
    assert summary["protected_segments"] == [segments.GetSegment(s).GetName() for s in summary["protected_segment_ids"]]
    assert cut.GetAnatomyVolumeNode() is not None
    assert cut.GetSegmentationNode() is not None
    # The drilling itself came back: the same removed volume, kept by the logic.
    field = cut.GetCutField()
    assert field is not None and field.GetNumberOfAllocatedBricks() > 0
    logic = reloaded.volume_cutting_logic
    assert logic.GetRemovedVolume(cut) == pytest.approx(summary["drilling"]["removed_volume_mm3"], abs=0.006)
    # Kept, or copied exactly where Slicer's reader reindexed a left-handed scan.
    assert logic.GetCutField(cut) is field or logic.GetCutField(cut).IsSameLattice(field)
    # Figures per segment are keyed by the segment's name, its ID beside.
    per_segment = summary["drilling"]["removed_volume_per_segment"]
    assert len(per_segment) == segments.GetNumberOfSegments()
    for name, entry in per_segment.items():
        assert segments.GetSegment(entry["segment_id"]).GetName() == name
        assert logic.GetRemovedVolumeInSegment(cut, entry["segment_id"]) == pytest.approx(entry["removed_volume_mm3"], abs=0.006)
    for name, entry in summary["drilling"]["removed_volume_table"].items():
        assert per_segment[name]["segment_id"] == entry["segment_id"]
    for segment_id in summary["protected_segment_ids"]:
        assert logic.GetRemovedVolumeInSegment(cut, segment_id) == 0.0
    for name, entry in summary["drilling"]["contacts_per_segment"].items():
        assert segments.GetSegment(entry["segment_id"]).GetName() == name and entry["contact_events"] > 0
    assert sum(e["contact_events"] for e in summary["drilling"]["contacts_per_segment"].values()) == \
        summary["drilling"]["contact_events"]
    # The axial slice is centred on the cut and shows it large enough to read
    # its depth, with bone around it (a fixed 70 mm field left it at 3-5 %).
    overlay = cut_overlay(read_png(out_dir / "cut_slice_axial.png"))
    assert 0.06 < overlay.mean() < 0.4
    rows, columns = np.nonzero(overlay)
    assert abs(rows.mean() / overlay.shape[0] - 0.5) < 0.1
    assert abs(columns.mean() / overlay.shape[1] - 0.5) < 0.1
    assert json.loads((out_dir / "summary.json").read_text()) == summary
    assert (out_dir / "removed.stl").stat().st_size > 1000
    assert reloaded.scene.GetFirstNodeByName(summary["exports"]["drilled_ct"]) is not None


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def connect_when_listening(port, clients, stop):
    """Connect a recording client as soon as the job's OpenIGTLink bridge listens (as a user's Slicer would)."""
    while not stop.is_set():
        try:
            clients.append(RecordingClient("127.0.0.1", port))
            return
        except OSError:
            time.sleep(0.02)


def test_main_job_on_the_phantom(tmp_path):
    # Streamed over OpenIGTLink as it drills (mainjob --openigtlink PORT), to a client connected from the start.
    port, clients, stop = free_port(), [], threading.Event()
    connector = threading.Thread(target=connect_when_listening, args=(port, clients, stop), daemon=True)
    connector.start()
    try:
        summary = mainjob.run(True, tmp_path, seed=3, size=(320, 240), openigtlink=igtloptions.BridgeOptions(port=port))
    finally:
        stop.set()
        connector.join(timeout=5)
    for structure in ("FacialNerve", "SigmoidSinus", "Malleus", "Incus", "Stapes"):
        assert structure in summary["protected_segments"]
    assert "MastoidBone" in summary["cuttable_segments"]
    check_outputs(summary, tmp_path)

    streamed = summary["openigtlink"]
    assert streamed["address"] == f"127.0.0.1:{port}" and streamed["flushed"] and not streamed["refused"]
    assert streamed["clients_connected"] == 1 and streamed["sent"]["TRANSFORM"] > 10 and streamed["image_updates"] >= 1
    client = clients[0]
    try:
        assert client.wait_for(lambda c: c.image is not None and c.messages("STRING", "NerveMonitor"))
        assert len(client.messages("TRANSFORM", "VolumeCutTool")) == streamed["sent"]["TRANSFORM"]
        # The mirrored removed region is the job's: as many voxels touched as its exported fraction volume has.
        assert client.error is None and client.image[0].shape == (96, 128, 128)
        assert client.image[0].astype(float).sum() / 255.0 * 0.4 * 0.4 * 0.5 > 0.5 * summary["drilling"]["removed_volume_mm3"]
    finally:
        client.close()
    # Off by default, bound to this machine unless told otherwise.
    parser = argparse.ArgumentParser()
    igtloptions.add_arguments(parser)
    assert igtloptions.options_from_arguments(parser.parse_args([])) is None
    assert igtloptions.options_from_arguments(parser.parse_args(["--openigtlink", "18944"])).host == "127.0.0.1"
    with pytest.raises(ValueError, match="goes with --openigtlink"):
        igtloptions.options_from_arguments(parser.parse_args(["--openigtlink-host", "0.0.0.0"]))
    with pytest.raises(ValueError, match="0 to 65535"):
        igtloptions.options_from_arguments(parser.parse_args(["--openigtlink", "70000"]))


@pytest.mark.realdata
def test_main_job_on_the_real_head_ct(tmp_path):
    summary = mainjob.run(False, tmp_path, size=(320, 240))
    assert summary["bone_segments"] == ["Cortical bone", "Trabecular bone"]
    assert summary["bone_segment_ids"] == ["CorticalBone", "TrabecularBone"]
    # The haptic replay's slow ticks come with the machine's: a constant-work thread as long, beside the same views.
    haptics = summary["haptics"]
    assert haptics["machine_check"]["ticks"] == haptics["ticks_run"]
    assert haptics["machine_check"]["display_frames"] > 0
    removed = summary["drilling"]["removed_volume_per_segment"]
    assert removed["Cortical bone"]["removed_volume_mm3"] > 100.0  # the mastoid cortex is opened
    check_outputs(summary, tmp_path)


def test_protected_nerve_survives_a_stroke_through_it(tmp_path):
    """A pass aimed through the facial nerve leaves the nerve and reports the contact."""
    from VolumeCuttingLib.data import phantom

    application = HeadlessSlicer()
    logic = application.volume_cutting_logic
    generated = phantom.generate_phantom(dimensions=(96, 96, 72), spacing=(0.5, 0.5, 0.6), seed=1)
    volume, segmentation = phantom.create_phantom_nodes(application.scene, generated)
    cut = logic.AddVolumeCutNode(volume, segmentation)
    cut.SetProtectedSegmentIDs(["FacialNerve"])
    cut.SetCuttableSegmentIDs(["MastoidBone", "FacialCanalWall"])
    nerve = generated.segment("FacialNerve")
    # A voxel centre of the nerve (labelmap indices are k, j, i).
    voxels = np.argwhere(generated.labelmap == nerve.label)
    middle = generated.ijk_to_ras_points(voxels[len(voxels) // 2][::-1].astype(float)[None, :])[0].tolist()
    assert nerve.contains(np.array([middle]))[0]
    start = [middle[0] + 6.0, middle[1], middle[2]]
    end = [middle[0] - 6.0, middle[1], middle[2]]
    assert logic.CutSphereSweep(cut, start, end, 1.5)
    assert logic.GetRemovedVolume(cut) > 10.0
    # Exactly nothing: no sample of the nerve was removed, whatever the
    # partial-volume ramp of the cut surface on its faces.
    assert logic.GetRemovedVolumeInSegment(cut, "FacialNerve") == 0.0
    assert logic.GetCutField(cut).GetSignedDistance(middle) > 0.0
    assert logic.GetContactSegmentID(cut) == "FacialNerve"
    assert logic.GetCutField(cut).GetMaximumContactDepth() > 1.0
