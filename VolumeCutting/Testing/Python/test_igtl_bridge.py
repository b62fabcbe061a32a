"""The OpenIGTLink bridge on a real scene: what a client receives, what it may send, what is refused.

The bone block of ``test_haptic_session`` (a protected nerve canal deep in
it) with a 4 mm burr from the shipped presets, the bridge on 127.0.0.1 and a
free port, clients on real sockets: pyigtl's own client and the bridge's
recording client (every message with its arrival time).
"""

from __future__ import annotations

import json
import random
import socket
import struct
import time

import numpy as np
import pyigtl
import pytest
import slicer
import vtk
from vtkmodules.util import numpy_support

from test_haptic_session import add_burr, block_scene
from VolumeCuttingLib.collaboration import igtlbridge, igtlprotocol
from VolumeCuttingLib.collaboration.igtlclient import RecordingClient
from VolumeCuttingLib.feedback import nervemonitor
from VolumeCuttingLib.jobs.selftests import cut_samples_by_position

HOST = "127.0.0.1"


def pose(x, y=0.0, z=0.0):
    matrix = vtk.vtkMatrix4x4()
    for axis, value in enumerate((x, y, z)):
        matrix.SetElement(axis, 3, float(value))
    return matrix


def as_array(matrix):
    return np.array([[matrix.GetElement(r, c) for c in range(4)] for r in range(4)])


def tool_pose(tool):
    matrix = vtk.vtkMatrix4x4()
    tool.GetParentTransformNode().GetMatrixTransformToWorld(matrix)
    return as_array(matrix)


def removed_fraction_bytes(logic, cut):
    """The removed fraction of every CT voxel as the bridge sends it (0-255), (k, j, i)."""
    image = vtk.vtkImageData()
    logic.GetCutField(cut).ExportRemovedFraction(image)
    dims = image.GetDimensions()
    fractions = numpy_support.vtk_to_numpy(image.GetPointData().GetScalars()).reshape(dims[2], dims[1], dims[0])
    return np.rint(np.clip(fractions, 0.0, 1.0) * 255.0).astype(np.uint8)


@pytest.fixture
def session():
    application, logic, cut = block_scene()
    tool = add_burr(application.scene, cut)
    nervemonitor.monitor_for(logic, cut)
    logic.MoveActiveTool(cut, pose(-14.0), slicer.vtkSlicerVolumeCuttingLogic.ToolMove)
    bridge = igtlbridge.IgtlBridge(igtlbridge.BridgeOptions(port=0)).start()
    bridge.attach(logic, cut)
    try:
        yield application, logic, cut, tool, bridge
    finally:
        bridge.stop()


