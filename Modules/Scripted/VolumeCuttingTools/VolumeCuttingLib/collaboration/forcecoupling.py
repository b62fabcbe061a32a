"""Forces forwarded: couple a haptic loop to a peer's over UDP, kept passive.

The instructor's and the trainee's haptic loops (``vtkHapticLoop``, 1 kHz)
each get a ``vtkHapticCoupling`` whose ``vtkHapticCouplingTransport`` sends
one small packet a tick to the peer's port: the instructor's device feels
the trainee's tool and can guide it through a spring-damper between the two
proxies, under an energy-tank passivity layer (see the C++ classes and
``Docs/Collaboration.md``, section *Forces forwarded*). Both ends bind to
127.0.0.1 unless told otherwise.

``ForceCoupling`` configures one end and attaches it to a stopped loop (the
logic's haptic session exposes its loop: ``session.GetLoop()``).

Two drilling sessions are coupled in the scan's RAS millimetres: the loop
hands the coupling its tool's proxy in RAS (each side through its own
device-to-RAS placement, rotation and scale included) and maps the spring's
force back into its device's axes. Both ends then carry the scan's
fingerprint (``scan_fingerprint``: dimensions, IJK-to-RAS, a checksum of the
samples) in every packet, and refuse a peer whose fingerprint differs: its
positions would be places in another scan. ``guide_loop`` makes the
instructor's side of such a pair: a device held over air in the same scan's
RAS, which feels the trainee's tool and pulls it.
``rehearse`` runs two coupled loops with simulated hands on loopback, ticked
in lockstep on the calling thread, with injected delay and loss: the
figures that tell whether a setting is stable (the benchmark area
``collaboration`` reports them).
"""

from __future__ import annotations

import ipaddress
import math
import socket
from dataclasses import dataclass

import slicer
import vtk

LOOPBACK = "127.0.0.1"


@dataclass(frozen=True)
class CouplingSettings:
    """One end of the coupling: where it listens, where its peer is, how stiff, and any injected faults."""

    local_port: int
    peer_port: int                  # 0: listen, the peer is whoever sends first (from peer_host unless 0.0.0.0)
    host: str = LOOPBACK
    peer_host: str = LOOPBACK
    stiffness: float = 0.5          # N per scene mm between the proxies
    damping: float = 0.002          # N s per scene mm
    maximum_force: float = 0.0      # N; 0: the device's maximum
    injected_delay_s: float = 0.0   # one-way, on this end's outgoing packets
    injected_loss: float = 0.0      # fraction of this end's outgoing packets dropped
    seed: int = 1                   # of the loss generator
    frame_fingerprint: int = 0      # 0: the devices' own mm; else scan_fingerprint of the scan both sides drill

    def validate(self) -> None:
        """Raise ValueError naming the first setting that cannot work."""
        for name, port in (("local_port", self.local_port), ("peer_port", self.peer_port)):
            if not isinstance(port, int) or not 0 <= port <= 65535:
                raise ValueError(f"{name} must be an integer from 0 to 65535, not {port!r}")
        for name, host in (("host", self.host), ("peer_host", self.peer_host)):
            try:
                ipaddress.IPv4Address(host)
            except (ipaddress.AddressValueError, ValueError):
                raise ValueError(f"{name} must be a numeric IPv4 address such as 127.0.0.1, not {host!r}") from None
        ranges = (("stiffness", self.stiffness, 0.0, 100.0), ("damping", self.damping, 0.0, 10.0),
                  ("maximum_force", self.maximum_force, 0.0, 1000.0),
                  ("injected_delay_s", self.injected_delay_s, 0.0, 1.0), ("injected_loss", self.injected_loss, 0.0, 1.0))
        for name, value, lowest, highest in ranges:
            if not (isinstance(value, (int, float)) and math.isfinite(value) and lowest <= value <= highest):
                raise ValueError(f"{name} must be from {lowest} to {highest}, not {value!r}")
        if not isinstance(self.seed, int) or self.seed < 0:
            raise ValueError(f"seed must be a non-negative integer, not {self.seed!r}")
        if not isinstance(self.frame_fingerprint, int) or not 0 <= self.frame_fingerprint < 2 ** 64:
            raise ValueError("frame_fingerprint must be 0 (the devices' own millimetres) or scan_fingerprint(volume_node), "
                             f"not {self.frame_fingerprint!r}")


