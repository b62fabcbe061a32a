"""The tool panel's "Drill with this device": VolumeCuttingLib.config.hapticdrilling on a real scene and view.

The mouse, chosen as the panel lists it, drills the block of
test_haptic_session in a real offscreen 3D view through the real haptic loop;
Stop gives the mouse back to the camera and keeps the cut. Devices that
cannot drive the drill, or cannot start, are refused with a reason and leave
nothing running.
"""

import time

import pytest

from test_haptic_mouse_driver import CAMERA_X, SIZE, START, event, view
from test_haptic_session import DISPLAY_PERIOD_S, add_burr, block_scene, place, tool_position
from VolumeCuttingLib.config import inputdevices
from VolumeCuttingLib.config.hapticdrilling import HapticDrilling, HapticDrillingError
from VolumeCuttingLib.config.inputdevices import FOOT_SWITCH, HAPTIC, SIX_DOF, InputDevice


def run_frames(drilling, seconds):
    """The panel's display-rate timer."""
    for _ in range(max(1, int(seconds / DISPLAY_PERIOD_S))):
        time.sleep(DISPLAY_PERIOD_S)
        drilling.update()


def test_the_listed_mouse_drills_and_stop_gives_the_mouse_back_to_the_camera():
    application, logic, cut = block_scene()
    tool = add_burr(application.scene, cut)
    place(tool, START)
    renderer, window, interactor = view()
    drilling = HapticDrilling(logic)
    mouse = next(device for device in inputdevices.list_devices() if device.device_id == inputdevices.MOUSE_DEVICE_ID)
    drilling.start(cut, mouse.device_id, renderer, interactor)
    try:
        assert drilling.running and not drilling.drilling  # the drill runs only while its button is held
        with pytest.raises(HapticDrillingError, match="running already"):
            drilling.start(cut, mouse.device_id, renderer, interactor)
        event(interactor, "MouseMoveEvent", SIZE // 2, SIZE // 2)
        event(interactor, "LeftButtonPressEvent", SIZE // 2, SIZE // 2)
        for _ in range(13):
            event(interactor, "MouseWheelForwardEvent", SIZE // 2, SIZE // 2)
            run_frames(drilling, 0.05)
        run_frames(drilling, 0.3)
        assert drilling.drilling  # what the desktop's drill sound follows
        event(interactor, "LeftButtonReleaseEvent", SIZE // 2, SIZE // 2)
        run_frames(drilling, 0.05)
        assert not drilling.drilling
        assert tool_position(tool)[0] + 2.0 > -7.5  # the burr went past the block's face
    finally:
        drilling.stop()
    assert not drilling.running
    removed = logic.GetRemovedVolumeInSegment(cut, "Bone")
    assert removed > 0.0
    # The mouse turns the camera again; the cut stays.
    event(interactor, "MouseMoveEvent", 100, 100)
    event(interactor, "LeftButtonPressEvent", 100, 100)
    event(interactor, "MouseMoveEvent", 150, 120)
    event(interactor, "LeftButtonReleaseEvent", 150, 120)
    assert renderer.GetActiveCamera().GetPosition() != pytest.approx((CAMERA_X, 0.0, 0.0), abs=1.0)
    assert logic.GetRemovedVolumeInSegment(cut, "Bone") == removed


def refused(drilling, cut, device, match, **kwargs):
    with pytest.raises(HapticDrillingError, match=match):
        drilling.start(cut, device, **kwargs)
    assert not drilling.running
    assert drilling.session is None and drilling.device is None and drilling.mouse_driver is None


def test_devices_that_cannot_drive_the_drill_are_refused_with_a_reason():
    application, logic, cut = block_scene()
    drilling = HapticDrilling(logic)
    renderer, window, interactor = view()
    # No tool yet: the session's own reason reaches the user.
    refused(drilling, cut, inputdevices.MOUSE_DEVICE_ID, "no active tool", renderer=renderer, interactor=interactor)
    add_burr(application.scene, cut)
    refused(drilling, None, inputdevices.MOUSE_DEVICE_ID, "no volume-cut node")
    refused(drilling, cut, inputdevices.MOUSE_DEVICE_ID, "3D view")
    refused(drilling, cut, "/dev/hidraw-that-was-unplugged", "not plugged in")
    pedal = InputDevice("/dev/hidraw-pedal", "PCsensor foot switch", FOOT_SWITCH, "hidapi", 0x0C45, 0x7403)
    refused(drilling, cut, pedal, "foot switch: it runs the drill but cannot move it")
    falcon = InputDevice("usb:1:7", "Novint Falcon", HAPTIC, "libusb", 0x0403, 0xCB48)
    refused(drilling, cut, falcon, "needs its firmware file")
    refused(drilling, cut, falcon, "is not a file", falcon_firmware="/nonexistent/falcon_firmware.bin")
    # A SpaceMouse whose hidraw node is gone: its backend's reason (hidapi could not open the path).
    spacemouse = InputDevice("/dev/hidraw-gone", "3Dconnexion SpaceMouse Pro Wireless (cable)", SIX_DOF, "hidapi", 0x256F, 0xC632)
    refused(drilling, cut, spacemouse, "'/dev/hidraw-gone' could not be opened")
    # The mouse with a foot switch that is no longer there: nothing starts, the mouse stays the camera's.
    refused(drilling, cut, inputdevices.MOUSE_DEVICE_ID, "not plugged in", renderer=renderer, interactor=interactor,
            foot_switch="/dev/hidraw-pedal-gone")
    assert logic.GetRemovedVolume(cut) == 0.0


def test_the_drill_takes_a_force_coupling_and_gives_it_back_at_stop():
    """The desktop Drill coupled to an instructor: attached before the loop starts, detached when it stops; a port
    in use stops the Drill from starting and leaves nothing running."""
    from VolumeCuttingLib.collaboration import forcecoupling

    application, logic, cut = block_scene()
    place(add_burr(application.scene, cut), START)
    renderer, window, interactor = view()
    frame = forcecoupling.scan_fingerprint(cut.GetAnatomyVolumeNode())
    drilling = HapticDrilling(logic)
    end = forcecoupling.ForceCoupling(forcecoupling.CouplingSettings(local_port=0, peer_port=0, frame_fingerprint=frame))
    drilling.start(cut, inputdevices.MOUSE_DEVICE_ID, renderer, interactor, coupling=end)
    try:
        assert drilling.running and drilling.session.GetLoop().GetCoupling() is end.coupling
        assert end.status()["frame"] == frame and end.transport.IsOpen()
        taken = forcecoupling.ForceCoupling(forcecoupling.CouplingSettings(local_port=end.local_port, peer_port=0))
        second = HapticDrilling(logic)
        refused(second, cut, inputdevices.MOUSE_DEVICE_ID, "could not bind", renderer=renderer, interactor=interactor,
                coupling=taken)
        assert second.coupling is None
    finally:
        drilling.stop()
    assert not end.transport.IsOpen() and drilling.coupling is None
