"""The OpenIGTLink bridge: desktop Slicer (SlicerOpenIGTLink) mirrors a drilling session and may drive it.

A TCP server (127.0.0.1 unless told otherwise) that streams from the module
logic, to every connected client:

==========  ===============  ==================================================
type        device           what
==========  ===============  ==================================================
TRANSFORM   VolumeCutTool    the active tool's pose (tool to RAS), at most
                             ``pose_rate_hz`` a second, only the latest pose
STRING      NerveMonitor     the nerve monitor's readings (JSON), at most
                             ``monitor_rate_hz``, at once on a change of level
STRING      Contact          the deepest contact with a segment the tool may
                             not cut (JSON), when it deepens
IMAGE       RemovedRegion    the removed fraction (0-255) of each CT voxel: the
                             whole image to a new client, then the box of the
                             voxels each change touched (a sub-volume)
==========  ===============  ==================================================

and accepts (:mod:`.igtlprotocol` checks every message first):

* TRANSFORM ``MoveTool``: the tool moves there (a tracker, another Slicer);
* TRANSFORM ``DrillTool``: the tool drills along the poses, one stroke (one
  undo step) until a ``MoveTool`` pose or ``stroke_idle_s`` without one;
* POINT ``GuideAxis`` (its first two points) or TRANSFORM ``GuideAxis`` (its
  origin and z axis, the tool's shaft): the guided-drilling axis, a markups
  line ``Guide axis`` in the scene (``vtkSlicerVolumeCuttingHapticSession.SetGuideLine``
  takes it as the haptic fixture).

The bridge never holds the drilling up. Everything on the network happens on
the bridge's own thread; the scene's observers only copy a pose or a reading
(microseconds) and poke the thread. Incoming commands wait in a queue until
the application calls :meth:`IgtlBridge.process_incoming` on the thread that
owns the scene. A client that reads slower than the session produces gets
only the latest pose and reading; one whose backlog passes
``max_backlog_bytes`` or that takes nothing for ``stall_timeout_s`` is
dropped. Malformed messages are refused and counted (``stats()["refused"]``);
one that breaks the byte stream closes that connection only.
"""

from __future__ import annotations

import collections
import json
import selectors
import socket
import threading
import time

import numpy as np
import slicer
import vtk
from vtkmodules.util import numpy_support

from ..feedback import nervemonitor
from . import igtlprotocol as protocol
from .igtloptions import BridgeOptions

__all__ = ["BridgeOptions", "IgtlBridge"]

TOOL_DEVICE = "VolumeCutTool"
MONITOR_DEVICE = "NerveMonitor"
CONTACT_DEVICE = "Contact"
IMAGE_DEVICE = "RemovedRegion"
MOVE_DEVICE = "MoveTool"
DRILL_DEVICE = "DrillTool"
GUIDE_DEVICE = "GuideAxis"
GUIDE_LINE_NAME = "Guide axis"
# A client's socket is refilled from its queue below this many bytes waiting in it.
LOW_WATER_BYTES = 256 * 1024
RECEIVE_CHUNK_BYTES = 65536
# Incoming commands kept for the scene's thread; a flood beyond this loses the oldest.
MAXIMUM_QUEUED_COMMANDS = 4096
# The bridge's thread computes an image update in slices of this many seconds, sending poses between them.
IMAGE_SLICE_S = 0.004


class _Client:
    """One connection: what it sent us so far, what waits to go out, and why it may be dropped."""

    def __init__(self, connection: socket.socket, address):
        self.socket = connection
        self.address = address
        self.received = bytearray()
        self.header: protocol.Header | None = None
        self.out = bytearray()
        self.latest: dict[str, tuple] = {}  # coalesced: one waiting (type, message) per device
        self.queue: collections.deque = collections.deque()  # in order: image updates, (type, message)
        self.queued_bytes = 0
        self.needs_full_image = True
        self.last_progress = time.monotonic()

    @property
    def waiting(self) -> bool:
        return bool(self.out or self.latest or self.queue)


