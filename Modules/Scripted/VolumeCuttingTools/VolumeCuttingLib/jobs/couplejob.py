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
With ``--ct FILE`` on both sides the two are drilling sessions on that scan,
coupled in its RAS millimetres: the trainee's side drills it (the logic's
haptic session: the cut, the protection of ``--protected`` segments of
``--segmentation``, and the force model act on the trainee's tool as ever),
the instructor's side holds its device over air in the same scan and feels
the trainee's tool, its contacts included, through the spring. Each side
places its device's centre at ``--tool-at R,A,S`` (default: the scan's
centre), axes along RAS, ``--device-scale`` scene mm per device mm. Each packet
carries the scan's fingerprint; a side that loaded another scan (or none) is
refused and told so, and the instructor's side ends.

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

import vtk

from ..collaboration import couplingoptions, forcecoupling
from ..config import inputdevices
from ..data import owndata
from ..scene.application import HeadlessSlicer
from . import hapticsjob

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
    """A device on a haptic loop, coupled to a peer: over air (no scan), or on a scan (``DrilledScan``)."""

    def __init__(self, options: couplingoptions.CouplingOptions, device, scan=None):
        self.options = options
        self.device = device
        self.scan = scan
        self.end = forcecoupling.ForceCoupling(options.settings(scan.fingerprint if scan is not None else 0))
        self.drills = scan is not None and not options.joins
        if self.drills:
            self.loop = scan.session.GetLoop()  # the trainee drills: the logic's haptic session's loop
        elif scan is not None:
            self.loop, self._model = forcecoupling.guide_loop(device, scan.device_to_ras())
        else:
            self.loop = slicer.vtkHapticLoop()
            self.loop.SetRate(1000.0)
            self.loop.SetDevice(device)
            self._model = forcecoupling.air_force_model()  # nothing to touch but the peer's tool
            self.loop.SetForceModel(self._model)
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
        started = self.scan.session.Start(self.scan.cut_node, self.device) if self.drills else self.loop.Start()
        if not started:
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
        if self.drills:
            self.scan.session.Update()  # the tool node and the cut node's events, at this display rate
        problem = self.peers.never_answered() or self.peers.refused()
        if problem:
            raise CouplingError(problem)
        return status

    def stop(self) -> dict:
        """Stop the loop, close the socket and the device; the figures."""
        if self.drills:
            self.scan.session.Stop()  # closes the open stroke and brings the logic's tables up to date
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
            "scan": self.scan.describe() if self.scan is not None else None,
            "status": status,
            "samples_columns": ["t_s", "fx_N", "fy_N", "fz_N", "peer_age_s", "gain"],
            "samples": self.samples,
        }


class DrilledScan:
    """The scan both sides load: its fingerprint, where the devices are placed in it, and the trainee's drilling."""

    def __init__(self, ct: Path, drills: bool, segmentation: Path | None = None, protected: str = "",
                 tool_at=None, device_scale: float = 1.0):
        self.application = HeadlessSlicer()
        scene = self.application.scene
        try:
            self.volume = owndata.load_ct(scene, ct)
            segmentation_node = owndata.load_segmentation(scene, segmentation, self.volume) if segmentation else None
        except owndata.InputError as error:
            raise CouplingError(str(error)) from None
        self.ct = ct
        self.fingerprint = forcecoupling.scan_fingerprint(self.volume)
        bounds = [0.0] * 6
        self.volume.GetRASBounds(bounds)
        self.tool_at = list(tool_at) if tool_at is not None else [(bounds[2 * a] + bounds[2 * a + 1]) / 2.0 for a in range(3)]
        self.device_scale = device_scale
        self.session = self.cut_node = None
        if not drills:
            return
        logic = self.application.volume_cutting_logic
        if segmentation_node is None:
            segmentation_node = logic.CreateBoneSegmentation(self.volume, 700.0, 200.0, 0.5)
            if segmentation_node is None:
                raise CouplingError(f"no bone could be segmented in {ct} (is it a CT in HU?)")
        segments = segmentation_node.GetSegmentation()
        names = [segments.GetSegment(s).GetName() for s in segments.GetSegmentIDs()]
        protected_names = [n.strip() for n in protected.split(",") if n.strip()]
        try:
            cuttable, protected_ids = owndata.resolve_roles(
                segmentation_node, [n for n in names if n.lower() not in {p.lower() for p in protected_names}],
                protected_names)
        except owndata.InputError as error:
            raise CouplingError(str(error)) from None
        self.cut_node = logic.AddVolumeCutNode(self.volume, segmentation_node)
        self.cut_node.SetCuttableSegmentIDs(cuttable)
        self.cut_node.SetProtectedSegmentIDs(protected_ids)
        tool, _ = hapticsjob.active_burr(scene, self.cut_node)
        start = vtk.vtkMatrix4x4()
        for axis in range(3):
            start.SetElement(axis, 3, self.tool_at[axis])
        tool.GetParentTransformNode().SetMatrixTransformToParent(start)
        self.session = slicer.vtkSlicerVolumeCuttingHapticSession()
        self.session.SetLogic(logic)
        self.session.SetDeviceScale(device_scale)

    def device_to_ras(self):
        """The device's placement in the scan, as the trainee's session makes it: centre at tool_at, axes along RAS."""
        matrix = vtk.vtkMatrix4x4()
        for axis in range(3):
            matrix.SetElement(axis, axis, self.device_scale)
            matrix.SetElement(axis, 3, self.tool_at[axis])
        return matrix

    def describe(self) -> dict:
        described = {"ct": str(self.ct), "fingerprint": f"{self.fingerprint:016x}", "tool_at_ras_mm": self.tool_at}
        if self.cut_node is not None:
            described["removed_mm3"] = round(self.application.volume_cutting_logic.GetRemovedVolume(self.cut_node), 3)
        return described