def scan_fingerprint(volume_node) -> int:
    """The fingerprint of a scan's RAS frame and samples that two coupled drilling sessions must share (never 0)."""
    image = volume_node.GetImageData() if volume_node is not None else None
    if image is None or image.GetPointData().GetScalars() is None:
        raise ValueError("the scan has no image data: load the CT before coupling its drilling session")
    ijk_to_ras = vtk.vtkMatrix4x4()
    volume_node.GetIJKToRASMatrix(ijk_to_ras)
    return int(slicer.vtkHapticCouplingTransport.ComputeFrameFingerprint(image, ijk_to_ras))


def describe_mismatch(status: dict, peer: str) -> str | None:
    """What to tell the user when the peer's packets were refused for their frame; None when none were."""
    if not status.get("frame_mismatches"):
        return None
    ours, theirs = status["frame"], status["refused_frame"]
    what = {0: "holds a free device (no scan)"}.get(theirs, f"loaded another scan (fingerprint {theirs:016x})")
    here = "this side holds a free device (no scan)" if ours == 0 else f"this side's scan has fingerprint {ours:016x}"
    return (f"{peer} {what}; {here}. Refused: the two tools would be in different places. Load the same CT on both "
            "sides (the same file: same dimensions, spacing, origin, axes and samples), or neither")


class ForceCoupling:
    """One end of forwarded forces, attached to a stopped haptic loop."""

    def __init__(self, settings: CouplingSettings):
        settings.validate()
        self.settings = settings
        self.transport = slicer.vtkHapticCouplingTransport()
        self.coupling = slicer.vtkHapticCoupling()
        self.coupling.SetTransport(self.transport)
        self._loop = None

    @property
    def local_port(self) -> int:
        """The port this end listens on (after attach; useful with local_port 0)."""
        return self.transport.GetLocalPort()

    def attach(self, loop) -> int:
        """Open the socket and give the coupling to ``loop`` (stopped). Returns the local port."""
        if loop.IsRunning():
            raise RuntimeError("stop the haptic loop before attaching the force coupling")
        settings = self.settings
        self.transport.SetInjectedDelay(settings.injected_delay_s)
        self.transport.SetInjectedLossRate(settings.injected_loss)
        self.transport.SetInjectionSeed(settings.seed)
        self.transport.SetFrameFingerprint(settings.frame_fingerprint)
        if not self.transport.Open(settings.host, settings.local_port, settings.peer_host, settings.peer_port):
            peer = "any peer" if settings.peer_port == 0 else f"its peer at {settings.peer_host}:{settings.peer_port}"
            raise OSError(f"the force coupling could not bind UDP {settings.host}:{settings.local_port} for {peer} "
                          "(port in use, or not an address of this machine?)")
        self.coupling.SetStiffness(settings.stiffness)
        self.coupling.SetDamping(settings.damping)
        self.coupling.SetMaximumForce(settings.maximum_force)
        loop.SetCoupling(self.coupling)
        self._loop = loop
        return self.local_port

    def detach(self) -> None:
        """Take the coupling off its loop (stopped) and close the socket."""
        if self._loop is not None:
            if self._loop.IsRunning():
                raise RuntimeError("stop the haptic loop before detaching the force coupling")
            self._loop.SetCoupling(None)
            self._loop = None
        self.transport.Close()

    def status(self) -> dict:
        """The latest tick's figures (any thread may read them while the loop runs)."""
        coupling, transport = self.coupling, self.transport
        force = [0.0, 0.0, 0.0]
        coupling.GetLatestForce(force)
        return {
            "force_N": force,
            "gain": coupling.GetLatestGain(),
            "peer_age_s": coupling.GetLatestPeerAge(),
            "tank_mJ": coupling.GetLatestTank(),
            "energy_in_mJ": coupling.GetEnergyIn(),
            "energy_out_mJ": coupling.GetEnergyOut(),
            "peer": transport.GetPeerAddress(),
            "packets_sent": transport.GetNumberOfPacketsSent(),
            "packets_accepted": transport.GetNumberOfPacketsAccepted(),
            "packets_garbled": transport.GetNumberOfGarbledPackets(),
            "packets_stale": transport.GetNumberOfStalePackets(),
            "packets_foreign": transport.GetNumberOfForeignSessionPackets() + transport.GetNumberOfForeignHostPackets(),
            "frame": int(transport.GetFrameFingerprint()),
            "frame_mismatches": transport.GetNumberOfFrameMismatches(),
            "refused_frame": int(transport.GetLastRefusedFrame()),
        }