class IgtlBridge:
    """The server (see the module's docstring): ``start()``, ``attach(logic, cut_node)``, ``process_incoming()``, ``stop()``."""

    def __init__(self, options: BridgeOptions | None = None):
        self.options = options or BridgeOptions()
        self.port = None
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = None
        self._selector = None
        self._listener = None
        self._wake_out = self._wake_in = None  # a socket pair that pokes the bridge's thread (while it runs)
        self._clients: list[_Client] = []
        # Snapshots the scene's thread hands over (under _lock).
        self._pose = None  # (16 floats, time)
        self._pose_seq = 0
        self._monitor = None  # (json text, time, urgent)
        self._monitor_seq = 0
        self._contact = None
        self._contact_seq = 0
        self._geometry = None  # (field, dims (i, j, k), ijk_to_ras 4x4)
        self._geometry_seq = 0
        self._commands: collections.deque = collections.deque(maxlen=MAXIMUM_QUEUED_COMMANDS)
        # Thread-side state.
        self._sent_pose_seq = self._sent_monitor_seq = self._sent_contact_seq = 0
        self._next_pose_at = self._next_monitor_at = self._next_image_at = 0.0
        self._image = None  # _ImageMirror of the attached field
        self._image_began = (0.0, 0.0)  # when the update in progress began: wall and processor seconds
        self._image_cpu = 0.0
        self._stats = {"sent": collections.Counter(), "sent_bytes": collections.Counter(), "refused": collections.Counter(),
                       "accepted": collections.Counter(), "clients_connected": 0, "clients_dropped": collections.Counter(),
                       "commands_dropped": 0, "image_updates": 0, "image_update_bytes": 0}
        self.last_refusal = ""
        # Each image update's computation on the bridge's thread (the latest ones): wall and processor seconds.
        self.image_compute_s: collections.deque = collections.deque(maxlen=1000)
        # Scene side.
        self.logic = None
        self.cut_node = None
        self._observations = []
        self._observed_transform = None
        self._stroke_open = False
        self._last_drill_time = 0.0
        self._last_monitor_snapshot = 0.0
        self.guide_line = None
        self.on_guide_axis = lambda line: None
        self.on_tool_driven = lambda action: None

    # ------------------------------------------------------------------ life

    def start(self) -> "IgtlBridge":
        """Listen and start the thread; OSError (the port in use, a bad host) says why not, nothing left open."""
        listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        try:
            listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            listener.bind((self.options.host, int(self.options.port)))
            listener.listen(self.options.max_clients)
            listener.setblocking(False)
        except OSError as error:
            listener.close()
            raise OSError(f"OpenIGTLink bridge cannot listen on {self.options.host}:{self.options.port}: {error}") from None
        self._listener = listener
        self.port = listener.getsockname()[1]
        self._wake_out, self._wake_in = socket.socketpair()
        self._wake_out.setblocking(False)
        self._wake_in.setblocking(False)
        self._selector = selectors.DefaultSelector()
        self._selector.register(listener, selectors.EVENT_READ, "listener")
        self._selector.register(self._wake_in, selectors.EVENT_READ, "wake")
        self._stop.clear()
        self._thread = threading.Thread(target=self._run, name="OpenIGTLink bridge", daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        """Close every connection and the server; the scene's observers go."""
        self.detach()
        if self._thread is not None:
            self._stop.set()
            self._wake()
            self._thread.join(timeout=5.0)
            self._thread = None
        for client in list(self._clients):
            self._close(client, None)
        if self._selector is not None:
            self._selector.close()
            self._selector = None
        if self._listener is not None:
            self._listener.close()
            self._listener = None
        for end in (self._wake_out, self._wake_in):
            if end is not None:
                end.close()
        self._wake_out = self._wake_in = None

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.stop()

    @property
    def address(self) -> str:
        return f"{self.options.host}:{self.port}"

    def client_count(self) -> int:
        with self._lock:
            return len(self._clients)

    def stats(self) -> dict:
        """What went out (messages and bytes per type, counted as they go to a client's socket; one replaced by a later
        pose or reading before it went is not counted), what came in (accepted, refused per reason), who was dropped."""
        with self._lock:
            return {"clients": len(self._clients), "sent": dict(self._stats["sent"]), "sent_bytes": dict(self._stats["sent_bytes"]),
                    "accepted": dict(self._stats["accepted"]), "refused": dict(self._stats["refused"]),
                    "clients_connected": self._stats["clients_connected"], "clients_dropped": dict(self._stats["clients_dropped"]),
                    "commands_dropped": self._stats["commands_dropped"], "image_updates": self._stats["image_updates"],
                    "image_update_bytes": self._stats["image_update_bytes"]}

    def flush(self, timeout_s: float = 2.0) -> bool:
        """Wait until every connected client has been sent all that is due (True), or ``timeout_s`` passed."""
        self.refresh()
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            with self._lock:
                due = self._pose_seq != self._sent_pose_seq or self._monitor_seq != self._sent_monitor_seq or \
                    self._contact_seq != self._sent_contact_seq or any(c.waiting for c in self._clients) or \
                    (self._image is not None and self._clients and
                     (self._image.updating or self._image.field.GetCurrentStamp() > self._image.stamp))
            if not due:
                return True
            self._wake()
            time.sleep(0.002)
        return False

    # ------------------------------------------------------------------ the scene's side (its thread)

    def attach(self, logic, cut_node) -> None:
        """Stream this cut node's tool, monitor, contacts and removed region (a new one replaces the last)."""
        self.detach()
        self.logic, self.cut_node = logic, cut_node
        self._observations = [
            (cut_node, cut_node.AddObserver(slicer.vtkMRMLVolumeCutNode.ProtectedContactEvent, self._on_contact)),
            (cut_node, cut_node.AddObserver(vtk.vtkCommand.ModifiedEvent, self._on_cut_node_modified)),
            (cut_node, cut_node.AddObserver(slicer.vtkMRMLVolumeCutNode.SegmentRolesModifiedEvent, self._on_geometry_changed)),
            (cut_node, cut_node.AddObserver(slicer.vtkMRMLVolumeCutNode.InputDataModifiedEvent, self._on_geometry_changed)),
            (logic, logic.AddObserver(slicer.vtkSlicerVolumeCuttingLogic.NerveMonitorLevelChangedEvent, self._on_level_changed)),
        ]
        self._observe_tool()
        self._on_geometry_changed()
        self.refresh()

    def detach(self) -> None:
        if self._stroke_open:
            self._end_remote_stroke(_LogicDriver(self.logic, self.cut_node))
        for node, tag in self._observations:
            node.RemoveObserver(tag)
        self._observations = []
        if self._observed_transform is not None:
            self._observed_transform[0].RemoveObserver(self._observed_transform[1])
            self._observed_transform = None
        self.logic = self.cut_node = None
        with self._lock:
            self._geometry = None
            self._geometry_seq += 1

    def refresh(self) -> None:
        """Hand the present pose and readings over now (they go out within their rates)."""
        if self.cut_node is None:
            return
        self._on_tool_moved()
        self._snapshot_monitor(urgent=True)

    def _observe_tool(self) -> None:
        tool = self.cut_node.GetActiveToolNode() if self.cut_node is not None else None
        transform = tool.GetParentTransformNode() if tool is not None else None
        if self._observed_transform is not None and self._observed_transform[0] is transform:
            return
        if self._observed_transform is not None:
            self._observed_transform[0].RemoveObserver(self._observed_transform[1])
            self._observed_transform = None
        if transform is not None:
            tag = transform.AddObserver(slicer.vtkMRMLTransformableNode.TransformModifiedEvent, self._on_tool_moved)
            self._observed_transform = (transform, tag)

    def _on_cut_node_modified(self, *_):
        self._observe_tool()  # the active tool may have changed

    def _on_tool_moved(self, *_):
        if self._observed_transform is None:
            return
        matrix = vtk.vtkMatrix4x4()
        self._observed_transform[0].GetMatrixTransformToWorld(matrix)
        now = time.time()
        with self._lock:
            self._pose = ([matrix.GetElement(r, c) for r in range(4) for c in range(4)], now)
            self._pose_seq += 1
        self._wake()
        # The logic measures the monitor after it moves the tool: these readings are those of the pose before.
        if now - self._last_monitor_snapshot >= 1.0 / self.options.monitor_rate_hz:
            self._snapshot_monitor(urgent=False)

    def _on_level_changed(self, *_):
        self._snapshot_monitor(urgent=True)

    def _snapshot_monitor(self, urgent: bool) -> None:
        monitor = self.logic.GetNerveMonitor(self.cut_node) if self.logic is not None else None
        if monitor is None:
            return
        now = time.time()
        self._last_monitor_snapshot = now
        text = json.dumps({"time": round(now, 4), "structures": nervemonitor.readings(monitor)})
        with self._lock:
            self._monitor = (text, now, urgent)
            self._monitor_seq += 1
        self._wake()

    def _on_contact(self, *_):
        field = self.cut_node.GetCutField()
        segment_id = self.logic.GetContactSegmentID(self.cut_node)
        if field is None or not segment_id:
            return
        segment = self.cut_node.GetSegmentationNode().GetSegmentation().GetSegment(segment_id)
        now = time.time()
        text = json.dumps({"time": round(now, 4), "segment_id": segment_id, "name": segment.GetName() if segment else segment_id,
                           "protected": bool(self.cut_node.IsSegmentProtected(segment_id)),
                           "depth_mm": round(float(field.GetMaximumContactDepth()), 4),
                           "position_ras_mm": [round(float(v), 3) for v in field.GetContactPosition()]})
        with self._lock:
            self._contact = (text, now)
            self._contact_seq += 1
        self._wake()

    def _on_geometry_changed(self, *_):
        field = self.logic.GetCutField(self.cut_node) if self.logic is not None else None
        anatomy = self.cut_node.GetAnatomyVolumeNode() if self.cut_node is not None else None
        geometry = None
        if field is not None and anatomy is not None and anatomy.GetImageData() is not None:
            matrix = vtk.vtkMatrix4x4()
            anatomy.GetIJKToRASMatrix(matrix)
            ijk_to_ras = np.array([[matrix.GetElement(r, c) for c in range(4)] for r in range(4)])
            geometry = (field, tuple(anatomy.GetImageData().GetDimensions()), ijk_to_ras)
        with self._lock:
            self._geometry = geometry
            self._geometry_seq += 1
        self._wake()

    # ------------------------------------------------------------------ incoming commands (the scene's thread)

    def process_incoming(self, driver=None) -> dict:
        """Apply what clients sent, on the scene's thread: tool moves, drilling strokes, the guide axis.

        ``driver`` moves the tool (``begin_stroke()``, ``move_tool(pose)``,
        ``end_stroke()``, ``in_stroke``; the web application's DrillSession is
        one); by default the logic itself. A stroke the user has open
        (``in_stroke`` without the bridge's stroke) is not interrupted: remote
        drilling waits for it, moves are refused meanwhile.
        """
        applied = collections.Counter()
        if self.cut_node is None:
            with self._lock:
                self._commands.clear()
            return dict(applied)
        driver = driver or _LogicDriver(self.logic, self.cut_node)
        while True:
            with self._lock:
                if not self._commands:
                    break
                device, payload, received = self._commands.popleft()
            if device == GUIDE_DEVICE:
                self._set_guide_axis(*payload)
                applied["guide"] += 1
                continue
            pose = vtk.vtkMatrix4x4()
            for index, value in enumerate(payload):
                pose.SetElement(index // 4, index % 4, float(value))
            local_stroke = driver.in_stroke and not self._stroke_open
            if local_stroke:
                applied["refused_user_stroke"] += 1
                continue
            if device == DRILL_DEVICE:
                if not self._stroke_open:
                    if not driver.begin_stroke():
                        applied["refused"] += 1
                        continue
                    self._stroke_open = True
                    self.on_tool_driven("stroke_began")
                driver.move_tool(pose)
                self._last_drill_time = time.monotonic()
                applied["drill"] += 1
                self.on_tool_driven("drilled")
            else:
                if self._stroke_open:
                    self._end_remote_stroke(driver)
                driver.move_tool(pose)
                applied["move"] += 1
                self.on_tool_driven("moved")
        if self._stroke_open and time.monotonic() - self._last_drill_time > self.options.stroke_idle_s:
            self._end_remote_stroke(driver)
            applied["strokes_ended"] += 1
        return dict(applied)

    def _end_remote_stroke(self, driver) -> None:
        self._stroke_open = False
        if driver is not None and driver.in_stroke:
            driver.end_stroke()
        self.on_tool_driven("stroke_ended")

    def _set_guide_axis(self, start, end) -> None:
        scene = self.cut_node.GetScene()
        line = self.guide_line if self.guide_line is not None and self.guide_line.GetScene() is scene else None
        if line is None:
            line = scene.GetFirstNodeByName(GUIDE_LINE_NAME)
            if not isinstance(line, slicer.vtkMRMLMarkupsLineNode):
                line = scene.AddNewNodeByClass("vtkMRMLMarkupsLineNode", GUIDE_LINE_NAME)
        line.RemoveAllControlPoints()
        line.AddControlPointWorld(vtk.vtkVector3d(*start))
        line.AddControlPointWorld(vtk.vtkVector3d(*end))
        self.guide_line = line
        self.on_guide_axis(line)

    # ------------------------------------------------------------------ the bridge's thread

    def _wake(self) -> None:
        poke = self._wake_out
        if poke is None:
            return  # not started, or stopped
        try:
            poke.send(b"\0")
        except (BlockingIOError, OSError):
            pass  # already awake: the pipe is full of pokes

    def _run(self) -> None:
        while not self._stop.is_set():
            now = time.monotonic()
            deadlines = [now + 0.1]
            if self._clients:
                # Only what waits to go out sets a deadline: a past one with nothing to send would spin.
                with self._lock:
                    pose_waits = self._pose is not None and self._pose_seq != self._sent_pose_seq
                    monitor_waits = self._monitor is not None and self._monitor_seq != self._sent_monitor_seq
                deadlines.append(self._next_image_at)
                if pose_waits:
                    deadlines.append(self._next_pose_at)
                if monitor_waits:
                    deadlines.append(self._next_monitor_at)
                if self._image is not None and self._image.updating:
                    deadlines.append(now)
            timeout = max(0.0, min(deadlines) - now)
            try:
                events = self._selector.select(timeout)
            except OSError:
                break
            for key, mask in events:
                if key.data == "listener":
                    self._accept()
                elif key.data == "wake":
                    try:
                        while self._wake_in.recv(4096):
                            pass
                    except (BlockingIOError, OSError):
                        pass
                else:
                    client = key.data
                    if mask & selectors.EVENT_READ:
                        self._receive(client)
                    if mask & selectors.EVENT_WRITE and client in self._clients:
                        self._send(client)
            # Poses and readings go out before an image update is computed: they are small and wanted first.
            for produce in (self._produce_streams, self._produce_images):
                try:
                    produce(time.monotonic())
                except Exception as error:  # a broken snapshot must not end the bridge
                    self.last_refusal = f"producing: {error}"
                for client in list(self._clients):
                    self._send(client)
            for client in list(self._clients):
                if client.waiting and time.monotonic() - client.last_progress > self.options.stall_timeout_s:
                    self._close(client, "stalled")

    def _accept(self) -> None:
        try:
            connection, address = self._listener.accept()
        except (BlockingIOError, OSError):
            return
        if len(self._clients) >= self.options.max_clients:
            connection.close()
            with self._lock:
                self._stats["clients_dropped"]["too many"] += 1
            return
        connection.setblocking(False)
        connection.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        if self.options.send_buffer_bytes > 0:
            connection.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, int(self.options.send_buffer_bytes))
        client = _Client(connection, address)
        with self._lock:
            self._clients.append(client)
            self._stats["clients_connected"] += 1
            # A newcomer gets the present state at once.
            self._sent_pose_seq = self._sent_monitor_seq = -1
        self._selector.register(connection, selectors.EVENT_READ, client)
        self._next_pose_at = self._next_monitor_at = self._next_image_at = time.monotonic()

    def _close(self, client: _Client, reason: str | None) -> None:
        with self._lock:
            if client in self._clients:
                self._clients.remove(client)
            if reason:
                self._stats["clients_dropped"][reason] += 1
        try:
            if self._selector is not None:
                self._selector.unregister(client.socket)
        except (KeyError, ValueError, OSError):
            pass
        client.socket.close()

    def _refuse(self, refusal: protocol.Refused) -> None:
        with self._lock:
            self._stats["refused"][refusal.reason] += 1
        self.last_refusal = str(refusal)

    def _receive(self, client: _Client) -> None:
        try:
            data = client.socket.recv(RECEIVE_CHUNK_BYTES)
        except (BlockingIOError, InterruptedError):
            return
        except OSError:
            self._close(client, "gone")
            return
        if not data:
            self._close(client, "gone")
            return
        client.received += data
        while True:
            if client.header is None:
                if len(client.received) < protocol.HEADER_SIZE:
                    return
                raw = bytes(client.received[:protocol.HEADER_SIZE])
                del client.received[:protocol.HEADER_SIZE]
                try:
                    client.header = protocol.read_header(raw)
                except protocol.Refused as refusal:
                    self._refuse(refusal)
                    self._close(client, "malformed")
                    return
            if len(client.received) < client.header.body_size:
                return
            header, client.header = client.header, None
            body = bytes(client.received[:header.body_size])
            del client.received[:header.body_size]
            try:
                message = protocol.decode(header, body)
            except protocol.Refused as refusal:
                self._refuse(refusal)
                continue
            self._accept_message(header, message)

    def _accept_message(self, header: protocol.Header, message) -> None:
        device = header.device_name
        if header.message_type == "TRANSFORM" and device in (MOVE_DEVICE, DRILL_DEVICE):
            payload = [float(v) for v in np.asarray(message.matrix, dtype=float).ravel()]
        elif device == GUIDE_DEVICE:
            payload = self._guide_from(header.message_type, message)
            if payload is None:
                return
        else:
            self._refuse(protocol.Refused("type", f"{header.message_type} '{device}' is not a device the bridge acts on"))
            return
        with self._lock:
            if len(self._commands) == self._commands.maxlen:
                self._stats["commands_dropped"] += 1
            self._commands.append((device, payload, time.time()))
            self._stats["accepted"][header.message_type] += 1

    def _guide_from(self, message_type: str, message):
        if message_type == "POINT":
            points = np.asarray(message.positions, dtype=float).reshape(-1, 3)
            if len(points) < 2 or np.linalg.norm(points[1] - points[0]) < 0.1:
                self._refuse(protocol.Refused("body", "a guide axis needs two points at least 0.1 mm apart"))
                return None
            return points[0].tolist(), points[1].tolist()
        matrix = np.asarray(message.matrix, dtype=float)
        origin = matrix[:3, 3]
        return origin.tolist(), (origin + 10.0 * matrix[:3, 2]).tolist()

    def _produce_streams(self, now: float) -> None:
        """Put what is due into every client's queue: the latest pose and readings, a new contact."""
        if not self._clients:
            return
        pose_period, monitor_period = 1.0 / self.options.pose_rate_hz, 1.0 / self.options.monitor_rate_hz
        with self._lock:
            pose = self._pose if self._pose_seq != self._sent_pose_seq else None
            pose_seq = self._pose_seq
            monitor = self._monitor if self._monitor_seq != self._sent_monitor_seq else None
            monitor_seq = self._monitor_seq
            contact = self._contact if self._contact_seq != self._sent_contact_seq else None
            self._sent_contact_seq = self._contact_seq
        if pose is not None and now >= self._next_pose_at:
            self._broadcast(TOOL_DEVICE, "TRANSFORM", protocol.pack_transform(TOOL_DEVICE, np.reshape(pose[0], (4, 4)), pose[1]))
            self._sent_pose_seq = pose_seq
            # Paced on a fixed grid: a faster source yields exactly the rate asked for.
            self._next_pose_at = max(self._next_pose_at + pose_period, now - pose_period)
        if monitor is not None and (monitor[2] or now >= self._next_monitor_at):
            self._broadcast(MONITOR_DEVICE, "STRING", protocol.pack_string(MONITOR_DEVICE, monitor[0], monitor[1]))
            self._sent_monitor_seq = monitor_seq
            self._next_monitor_at = now + monitor_period
        if contact is not None:
            self._broadcast(CONTACT_DEVICE, "STRING", protocol.pack_string(CONTACT_DEVICE, contact[0], contact[1]))

    def _produce_images(self, now: float) -> None:
        """The whole image to newcomers, the changed box to the others, at most ``image_rate_hz``."""
        if not self._clients:
            return
        with self._lock:
            geometry, geometry_seq = self._geometry, self._geometry_seq
        if self._image is None or self._image.seq != geometry_seq:
            self._image = _ImageMirror(geometry, geometry_seq) if geometry is not None else None
            for client in self._clients:
                client.needs_full_image = True
        due = now >= self._next_image_at and (self._image is None or not self._image.updating)
        if due:
            self._next_image_at = now + 1.0 / self.options.image_rate_hz
        if self._image is None:
            return
        if due:
            self._image_began = (time.perf_counter(), self._image_cpu)
            self._image.begin_update()  # follows the field whoever is behind
        if self._image.updating:
            # A slice at a time: poses and readings go out between slices, and the scene's thread gets the interpreter.
            began_cpu = time.thread_time()
            box = self._image.advance(IMAGE_SLICE_S)
            self._image_cpu += time.thread_time() - began_cpu
            if box is not None:
                self.image_compute_s.append((time.perf_counter() - self._image_began[0], self._image_cpu - self._image_began[1]))
                self._send_image_box(box)
        if not self._image.updating:
            # Newcomers get the whole image when no update is half done.
            for client in self._clients:
                if client.needs_full_image:
                    self._queue(client, self._image.pack_whole())
                    client.needs_full_image = False

    def _broadcast(self, device: str, message_type: str, packed: bytes) -> None:
        for client in self._clients:
            client.latest[device] = (message_type, packed)  # replaces one not sent yet

    def _send_image_box(self, box) -> None:
        packed = self._image.pack_box(*box)
        for client in self._clients:
            if not client.needs_full_image:
                self._queue(client, packed)
        with self._lock:
            self._stats["image_updates"] += 1
            self._stats["image_update_bytes"] += len(packed)

    def _queue(self, client: _Client, packed: bytes) -> None:
        if client.queued_bytes + len(packed) > self.options.max_backlog_bytes:
            # Behind by more than the backlog: its image starts again whole once it catches up.
            client.queue.clear()
            client.queued_bytes = 0
            client.needs_full_image = True
            return
        client.queue.append(("IMAGE", packed))
        client.queued_bytes += len(packed)

    def _send(self, client: _Client) -> None:
        if len(client.out) < LOW_WATER_BYTES:
            moved = [client.latest.pop(device) for device in list(client.latest)]
            while client.queue and len(client.out) + sum(len(m[1]) for m in moved) < LOW_WATER_BYTES:
                moved.append(client.queue.popleft())
                client.queued_bytes -= len(moved[-1][1])
            if moved:
                with self._lock:
                    for message_type, packed in moved:
                        client.out += packed
                        self._stats["sent"][message_type] += 1
                        self._stats["sent_bytes"][message_type] += len(packed)
        if len(client.out) > self.options.max_backlog_bytes:
            self._close(client, "too slow")
            return
        if client.out:
            try:
                sent = client.socket.send(client.out)
            except (BlockingIOError, InterruptedError):
                sent = 0
            except OSError:
                self._close(client, "gone")
                return
            if sent:
                del client.out[:sent]
                client.last_progress = time.monotonic()
        if not client.waiting:
            client.last_progress = time.monotonic()
        events = selectors.EVENT_READ | (selectors.EVENT_WRITE if client.out else 0)
        try:
            self._selector.modify(client.socket, events, client)
        except (KeyError, ValueError, OSError):
            pass


class _ImageMirror:
    """The removed fraction (0-255) of every CT voxel, kept up to date from the cut field's brick stamps.

    ``vtkVolumeCutFractionMirror`` does the work in C++ on the bridge's thread
    and releases Python's interpreter lock meanwhile, so that the scene's
    thread (the mouse's drilling) runs beside it; it recomputes the changed
    bricks and their neighbours a slice at a time (``advance``).
    """

    def __init__(self, geometry, seq: int):
        self.field, self.dimensions, self.ijk_to_ras = geometry
        self.seq = seq
        self.mirror = slicer.vtkVolumeCutFractionMirror()
        if not self.mirror.Reset(self.field):
            raise RuntimeError("the removed region cannot be mirrored: the cut field is not initialized")
        image = self.mirror.GetImage()
        # A view of the C++ image's voxels (k, j, i), valid while the mirror lives.
        self.voxels = numpy_support.vtk_to_numpy(image.GetPointData().GetScalars()).reshape(self.dimensions[::-1])
        self._box = None

    @property
    def updating(self) -> bool:
        return bool(self.mirror.IsUpdating())

    @property
    def stamp(self) -> int:
        return self.mirror.GetStamp()

    def begin_update(self) -> None:
        """List the bricks to recompute: those changed since the last update and their neighbours."""
        self._box = None
        if self.mirror.BeginUpdate():
            box = [0] * 6
            self.mirror.GetUpdateBox(box)
            self._box = (np.array(box[0::2]), np.array(box[1::2]))

    def advance(self, budget_s: float):
        """Recompute pending bricks for about ``budget_s``; the changed box (lower, upper: i, j, k) once all are done."""
        if self._box is None:
            return None
        done = self.mirror.Advance(budget_s)
        return self._box if done else None

    def pack_whole(self) -> bytes:
        return protocol.pack_image(IMAGE_DEVICE, self.voxels, self.dimensions, (0, 0, 0), self.ijk_to_ras, time.time())

    def pack_box(self, lower, upper) -> bytes:
        box = self.voxels[lower[2]:upper[2], lower[1]:upper[1], lower[0]:upper[0]]
        return protocol.pack_image(IMAGE_DEVICE, box, self.dimensions, tuple(int(v) for v in lower), self.ijk_to_ras, time.time())


class _LogicDriver:
    """Moves the cut node's active tool through the module logic, as the mouse or a replay does."""

    def __init__(self, logic, cut_node):
        self.logic, self.cut_node = logic, cut_node

    @property
    def in_stroke(self) -> bool:
        field = self.cut_node.GetCutField() if self.cut_node is not None else None
        return bool(field is not None and field.IsStrokeOpen())

    def begin_stroke(self) -> bool:
        return bool(self.logic.BeginStroke(self.cut_node))

    def move_tool(self, pose) -> bool:
        action = slicer.vtkSlicerVolumeCuttingLogic.ToolCut if self.in_stroke else slicer.vtkSlicerVolumeCuttingLogic.ToolMove
        return bool(self.logic.MoveActiveTool(self.cut_node, pose, action))

    def end_stroke(self) -> bool:
        return bool(self.logic.EndStroke(self.cut_node))
