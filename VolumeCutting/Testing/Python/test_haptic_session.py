"""The logic drills through a haptic device: the loop on its own thread, the scene at display rate.

Real scene, real CT block, real tool node from the shipped presets, the real
haptic loop at 1 kHz with the virtual device (driven from this thread as the
mouse in the 3D view drives it) and the replay device. The loop cuts the cut
node's field; vtkSlicerVolumeCuttingHapticSession.Update, called here at
display rate, moves the tool's transform node and sends the node's events;
Stop brings the logic's tables up to date.
"""

import time
from types import SimpleNamespace

import numpy as np
import pytest
import slicer
import vtk

from test_session_persistence import VtkMessages
from VolumeCuttingLib.config import toolconfig
from VolumeCuttingLib.jobs import hapticsjob
from VolumeCuttingLib.scene import nodes
from VolumeCuttingLib.scene.application import HeadlessSlicer

SHAPE = (30, 48, 48)  # k, j, i
SPACING = (0.5, 0.5, 0.8)
DISPLAY_PERIOD_S = 1.0 / 60.0


def block_scene():
    """A bone block (1200 HU in air) with a nerve canal, segmented; x = -7.5 mm is its left face."""
    application = HeadlessSlicer()
    scene = application.scene
    logic = application.volume_cutting_logic
    ijk_to_ras = np.diag([SPACING[0], SPACING[1], SPACING[2], 1.0])
    ijk_to_ras[:3, 3] = [-12.0, -12.0, -12.0]
    k, j, i = np.mgrid[0 : SHAPE[0], 0 : SHAPE[1], 0 : SHAPE[2]]
    ct = np.where((i > 8) & (i < 40) & (j > 8) & (j < 40) & (k > 4) & (k < 26), 1200, -1000).astype(np.int16)
    volume = nodes.create_scalar_volume_node(scene, ct, ijk_to_ras, "CT")
    labels = np.zeros(SHAPE, np.uint8)
    labels[ct > 0] = 1
    labels[(ct > 0) & ((j - 24) ** 2 + (k - 15) ** 2 <= 4) & (i > 30)] = 2  # "Nerve": deep in the block
    segmentation = nodes.create_segmentation_from_labels(scene, volume, labels, {1: "Bone", 2: "Nerve"}, "Anatomy")
    cut = logic.AddVolumeCutNode(volume, segmentation)
    cut.SetCuttableSegmentIDs(["Bone"])
    cut.SetProtectedSegmentIDs(["Nerve"])
    cut.SetSurfaceIsoValue(300.0)
    return application, logic, cut


def add_burr(scene, cut, name="Cutting burr 4 mm"):
    preset = next(p for p in toolconfig.load_presets() if p.name == name)
    tool = toolconfig.create_tool_node(scene, toolconfig.from_preset(preset), name=name)
    cut.SetAndObserveActiveToolNodeID(tool.GetID())
    return tool


def place(tool, position):
    matrix = vtk.vtkMatrix4x4()
    for axis in range(3):
        matrix.SetElement(axis, 3, float(position[axis]))
    tool.GetParentTransformNode().SetMatrixTransformToParent(matrix)


def tool_position(tool):
    matrix = vtk.vtkMatrix4x4()
    tool.GetParentTransformNode().GetMatrixTransformToWorld(matrix)
    return np.array([matrix.GetElement(axis, 3) for axis in range(3)])


def count_events(node, event):
    counter = {"n": 0}

    def observe(caller, event_id):
        counter["n"] += 1

    return counter, node.AddObserver(event, observe)


