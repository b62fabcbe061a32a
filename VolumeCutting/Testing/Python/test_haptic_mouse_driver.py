"""The mouse in a 3D view drills through the haptic session: vtkVirtualHapticDeviceMouseDriver.

A real offscreen view (render window, renderer, interactor with the
trackball-camera style) looks at the CT block of test_haptic_session along
+x; mouse events go through the interactor as a desktop view's would. The
driver moves the virtual device, the real haptic loop (its own thread, 1 kHz)
cuts, and the session's Update moves the tool node at display rate.
"""

import math
import time
from types import SimpleNamespace

import numpy as np
import pytest
import slicer
import vtk

from test_haptic_session import DISPLAY_PERIOD_S, add_burr, block_scene, place, tool_position

SIZE = 200
CAMERA_X = -60.0
START = np.array([-14.0, 0.0, 0.0])  # 6.5 mm left of the block's face at x = -7.5, in air


def view():
    renderer = vtk.vtkRenderer()
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(SIZE, SIZE)
    window.AddRenderer(renderer)
    interactor = vtk.vtkGenericRenderWindowInteractor()
    interactor.SetRenderWindow(window)
    interactor.SetInteractorStyle(vtk.vtkInteractorStyleTrackballCamera())
    camera = renderer.GetActiveCamera()
    camera.SetPosition(CAMERA_X, 0.0, 0.0)
    camera.SetFocalPoint(0.0, 0.0, 0.0)
    camera.SetViewUp(0.0, 0.0, 1.0)
    camera.SetViewAngle(30.0)
    camera.SetClippingRange(1.0, 500.0)
    window.Render()
    return renderer, window, interactor


def event(interactor, name, x, y, shift=False):
    interactor.SetEventInformation(x, y, 0, 1 if shift else 0)
    interactor.InvokeEvent(name)


def run_frames(session, seconds):
    for _ in range(max(1, int(seconds / DISPLAY_PERIOD_S))):
        time.sleep(DISPLAY_PERIOD_S)
        session.Update()


def world_to_device(session):
    device_to_world = vtk.vtkMatrix4x4()
    session.GetLoop().GetDeviceToRAS(device_to_world)
    world_to_device = vtk.vtkMatrix4x4()
    vtk.vtkMatrix4x4.Invert(device_to_world, world_to_device)
    return world_to_device


def drive_with_the_mouse(scale, wheel_step):
    """The block scene, a session started with a virtual device, and the view's mouse driving it."""
    application, logic, cut = block_scene()
    tool = add_burr(application.scene, cut)
    place(tool, START)
    device = slicer.vtkVirtualHapticDevice()
    session = slicer.vtkSlicerVolumeCuttingHapticSession()
    session.SetLogic(logic)
    session.SetDeviceScale(scale)
    renderer, window, interactor = view()
    driver = slicer.vtkVirtualHapticDeviceMouseDriver()
    assert session.Start(cut, device)
    try:
        assert driver.SetWorldToDevice(world_to_device(session))
        driver.SetInteractor(interactor)
        driver.SetDefaultRenderer(renderer)
        driver.SetDevice(device)
        driver.SetWheelStep(wheel_step)
        driver.SetEnabled(1)
        assert driver.GetEnabled()
    except BaseException:
        session.Stop()
        raise
    return SimpleNamespace(
        logic=logic,
        cut=cut,
        tool=tool,
        device=device,
        session=session,
        renderer=renderer,
        window=window,
        interactor=interactor,
        driver=driver,
    )


