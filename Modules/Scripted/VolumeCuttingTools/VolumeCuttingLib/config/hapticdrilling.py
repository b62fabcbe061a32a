"""Drilling with the input device chosen in the tool panel: what its "Drill" button runs.

The panel lists the mouse and the known devices plugged in
(:func:`VolumeCuttingLib.config.inputdevices.list_devices`); :class:`HapticDrilling`
turns the chosen one into a haptic device, starts the logic's haptic session
(``vtkSlicerVolumeCuttingHapticSession``: the loop on its own thread, the
force model on what the view draws) on the cut node's active tool, and, for
the mouse, attaches ``vtkVirtualHapticDeviceMouseDriver`` to the 3D view so
that the pointer moves the drill, the wheel pushes it in depth and the left
button runs it. ``update`` is called at display rate (the desktop widget's
timer, or a web view's frame); ``stop`` ends the session and gives the mouse
back to the camera; ``restart`` starts it again as it was, with or without a
force coupling (the instructor coupling: ``collaboration.desktopcoupling``).
Qt-free: the desktop widget only connects a button and a timer to it.

Anything that cannot start (no tool, a device that does not open, a Falcon
without its firmware file, a foot switch chosen to move the drill) raises
:class:`HapticDrillingError` with a reason a user can act on, and leaves
nothing running and every cut made so far in place.
"""

from __future__ import annotations

from pathlib import Path

import slicer
import vtk

from . import inputdevices
from .inputdevices import FOOT_SWITCH, HAPTIC, MOUSE, SIX_DOF, InputDevice


class HapticDrillingError(RuntimeError):
    """A drilling session that could not start, with the reason."""


class _ErrorCollector:
    """VTK errors of the objects it watches, kept instead of printed: the reason a start failed."""

    def __init__(self):
        self.messages: list[str] = []
        self._observed: list[tuple[vtk.vtkObject, int]] = []

    def watch(self, obj) -> None:
        @vtk.calldata_type(vtk.VTK_STRING)
        def collect(caller, event, message):
            self.messages.append(" ".join(str(message).split()))

        self._observed.append((obj, obj.AddObserver(vtk.vtkCommand.ErrorEvent, collect)))

    def release(self) -> None:
        for obj, tag in self._observed:
            obj.RemoveObserver(tag)
        self._observed.clear()

    def reason(self, default: str) -> str:
        # VTK's messages start with where they were raised ("ERROR: In file, line ... Class (0x...): ").
        texts = [message.split("): ", 1)[-1] for message in self.messages]
        return "; ".join(texts) if texts else default


def resolve_device(device) -> InputDevice:
    """The InputDevice for a device_id (as the parameter node keeps it), or the device itself."""
    if isinstance(device, InputDevice):
        return device
    for listed in inputdevices.list_devices():
        if listed.device_id == device:
            return listed
    raise HapticDrillingError(f"the input device '{device}' is not plugged in (any more): refresh the device list and choose again")


