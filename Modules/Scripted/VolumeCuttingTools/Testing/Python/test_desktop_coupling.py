"""The desktop panel's instructor coupling (collaboration.desktopcoupling) on a real scene with real haptic loops.

Two controllers in one process on 127.0.0.1, as two desktop Slicers would be:
the trainee's couples its running Drill (the mouse's virtual device, the
logic's haptic session on the bone plate of ``data.boneplate``), the
instructor's holds a virtual device over the same CT. The trainee's hand is
simulated as a compliant one (it gives way along the force its device
renders), so that "pulled toward the instructor's tool" is a position the
trainee's tool node reaches, not only a force's sign. Each wait has a
deadline; nothing counts what a fixed sleep yields.
"""

import socket
import time

import numpy as np
import pytest
import slicer
import vtk

from VolumeCuttingLib.collaboration import desktopcoupling
from VolumeCuttingLib.collaboration.desktopcoupling import INSTRUCTOR, OFF, TRAINEE, CouplingInputError, DesktopCoupling
from VolumeCuttingLib.config import inputdevices, toolconfig
from VolumeCuttingLib.config.hapticdrilling import HapticDrilling
from VolumeCuttingLib.data import boneplate
from VolumeCuttingLib.scene import nodes
from VolumeCuttingLib.scene.application import HeadlessSlicer

MOUSE = inputdevices.MOUSE_DEVICE_ID
#: The two tools in air before the plate's near face (x = -5.25 mm); the 4 mm burr reaches 2 mm around its centre.
TRAINEE_AT = np.array([-8.0, -1.5, 0.0])
INSTRUCTOR_AT = np.array([-8.0, 1.5, 0.0])
#: The simulated trainee's hand gives way this much (mm) per newton at each display tick.
COMPLIANCE_MM_PER_N = 0.2
DISPLAY_PERIOD_S = 0.016


def burr(scene, name):
    preset = next(p for p in toolconfig.load_presets() if p.name == "Cutting burr 4 mm")
    return toolconfig.create_tool_node(scene, toolconfig.from_preset(preset), name=name)


def place(tool, position):
    matrix = vtk.vtkMatrix4x4()
    for axis in range(3):
        matrix.SetElement(axis, 3, float(position[axis]))
    tool.GetParentTransformNode().SetMatrixTransformToParent(matrix)
    return tool


def tool_position(tool):
    matrix = vtk.vtkMatrix4x4()
    tool.GetParentTransformNode().GetMatrixTransformToWorld(matrix)
    return np.array([matrix.GetElement(axis, 3) for axis in range(3)])


@pytest.fixture
def desk():
    """The trainee drilling the plate with the mouse, an offscreen 3D view, the instructor's tool node."""
    application = HeadlessSlicer()
    tool = burr(application.scene, "Trainee's burr")
    cut = boneplate.plate_with_nerve(application, tool)
    place(tool, TRAINEE_AT)
    renderer, window = vtk.vtkRenderer(), vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.AddRenderer(renderer)
    interactor = vtk.vtkGenericRenderWindowInteractor()
    interactor.SetRenderWindow(window)
    drilling = HapticDrilling(application.volume_cutting_logic)
    drilling.start(cut, MOUSE, renderer, interactor)
    sides = []
    desk = dict(application=application, cut=cut, tool=tool, drilling=drilling, renderer=renderer,
                interactor=interactor, volume=cut.GetAnatomyVolumeNode(), sides=sides,
                guide_tool=place(burr(application.scene, "Instructor's burr"), INSTRUCTOR_AT))
    yield desk
    for side in sides:
        side.stop()
    drilling.stop()


def side(desk) -> DesktopCoupling:
    coupling = DesktopCoupling()
    desk["sides"].append(coupling)
    return coupling


def start_instructor(desk, coupling, port, volume=None):
    return coupling.start(INSTRUCTOR, peer=f"127.0.0.1:{port}", volume=volume or desk["volume"], device=MOUSE,
                          renderer=desk["renderer"], interactor=desk["interactor"], tool_node=desk["guide_tool"])


def wait_for(condition, seconds=10.0):
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.01)
    return condition()


