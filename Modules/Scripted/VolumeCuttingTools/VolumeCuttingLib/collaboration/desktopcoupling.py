"""The instructor coupling of desktop Slicer, without Qt: what the module panel's "Instructor coupling" group runs.

The panel offers three choices: off, "I am the trainee: listen on port N",
"I am the instructor: connect to HOST:PORT", a Start/Stop button and a
status line. The widget (``VolumeCuttingTools.py``) only draws and forwards:
:meth:`DesktopCoupling.start` and :meth:`DesktopCoupling.stop` on the button,
:meth:`DesktopCoupling.status` on its display timer, whose
:class:`CouplingSnapshot` it shows.

The trainee's side couples the running Drill (``config.hapticdrilling``): a
coupling is attached to a stopped loop only, so the Drill's session is
started again with it (:meth:`HapticDrilling.restart`; every cut stays, the
device is placed where the tool is now) and again without it at Stop. The
instructor's side holds the panel's input device over the same scan
(``forcecoupling.guide_loop``: it cuts nothing, it feels the trainee's tool
and pulls it), its centre where the panel's tool is (else the scan's
centre), axes along RAS, as the trainee's Drill places its own. Both carry
the scan's fingerprint: a peer with another scan is refused and the status
says "Load the same CT on both sides".

Bad input (a port outside 0..65535 or in use, an address that is not
HOST:PORT or does not resolve, no Drill running on the trainee's side, the
Drill running on the instructor's, no scan) raises :class:`CouplingInputError`
with what to do, before anything is changed; nothing the trainee drilled is
lost. The status never raises.

What the status cannot say: the round-trip delay. The packets carry each
side's clock but no echo of the peer's, so neither side can time a round
trip; it shows how long ago the latest packet came and the share of the
peer's packets (one a tick at 1 kHz) that did not arrive.
"""

from __future__ import annotations

import errno
import math
import socket
import time
from collections import deque
from dataclasses import dataclass

import vtk

from ..config import hapticdrilling, inputdevices
from . import couplingoptions, forcecoupling

OFF = "off"
TRAINEE = couplingoptions.TRAINEE
INSTRUCTOR = couplingoptions.INSTRUCTOR
ROLES = (OFF, TRAINEE, INSTRUCTOR)
#: Every interface: a trainee reachable from another machine.
ANY_ADDRESS = "0.0.0.0"
#: The peer's loop sends one packet a tick at this rate (packets/s).
PEER_RATE_HZ = 1000.0
#: The packets/s are counted over this much of the latest polls (s).
RATE_WINDOW_S = 1.0
#: How often the panel polls the status (s).
STATUS_PERIOD_S = 0.1
#: The instructor's side says nobody answered after this long (s); it goes on waiting.
ANSWER_WAIT_S = couplingoptions.DEFAULT_ANSWER_TIMEOUT_S


class CouplingInputError(ValueError):
    """What the panel asked cannot start; the message says what to do. Nothing was changed."""


@dataclass(frozen=True)
class CouplingSnapshot:
    """What the panel's status line shows, read at one poll."""

    role: str = OFF
    #: off, waiting, coupled, gone (the peer fell silent), refused (another scan), ended (the Drill stopped)
    state: str = "off"
    text: str = "Off."
    local_port: int = 0
    peer: str = ""
    packets_per_s: float = 0.0
    #: Share of the peer's packets that did not arrive over the latest second (%), None while not coupled.
    missing_percent: float | None = None
    last_packet_ms: float | None = None
    refused_other_scan: int = 0
    force_N: float = 0.0
    device_limit_N: float = 0.0
    #: Between this side's tool and the peer's (scene mm), None before the peer's first packet.
    distance_mm: float | None = None

    @property
    def running(self) -> bool:
        return self.state not in ("off", "ended")


def parse_port(port) -> int:
    """The trainee's port as an int 0..65535 (0: any free port); CouplingInputError otherwise."""
    text = str(port).strip()
    if isinstance(port, bool) or not text.isdigit() or not 0 <= int(text) <= 65535:
        raise CouplingInputError(f"listen on port {port!r}: give a port from 1 to 65535 (such as 47000), or 0 for any "
                                 "free port")
    return int(text)


