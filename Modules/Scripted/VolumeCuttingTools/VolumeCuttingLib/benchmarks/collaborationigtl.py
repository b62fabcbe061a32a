"""The OpenIGTLink bridge's figures (issue 27), for the area ``collaboration``.

The scene is the main job's: the temporal-bone phantom (128x128x96 voxels of
0.4x0.4x0.5 mm) with its protected structures monitored and the 4 mm
cutting burr; the bridge on 127.0.0.1, one recording client
(``collaboration.igtlclient``) on a real socket, all in this process.

* Pose stream: the tool moved through the logic at 1 kHz for 2 s (a haptic
  device's rate); the TRANSFORM rate the client received against the rate
  asked for (60 Hz, then 250 Hz), and the latency from the pose in the scene
  (the message's time stamp) to its arrival, p50 / p99 / max, against a
  TRANSFORM of the same bytes sent over a bare loopback socket.
* First messages: from the client's connect to its first TRANSFORM and to
  the whole removed-region IMAGE, against moving those bytes over a bare
  loopback socket.
* Removed region: after each pass of the main job's mastoidectomy plan, the
  IMAGE sub-volume update's size against the whole image's, and the time
  from the stroke's end to its arrival against the naive update (export the
  removed fraction of the whole CT, pack it, send it over a bare socket).
* Drilling cost: the passes' per-pose time with the bridge streaming to a
  client against the same passes on a second copy of the scene with no
  bridge, pass by pass in turn.
"""

from __future__ import annotations

import socket
import statistics
import threading
import time

import numpy as np
import slicer
import vtk
from vtkmodules.util import numpy_support

from ..collaboration import igtlbridge, igtlprotocol
from ..collaboration.igtlclient import RecordingClient
from ..config import toolconfig
from ..cutting import drilling
from ..data import phantom
from ..feedback import nervemonitor
from ..scene.application import HeadlessSlicer
from .harness import machine_description, measurement

DIMENSIONS, SPACING = (128, 128, 96), (0.4, 0.4, 0.5)
HOST = "127.0.0.1"
POSE_SECONDS = 2.0
POSE_PERIOD_S = 0.001


def _scene():
    application = HeadlessSlicer()
    logic = application.volume_cutting_logic
    generated = phantom.generate_phantom(dimensions=DIMENSIONS, spacing=SPACING, seed=0)
    volume, segmentation = phantom.create_phantom_nodes(application.scene, generated)
    cut = logic.AddVolumeCutNode(volume, segmentation)
    ids = set(segmentation.GetSegmentation().GetSegmentIDs())
    cut.SetCuttableSegmentIDs([s for s in phantom.CUTTABLE_SEGMENTS if s in ids])
    cut.SetProtectedSegmentIDs([s for s in phantom.PROTECTED_SEGMENTS if s in ids])
    preset = next(p for p in toolconfig.load_presets() if p.name == "Cutting burr 4 mm")
    tool = toolconfig.create_tool_node(application.scene, toolconfig.from_preset(preset), name=preset.name)
    cut.SetAndObserveActiveToolNodeID(tool.GetID())
    nervemonitor.monitor_for(logic, cut)
    bounds = [0.0] * 6
    segmentation.GetSegmentation().GetSegment("MastoidAirCells").GetBounds(bounds)
    plan = drilling.MastoidectomyPlan(entry=drilling.lateral_entry(volume, (bounds[2] + bounds[3]) / 2.0, (bounds[4] + bounds[5]) / 2.0),
                                      surface_radius=7.0, depth=8.0, burr_radius=2.0)
    return application, logic, cut, plan


def _pose(point):
    matrix = vtk.vtkMatrix4x4()
    for axis in range(3):
        matrix.SetElement(axis, 3, float(point[axis]))
    return matrix


def _bare_loopback(payloads: list[bytes]) -> list[float]:
    """Seconds from sending each payload over a bare loopback TCP connection to its last byte's arrival."""
    listener = socket.create_server((HOST, 0))
    sender = socket.create_connection(listener.getsockname())
    receiver, _ = listener.accept()
    for connection in (sender, receiver):
        connection.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    times = []
    try:
        for payload in payloads:
            start = time.perf_counter()
            done = threading.Thread(target=sender.sendall, args=(payload,))
            done.start()
            missing = len(payload)
            while missing:
                missing -= len(receiver.recv(min(missing, 1 << 20)))
            times.append(time.perf_counter() - start)
            done.join()
    finally:
        for connection in (sender, receiver, listener):
            connection.close()
    return times