def test_coupled_the_trainees_tool_is_pulled_to_the_instructors_and_stop_detaches_cleanly(desk):
    drilling, tool = desk["drilling"], desk["tool"]
    trainee, instructor = side(desk), side(desk)
    waiting = trainee.start(TRAINEE, port=0, drilling=drilling)
    assert waiting.state == "waiting" and waiting.local_port > 0 and "Waiting for the instructor" in waiting.text
    end = trainee.end
    assert drilling.running and drilling.coupling is end and drilling.session.GetLoop().GetCoupling() is end.coupling
    time.sleep(DISPLAY_PERIOD_S)
    drilling.update()  # the Drill started again with the coupling: the tool stays where it was until the hand moves
    assert np.allclose(tool_position(tool), TRAINEE_AT)
    start_instructor(desk, instructor, waiting.local_port)
    instructor.device.SetPose([0.0, 0.0, 0.0], 0)  # the instructor's tool at its burr's place
    assert wait_for(lambda: trainee.status().state == "coupled" and instructor.status().state == "coupled")
    # Both hands still, 3 mm apart along A: the instructor's device is pulled toward the trainee's tool (-A).
    force = [0.0, 0.0, 0.0]
    assert wait_for(lambda: instructor.device.GetCommandedForce(force) or force[1] < -0.5)
    assert abs(force[0]) < 0.05 * abs(force[1]) and abs(force[2]) < 0.05 * abs(force[1])
    seen = instructor.status()
    assert seen.distance_mm == pytest.approx(3.0, abs=0.05) and seen.force_N <= seen.device_limit_N
    assert "Coupled with the trainee at 127.0.0.1" in seen.text and "device limit 8.0 N" in seen.text
    # The instructor's panel may not Drill meanwhile; the trainee's may (it does).
    assert "does not drill" in instructor.refuses_drill() and trainee.refuses_drill() is None

    # The trainee's compliant hand gives way to its device's force: the tool node reaches the instructor's tool.
    hand = np.zeros(3)
    largest = 0.0

    def pulled():
        nonlocal hand, largest
        drilling.device.GetCommandedForce(force)
        largest = max(largest, float(np.linalg.norm(force)))
        hand = hand + COMPLIANCE_MM_PER_N * np.array(force)
        drilling.device.SetPose(list(hand), 0)
        time.sleep(DISPLAY_PERIOD_S)
        drilling.update()
        return np.linalg.norm(tool_position(tool) - INSTRUCTOR_AT) < 0.3

    assert wait_for(pulled), tool_position(tool)
    assert largest <= drilling.device.GetCapabilities().GetMaximumForce()
    coupled = trainee.status()
    assert coupled.state == "coupled" and coupled.distance_mm < 0.5 and coupled.packets_per_s > 100.0
    assert coupled.missing_percent is None or 0.0 <= coupled.missing_percent <= 100.0
    assert desk["application"].volume_cutting_logic.GetRemovedVolume(desk["cut"]) == 0.0  # in air: nothing cut

    # Stop on the trainee's side: the Drill goes on uncoupled, the socket is closed, the instructor sees it gone.
    assert trainee.stop().state == OFF
    assert drilling.running and drilling.coupling is None and drilling.session.GetLoop().GetCoupling() is None
    assert not end.transport.IsOpen() and not trainee.running
    assert wait_for(lambda: instructor.status().state == "gone")
    assert "is gone" in instructor.status().text
    guide_end, guide_device, guide_loop = instructor.end, instructor.device, instructor.loop
    assert instructor.stop().state == OFF
    assert not guide_loop.IsRunning() and guide_loop.GetCoupling() is None
    assert not guide_end.transport.IsOpen() and not guide_device.IsConnected()
    assert trainee.stop().state == OFF  # stopping twice is harmless


def test_an_instructor_with_another_scan_is_refused_with_the_message(desk):
    other = slicer.vtkMRMLScene()
    array = nodes.array_from_volume_node(desk["volume"]).copy()
    array[3, 3, 3] += 1  # one voxel differs
    another = nodes.create_scalar_volume_node(other, array, nodes.volume_node_ijk_to_ras(desk["volume"]), "CT")
    trainee, instructor = side(desk), side(desk)
    port = trainee.start(TRAINEE, port=0, drilling=desk["drilling"]).local_port
    start_instructor(desk, instructor, port, volume=another)
    assert wait_for(lambda: instructor.status().state == "refused" and trainee.status().state == "refused")
    for snapshot in (instructor.status(), trainee.status()):
        assert snapshot.refused_other_scan > 0 and "Load the same CT on both sides" in snapshot.text
        assert "loaded another scan" in snapshot.text and snapshot.force_N == 0.0
    force = [0.0, 0.0, 0.0]
    desk["drilling"].device.GetCommandedForce(force)
    assert force == [0.0, 0.0, 0.0]
    assert trainee.end.status()["packets_accepted"] == 0


