"""Hold a haptic device coupled to another's: the instructor guides the trainee (forces forwarded).

    Utilities/vc couple --couple-listen 47000 --device falcon --falcon-firmware FILE      (trainee: waits)
    Utilities/vc couple --couple-to 192.168.1.20:47000 --device falcon --falcon-firmware FILE   (instructor: joins)

Each side runs its own haptic loop at 1 kHz on its device; the two loops are
coupled over UDP (``collaboration.forcecoupling``: a spring between the two
tools, kept passive under delay and loss). The trainee's side waits on a
port and prints it; the instructor's side joins it. While they are coupled,
each device is pulled toward the other's tool: the instructor feels where the
trainee's tool is and guides it by pulling, the trainee feels that pull.
Both devices work in their own millimetres about their workspace's centre,
the same frame on both sides: the tools coincide when the two hands do.

Nothing here can be lost: a peer that goes away (its process ends, the
network drops) is reported and its pull fades out within 0.15 s, the loop
goes on and takes the peer back if it returns. The instructor's side gives up
with a clear message when the trainee's side never answers (``--couple-wait``).
``--device virtual`` holds a virtual device still (try the link without a
device); ``--device replay --replay FILE`` plays a recorded hand
(``vtkHapticRecorder`` file). ``--summary PATH`` writes what the device felt.
"""

from __future__ import annotations

import argparse
import json
import math
import signal
import sys
import time
from pathlib import Path

import slicer

from ..collaboration import couplingoptions, forcecoupling
from ..config import inputdevices

#: How often the job looks at the coupling (s): the events it prints and the force samples of the summary.
WATCH_PERIOD_S = 0.01
#: Force samples kept for the summary (at WATCH_PERIOD_S, ten minutes).
MAXIMUM_SAMPLES = 60000


class CouplingError(RuntimeError):
    """The coupled session could not start or its peer never answered; the message says what to do."""


def open_device(kind: str, falcon_firmware: Path | None = None, replay: Path | None = None):
    """The device named on the command line, not opened yet; CouplingError when it cannot be."""
    if kind == "virtual":
        device = slicer.vtkVirtualHapticDevice()
        return device
    if kind == "replay":
        if replay is None or not Path(replay).is_file():
            raise CouplingError(f"--device replay needs --replay FILE, a haptic recording ({replay} is not a file)")
        device = slicer.vtkReplayHapticDevice()
        if not device.ReadFile(str(replay)):
            raise CouplingError(f"{replay} is not a haptic recording this version reads (vtkHapticRecorder file)")
        return device
    if kind == "falcon":
        if not any(listed.kind == inputdevices.HAPTIC for listed in inputdevices.list_devices()):
            raise CouplingError("no Novint Falcon is plugged in (or its USB device cannot be read: libusb missing, "
                                "or no permission on it)")
        if falcon_firmware is None or not Path(falcon_firmware).is_file():
            raise CouplingError("the Falcon needs its firmware file, which is not shipped: give --falcon-firmware FILE "
                                "(the file your device came with)")
        device = slicer.vtkNovintFalconDevice()
        device.SetFirmwareFileName(str(falcon_firmware))
        return device
    raise CouplingError(f"unknown device {kind!r}")