def check_port_free(host: str, port: int) -> None:
    """CouplingInputError when UDP host:port cannot be bound now (before the Drill is touched)."""
    if port == 0:
        return
    probe = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        probe.bind((host, port))
    except OSError as error:
        reason = {errno.EADDRINUSE: "is in use on this machine (another coupling or program): choose another port",
                  errno.EACCES: "needs administrator rights (ports below 1024): choose a port from 1024 up"}
        raise CouplingInputError(f"UDP port {port} {reason.get(error.errno, f'cannot be opened ({error.strerror})')}") \
            from None
    finally:
        probe.close()


def scan_of(volume) -> int:
    """The fingerprint of the scan both sides must load; CouplingInputError when there is none."""
    try:
        return forcecoupling.scan_fingerprint(volume)
    except ValueError:
        raise CouplingInputError("no scan is loaded: load the CT the trainee drills (the same file on both sides) and "
                                 "choose it as the CT volume") from None


def device_to_ras(volume, tool_node=None) -> vtk.vtkMatrix4x4:
    """The instructor's device placed in the scan: its centre where ``tool_node`` is (else the scan's centre), axes
    along RAS, one scene mm per device mm (as the trainee's Drill places its own)."""
    placement = vtk.vtkMatrix4x4()
    if tool_node is not None and tool_node.GetParentTransformNode() is not None:
        tool_node.GetParentTransformNode().GetMatrixTransformToWorld(placement)
        centre = [placement.GetElement(axis, 3) for axis in range(3)]
        placement.Identity()
    else:
        bounds = [0.0] * 6
        volume.GetRASBounds(bounds)
        centre = [(bounds[2 * axis] + bounds[2 * axis + 1]) / 2.0 for axis in range(3)]
    for axis in range(3):
        placement.SetElement(axis, 3, centre[axis])
    return placement