def free_loopback_ports(count: int) -> list[int]:
    """Ports free on 127.0.0.1 right now (for rehearsals and tests; another process may take one meanwhile)."""
    sockets = [socket.socket(socket.AF_INET, socket.SOCK_DGRAM) for _ in range(count)]
    try:
        for bound in sockets:
            bound.bind((LOOPBACK, 0))
        return [bound.getsockname()[1] for bound in sockets]
    finally:
        for bound in sockets:
            bound.close()


# The rehearsal's hands (device mm, kg, N/mm, N s/mm) and the Touch-like force limit.
TIME_STEP = 1e-3
DEVICE_MAXIMUM_FORCE = 3.3
TRAINEE_START = (3.0, -2.0, 0.0)


def instructor_target(time: float) -> tuple[float, float, float]:
    """The instructor's path: a slow figure, then a 12 mm step at 2 s."""
    return (8.0 * math.sin(math.pi * time) + (12.0 if time >= 2.0 else 0.0), 4.0 * math.sin(0.5 * math.pi * time), 0.0)


def air_force_model():
    """A force model over air only: the rehearsal's tools touch nothing but each other, idle ticks nothing."""
    image = vtk.vtkImageData()
    image.SetDimensions(4, 4, 4)
    image.AllocateScalars(vtk.VTK_FLOAT, 1)
    image.GetPointData().GetScalars().Fill(-1000.0)
    model = slicer.vtkHapticForceModel()
    model.SetAnatomy(image, vtk.vtkMatrix4x4())
    model.SetSphereRadius(2.0)
    return model


def guide_loop(device, device_to_ras):
    """The instructor's loop for coupling to a drilling session: ``device`` over air, placed in the scan's RAS.

    ``device_to_ras`` (a vtkMatrix4x4: rotation, uniform scale, translation)
    places the device in the scan as the trainee's session places its own
    (by default the session puts the device's centre where the tool is, axes
    along RAS). The tool touches nothing: the instructor feels the trainee's
    tool, and its contacts, only through the coupling. Returns (loop, model).
    """
    loop = slicer.vtkHapticLoop()
    loop.SetRate(1000.0)
    loop.SetDevice(device)
    model = air_force_model()
    loop.SetForceModel(model)
    if not loop.SetDeviceToRAS(device_to_ras):
        raise ValueError("the device's placement in the scan must be a rotation, a uniform scale and a translation")
    return loop, model