def test_a_client_receives_the_pose_the_monitor_contacts_and_the_removed_region(session):
    application, logic, cut, tool, bridge = session
    assert bridge.options.host == HOST and bridge.port > 0

    # pyigtl's own client: the tool's pose and the monitor's readings.
    plain = pyigtl.OpenIGTLinkClient(HOST, bridge.port)
    try:
        transform = plain.wait_for_message(igtlbridge.TOOL_DEVICE, timeout=5)
        readings = plain.wait_for_message(igtlbridge.MONITOR_DEVICE, timeout=5)
    finally:
        plain.stop()
    assert transform is not None and np.allclose(transform.matrix, tool_pose(tool), atol=1e-5)
    assert readings is not None and json.loads(readings.string)["structures"]["Nerve"]["level"] == "silent"

    client = RecordingClient(HOST, bridge.port)
    try:
        assert client.wait_for(lambda c: c.messages("IMAGE") and c.messages("TRANSFORM"))
        # The whole image first: nothing removed yet, on the CT's grid.
        whole = client.messages("IMAGE")[0].message
        assert whole.full_size == (48, 48, 30) and whole.offset == (0, 0, 0) and whole.image.shape == (30, 48, 48)
        assert not whole.image.any()
        ijk_to_ras = vtk.vtkMatrix4x4()
        cut.GetAnatomyVolumeNode().GetIJKToRASMatrix(ijk_to_ras)
        assert np.allclose(whole.ijk_to_world_matrix, as_array(ijk_to_ras), atol=1e-4)

        # The tool moves at 1 kHz for 0.6 s: the client gets 60 poses a second, the latest each time.
        start = len(client.messages("TRANSFORM"))
        began = time.time()
        for step in range(600):
            logic.MoveActiveTool(cut, pose(-14.0 + 0.005 * step, 0.002 * step), slicer.vtkSlicerVolumeCuttingLogic.ToolMove)
            time.sleep(0.001)
        elapsed = time.time() - began
        assert client.wait_for(lambda c: np.allclose(c.messages("TRANSFORM")[-1].message.matrix, tool_pose(tool), atol=1e-5))
        poses = client.messages("TRANSFORM")[start:]
        rate = len(poses) / elapsed
        latencies_ms = 1000.0 * np.array([p.latency_s for p in poses])
        print(f"TRANSFORM: {len(poses)} in {elapsed:.3f} s ({rate:.1f} Hz), latency p50 {np.percentile(latencies_ms, 50):.2f} "
              f"max {latencies_ms.max():.2f} ms")
        # Throttled to the pose rate (or the source's, if a loaded machine moved the tool slower); a shared
        # machine's scheduling may starve the bridge's thread now and then (the benchmark measures the rate).
        expected = min(60.0, 600 / elapsed)
        assert 0.25 * expected < rate < 1.2 * expected + 2.0
        assert np.all(latencies_ms >= 0.0)
        assert all(p.message.matrix.shape == (4, 4) for p in poses)

        # A stroke into the block: the removed region arrives as sub-volume updates and equals the field's fractions.
        assert logic.BeginStroke(cut)
        for x in np.arange(-10.0, -4.0, 0.25):
            logic.MoveActiveTool(cut, pose(x), slicer.vtkSlicerVolumeCuttingLogic.ToolCut)
        logic.EndStroke(cut)
        expected = removed_fraction_bytes(logic, cut)
        assert expected.sum() > 0
        assert client.wait_for(lambda c: c.image is not None and np.array_equal(c.image[0], expected)), \
            int(np.abs(client.image[0].astype(int) - expected).max())
        updates = client.messages("IMAGE")[1:]
        assert updates and all(u.message.full_size == (48, 48, 30) for u in updates)
        assert all(u.message.image.size < expected.size for u in updates)  # boxes, not the whole image

        # Into the nerve: the monitor says contact, and the contact with the protected segment is reported.
        assert logic.BeginStroke(cut)
        for x in np.arange(-4.0, 2.0, 0.25):
            logic.MoveActiveTool(cut, pose(x), slicer.vtkSlicerVolumeCuttingLogic.ToolCut)
        logic.EndStroke(cut)
        assert client.wait_for(lambda c: c.messages("STRING", igtlbridge.CONTACT_DEVICE))
        contact = json.loads(client.messages("STRING", igtlbridge.CONTACT_DEVICE)[-1].message.string)
        assert contact["name"] == "Nerve" and contact["protected"] and contact["depth_mm"] > 0.0
        assert client.wait_for(lambda c: json.loads(c.messages("STRING", igtlbridge.MONITOR_DEVICE)[-1].message.string)
                               ["structures"]["Nerve"]["level"] == "contact")
        assert client.wait_for(lambda c: np.array_equal(c.image[0], removed_fraction_bytes(logic, cut)))
        assert client.error is None
    finally:
        client.close()
    stats = bridge.stats()
    assert stats["sent"]["TRANSFORM"] > 30 and stats["sent"]["IMAGE"] >= 3 and stats["sent"]["STRING"] >= 3
    assert not stats["refused"]


def header(message_type=b"TRANSFORM", device=b"MoveTool", body=b"", version=1, size=None, crc=None):
    return igtlprotocol.HEADER.pack(version, message_type, device, 0, 0, len(body) if size is None else size,
                                    igtlprotocol.igtl.CRC64(body) if crc is None else crc)