class DesktopCoupling:
    """One side of the instructor coupling in desktop Slicer (trainee or instructor), for the module panel."""

    def __init__(self):
        self.role = OFF
        self.options = None    # couplingoptions.CouplingOptions
        self.end = None        # forcecoupling.ForceCoupling
        self.peers = None      # couplingoptions.PeerWatch
        self.drilling = None   # the trainee's HapticDrilling
        self.loop = None       # the instructor's guide loop, its device and mouse driver
        self.device = None
        self.mouse_driver = None
        self._model = None
        self._ended = ("off", "Off.")
        self._counts = deque()

    @property
    def running(self) -> bool:
        return self.end is not None

    def start(self, role: str, port=0, peer: str = "", from_other_machines: bool = False, drilling=None, volume=None,
              device=None, renderer=None, interactor=None, falcon_firmware=None, tool_node=None) -> CouplingSnapshot:
        """Start this side: ``TRAINEE`` waits on ``port`` (the running ``drilling`` is coupled), ``INSTRUCTOR``
        connects to ``peer`` (HOST:PORT) with ``device`` (a device_id of the panel's list) over ``volume``.
        CouplingInputError, with nothing changed, when that cannot be; the first snapshot otherwise."""
        if self.running:
            raise CouplingInputError("the coupling runs already: press Stop first")
        if role == TRAINEE:
            self._start_trainee(port, from_other_machines, drilling)
        elif role == INSTRUCTOR:
            self._start_instructor(peer, drilling, volume, device, renderer, interactor, falcon_firmware, tool_node)
        elif role == OFF:
            raise CouplingInputError("choose a side first: \"I am the trainee\" or \"I am the instructor\"")
        else:
            raise CouplingInputError(f"unknown side {role!r}: choose the trainee's or the instructor's")
        return self.status()

    def _start_trainee(self, port, from_other_machines: bool, drilling) -> None:
        port = parse_port(port)
        if drilling is None or not drilling.running:
            raise CouplingInputError("no haptic session is running: press \"Drill with this device\" first; the "
                                     "instructor's device guides the trainee's drilling")
        fingerprint = scan_of(drilling.session.GetCutNode().GetAnatomyVolumeNode())
        host = ANY_ADDRESS if from_other_machines else forcecoupling.LOOPBACK
        check_port_free(host, port)
        options = couplingoptions.CouplingOptions(TRAINEE, port, host=host)
        end = forcecoupling.ForceCoupling(options.settings(fingerprint))
        try:
            drilling.restart(coupling=end)
        except hapticdrilling.HapticDrillingError as error:
            after = "the drilling goes on uncoupled" if drilling.running else "the drilling session stopped"
            raise CouplingInputError(f"the coupling could not start ({error}); {after}") from None
        self.drilling = drilling
        self._begin(TRAINEE, options, end)

    def _start_instructor(self, peer: str, drilling, volume, device, renderer, interactor, falcon_firmware,
                          tool_node) -> None:
        try:
            peer_host, port = couplingoptions.parse_peer(peer, "connect to")
        except ValueError as error:
            raise CouplingInputError(str(error)) from None
        if drilling is not None and drilling.running:
            raise CouplingInputError("stop the Drill first: the instructor's device guides the trainee's tool over the "
                                     "same scan, it does not drill here")
        fingerprint = scan_of(volume)
        options = couplingoptions.CouplingOptions(INSTRUCTOR, port, peer_host=peer_host,
                                                  host=couplingoptions.joining_host(peer_host))
        placement = device_to_ras(volume, tool_node)
        try:
            chosen = hapticdrilling.resolve_device(device)
            haptic = hapticdrilling.make_device(chosen, renderer, interactor, falcon_firmware)
        except hapticdrilling.HapticDrillingError as error:
            raise CouplingInputError(str(error)) from None
        loop, model = forcecoupling.guide_loop(haptic, placement)
        end = forcecoupling.ForceCoupling(options.settings(fingerprint))
        try:
            end.attach(loop)
        except OSError as error:
            raise CouplingInputError(str(error)) from None
        driver = None
        try:
            if not haptic.Open():
                raise CouplingInputError(f"{chosen.name} could not be opened: "
                                         f"{haptic.GetLastErrorMessage() or 'is it plugged in and free?'}")
            if chosen.kind == inputdevices.MOUSE:
                driver = hapticdrilling.attach_mouse_driver(haptic, placement, renderer, interactor)
            if not loop.Start():
                raise CouplingInputError("the instructor's haptic loop could not start (see the log)")
        except BaseException:
            if driver is not None:
                driver.SetEnabled(0)
            loop.Stop()
            end.detach()
            if haptic.IsConnected():
                haptic.Close()
            raise
        self.loop, self.device, self.mouse_driver, self._model = loop, haptic, driver, model
        self._begin(INSTRUCTOR, options, end)

    def _begin(self, role: str, options, end) -> None:
        self.role, self.options, self.end = role, options, end
        self.peers = couplingoptions.PeerWatch(options, end)
        self._counts.clear()

    def refuses_drill(self) -> str | None:
        """Why the panel's Drill may not start now (None: it may): the instructor's device guides, it does not drill."""
        if self.running and self.role == INSTRUCTOR:
            return ("this side is the instructor's: its device guides the trainee's tool and does not drill. Stop the "
                    "coupling first")
        return None

    def stop(self) -> CouplingSnapshot:
        """End this side; the trainee's Drill goes on uncoupled, every cut kept. Safe to call when not running."""
        message = "Off: the coupling was stopped."
        if self.role == TRAINEE and self.drilling is not None:
            if self.drilling.running and self.drilling.coupling is self.end:
                try:
                    self.drilling.restart(coupling=None)
                except hapticdrilling.HapticDrillingError as error:
                    message = f"Off: the coupling was stopped; the drilling could not go on ({error})."
            self.end.detach()  # the Drill has detached it already: this only makes sure the socket is closed
        elif self.role == INSTRUCTOR:
            if self.mouse_driver is not None:
                self.mouse_driver.SetEnabled(0)
            self.loop.Stop()
            self.end.detach()
            if self.device.IsConnected():
                self.device.Close()
        self._forget("off", message)
        return self.status()

    def _forget(self, state: str, message: str) -> None:
        self.role, self.options, self.end, self.peers = OFF, None, None, None
        self.drilling = self.loop = self.device = self.mouse_driver = self._model = None
        self._ended = (state, message)

    def status(self, now_s: float | None = None) -> CouplingSnapshot:
        """The status line's figures now (call it at display rate: the packet rate is counted between calls)."""
        if self.end is None:
            return CouplingSnapshot(state=self._ended[0], text=self._ended[1])
        if self.role == TRAINEE and self.drilling.coupling is not self.end:
            self.end.detach()
            self._forget("ended", "Ended: the drilling stopped, and the coupling with it. Press Drill, then Start, to wait for "
                         "the instructor again.")
            return self.status()
        now_s = time.monotonic() if now_s is None else now_s
        status = self.peers.look(say=lambda text: None)
        self._counts.append((now_s, status["packets_accepted"]))
        while len(self._counts) > 2 and now_s - self._counts[1][0] >= RATE_WINDOW_S:
            self._counts.popleft()
        span = now_s - self._counts[0][0]
        rate = (status["packets_accepted"] - self._counts[0][1]) / span if span > 0.0 else 0.0
        loop = self.drilling.session.GetLoop() if self.role == TRAINEE else self.loop
        device = loop.GetDevice()
        limit = device.GetCapabilities().GetMaximumForce() if device is not None else 0.0
        force = math.sqrt(sum(f * f for f in status["force_N"]))
        distance = self._distance(loop)
        age = status["peer_age_s"]
        figures = dict(role=self.role, local_port=self.end.local_port, peer=status["peer"], packets_per_s=rate,
                       last_packet_ms=1000.0 * age if age >= 0.0 else None,
                       refused_other_scan=int(status["frame_mismatches"]), force_N=force, device_limit_N=limit,
                       distance_mm=distance)
        other = "the instructor" if self.role == TRAINEE else "the trainee"
        if self.peers.mismatch and not self.peers.present:
            return CouplingSnapshot(state="refused", text=f"Refused {status['frame_mismatches']} packets: "
                                    + self.peers.mismatch + ".", **figures)
        if self.peers.present:
            missing = max(0.0, 100.0 * (1.0 - rate / PEER_RATE_HZ)) if span >= 0.5 * RATE_WINDOW_S else None
            text = (f"Coupled with {other} at {status['peer']}: {rate:.0f} packets/s"
                    + (f" ({missing:.1f} % of theirs missing)" if missing is not None else "")
                    + f", latest {1000.0 * age:.0f} ms ago; force {force:.2f} N (device limit {limit:.1f} N)"
                    + (f"; tools {distance:.1f} mm apart" if distance is not None else "") + ".")
            return CouplingSnapshot(state="coupled", text=text, missing_percent=missing, **figures)
        if self.peers.joined:
            return CouplingSnapshot(state="gone", text=f"{other.capitalize()} is gone (nothing for "
                                    f"{couplingoptions.PEER_GONE_S:g} s): the pull faded out; waiting for {other} to "
                                    "come back.", **figures)
        return CouplingSnapshot(state="waiting", text=self._waiting_text(), **figures)

    def _waiting_text(self) -> str:
        options = self.options
        if options.role == TRAINEE:
            where = ("any machine" if options.host == ANY_ADDRESS else "this machine only")
            return (f"Waiting for the instructor on UDP port {self.end.local_port} ({where}): they choose \"I am the "
                    f"instructor\" and connect to this machine's address, port {self.end.local_port}.")
        waited = self.peers.elapsed()
        text = f"Waiting for the trainee at {options.peer_host}:{options.port} ({waited:.0f} s)."
        if waited > ANSWER_WAIT_S:
            text += (f" Nobody answered: on the trainee's side press Drill, choose \"I am the trainee\", port "
                     f"{options.port}, and Start (with \"from other machines\" for another machine); check the address "
                     f"and that UDP port {options.port} is open between the machines.")
        return text

    def _distance(self, loop) -> float | None:
        peer = [0.0, 0.0, 0.0]
        if not self.end.coupling.GetLatestPeerPosition(peer):
            return None
        pose = vtk.vtkMatrix4x4()
        if not loop.GetLatestToolPose(pose):
            return None
        return math.dist(peer, [pose.GetElement(axis, 3) for axis in range(3)])
