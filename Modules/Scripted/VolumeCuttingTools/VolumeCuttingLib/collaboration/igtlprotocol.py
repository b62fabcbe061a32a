"""OpenIGTLink messages on the wire: what the bridge sends, and the checks every incoming message passes.

The message classes and the CRC-64 are pyigtl's (``pyigtl.messages``); this
module adds what the bridge needs around them:

* :func:`read_header` and :func:`decode` refuse a malformed message with a
  :class:`Refused` that names one of the reasons in :data:`REASONS` (bad
  header, size, CRC, type, body). A refusal after which the byte stream
  cannot be trusted (a header that is not one, a body too large to read) is
  ``fatal``: the bridge closes that connection; the others skip the message.
  pyigtl itself checks no CRC and reads any body size, so both are checked
  here before pyigtl unpacks anything.
* :class:`SubVolumeImageMessage` sends part of an image: the whole image's
  size and geometry with the offset and size of the voxels carried, the
  OpenIGTLink IMAGE message's sub-volume, which SlicerOpenIGTLink writes into
  the volume it already has (pyigtl 0.3.4 sends and reads whole images only).
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

import numpy as np
from pyigtl import messages as igtl

HEADER = struct.Struct(">H12s20sIIQQ")
HEADER_SIZE = HEADER.size  # 58 bytes
EXTENDED_HEADER = struct.Struct(">HHII")  # header version 2: its size, metadata sizes, message ID
HEADER_VERSIONS = (1, 2)
# Bodies above this are not read: the sender is not one the bridge serves, the connection is closed.
MAXIMUM_BODY_BYTES = 1 << 20
TRANSFORM_CONTENT_BYTES = 48
POINT_ITEM_BYTES = 136
MAXIMUM_POINTS = 64
# What the bridge accepts; every other type is refused (its body skipped).
ACCEPTED_TYPES = ("TRANSFORM", "POINT")
# Scene coordinates beyond this (mm) are not a pose in any patient.
MAXIMUM_COORDINATE_MM = 1.0e4
ROTATION_TOLERANCE = 1.0e-3

REASONS = ("header", "size", "crc", "type", "body")


class Refused(Exception):
    """A message the bridge does not act on: ``reason`` (one of REASONS) and whether the stream is lost (``fatal``)."""

    def __init__(self, reason: str, message: str, fatal: bool = False):
        super().__init__(message)
        self.reason = reason
        self.fatal = fatal


@dataclass(frozen=True)
class Header:
    version: int
    message_type: str
    device_name: str
    timestamp: float
    body_size: int
    crc: int

    def fields(self) -> dict:
        """The header as pyigtl's ``MessageBase.unpack`` takes it."""
        return {"header_version": self.version, "message_type": self.message_type, "device_name": self.device_name,
                "timestamp": self.timestamp, "body_size": self.body_size}


def _text_field(raw: bytes, what: str, required: bool) -> str:
    text = raw.split(b"\0", 1)[0]
    try:
        decoded = text.decode("ascii")
    except UnicodeDecodeError:
        raise Refused("header", f"the {what} is not ASCII", fatal=True) from None
    if required and not decoded:
        raise Refused("header", f"the {what} is empty", fatal=True)
    if not all(32 < ord(c) < 127 for c in decoded):
        raise Refused("header", f"the {what} has characters that are not printable", fatal=True)
    return decoded


def read_header(raw: bytes) -> Header:
    """The header of 58 bytes; Refused (fatal) when it cannot be one, or announces a body the bridge does not read."""
    if len(raw) != HEADER_SIZE:
        raise Refused("header", f"a header has {HEADER_SIZE} bytes, not {len(raw)}", fatal=True)
    version, message_type, device_name, seconds, fraction, body_size, crc = HEADER.unpack(raw)
    if version not in HEADER_VERSIONS:
        raise Refused("header", f"header version {version} (1 and 2 are known)", fatal=True)
    message_type = _text_field(message_type, "message type", required=True)
    device_name = _text_field(device_name, "device name", required=False)
    if body_size > MAXIMUM_BODY_BYTES:
        raise Refused("size", f"a body of {body_size} bytes (at most {MAXIMUM_BODY_BYTES} are read)", fatal=True)
    timestamp = seconds + igtl._igtl_frac_to_nanosec(fraction) * 1e-9
    return Header(version, message_type, device_name, timestamp, int(body_size), int(crc))