def malformed(kind: str, rng: random.Random) -> tuple[bytes, bool]:
    """One malformed message of ``kind``, and whether it breaks the stream (the bridge then closes the connection)."""
    good = pyigtl.TransformMessage(np.eye(4), device_name="MoveTool").pack()
    body = good[igtlprotocol.HEADER_SIZE:]
    if kind == "header":
        choice = rng.randrange(3)
        if choice == 0:
            raw = header(body=body, version=rng.choice([0, 3, 255, 65535]))
        elif choice == 1:
            raw = header(message_type=bytes([rng.randrange(128, 256)]) + b"RANSFORM", body=body)
        else:
            raw = header(message_type=b"\0" * 12, body=body)
        return raw + body, True
    if kind == "size":
        if rng.random() < 0.5:
            return header(body=body, size=rng.randrange(igtlprotocol.MAXIMUM_BODY_BYTES + 1, 1 << 63)), True
        wrong = body + bytes(rng.randrange(1, 64))
        return header(body=wrong) + wrong, False
    if kind == "crc":
        return header(body=body, crc=igtlprotocol.igtl.CRC64(body) ^ (1 << rng.randrange(64))) + body, False
    if kind == "type":
        message_type = rng.choice([b"IMAGE", b"STRING", b"STATUS", b"GET_IMAGE", b"POLYDATA", b"SENSOR", b"X"])
        noise = bytes(rng.randrange(256) for _ in range(rng.randrange(0, 200)))
        return header(message_type=message_type, body=noise) + noise, False
    # body: the right size and CRC, contents that are not a pose.
    matrix = np.eye(4)
    choice = rng.randrange(4)
    if choice == 0:
        matrix[rng.randrange(3), rng.randrange(4)] = float("nan")
    elif choice == 1:
        matrix[:3, :3] *= rng.uniform(1.1, 3.0)  # scaled
    elif choice == 2:
        matrix[0, 0] = -1.0  # mirrored
    else:
        matrix[rng.randrange(3), 3] = rng.choice([1, -1]) * 1.0e6
    bad = struct.pack(">12f", *matrix[:3, 0], *matrix[:3, 1], *matrix[:3, 2], *matrix[:3, 3])
    return header(body=bad) + bad, False


def closed_by_peer(connection, timeout_s=5.0) -> bool:
    """Whether the other end closes the connection within ``timeout_s`` (what it streamed meanwhile is read and dropped)."""
    connection.settimeout(timeout_s)
    try:
        while connection.recv(1 << 20):
            pass
    except ConnectionResetError:
        pass
    except socket.timeout:
        return False
    return True


def test_a_thousand_malformed_messages_are_refused_and_change_nothing(session):
    application, logic, cut, tool, bridge = session
    # A cut to protect, and the tool where it is.
    assert logic.BeginStroke(cut)
    for x in np.arange(-10.0, -5.0, 0.25):
        logic.MoveActiveTool(cut, pose(x), slicer.vtkSlicerVolumeCuttingLogic.ToolCut)
    logic.EndStroke(cut)
    field = logic.GetCutField(cut)
    samples, stamp, tool_before = cut_samples_by_position(field), field.GetCurrentStamp(), tool_pose(tool)
    undo_steps = field.GetNumberOfUndoSteps()

    rng = random.Random(27)
    kinds = [kind for kind in igtlprotocol.REASONS for _ in range(200)]
    rng.shuffle(kinds)
    raw = None
    began = time.perf_counter()
    for count, kind in enumerate(kinds, start=1):
        data, fatal = malformed(kind, rng)
        if raw is None:
            raw = socket.create_connection((HOST, bridge.port), timeout=5)
            raw.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)  # each message goes out at once
        raw.sendall(data)
        deadline = time.monotonic() + 5.0
        while sum(bridge.stats()["refused"].values()) < count and time.monotonic() < deadline:
            time.sleep(0.0005)
        assert sum(bridge.stats()["refused"].values()) == count, (kind, bridge.last_refusal)
        if fatal:
            assert closed_by_peer(raw)
            raw.close()
            raw = None
        # The scene's thread runs as the application's would: nothing reaches it.
        assert bridge.process_incoming() == {}
    if raw is not None:
        raw.close()
    elapsed = time.perf_counter() - began
    refused = bridge.stats()["refused"]
    print(f"1000 malformed messages refused in {elapsed:.2f} s: {refused}")
    assert refused == {reason: 200 for reason in igtlprotocol.REASONS}
    assert field.GetCurrentStamp() == stamp and field.GetNumberOfUndoSteps() == undo_steps
    assert np.array_equal(cut_samples_by_position(logic.GetCutField(cut)), samples)
    assert np.array_equal(tool_pose(tool), tool_before)

    # Still serving: a good client is streamed to, and its pose moves the tool.
    client = RecordingClient(HOST, bridge.port)
    try:
        assert client.wait_for(lambda c: c.messages("TRANSFORM") and c.messages("IMAGE"))
        target = np.eye(4)
        target[:3, 3] = [-13.0, 1.0, 0.5]
        client.send(pyigtl.TransformMessage(target, device_name=igtlbridge.MOVE_DEVICE))
        deadline = time.monotonic() + 5.0
        while not bridge.process_incoming().get("move") and time.monotonic() < deadline:
            time.sleep(0.002)
        assert np.allclose(tool_pose(tool), target, atol=1e-5)
        assert client.wait_for(lambda c: np.allclose(c.messages("TRANSFORM")[-1].message.matrix, target, atol=1e-5))
    finally:
        client.close()
    assert field.GetCurrentStamp() == stamp