def test_virtual_device_drills_and_the_tool_node_follows_at_display_rate():
    application, logic, cut = block_scene()
    tool = add_burr(application.scene, cut)
    start = np.array([-14.0, 0.0, 0.0])  # 6.5 mm left of the block, in air
    place(tool, start)
    device = slicer.vtkVirtualHapticDevice()
    session = slicer.vtkSlicerVolumeCuttingHapticSession()
    session.SetLogic(logic)
    modified, modified_tag = count_events(cut, slicer.vtkMRMLVolumeCutNode.CutModifiedEvent)
    assert logic.GetRemovedVolume(cut) == 0.0
    assert session.Start(cut, device)
    assert session.IsRunning() and session.GetCutNode() is cut
    forces = []
    positions = []
    try:
        # The hand moves 12 mm along +x in 2 s with the drill on (button 1),
        # at display rate; the loop samples the device at 1 kHz meanwhile.
        frames = int(2.0 / DISPLAY_PERIOD_S)
        for frame in range(frames + 1):
            device.SetPose([12.0 * frame / frames, 0.0, 0.0], 1)
            time.sleep(DISPLAY_PERIOD_S)
            session.Update()
            positions.append(tool_position(tool))
            force = [0.0, 0.0, 0.0]
            session.GetLoop().GetLatestForce(force)
            forces.append(force)
        ticks = session.GetLoop().GetNumberOfTicks()
    finally:
        session.Stop()
        cut.RemoveObserver(modified_tag)
    assert not session.IsRunning() and session.GetCutNode() is None
    loop = session.GetLoop()
    # The loop ran at its own rate, many ticks per display frame.
    assert ticks > 5 * frames
    assert loop.GetNumberOfCutStrokes() > 0 and loop.GetNumberOfDrillPresses() == 1
    # The tool node followed the loop's proxy into the bone; never through the
    # block in one go (the proxy stays on the material the burr has not cut).
    positions = np.array(positions)
    assert positions[0][0] == pytest.approx(start[0], abs=0.5)
    assert positions[-1][0] > -7.5
    assert positions[-1][0] < start[0] + 12.0 + 1e-6
    assert np.all(np.diff(positions[:, 0]) > -0.5)
    # Contact pushed back (towards -x), and the cut was seen by the views and the tables.
    assert min(f[0] for f in forces) < -0.1
    assert modified["n"] > 0
    removed = logic.GetRemovedVolume(cut)
    assert removed > 1.0
    # Some of what the burr swept is the air in front of the block.
    assert 1.0 < logic.GetRemovedVolumeInSegment(cut, "Bone") < removed
    assert logic.GetRemovedVolumeInSegment(cut, "Nerve") == 0.0
    # A stopped session leaves the scene as it is; a second one starts again.
    assert session.Update() == 0
    assert session.Start(cut, device)
    session.Stop()


def test_the_drill_only_cuts_while_its_button_is_down():
    application, logic, cut = block_scene()
    tool = add_burr(application.scene, cut)
    place(tool, [-14.0, 0.0, 0.0])
    device = slicer.vtkVirtualHapticDevice()
    session = slicer.vtkSlicerVolumeCuttingHapticSession()
    session.SetLogic(logic)
    assert session.Start(cut, device)
    try:
        for frame in range(61):
            device.SetPose([10.0 * frame / 60, 0.0, 0.0], 0)
            time.sleep(DISPLAY_PERIOD_S / 4)
            session.Update()
    finally:
        session.Stop()
    # Pressed against the bone without the drill: force, no cut, and the tool
    # node stays on the bone's surface (what is felt is what is drawn).
    assert session.GetLoop().GetNumberOfCutStrokes() == 0
    assert logic.GetRemovedVolume(cut) == 0.0
    surface_x = tool_position(tool)[0] + 2.0  # the burr's radius
    assert surface_x == pytest.approx(-7.5, abs=0.8)


def test_bad_input_is_refused_with_a_message():
    application, logic, cut = block_scene()
    device = slicer.vtkVirtualHapticDevice()
    session = slicer.vtkSlicerVolumeCuttingHapticSession()
    with VtkMessages() as messages:
        assert not session.Start(cut, device)
    assert "no module logic" in messages.text
    session.SetLogic(logic)
    with VtkMessages() as messages:
        assert not session.Start(cut, device)
        assert not session.Start(None, device)
        assert not session.Start(cut, None)
    assert "has no active tool node" in messages.text
    assert "no volume-cut node" in messages.text and "no device" in messages.text
    assert not session.IsRunning()

    tool = add_burr(application.scene, cut)
    place(tool, [-14.0, 0.0, 0.0])
    line = application.scene.AddNewNodeByClass("vtkMRMLMarkupsLineNode", "Guide")
    line.AddControlPointWorld(vtk.vtkVector3d(-14.0, 0.0, 0.0))
    with VtkMessages() as messages:
        assert not session.SetGuideLine(line)
        line.AddControlPointWorld(vtk.vtkVector3d(-14.0, 0.0, 0.0))
        assert not session.SetGuideLine(line)
    assert "two control points" in messages.text and "coincide" in messages.text
    line.SetNthControlPointPositionWorld(1, 0.0, 0.0, 0.0)
    assert session.SetGuideLine(line)
    assert session.GetForceModel().GetGuideEnabled()

    # An unplugged device cannot start a session; nothing is cut.
    device.SetPlugged(False)
    with VtkMessages() as messages:
        assert not session.Start(cut, device)
    assert "could not be opened" in messages.text
    device.SetPlugged(True)
    assert session.Start(cut, device)
    with VtkMessages() as messages:
        assert not session.Start(cut, device)
        assert not session.SetGuideLine(line)
    assert "running already" in messages.text and "stop the haptic session first" in messages.text
    session.Stop()
    assert logic.GetRemovedVolume(cut) == 0.0