def content_size(header: Header, body: bytes) -> int:
    """The bytes of the message's own content: the body less a version-2 extended header and metadata."""
    if header.version == 1:
        return len(body)
    if len(body) < EXTENDED_HEADER.size:
        raise Refused("body", "the extended header is cut short")
    extended, metadata_header, metadata_body, _ = EXTENDED_HEADER.unpack(body[:EXTENDED_HEADER.size])
    if extended < EXTENDED_HEADER.size or extended + metadata_header + metadata_body > len(body):
        raise Refused("body", "the extended header's sizes do not fit in the body")
    return len(body) - extended - metadata_header - metadata_body


def _rigid(matrix: np.ndarray) -> str | None:
    """Why ``matrix`` is not a rigid pose in the scene, or None."""
    if not np.all(np.isfinite(matrix)):
        return "it is not finite"
    if np.any(np.abs(matrix[:3, 3]) > MAXIMUM_COORDINATE_MM):
        return f"its translation is beyond {MAXIMUM_COORDINATE_MM:g} mm"
    rotation = matrix[:3, :3]
    if np.max(np.abs(rotation.T @ rotation - np.eye(3))) > ROTATION_TOLERANCE or np.linalg.det(rotation) <= 0.0:
        return "its rotation is not a rotation (a scaled, sheared or mirrored matrix)"
    return None


def decode(header: Header, body: bytes):
    """A checked message (pyigtl's TransformMessage or PointMessage), or Refused saying why not."""
    if len(body) != header.body_size:
        raise Refused("size", f"the body has {len(body)} bytes, the header says {header.body_size}")
    if igtl.CRC64(body) != header.crc:
        raise Refused("crc", f"{header.message_type} '{header.device_name}': the body's CRC-64 does not match the header's")
    if header.message_type not in ACCEPTED_TYPES:
        raise Refused("type", f"{header.message_type} messages are not accepted (only {', '.join(ACCEPTED_TYPES)})")
    size = content_size(header, body)
    if header.message_type == "TRANSFORM" and size != TRANSFORM_CONTENT_BYTES:
        raise Refused("size", f"a TRANSFORM carries {TRANSFORM_CONTENT_BYTES} bytes, not {size}")
    if header.message_type == "POINT" and (size == 0 or size % POINT_ITEM_BYTES or size > MAXIMUM_POINTS * POINT_ITEM_BYTES):
        raise Refused("size", f"a POINT carries 1 to {MAXIMUM_POINTS} items of {POINT_ITEM_BYTES} bytes, not {size} bytes")
    message = igtl.MessageBase.create_message(header.message_type)
    try:
        message.unpack(header.fields(), body)
    except Exception as error:  # pyigtl raises whatever struct or decoding raises: all mean a bad body
        raise Refused("body", f"{header.message_type} '{header.device_name}' does not unpack: {error}") from None
    if header.message_type == "TRANSFORM":
        why = _rigid(np.asarray(message.matrix, dtype=float))
        if why:
            raise Refused("body", f"TRANSFORM '{header.device_name}': {why}")
    else:
        positions = np.asarray(message.positions, dtype=float).reshape(-1, 3)
        if not np.all(np.isfinite(positions)) or np.any(np.abs(positions) > MAXIMUM_COORDINATE_MM):
            raise Refused("body", f"POINT '{header.device_name}': a position is not finite or beyond {MAXIMUM_COORDINATE_MM:g} mm")
    return message


def pack_transform(device_name: str, matrix, timestamp: float) -> bytes:
    return igtl.TransformMessage(np.asarray(matrix, dtype=np.float32).reshape(4, 4), timestamp=timestamp,
                                 device_name=device_name).pack()