def pump_until(bridge, key, count, timeout_s=5.0):
    applied = {}
    deadline = time.monotonic() + timeout_s
    while applied.get(key, 0) < count and time.monotonic() < deadline:
        for name, value in bridge.process_incoming().items():
            applied[name] = applied.get(name, 0) + value
        time.sleep(0.002)
    return applied


def test_incoming_transforms_move_the_tool_drill_a_stroke_and_set_the_guide_axis(session):
    application, logic, cut, tool, bridge = session
    path = [(-12.0 + 0.5 * n, 0.3 * np.sin(n / 3.0), 0.0) for n in range(17)]
    # The same stroke through the logic, on a scene of its own: the reference.
    _, reference_logic, reference_cut = block_scene()
    add_burr(reference_logic.GetMRMLScene(), reference_cut)
    reference_logic.MoveActiveTool(reference_cut, pose(-14.0), slicer.vtkSlicerVolumeCuttingLogic.ToolMove)
    assert reference_logic.BeginStroke(reference_cut)
    for point in path:
        reference_logic.MoveActiveTool(reference_cut, pose(*point), slicer.vtkSlicerVolumeCuttingLogic.ToolCut)
    reference_logic.EndStroke(reference_cut)

    client = RecordingClient(HOST, bridge.port)
    try:
        assert client.wait_for(lambda c: c.messages("TRANSFORM"))
        # Moving does not cut.
        client.send(pyigtl.TransformMessage(as_array(pose(-11.0, 2.0)), device_name=igtlbridge.MOVE_DEVICE))
        assert pump_until(bridge, "move", 1)["move"] == 1
        assert np.allclose(tool_pose(tool), as_array(pose(-11.0, 2.0)), atol=1e-5)
        assert logic.GetRemovedVolume(cut) == 0.0
        # Drilling: one stroke, one undo step, the same cut as the stroke through the logic.
        for point in path:
            client.send(pyigtl.TransformMessage(as_array(pose(*point)), device_name=igtlbridge.DRILL_DEVICE))
        applied = pump_until(bridge, "drill", len(path))
        assert applied["drill"] == len(path)
        assert pump_until(bridge, "strokes_ended", 1, timeout_s=2.0)["strokes_ended"] == 1
        field = logic.GetCutField(cut)
        assert not field.IsStrokeOpen() and field.GetNumberOfUndoSteps() == 1
        assert logic.GetRemovedVolume(cut) > 10.0
        assert np.array_equal(cut_samples_by_position(field), cut_samples_by_position(reference_logic.GetCutField(reference_cut)))

        # The guide axis: two points, then a transform's origin and z axis.
        client.send(pyigtl.PointMessage(positions=[[-14.0, 0.0, 0.0], [0.0, 0.0, 0.0]], device_name=igtlbridge.GUIDE_DEVICE))
        assert pump_until(bridge, "guide", 1)["guide"] == 1
        line = application.scene.GetFirstNodeByName(igtlbridge.GUIDE_LINE_NAME)
        assert isinstance(line, slicer.vtkMRMLMarkupsLineNode) and line.GetNumberOfControlPoints() == 2
        assert np.allclose(line.GetNthControlPointPositionWorld(1), [0.0, 0.0, 0.0])
        axis = np.eye(4)
        axis[:3, :3] = [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]  # z along +x
        axis[:3, 3] = [-14.0, 1.0, 0.0]
        client.send(pyigtl.TransformMessage(axis, device_name=igtlbridge.GUIDE_DEVICE))
        assert pump_until(bridge, "guide", 1)["guide"] == 1
        assert application.scene.GetFirstNodeByName(igtlbridge.GUIDE_LINE_NAME) is line
        assert np.allclose(line.GetNthControlPointPositionWorld(0), [-14.0, 1.0, 0.0])
        assert np.allclose(line.GetNthControlPointPositionWorld(1), [-4.0, 1.0, 0.0])
        # The haptic session takes the line as its fixture.
        haptic = slicer.vtkSlicerVolumeCuttingHapticSession()
        haptic.SetLogic(logic)
        assert haptic.SetGuideLine(line)
    finally:
        client.close()
    assert bridge.stats()["accepted"] == {"TRANSFORM": 2 + len(path), "POINT": 1}