def test_guided_drilling_keeps_the_tool_on_the_axis():
    application, logic, cut = block_scene()
    tool = add_burr(application.scene, cut)
    place(tool, [-14.0, 0.0, 0.0])
    line = application.scene.AddNewNodeByClass("vtkMRMLMarkupsLineNode", "Guide")
    line.AddControlPointWorld(vtk.vtkVector3d(-14.0, 0.0, 0.0))
    line.AddControlPointWorld(vtk.vtkVector3d(0.0, 0.0, 0.0))
    device = slicer.vtkVirtualHapticDevice()
    session = slicer.vtkSlicerVolumeCuttingHapticSession()
    session.SetLogic(logic)
    assert session.SetGuideLine(line)
    assert session.Start(cut, device)
    forces = []
    try:
        # The hand drifts 2 mm off the axis (in y) in air: the fixture pulls it back.
        for frame in range(31):
            device.SetPose([0.0, 2.0 * frame / 30, 0.0], 0)
            time.sleep(DISPLAY_PERIOD_S / 4)
            session.Update()
            force = [0.0, 0.0, 0.0]
            session.GetLoop().GetLatestForce(force)
            forces.append(force)
    finally:
        session.Stop()
    assert forces[-1][1] < -0.1
    assert abs(forces[-1][0]) < abs(forces[-1][1])


def test_main_job_haptics_replays_a_recorded_session_through_the_loop(tmp_path):
    application, logic, cut = block_scene()
    # The plan of a cavity at the block's left face, drilled along +x.
    plan = SimpleNamespace(entry=np.array([-7.5, 0.0, 0.0]), direction=np.array([1.0, 0.0, 0.0]), surface_radius=2.0)
    modified, tag = count_events(cut, slicer.vtkMRMLVolumeCutNode.CutModifiedEvent)
    summary = hapticsjob.run(application, cut, plan, tmp_path)
    cut.RemoveObserver(tag)
    assert (tmp_path / "haptic_session.vchr").is_file() and (tmp_path / "haptic_replay.vchr").is_file()
    assert summary["tool"] == "Haptic burr (created)"
    # Every recorded tick went through the loop; the pedal cut strokes.
    assert summary["ticks_run"] >= summary["ticks_recorded"] > 4000
    assert summary["drill_presses"] == 1 and summary["cut_strokes"] > 100
    assert summary["ticks_drilling"] >= 2400
    assert summary["removed_volume_mm3"] > 5.0
    assert logic.GetRemovedVolume(cut) == pytest.approx(summary["removed_volume_mm3"], abs=0.01)
    # The burr went into the bone, pushed back, and the views were told.
    assert summary["burr_centre_depth_below_surface_mm"] > 1.0
    assert summary["force_max_n"] > 0.5
    assert summary["cut_modified_events"] == modified["n"] > 0
    assert summary["display_frames"] > 100
    # The tool node ended where the hand withdrew to (the standoff, in air).
    surface = np.array(summary["surface_ras_mm"])
    assert np.allclose(summary["tool_node_moved_to_ras_mm"], surface - hapticsjob.STANDOFF_MM * plan.direction, atol=0.5)

    # The replay is deterministic: the recorded forces come back tick for tick.
    first = slicer.vtkHapticRecorder()
    assert first.ReadFile(str(tmp_path / "haptic_replay.vchr"))
    assert first.GetNumberOfTicks() == summary["ticks_run"]

    # The machine's share, measured after the replay: as many ticks of the replay's own work, tick by tick, as
    # arithmetic, with the views drawing as they did; slow ticks counted as the replay's are.
    machine, profile = summary["machine_check"], summary["tick_profile"]
    assert machine["ticks"] == summary["ticks_run"]
    assert machine["work_us_mean_calibrated"] == pytest.approx(profile["mean_us"]["cpu_us"], rel=0.3, abs=3.0)
    assert machine["work_us_p50"] == pytest.approx(profile["p50_us"]["cpu_us"], rel=0.5, abs=5.0)
    assert machine["display_frames"] == 0  # no views here: the check sleeps a display period between updates
    assert 0 <= machine["slow_ticks_processor_bound"] <= machine["slow_ticks"] <= machine["ticks"]
    assert machine["tick_us_p50"] <= machine["tick_us_p99"] <= machine["tick_us_max"]
    # Overruns slept through (woken late) are among the overruns, in the loop's figures and the check's alike.
    for figures in (summary, machine):
        assert 0 <= figures["overruns_woken_late"] <= figures["overruns"]
        assert figures["wake_up_lateness_us_max"] >= 0.0
    # The force model's pace per lookup, and each slowest tick's against it.
    assert profile["lookup_us_median"] > 0.0
    assert profile["most_lookups_at_median_pace_us"] == pytest.approx(
        profile["max_us"]["samples"] * profile["lookup_us_median"], rel=0.01)
    assert all(tick["pace_ratio"] is None or tick["pace_ratio"] > 0.0 for tick in profile["slowest"])
    # The lookups by kind: the cut field's among them once the burr has cut, each costlier than a CT-only one.
    assert 0 < profile["max_us"]["cut_samples"] <= profile["max_us"]["samples"]
    fixed, per_ct, per_cut = profile["own_work_fit_us"]
    assert per_cut > 0.0 and profile["longest_own_work_us"] > 0.0
    assert all(tick["own_work_us"] is not None for tick in profile["slowest"])


