"""A client of the OpenIGTLink bridge that keeps every message it receives, with its arrival time.

pyigtl's own ``OpenIGTLinkClient`` keeps only the latest message per device
and reads whole images only; scripts, tests and benchmarks that count rates
and latencies need each message, and the removed region's sub-volume
updates. This client reads them with pyigtl's message classes (and
:class:`.igtlprotocol.SubVolumeImageMessage` for IMAGE, which places a
sub-volume as SlicerOpenIGTLink does) and can send any pyigtl message.
"""

from __future__ import annotations

import socket
import threading
import time
from dataclasses import dataclass

import numpy as np
from pyigtl import messages as igtl

from . import igtlprotocol as protocol


@dataclass
class Received:
    message_type: str
    device_name: str
    arrived: float  # time.time() when its last byte was read
    timestamp: float  # the sender's time stamp
    size_bytes: int
    message: object

    @property
    def latency_s(self) -> float:
        return self.arrived - self.timestamp


class RecordingClient:
    """Connects to ``host:port`` and records what arrives until ``close()``; ``image`` is the IMAGE as assembled."""

    def __init__(self, host: str, port: int, connect_timeout_s: float = 5.0):
        self.received: list[Received] = []
        self.connected_at = time.time()
        self.image = None  # (voxels k, j, i; ijk_to_ras) assembled from whole images and sub-volumes
        self.error = None
        self._lock = threading.RLock()  # wait_for's predicate may call messages()
        self._socket = socket.create_connection((host, port), timeout=connect_timeout_s)
        self._socket.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self._socket.settimeout(0.2)
        self._closing = False
        self._thread = threading.Thread(target=self._read, name="OpenIGTLink recording client", daemon=True)
        self._thread.start()

    def _read_exactly(self, count: int) -> bytes | None:
        chunks, missing = [], count
        while missing:
            try:
                chunk = self._socket.recv(min(missing, 1 << 20))
            except socket.timeout:
                if self._closing:
                    return None
                continue
            except OSError:
                return None
            if not chunk:
                return None
            chunks.append(chunk)
            missing -= len(chunk)
        return b"".join(chunks)

    def _read(self) -> None:
        while not self._closing:
            raw = self._read_exactly(protocol.HEADER_SIZE)
            if raw is None:
                return
            fields = igtl.MessageBase.parse_header(raw)
            body = self._read_exactly(fields["body_size"])
            if body is None:
                return
            arrived = time.time()
            message_type = fields["message_type"]
            message = protocol.SubVolumeImageMessage() if message_type == "IMAGE" else igtl.MessageBase.create_message(message_type)
            try:
                if message is None:
                    raise ValueError(f"unknown message type {message_type}")
                if igtl.CRC64(body) != struct_crc(raw):
                    raise ValueError(f"{message_type} '{fields['device_name']}': CRC mismatch")
                message.unpack(fields, body)
            except Exception as error:  # recorded: a test says what was wrong
                self.error = str(error)
                continue
            with self._lock:
                if message_type == "IMAGE":
                    self._place(message)
                self.received.append(Received(message_type, fields["device_name"], arrived, fields["timestamp"],
                                              protocol.HEADER_SIZE + len(body), message))

    def _place(self, message) -> None:
        size = message.full_size
        if self.image is None or self.image[0].shape != (size[2], size[1], size[0]):
            self.image = (np.zeros((size[2], size[1], size[0]), dtype=message.image.dtype), message.ijk_to_world_matrix)
        i, j, k = message.offset
        depth, rows, columns = message.image.shape[:3]
        self.image[0][k:k + depth, j:j + rows, i:i + columns] = message.image

    def messages(self, message_type: str | None = None, device_name: str | None = None) -> list[Received]:
        with self._lock:
            return [r for r in self.received if (message_type is None or r.message_type == message_type)
                    and (device_name is None or r.device_name == device_name)]

    def wait_for(self, predicate, timeout_s: float = 5.0) -> bool:
        """Wait until ``predicate(self)`` holds (True) or ``timeout_s`` passes (False)."""
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            with self._lock:
                if predicate(self):
                    return True
            time.sleep(0.002)
        with self._lock:
            return bool(predicate(self))

    def send(self, message) -> None:
        self._socket.sendall(message.pack())

    def close(self) -> None:
        self._closing = True
        try:
            self._socket.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
        self._thread.join(timeout=2.0)
        self._socket.close()


def struct_crc(raw_header: bytes) -> int:
    """The CRC-64 a header announces for its body."""
    return protocol.HEADER.unpack(raw_header)[6]