class CoupledDevice:
    """A device on a haptic loop over air, coupled to a peer: what ``main`` runs."""

    def __init__(self, options: couplingoptions.CouplingOptions, device):
        self.options = options
        self.device = device
        self.loop = slicer.vtkHapticLoop()
        self.loop.SetRate(1000.0)
        self.loop.SetDevice(device)
        self._model = forcecoupling.air_force_model()  # nothing to touch but the peer's tool
        self.loop.SetForceModel(self._model)
        self.end = forcecoupling.ForceCoupling(options.settings())
        self.peers = couplingoptions.PeerWatch(options, self.end)
        self.samples: list[tuple] = []
        self._started = None

    def start(self) -> int:
        """Open the socket and the device, start the loop; the local port. CouplingError if any cannot."""
        try:
            port = self.end.attach(self.loop)
        except OSError as error:
            raise CouplingError(str(error)) from None
        if not self.device.Open():
            self.end.detach()
            raise CouplingError(f"the device could not be opened: {self.device.GetLastErrorMessage() or 'see the log'}")
        if isinstance(self.device, slicer.vtkVirtualHapticDevice):
            self.device.SetPose([0.0, 0.0, 0.0], 0)
        if not self.loop.Start():
            self.device.Close()
            self.end.detach()
            raise CouplingError("the haptic loop could not start (see the log)")
        self._started = time.perf_counter()
        self.peers = couplingoptions.PeerWatch(self.options, self.end)  # its wait counts from here
        return port

    def elapsed(self) -> float:
        return time.perf_counter() - self._started

    def watch(self, say=print) -> dict:
        """One look: a force sample, the peer's joining, loss and return told through ``say``; CouplingError
        once the instructor's side has waited too long for the trainee's."""
        status = self.peers.look(say)
        force = [0.0, 0.0, 0.0]
        self.device.GetCommandedForce(force)
        if len(self.samples) < MAXIMUM_SAMPLES:
            self.samples.append((round(self.elapsed(), 4), *(round(f, 4) for f in force), round(status["peer_age_s"], 4),
                                 round(status["gain"], 4)))
        problem = self.peers.never_answered()
        if problem:
            raise CouplingError(problem)
        return status

    def stop(self) -> dict:
        """Stop the loop, close the socket and the device; the figures."""
        self.loop.Stop()
        status = self.end.status()
        self.end.detach()
        if self.device.IsConnected():
            self.device.Close()
        forces = [math.sqrt(fx * fx + fy * fy + fz * fz) for _, fx, fy, fz, _, _ in self.samples]
        return {
            "role": self.options.role,
            "coupling": self.options.describe(),
            "peer": status["peer"],
            "seconds": round(self.elapsed(), 3) if self._started else 0.0,
            "ticks": int(self.loop.GetNumberOfTicks()),
            "device_force_limit_N": self.device.GetCapabilities().GetMaximumForce(),
            "largest_force_N": round(max(forces, default=0.0), 4),
            "events": self.peers.events,
            "status": status,
            "samples_columns": ["t_s", "fx_N", "fy_N", "fz_N", "peer_age_s", "gain"],
            "samples": self.samples,
        }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    couplingoptions.add_arguments(parser)
    parser.add_argument("--device", choices=("falcon", "virtual", "replay"), default="falcon",
                        help="the haptic device this side holds (default falcon; virtual: held still at its origin; "
                             "replay: a recorded hand, --replay FILE)")
    parser.add_argument("--falcon-firmware", type=Path, default=None, help="the Falcon's firmware file (not shipped)")
    parser.add_argument("--replay", type=Path, default=None, help="with --device replay: the haptic recording to play")
    parser.add_argument("--seconds", type=float, default=0.0,
                        help="stop after this long (default: until Ctrl-C, or the end of a replayed recording)")
    parser.add_argument("--summary", type=Path, default=None, help="write what the device felt here (JSON)")
    args = parser.parse_args(argv)
    try:
        options = couplingoptions.options_from_arguments(args)
    except ValueError as error:
        parser.error(str(error))
    if options is None:
        parser.error("say which side this is: --couple-listen PORT (the trainee's, waits) or --couple-to HOST:PORT "
                     "(the instructor's, joins)")
    if args.seconds < 0 or not math.isfinite(args.seconds):
        parser.error(f"--seconds {args.seconds}: give a time of 0 (until Ctrl-C) or more")

    stop = {"now": False}
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda *_: stop.__setitem__("now", True))
    coupled = None
    failure = None
    try:
        device = open_device(args.device, args.falcon_firmware, args.replay)
        coupled = CoupledDevice(options, device)
        port = coupled.start()
        where = (f"waiting for the instructor on {options.host}:{port} (they join with --couple-to HOST:{port})"
                 if not options.joins else f"joining the trainee at {options.peer_host}:{options.port}")
        print(f"coupling: {where}", flush=True)
        replayed = isinstance(device, slicer.vtkReplayHapticDevice)
        while not stop["now"]:
            coupled.watch(lambda text: print(f"coupling: {text}", flush=True))
            if args.seconds and coupled.elapsed() >= args.seconds:
                break
            if replayed and device.IsFinished():
                break
            time.sleep(WATCH_PERIOD_S)
    except CouplingError as error:
        failure = str(error)
    finally:
        summary = coupled.stop() if coupled is not None and coupled._started is not None else {"role": options.role}
        if failure:
            summary["error"] = failure
        if args.summary is not None:
            args.summary.parent.mkdir(parents=True, exist_ok=True)
            args.summary.write_text(json.dumps(summary))
    if failure:
        print(f"coupling: {failure}", file=sys.stderr, flush=True)
        return 3
    print(f"coupling: ended after {summary['seconds']:.1f} s; largest force on this device "
          f"{summary['largest_force_N']:.2f} N (limit {summary['device_force_limit_N']:.1f} N)", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