def rehearse(delay_s: float, loss: float, seconds: float = 4.0, passivity: bool = True, seed: int = 1) -> dict:
    """Two coupled loops on loopback with simulated hands; the stability figures.

    The instructor: a 0.15 kg handle held by a 0.3 N/mm, 0.004 N s/mm arm
    following ``instructor_target``; the trainee: a relaxed 0.1 kg handle
    (0.001 N s/mm) starting 3.6 mm away. Both devices render at most 3.3 N.
    Returned: the largest device force (N), the passivity margin (mJ: the
    tanks' initial energy less the most net energy the coupling ever gave
    the two handles; negative means it gave more than it was given), the
    largest separation (mm), the trainee's tracking RMS over 0.5-2 s (mm),
    the coupling's update time (us, p50/p99/max over both ends), and the
    whole tick's p50 (us).
    """
    hands = []
    ends = []
    ports = free_loopback_ports(2)
    for index in range(2):
        device = slicer.vtkVirtualHapticDevice()
        device.GetCapabilities().SetMaximumForce(DEVICE_MAXIMUM_FORCE)
        loop = slicer.vtkHapticLoop()
        loop.SetDevice(device)
        model = air_force_model()
        loop.SetForceModel(model)
        loop.SetStatisticsCapacity(max(16, int(seconds / TIME_STEP) + 16))
        end = ForceCoupling(CouplingSettings(local_port=ports[index], peer_port=ports[1 - index], injected_delay_s=delay_s,
                                             injected_loss=loss, seed=seed + 17 * index))
        end.coupling.SetPassivityControl(passivity)
        end.coupling.SetStatisticsCapacity(max(16, int(seconds / TIME_STEP) + 16))
        end.attach(loop)
        if not device.Open():
            raise RuntimeError("the virtual device could not be opened")
        start = (0.0, 0.0, 0.0) if index == 0 else TRAINEE_START
        hands.append({"device": device, "loop": loop, "model": model, "x": list(start), "v": [0.0, 0.0, 0.0], "work": 0.0,
                      "mass": 0.15 if index == 0 else 0.1, "k": 0.3 if index == 0 else 0.0,
                      "b": 0.004 if index == 0 else 0.001})
        ends.append(end)
        device.SetPose(start, 0)
    initial = sum(end.coupling.GetInitialEnergy() for end in ends)
    largest_force, worst, separation_max, squared, tracked = 0.0, -math.inf, 0.0, 0.0, 0
    force = [0.0, 0.0, 0.0]
    try:
        for tick in range(int(round(seconds / TIME_STEP))):
            time = tick * TIME_STEP
            for index, hand in enumerate(hands):
                hand["device"].GetCommandedForce(force)
                largest_force = max(largest_force, math.sqrt(sum(f * f for f in force)))
                target = instructor_target(time) if index == 0 else hand["x"]
                for axis in range(3):
                    push = hand["k"] * (target[axis] - hand["x"][axis]) - hand["b"] * hand["v"][axis]
                    hand["v"][axis] += TIME_STEP * 1000.0 * (force[axis] + push) / hand["mass"]
                    step = TIME_STEP * hand["v"][axis]
                    hand["x"][axis] += step
                    hand["work"] += force[axis] * step
                hand["device"].SetPose(hand["x"], 0)
            for hand in hands:
                if not hand["loop"].RunTicks(1):
                    raise RuntimeError("the haptic loop refused to tick (see the VTK error above)")
            worst = max(worst, hands[0]["work"] + hands[1]["work"] - initial)
            separation = math.dist(hands[0]["x"], hands[1]["x"])
            if not math.isfinite(separation):
                raise FloatingPointError("the rehearsal diverged")
            separation_max = max(separation_max, separation)
            if 0.5 <= time < 2.0:
                squared += separation * separation
                tracked += 1
        updates = [[end.coupling.GetUpdateDurationPercentile(q) for end in ends] for q in (50.0, 99.0, 100.0)]
        return {
            "delay_ms": 1000.0 * delay_s,
            "loss_percent": 100.0 * loss,
            "passivity": passivity,
            "device_force_limit_N": DEVICE_MAXIMUM_FORCE,
            "max_force_N": largest_force,
            "clamped_forces": sum(hand["device"].GetNumberOfClampedForces() for hand in hands),
            "energy_bound_margin_mJ": -worst,
            "max_separation_mm": separation_max,
            "tracking_rms_mm": math.sqrt(squared / tracked) if tracked else math.nan,
            "coupling_update_us": {"p50": max(updates[0]), "p99": max(updates[1]), "max": max(updates[2])},
            "tick_p50_us": max(hand["loop"].GetTickDurationPercentile(50.0) for hand in hands),
            "packets_accepted": [end.transport.GetNumberOfPacketsAccepted() for end in ends],
        }
    finally:
        for hand in hands:
            hand["loop"].Stop()
        for end in ends:
            end.detach()