def pack_string(device_name: str, text: str, timestamp: float) -> bytes:
    return igtl.StringMessage(text, timestamp=timestamp, device_name=device_name).pack()


class SubVolumeImageMessage(igtl.ImageMessage):
    """An IMAGE message carrying the voxels of a box of a larger image (OpenIGTLink's sub-volume).

    ``image`` holds the box's voxels (k, j, i), ``full_size`` the whole
    image's (i, j, k) size, ``offset`` the box's first voxel (i, j, k), and
    ``ijk_to_world_matrix`` the whole image's geometry. Unpacking reads
    whole images and sub-volumes alike (the ``offset`` and ``full_size`` say
    where the voxels go), so that scripts and tests read what Slicer reads.
    """

    def __init__(self, image=None, full_size=None, offset=(0, 0, 0), ijk_to_world_matrix=None, timestamp=None, device_name=None):
        super().__init__(image=image, ijk_to_world_matrix=ijk_to_world_matrix, world_coordinate_system="ras",
                         timestamp=timestamp, device_name=device_name)
        self.offset = tuple(int(v) for v in offset)
        self.full_size = tuple(int(v) for v in full_size) if full_size is not None else \
            (tuple(self.image.shape[2::-1]) if self.image is not None else (0, 0, 0))

    def _pack_content(self):
        sub_size = self.image.shape[2::-1]
        scalar_type = next(code for code, dtype in igtl.ImageMessage.scalar_types.items() if self.image.dtype == dtype)
        matrix = np.asarray(self.ijk_to_world_matrix, dtype=float)
        # OpenIGTLink places an image by its centre; its axes carry the spacing (as the C++ library packs them).
        center = matrix @ np.array([(self.full_size[0] - 1) / 2.0, (self.full_size[1] - 1) / 2.0, (self.full_size[2] - 1) / 2.0, 1.0])
        axes = matrix[:3, :3]
        little = 2 if self.image.dtype.byteorder in ("<", "=", "|") else 1
        content = struct.pack(">HBBBBHHH", 1, 1, scalar_type, little, 1, *self.full_size)
        content += struct.pack(">12f", *axes[:, 0], *axes[:, 1], *axes[:, 2], *center[:3])
        content += struct.pack(">6H", *self.offset, *sub_size)
        return content + np.ascontiguousarray(self.image).tobytes()

    def _unpack_content(self, content):
        head = struct.Struct(">HBBBBHHH12f6H")
        values = head.unpack(content[:head.size])
        components, scalar_type, endian = values[1], values[2], values[3]
        self.world_coordinate_system = "ras" if values[4] == 1 else "lps"
        self.full_size = tuple(values[5:8])
        axes = np.array(values[8:17], dtype=float).reshape(3, 3).T
        center = np.array(values[17:20], dtype=float)
        self.offset = tuple(values[20:23])
        sub_size = values[23:26]
        dtype = np.dtype(igtl.ImageMessage.scalar_types[scalar_type]).newbyteorder("<" if endian == 2 else ">")
        voxels = np.frombuffer(content[head.size:], dtype=dtype)
        shape = [sub_size[2], sub_size[1], sub_size[0]] + ([components] if components > 1 else [])
        self.image = voxels.reshape(shape)
        self.ijk_to_world_matrix = np.eye(4)
        self.ijk_to_world_matrix[:3, :3] = axes
        self.ijk_to_world_matrix[:3, 3] = center - axes @ ((np.array(self.full_size) - 1) / 2.0)


def pack_image(device_name: str, voxels: np.ndarray, full_size, offset, ijk_to_ras: np.ndarray, timestamp: float) -> bytes:
    """An IMAGE message of ``voxels`` (k, j, i) at ``offset`` (i, j, k) in an image of ``full_size`` (i, j, k)."""
    if any(size > 65535 for size in full_size):
        raise ValueError(f"an OpenIGTLink image has at most 65535 voxels along an axis, not {tuple(full_size)}")
    return SubVolumeImageMessage(voxels, full_size=full_size, offset=offset, ijk_to_world_matrix=ijk_to_ras, timestamp=timestamp,
                                 device_name=device_name).pack()