class HapticDrilling:
    """A haptic drilling session on a cut node with a device the panel lists."""

    def __init__(self, logic):
        #: vtkSlicerVolumeCuttingLogic (the module's logic).
        self.logic = logic
        self.session = None
        self.device = None
        self.foot_switch = None
        self.mouse_driver = None
        self.coupling = None
        #: How the session was last started (restart starts it again so).
        self._started_with = None

    @property
    def running(self) -> bool:
        return self.session is not None and self.session.IsRunning()

    @property
    def drilling(self) -> bool:
        """Whether the drill runs now (the device's button or the foot switch, as the haptic loop last read it)."""
        return self.running and bool(self.session.GetLoop().GetDrilling())

    def start(self, cut_node, device, renderer=None, interactor=None, foot_switch=None, falcon_firmware=None,
              device_scale: float = 1.0, coupling=None) -> None:
        """Start drilling ``cut_node`` with its active tool, moved by ``device`` (an InputDevice or a device_id).

        The mouse needs the 3D view's ``renderer`` and ``interactor``; a
        Falcon needs ``falcon_firmware``, the firmware file the user has (it
        is not shipped); ``foot_switch`` (optional) runs the drill as well
        as the device's own button. ``coupling`` (optional, a
        ``collaboration.forcecoupling.ForceCoupling`` made with the CT's
        ``scan_fingerprint``) couples the session's loop to a peer's: it is
        attached before the loop starts and detached when the session stops.
        Raises HapticDrillingError.
        """
        if self.running:
            raise HapticDrillingError("a drilling session is running already: stop it first")
        if cut_node is None:
            raise HapticDrillingError("no volume-cut node: create a cut session on the CT first")
        chosen = resolve_device(device)
        collector = _ErrorCollector()
        try:
            self.device = make_device(chosen, renderer, interactor, falcon_firmware)
            self.foot_switch = self._make_foot_switch(foot_switch) if foot_switch is not None else None
            session = slicer.vtkSlicerVolumeCuttingHapticSession()
            session.SetLogic(self.logic)
            session.SetDeviceScale(device_scale)
            for watched in (session, session.GetLoop(), self.device, self.foot_switch):
                if watched is not None:
                    collector.watch(watched)
            if coupling is not None:
                try:
                    coupling.attach(session.GetLoop())
                except OSError as error:
                    raise HapticDrillingError(str(error)) from None
                self.coupling = coupling
            started = (session.Start(cut_node, self.device, self.foot_switch) if self.foot_switch is not None
                       else session.Start(cut_node, self.device))
            if not started:
                raise HapticDrillingError(collector.reason(f"the drilling session with {chosen.name} could not start"))
            self.session = session
            if chosen.kind == MOUSE:
                # The tool stays where it is until the mouse moves: a virtual device without a pose yet would put it
                # at the scene's origin at the next update (and a restart would make it jump there).
                self.device.SetPose([0.0, 0.0, 0.0], 0)
                self._attach_mouse(renderer, interactor)
            self._started_with = dict(cut_node=cut_node, device=chosen, renderer=renderer, interactor=interactor,
                                      foot_switch=foot_switch, falcon_firmware=falcon_firmware, device_scale=device_scale)
        except BaseException:
            self._release()
            raise
        finally:
            collector.release()

    def restart(self, coupling=None) -> None:
        """Stop and start again as last started, now with ``coupling`` (None: uncoupled): a coupling can only be
        attached to a stopped loop. The cut stays; the device's centre is placed where the tool is now.

        When the session cannot start with ``coupling`` (its port is in use), it starts again without it, so that
        the trainee goes on drilling, and HapticDrillingError says why.
        """
        if not self.running or self._started_with is None:
            raise HapticDrillingError("no drilling session is running: press Drill first")
        arguments = self._started_with
        self._release()
        try:
            self.start(**arguments, coupling=coupling)
        except HapticDrillingError:
            if coupling is None:
                raise
            self.start(**arguments)
            raise

    def update(self) -> int:
        """At display rate: moves the tool node where the haptic thread put it; the strokes cut since the last call."""
        if self.session is None:
            return 0
        return self.session.Update()

    def stop(self) -> None:
        """End the session (every cut made stays); the mouse goes back to the camera."""
        self._release()

    def _release(self) -> None:
        if self.mouse_driver is not None:
            self.mouse_driver.SetEnabled(0)
            self.mouse_driver = None
        if self.session is not None:
            self.session.Stop()
            self.session = None
        if self.coupling is not None:
            self.coupling.detach()
            self.coupling = None
        for device in (self.device, self.foot_switch):
            if device is not None and device.IsConnected():
                device.Close()
        self.device = None
        self.foot_switch = None

    @staticmethod
    def _make_foot_switch(foot_switch):
        chosen = resolve_device(foot_switch)
        if chosen.kind != FOOT_SWITCH:
            raise HapticDrillingError(f"{chosen.name} is not a foot switch")
        pedal = slicer.vtkFootSwitchDevice()
        pedal.GetConnection().SetDevicePath(chosen.device_id)
        return pedal

    def _attach_mouse(self, renderer, interactor) -> None:
        device_to_world = vtk.vtkMatrix4x4()
        self.session.GetLoop().GetDeviceToRAS(device_to_world)
        self.mouse_driver = attach_mouse_driver(self.device, device_to_world, renderer, interactor)


def make_device(chosen: InputDevice, renderer=None, interactor=None, falcon_firmware=None):
    """The haptic device for a listed device that moves the tool, not opened yet (HapticDrillingError when it cannot
    be: a foot switch, a Falcon without its firmware file, the mouse without a 3D view)."""
    if chosen.kind == MOUSE:
        if renderer is None or interactor is None:
            raise HapticDrillingError("the mouse drills in a 3D view: no 3D view was given")
        return slicer.vtkVirtualHapticDevice()
    if chosen.kind == HAPTIC:
        if not falcon_firmware or not Path(falcon_firmware).is_file():
            raise HapticDrillingError(
                f"{chosen.name} needs its firmware file, which is not shipped: choose the file your device came with"
                + (f" ({falcon_firmware} is not a file)" if falcon_firmware else ""))
        falcon = slicer.vtkNovintFalconDevice()
        falcon.SetFirmwareFileName(str(falcon_firmware))
        return falcon
    if chosen.kind == SIX_DOF:
        spacemouse = slicer.vtkSpaceMouseDevice()
        spacemouse.GetConnection().SetDevicePath(chosen.device_id)
        return spacemouse
    if chosen.kind == FOOT_SWITCH:
        raise HapticDrillingError(
            f"{chosen.name} is a foot switch: it runs the drill but cannot move it; choose the mouse or a device that "
            "moves the tool, and the foot switch as its drill switch")
    raise HapticDrillingError(f"{chosen.name} cannot drive the drill")


def attach_mouse_driver(device, device_to_world, renderer, interactor):
    """Let the mouse in the 3D view move ``device`` (a vtkVirtualHapticDevice) placed in the scene by
    ``device_to_world``; the enabled driver (``SetEnabled(0)`` gives the mouse back to the camera)."""
    world_to_device = vtk.vtkMatrix4x4()
    vtk.vtkMatrix4x4.Invert(device_to_world, world_to_device)
    driver = slicer.vtkVirtualHapticDeviceMouseDriver()
    if not driver.SetWorldToDevice(world_to_device):
        raise HapticDrillingError("the device's frame in the scene cannot be inverted")
    driver.SetInteractor(interactor)
    driver.SetDefaultRenderer(renderer)
    driver.SetDevice(device)
    driver.SetEnabled(1)
    return driver