def _pose_stream(logic, cut, plan, rate_hz: float) -> dict:
    """The tool moved at 1 kHz for POSE_SECONDS with the bridge at ``rate_hz``: received rate and latencies."""
    options = igtlbridge.BridgeOptions(port=0, pose_rate_hz=rate_hz)
    with igtlbridge.IgtlBridge(options) as bridge:
        bridge.attach(logic, cut)
        connect = time.time()
        client = RecordingClient(HOST, bridge.port)
        try:
            client.wait_for(lambda c: c.messages("TRANSFORM") and c.messages("IMAGE"), timeout_s=10.0)
            first_pose_s = client.messages("TRANSFORM")[0].arrived - connect
            first_image = client.messages("IMAGE")[0]
            first_image_s, image_bytes = first_image.arrived - connect, first_image.size_bytes
            start_index = len(client.messages("TRANSFORM"))
            outside = np.asarray(plan.entry) - 8.0 * np.asarray(plan.direction)
            began = time.time()
            step = 0
            while time.time() - began < POSE_SECONDS:
                offset = np.array([0.0, 3.0 * np.sin(step * 0.01), 3.0 * np.cos(step * 0.01)])
                logic.MoveActiveTool(cut, _pose(outside + offset), slicer.vtkSlicerVolumeCuttingLogic.ToolMove)
                step += 1
                time.sleep(POSE_PERIOD_S)
            elapsed = time.time() - began
            bridge.flush()
            time.sleep(0.05)
            poses = client.messages("TRANSFORM")[start_index:]
        finally:
            client.close()
    latencies = np.array([p.latency_s for p in poses]) * 1e3
    return {"rate_hz": len(poses) / elapsed, "source_rate_hz": step / elapsed, "latency_ms": latencies,
            "first_pose_s": first_pose_s, "first_image_s": first_image_s, "image_bytes": image_bytes}


def _strokes(streamed_scene, plain_scene, plan, passes: int) -> dict:
    """The plan's passes on two copies of the scene, one streamed to a client, pass by pass in turn."""
    logic, cut = streamed_scene
    bridge = igtlbridge.IgtlBridge(igtlbridge.BridgeOptions(port=0)).start()
    bridge.attach(logic, cut)
    client = RecordingClient(HOST, bridge.port)
    client.wait_for(lambda c: c.messages("IMAGE"), timeout_s=10.0)
    pose_times = {True: [], False: []}
    updates = []
    try:
        for number, poses in enumerate(plan.strokes()):
            if number >= passes:
                break
            for streamed, (scene_logic, scene_cut) in ((True, streamed_scene), (False, plain_scene)):
                before = len(client.messages("IMAGE"))
                scene_logic.BeginStroke(scene_cut)
                for point in poses:
                    start = time.perf_counter()
                    scene_logic.MoveActiveTool(scene_cut, _pose(point), slicer.vtkSlicerVolumeCuttingLogic.ToolCut)
                    pose_times[streamed].append(time.perf_counter() - start)
                scene_logic.EndStroke(scene_cut)
                ended = time.time()
                if streamed and client.wait_for(lambda c: any(m.timestamp >= ended for m in c.messages("IMAGE")[before:]), 5.0):
                    update = next(m for m in client.messages("IMAGE")[before:] if m.timestamp >= ended)
                    updates.append({"bytes": update.size_bytes, "latency_s": update.arrived - ended})
        compute_s = list(bridge.image_compute_s)
    finally:
        client.close()
        bridge.stop()
    return {"pose_times": pose_times, "updates": updates, "compute_s": compute_s}