def test_a_client_that_stops_reading_or_vanishes_is_dropped_and_the_others_keep_streaming():
    application, logic, cut = block_scene()
    add_burr(application.scene, cut)
    logic.MoveActiveTool(cut, pose(-14.0), slicer.vtkSlicerVolumeCuttingLogic.ToolMove)
    options = igtlbridge.BridgeOptions(port=0, stall_timeout_s=0.5, max_backlog_bytes=1 << 20, send_buffer_bytes=4096)
    with igtlbridge.IgtlBridge(options) as bridge:
        bridge.attach(logic, cut)
        # One that never reads, with a tiny receive buffer: the bridge's sends stop going through at once.
        silent = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        silent.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        silent.connect((HOST, bridge.port))
        vanishing = socket.create_connection((HOST, bridge.port))
        good = RecordingClient(HOST, bridge.port)
        try:
            assert good.wait_for(lambda c: c.messages("IMAGE"))
            vanishing.close()
            # Drilling goes on meanwhile, pose after pose.
            began = time.monotonic()
            assert logic.BeginStroke(cut)
            for step in range(200):
                logic.MoveActiveTool(cut, pose(-10.0 + 0.03 * step, 0.5 * np.sin(step / 10.0)), slicer.vtkSlicerVolumeCuttingLogic.ToolCut)
                time.sleep(0.005)
            logic.EndStroke(cut)
            drilling_s = time.monotonic() - began
            deadline = time.monotonic() + 5.0
            while bridge.client_count() > 1 and time.monotonic() < deadline:
                time.sleep(0.01)
            dropped = bridge.stats()["clients_dropped"]
            assert bridge.client_count() == 1 and dropped.get("gone") == 1, dropped
            assert dropped.get("stalled", 0) + dropped.get("too slow", 0) == 1, dropped
            # The good client saw it all: the last pose, the removed region as it is.
            assert good.wait_for(lambda c: np.allclose(c.messages("TRANSFORM")[-1].message.matrix, tool_pose_of(cut), atol=1e-5))
            assert good.wait_for(lambda c: np.array_equal(c.image[0], removed_fraction_bytes(logic, cut)))
            assert drilling_s < 200 * 0.005 + 5.0  # never held up by the silent client
        finally:
            good.close()
            silent.close()


def tool_pose_of(cut):
    matrix = vtk.vtkMatrix4x4()
    cut.GetActiveToolNode().GetParentTransformNode().GetMatrixTransformToWorld(matrix)
    return as_array(matrix)