def test_the_mouse_moves_the_tool_and_its_left_button_drills():
    view_session = drive_with_the_mouse(scale=2.0, wheel_step=1.0)
    logic, cut, tool = view_session.logic, view_session.cut, view_session.tool
    device, session, driver = view_session.device, view_session.session, view_session.driver
    renderer, interactor = view_session.renderer, view_session.interactor
    try:
        # The tool follows the cursor on the plane x = -14 facing the camera.
        # Looking along +x with z up, the view's right is -y; the expectation
        # is the perspective camera's analytic projection. In air the loop's
        # proxy is the hand, so what separates the tool node from it is the
        # round-off of the matrices (the 0.01 mm bound is far above it and far
        # below the 0.5 mm voxel).
        event(interactor, "MouseMoveEvent", 130, 80)
        run_frames(session, 0.1)
        half = (START[0] - CAMERA_X) * math.tan(math.radians(15.0))
        expected = [START[0], -(2 * 130 / SIZE - 1) * half, (2 * 80 / SIZE - 1) * half]
        assert tool_position(tool) == pytest.approx(expected, abs=0.01)
        # Device frame: scene mm / DeviceScale about the workspace centre (the tool's start).
        position = [0.0, 0.0, 0.0]
        assert device.GetLatestPosition(position)
        assert position == pytest.approx(list((np.array(expected) - START) / 2.0), abs=1e-6)

        # Back on the axis; the wheel takes the tool 3 mm deeper, still in air.
        event(interactor, "MouseMoveEvent", SIZE // 2, SIZE // 2)
        for _ in range(3):
            event(interactor, "MouseWheelForwardEvent", SIZE // 2, SIZE // 2)
        run_frames(session, 0.1)
        assert tool_position(tool) == pytest.approx([START[0] + 3.0, 0.0, 0.0], abs=0.01)
        assert session.GetLoop().GetNumberOfCutStrokes() == 0

        # Left button down: the drill runs while the wheel pushes the hand 10 mm into the bone.
        event(interactor, "LeftButtonPressEvent", SIZE // 2, SIZE // 2)
        assert device.GetLatestButtons() == 1
        for _ in range(10):
            event(interactor, "MouseWheelForwardEvent", SIZE // 2, SIZE // 2)
            run_frames(session, 0.05)
        run_frames(session, 0.3)
        assert session.GetLoop().GetNumberOfDrillPresses() == 1
        assert session.GetLoop().GetNumberOfCutStrokes() > 0
        assert tool_position(tool)[0] + 2.0 > -7.5  # the burr went past the block's face

        # Up: the drill stops; pushing on cuts nothing more.
        event(interactor, "LeftButtonReleaseEvent", SIZE // 2, SIZE // 2)
        assert device.GetLatestButtons() == 0
        run_frames(session, 0.1)
        strokes = session.GetLoop().GetNumberOfCutStrokes()
        for _ in range(3):
            event(interactor, "MouseWheelForwardEvent", SIZE // 2, SIZE // 2)
        run_frames(session, 0.3)
        assert session.GetLoop().GetNumberOfCutStrokes() == strokes
        # The camera did not move: the driver took the left button and the wheel.
        assert renderer.GetActiveCamera().GetPosition() == pytest.approx((CAMERA_X, 0.0, 0.0))
    finally:
        session.Stop()
        driver.SetEnabled(0)
    assert logic.GetRemovedVolume(cut) > 0.0
    assert logic.GetRemovedVolumeInSegment(cut, "Bone") > 0.0

    # Disabled, the left drag turns the camera again and the device hears nothing.
    samples = device.GetNumberOfSamples()
    event(interactor, "MouseMoveEvent", 100, 100)
    event(interactor, "LeftButtonPressEvent", 100, 100)
    event(interactor, "MouseMoveEvent", 150, 120)
    event(interactor, "LeftButtonReleaseEvent", 150, 120)
    assert renderer.GetActiveCamera().GetPosition() != pytest.approx((CAMERA_X, 0.0, 0.0), abs=1.0)
    assert device.GetNumberOfSamples() == samples


def test_the_workspace_bounds_the_mouse():
    view_session = drive_with_the_mouse(scale=1.0, wheel_step=5.0)
    tool, device, session = view_session.tool, view_session.device, view_session.session
    interactor, driver = view_session.interactor, view_session.driver
    try:
        # 20 notches of 5 mm towards the viewer ask for 100 mm; the Falcon-like workspace is 40 mm.
        for _ in range(20):
            event(interactor, "MouseWheelBackwardEvent", SIZE // 2, SIZE // 2)
        run_frames(session, 0.1)
    finally:
        session.Stop()
        driver.SetEnabled(0)
    position = [0.0, 0.0, 0.0]
    assert device.GetLatestPosition(position)
    radius = device.GetCapabilities().GetWorkspaceRadius()
    assert np.linalg.norm(position) == pytest.approx(radius, abs=1e-9)
    assert driver.GetNumberOfClampedPositions() > 0
    assert tool_position(tool) == pytest.approx([START[0] - radius, 0.0, 0.0], abs=0.01)