def refused(coupling, match, **arguments):
    with pytest.raises(CouplingInputError, match=match):
        coupling.start(**arguments)
    assert not coupling.running and coupling.status().state == OFF


def test_bad_input_is_refused_with_a_message_and_nothing_changes(desk):
    drilling = desk["drilling"]
    coupling = side(desk)
    assert coupling.status().text == "Off."
    refused(coupling, "choose a side first", role=OFF)
    for port in (70000, -1, "abc", "", True):
        refused(coupling, "give a port from 1 to 65535", role=TRAINEE, port=port, drilling=drilling)
    refused(coupling, "no haptic session is running", role=TRAINEE, port=47000, drilling=None)
    idle = HapticDrilling(desk["application"].volume_cutting_logic)
    refused(coupling, "no haptic session is running", role=TRAINEE, port=47000, drilling=idle)
    taken = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    taken.bind(("127.0.0.1", 0))
    try:
        session = drilling.session
        refused(coupling, f"UDP port {taken.getsockname()[1]} is in use", role=TRAINEE, port=taken.getsockname()[1],
                drilling=drilling)
    finally:
        taken.close()
    # The Drill was not touched: the same session runs, uncoupled.
    assert drilling.session is session and drilling.running and drilling.coupling is None
    for peer in ("127.0.0.1", "127.0.0.1:0", ":47000", "127.0.0.1:port", "127.0.0.1:65536"):
        refused(coupling, "expected HOST:PORT", role=INSTRUCTOR, peer=peer, volume=desk["volume"], device=MOUSE,
                renderer=desk["renderer"], interactor=desk["interactor"])
    refused(coupling, "stop the Drill first", role=INSTRUCTOR, peer="127.0.0.1:47000", drilling=drilling,
            volume=desk["volume"], device=MOUSE, renderer=desk["renderer"], interactor=desk["interactor"])
    empty = slicer.vtkMRMLScalarVolumeNode()
    for volume in (None, empty):
        refused(coupling, "no scan is loaded", role=INSTRUCTOR, peer="127.0.0.1:47000", volume=volume, device=MOUSE,
                renderer=desk["renderer"], interactor=desk["interactor"])
    refused(coupling, "not plugged in", role=INSTRUCTOR, peer="127.0.0.1:47000", volume=desk["volume"],
            device="/dev/hidraw-gone")
    refused(coupling, "3D view", role=INSTRUCTOR, peer="127.0.0.1:47000", volume=desk["volume"], device=MOUSE)
    coupling.start(TRAINEE, port=0, drilling=drilling)
    with pytest.raises(CouplingInputError, match="runs already"):
        coupling.start(TRAINEE, port=0, drilling=drilling)
    assert coupling.running and drilling.coupling is coupling.end


def test_an_instructor_nobody_answers_keeps_waiting_and_says_what_to_check(desk, monkeypatch):
    monkeypatch.setattr(desktopcoupling, "ANSWER_WAIT_S", 0.2)
    silent = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    silent.bind(("127.0.0.1", 0))  # a port that takes the packets and never answers
    try:
        instructor = side(desk)
        port = silent.getsockname()[1]
        first = start_instructor(desk, instructor, port)
        assert first.state == "waiting" and f"Waiting for the trainee at 127.0.0.1:{port}" in first.text
        assert "Nobody answered" not in first.text
        assert wait_for(lambda: "Nobody answered" in instructor.status().text)
        later = instructor.status()
        assert later.state == "waiting" and later.running and f"UDP port {port} is open" in later.text
    finally:
        silent.close()


def test_the_drill_stopped_ends_the_trainees_coupling(desk):
    drilling = desk["drilling"]
    trainee = side(desk)
    trainee.start(TRAINEE, port=0, drilling=drilling)
    end = trainee.end
    drilling.stop()
    ended = trainee.status()
    assert ended.state == "ended" and not ended.running and "the drilling stopped" in ended.text
    assert not end.transport.IsOpen() and not trainee.running