def _naive_image_update(logic, cut, repeats: int) -> float:
    """Seconds to export the whole removed fraction, pack it as one IMAGE and move it over a bare socket."""
    anatomy = cut.GetAnatomyVolumeNode()
    matrix = vtk.vtkMatrix4x4()
    anatomy.GetIJKToRASMatrix(matrix)
    ijk_to_ras = np.array([[matrix.GetElement(r, c) for c in range(4)] for r in range(4)])
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        image = vtk.vtkImageData()
        logic.GetCutField(cut).ExportRemovedFraction(image)
        dims = image.GetDimensions()
        fractions = numpy_support.vtk_to_numpy(image.GetPointData().GetScalars()).reshape(dims[2], dims[1], dims[0])
        voxels = np.rint(np.clip(fractions, 0.0, 1.0) * 255.0).astype(np.uint8)
        packed = igtlprotocol.pack_image(igtlbridge.IMAGE_DEVICE, voxels, dims, (0, 0, 0), ijk_to_ras, time.time())
        _bare_loopback([packed])
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def igtl_measurements(repeats: int) -> list[dict]:
    machine = machine_description()
    application, logic, cut, plan = _scene()
    results = []
    transform = igtlprotocol.pack_transform(igtlbridge.TOOL_DEVICE, np.eye(4), time.time())
    bare_ms = np.array(_bare_loopback([transform] * 2000)) * 1e3
    for rate in (60.0, 250.0):
        runs = [_pose_stream(logic, cut, plan, rate) for _ in range(max(1, repeats))]
        latencies = np.concatenate([run["latency_ms"] for run in runs])
        achieved = statistics.median(run["rate_hz"] for run in runs)
        results.append(measurement(f"TRANSFORM rate received, tool moved at {statistics.median(r['source_rate_hz'] for r in runs):.0f} Hz, "
                                   f"bridge at {rate:g} Hz (Hz)", achieved, "Hz", "rate asked for", rate, repeats, machine))
        for label, value, bare in (("p50", np.percentile(latencies, 50), np.percentile(bare_ms, 50)),
                                   ("p99", np.percentile(latencies, 99), np.percentile(bare_ms, 99)),
                                   ("max", latencies.max(), bare_ms.max())):
            results.append(measurement(f"TRANSFORM latency {label}, pose in the scene to its arrival, bridge at {rate:g} Hz "
                                       f"({len(latencies)} poses)", float(value), "ms",
                                       f"the same TRANSFORM over a bare loopback socket, {label}", float(bare), repeats, machine))
    first = _pose_stream(logic, cut, plan, 60.0)
    bare_image_s = statistics.median(_bare_loopback([bytes(first["image_bytes"])] * max(3, repeats)))
    results.append(measurement("first TRANSFORM after connecting (ms)", first["first_pose_s"] * 1e3, "ms",
                               "one TRANSFORM over a bare loopback socket, median", float(np.percentile(bare_ms, 50)), 1, machine))
    results.append(measurement(f"whole removed-region IMAGE after connecting, {first['image_bytes']} bytes (ms)",
                               first["first_image_s"] * 1e3, "ms", "the same bytes over a bare loopback socket", bare_image_s * 1e3,
                               1, machine))
    _, plain_logic, plain_cut, _ = _scene()
    strokes = _strokes((logic, cut), (plain_logic, plain_cut), plan, passes=16)
    updates = strokes["updates"]
    update_bytes = statistics.median(u["bytes"] for u in updates)
    update_latency = statistics.median(u["latency_s"] for u in updates)
    results.append(measurement(f"IMAGE sub-volume update after a pass of the mastoidectomy, median of {len(updates)} (bytes)",
                               update_bytes, "bytes", "the whole image", first["image_bytes"], len(updates), machine))
    naive_ms = _naive_image_update(logic, cut, 5) * 1e3
    results.append(measurement(f"IMAGE update latency, stroke end to arrival while the next pass drills, median of {len(updates)} "
                               "(ms; the bridge sends images at 5 Hz)", update_latency * 1e3, "ms",
                               "export the whole removed fraction, pack and send it", naive_ms, len(updates), machine))
    compute = strokes["compute_s"]
    for index, kind in ((0, "wall"), (1, "processor")):
        results.append(measurement(f"IMAGE update computed on the bridge's thread (changed bricks and their neighbours), {kind} "
                                   f"time, median of {len(compute)} (ms)", statistics.median(c[index] for c in compute) * 1e3, "ms",
                                   "export the whole removed fraction, pack and send it (wall)", naive_ms, len(compute), machine))
    streamed = np.array(strokes["pose_times"][True]) * 1e3
    alone = np.array(strokes["pose_times"][False]) * 1e3
    for label, function in (("p50", lambda a: np.percentile(a, 50)), ("p99", lambda a: np.percentile(a, 99))):
        results.append(measurement(f"drilling pose {label} with the bridge streaming to a client ({len(streamed)} poses)",
                                   float(function(streamed)), "ms", f"the same passes' poses without a bridge ({len(alone)})",
                                   float(function(alone)), 1, machine))
    return results