def _point(text: str):
    parts = str(text).split(",")
    try:
        values = [float(part) for part in parts]
    except ValueError:
        values = []
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise argparse.ArgumentTypeError(f"{text!r}: give R,A,S in millimetres, such as 10,-4.5,22")
    return values


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
    scan = parser.add_argument_group("coupled drilling", "both sides load the same CT: the trainee drills it, the "
                                     "instructor feels the trainee's tool in it and guides it")
    scan.add_argument("--ct", type=Path, default=None,
                      help="the CT both sides load (the same file: a side with another scan, or none, is refused)")
    scan.add_argument("--segmentation", type=Path, default=None,
                      help="trainee's side: its segments (default: the bone the CT shows); all are cut but --protected")
    scan.add_argument("--protected", default="", metavar="NAMES",
                      help="trainee's side: segments of --segmentation the drill may not cut (comma-separated)")
    scan.add_argument("--tool-at", type=_point, default=None, metavar="R,A,S",
                      help="where each side's device centre is placed in the CT (default: its centre); give the same "
                           "on both sides, so that the tools coincide when the hands do")
    scan.add_argument("--device-scale", type=float, default=1.0,
                      help="scene mm per device mm (default 1; the same on both sides)")
    args = parser.parse_args(argv)
    try:
        options = couplingoptions.options_from_arguments(args)
    except ValueError as error:
        parser.error(str(error))
    if options is None:
        parser.error("say which side this is: --couple-listen PORT (the trainee's, waits) or --couple-to HOST:PORT "
                     "(the instructor's, joins)")
    if args.ct is None and (args.segmentation or args.protected or args.tool_at):
        parser.error("--segmentation, --protected and --tool-at go with --ct")
    if not (math.isfinite(args.device_scale) and 0.01 <= args.device_scale <= 100.0):
        parser.error(f"--device-scale {args.device_scale}: give 0.01 to 100 scene mm per device mm")
    if args.seconds < 0 or not math.isfinite(args.seconds):
        parser.error(f"--seconds {args.seconds}: give a time of 0 (until Ctrl-C) or more")

    stop = {"now": False}
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda *_: stop.__setitem__("now", True))
    coupled = None
    failure = None
    try:
        device = open_device(args.device, args.falcon_firmware, args.replay)
        drilled = None
        if args.ct is not None:
            drilled = DrilledScan(args.ct, drills=not options.joins, segmentation=args.segmentation,
                                  protected=args.protected, tool_at=args.tool_at, device_scale=args.device_scale)
            print(f"coupling: scan {args.ct}, fingerprint {drilled.fingerprint:016x}", flush=True)
        coupled = CoupledDevice(options, device, drilled)
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