def test_the_haptic_thread_neither_cuts_nor_builds_shield_bricks_with_its_cutter_and_preparer(tmp_path):
    """A replay towards a protected nerve: the cutter cuts off the haptic thread, the shield is built ahead, the same cut."""
    application, logic, cut = block_scene()
    # Drilled from the block's right face along -x, 2.5 mm above the nerve's axis: the burr grazes the nerve.
    plan = SimpleNamespace(entry=np.array([7.5, 0.0, 10.5]), direction=np.array([-1.0, 0.0, 0.0]), surface_radius=2.0)
    protection = logic.GetCutField(cut).GetProtection()
    summaries = {}
    for off_thread in (False, True):
        logic.ClearCut(cut)
        protection.ClearBricks()
        (tmp_path / str(off_thread)).mkdir()
        summaries[off_thread] = hapticsjob.run(application, cut, plan, tmp_path / str(off_thread),
                                               prepare_shield_ahead=off_thread, asynchronous_cutting=off_thread,
                                               check_machine=False)
    in_ticks, off = summaries[False], summaries[True]
    assert in_ticks["protected_segments"] == off["protected_segments"] == 1
    # Cutting in the ticks without the preparer, the ticks that first reach the nerve's band build its shield themselves.
    assert in_ticks["shield_bricks_built_in_ticks"] > 0 and in_ticks["ticks_building_shield"] > 0
    assert in_ticks["tick_profile"]["max_us"]["shield_bricks_built"] > 0
    assert in_ticks["cutter_us_p99"] == 0.0 and in_ticks["tick_profile"]["max_us"]["cut_us"] > 0.0
    # With the cutter and the preparer no tick cut or built anything: the cutter cut every segment the ticks queued.
    assert off["asynchronous_cutting"] and off["cutter_us_p99"] > 0.0
    assert off["shield_bricks_built_in_ticks"] == 0 and off["ticks_building_shield"] == 0
    assert off["tick_us_max_building_shield"] == 0.0 and off["tick_profile"]["max_us"]["shield_bricks_built"] == 0
    assert off["shield_bricks_prepared_ahead"] > 0 and in_ticks["shield_bricks_prepared_ahead"] == 0
    assert off["cut_strokes"] > 100 and off["drill_presses"] == 1
    # The same shield and the same strokes: the same cut (the force reads the field a moment behind the cutter,
    # which may move the burr by a fraction of a sample), nothing of the nerve removed.
    assert off["removed_volume_mm3"] == pytest.approx(in_ticks["removed_volume_mm3"], rel=0.02)
    assert off["removed_volume_mm3"] > 1.0
    assert logic.GetRemovedVolumeInSegment(cut, "Nerve") == 0.0


def test_the_idle_loop_measures_the_machine_alone():
    """The no-op 1 kHz loop that tells the machine's scheduling noise from a tick's cost."""
    idle = hapticsjob.idle_loop(0.3)
    assert 200 <= idle["ticks_run"] <= 400
    assert 0.0 < idle["tick_us_p50"] <= idle["tick_us_p99"] <= idle["tick_us_max"]
    profile = idle["profile"]
    assert profile["ticks"] == idle["ticks_run"]
    # It neither cuts nor monitors: its ticks are a device read and a force-model step in air.
    assert profile["max_us"]["cut_us"] == 0.0 and profile["max_us"]["nerve_monitor_us"] == 0.0
    assert profile["max_us"]["shield_bricks_built"] == 0.0
    assert len(profile["slowest"]) == 5 and profile["slowest"][0]["tick_us"] == idle["tick_us_max"]
