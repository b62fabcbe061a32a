"""Forces forwarded between drilling sessions: the desktop Drill's session coupled to an instructor over loopback.

The trainee drills the bone block through the logic's haptic session (its loop
on its own thread, the device placed where the tool is, 1.5 scene mm per device
mm), the coupling attached to the session's loop as Docs/Collaboration.md shows; the instructor's side is a guide loop
(``forcecoupling.guide_loop``) whose device is placed in the same CT's RAS turned
and offset. Both exchange their tools in RAS: the trainee's coupling holds the
instructor's tool where it is in the CT whatever either placement, and the
trainee's device is pushed toward it along its own axes. A CT that differs is
refused on both sides with a message saying so. The guided drilling itself
(the pull, the cut, the protection, the energy bound under delay and loss) is
vtkHapticCouplingDrillingTest1's, ticked in lockstep.
"""

import time

import numpy as np
import slicer
import vtk

from test_haptic_session import add_burr, block_scene, place
from VolumeCuttingLib.collaboration import forcecoupling
from VolumeCuttingLib.scene import nodes

#: Where the instructor holds its tool (RAS mm): 3 mm right of the trainee's tool, both in air beside the block.
GUIDE_RAS = np.array([-11.0, 1.0, -1.0])
TRAINEE_START = np.array([-14.0, 0.0, 0.0])


def guide_placement():
    """The instructor's device in the CT: turned 30 degrees about A, 2 mm per device mm, centred elsewhere."""
    placement = vtk.vtkTransform()
    placement.Translate(-20.0, 5.0, 3.0)
    placement.RotateWXYZ(30.0, 0.0, 1.0, 0.0)
    placement.Scale(2.0, 2.0, 2.0)
    return placement.GetMatrix()


def start_pair(guide_scan=lambda volume: volume):
    """The trainee drilling, the instructor's guide loop running; the guide's frame is that of ``guide_scan(CT)``."""
    application, logic, cut = block_scene()
    tool = add_burr(application.scene, cut)
    place(tool, TRAINEE_START)
    volume = cut.GetAnatomyVolumeNode()
    frame = forcecoupling.scan_fingerprint(volume)
    ports = forcecoupling.free_loopback_ports(2)
    trainee_end = forcecoupling.ForceCoupling(forcecoupling.CouplingSettings(
        local_port=ports[0], peer_port=ports[1], frame_fingerprint=frame))
    guide_end = forcecoupling.ForceCoupling(forcecoupling.CouplingSettings(
        local_port=ports[1], peer_port=ports[0], frame_fingerprint=forcecoupling.scan_fingerprint(guide_scan(volume))))
    for end in (trainee_end, guide_end):
        end.coupling.SetEngageTime(0.0)
    trainee_device = slicer.vtkVirtualHapticDevice()
    session = slicer.vtkSlicerVolumeCuttingHapticSession()
    session.SetLogic(logic)
    session.SetDeviceScale(1.5)
    trainee_end.attach(session.GetLoop())
    assert session.Start(cut, trainee_device)
    trainee_device.SetPose([0.0, 0.0, 0.0], 0)  # the hand at the device's centre: the tool where it was placed
    guide_device = slicer.vtkVirtualHapticDevice()
    assert guide_device.Open()
    placement = guide_placement()
    inverse = vtk.vtkMatrix4x4()
    vtk.vtkMatrix4x4.Invert(placement, inverse)
    guide_device.SetPose(list(inverse.MultiplyPoint([*GUIDE_RAS, 1.0])[:3]), 0)
    guide, model = forcecoupling.guide_loop(guide_device, placement)
    guide_end.attach(guide)
    assert guide.Start()
    return application, session, trainee_device, trainee_end, guide, guide_end, model


def wait_for(condition, seconds=10.0):
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline and not condition():
        time.sleep(0.01)
    return condition()


def stop_pair(session, trainee_end, guide, guide_end):
    guide.Stop()
    guide_end.detach()
    session.Stop()
    trainee_end.detach()


def test_the_trainee_feels_the_instructors_tool_where_it_is_in_the_ct():
    application, session, device, trainee_end, guide, guide_end, model = start_pair()
    try:
        assert wait_for(lambda: trainee_end.status()["packets_accepted"] > 20 and guide_end.status()["packets_accepted"] > 20)
        peer = [0.0, 0.0, 0.0]
        assert trainee_end.coupling.GetLatestPeerPosition(peer)
        # The instructor's tool as the trainee's side holds it: the RAS point, through a turned, scaled, offset placement.
        assert np.allclose(peer, GUIDE_RAS, atol=1e-6)
        force = [0.0, 0.0, 0.0]
        assert wait_for(lambda: (device.GetCommandedForce(force) or np.linalg.norm(force) > 0.1))
        # The trainee's device (axes along RAS) is pushed toward the instructor's tool, 3 mm to its right (+R).
        assert force[0] > 0.9 * np.linalg.norm(force)
        status = trainee_end.status()
        assert status["frame"] == forcecoupling.scan_fingerprint(session.GetCutNode().GetAnatomyVolumeNode())
        assert status["frame_mismatches"] == 0
    finally:
        stop_pair(session, trainee_end, guide, guide_end)
    assert not trainee_end.transport.IsOpen()


def test_a_different_ct_is_refused_on_both_sides_with_a_message():
    other = slicer.vtkMRMLScene()
    changed = {}

    def another_scan(volume):
        array = nodes.array_from_volume_node(volume).copy()
        array[3, 3, 3] += 1  # one voxel differs
        changed["node"] = nodes.create_scalar_volume_node(other, array, nodes.volume_node_ijk_to_ras(volume), "CT")
        return changed["node"]

    application, session, device, trainee_end, guide, guide_end, model = start_pair(another_scan)
    foreign = forcecoupling.scan_fingerprint(changed["node"])
    try:
        assert wait_for(lambda: trainee_end.status()["frame_mismatches"] > 20 and guide_end.status()["frame_mismatches"] > 20)
        trainee, instructor = trainee_end.status(), guide_end.status()
        assert trainee["packets_accepted"] == 0 and instructor["packets_accepted"] == 0
        assert trainee["refused_frame"] == foreign and instructor["refused_frame"] == trainee["frame"]
        force = [0.0, 0.0, 0.0]
        trainee_end.coupling.GetLatestForce(force)
        assert force == [0.0, 0.0, 0.0]
        message = forcecoupling.describe_mismatch(instructor, "the trainee")
        assert "loaded another scan" in message and "Load the same CT" in message
    finally:
        stop_pair(session, trainee_end, guide, guide_end)
