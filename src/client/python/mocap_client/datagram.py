"""Codec of the UDP datagram, version 1 (all fields little-endian):

    offset size field
    0      4    magic b"MCAP"
    4      2    version (1)
    6      2    J, number of joint records
    8      8    sequence number (uint64)
    16     8    capture timestamp, ns, CLOCK_MONOTONIC (trigger of the frame)
    24     8    publish timestamp, ns, same clock
    32     4    flags (bit 0: every body of the model was found)
    36     4    reserved, 0
    40     32*J joint records: uint16 index, uint8 type (0 ball, 1 hinge), uint8 valid,
                float32 a0 a1 a2 (radians), float32 qw qx qy qz
    40+32J 4    CRC-32 (zlib.crc32) of all bytes before it

Receivers drop datagrams whose magic, version, length or CRC do not match: decode()
raises DecodeError with `reason` one of "short", "magic", "version", "length", "crc".
"""
import struct
import zlib
from collections import namedtuple

VERSION = 1
BALL = 0
HINGE = 1
FLAG_ALL_BODIES_FOUND = 1
MAX_JOINTS = 32

_HEADER = struct.Struct("<4sHHQqqII")
_RECORD = struct.Struct("<HBB3f4f")
_CRC = struct.Struct("<I")

JointRecord = namedtuple("JointRecord", "index type valid a q")
JointRecord.__doc__ = ("One joint: index in model.yaml, type (BALL/HINGE), valid (bool), "
                       "a = (a0, a1, a2) radians, q = (qw, qx, qy, qz) of R_parent^T R_child")

Message = namedtuple("Message", "sequence capture_ns publish_ns flags joints")
Message.__doc__ = "One decoded datagram; joints is a tuple of JointRecord."


class DecodeError(ValueError):
    """A datagram that a receiver must drop; `reason` says why."""

    def __init__(self, reason, detail):
        super().__init__("%s: %s" % (reason, detail))
        self.reason = reason


def decode(data):
    """Decodes one datagram (bytes-like) into a Message, or raises DecodeError."""
    data = bytes(data)
    if len(data) < _HEADER.size + _CRC.size:
        raise DecodeError("short", "%d bytes, at least 44 needed" % len(data))
    magic, version, count, seq, capture, publish, flags, _reserved = _HEADER.unpack_from(data, 0)
    if magic != b"MCAP":
        raise DecodeError("magic", "magic %r is not b'MCAP'" % magic)
    if version != VERSION:
        raise DecodeError("version", "version %d is not 1" % version)
    body = _HEADER.size + _RECORD.size * count
    if count > MAX_JOINTS or len(data) != body + _CRC.size:
        raise DecodeError("length", "%d bytes do not fit J=%d" % (len(data), count))
    (crc,) = _CRC.unpack_from(data, body)
    if crc != zlib.crc32(data[:body]) & 0xFFFFFFFF:
        raise DecodeError("crc", "CRC-32 mismatch")
    joints = []
    for j in range(count):
        index, jtype, valid, a0, a1, a2, qw, qx, qy, qz = _RECORD.unpack_from(
            data, _HEADER.size + _RECORD.size * j)
        joints.append(JointRecord(index, jtype, bool(valid), (a0, a1, a2), (qw, qx, qy, qz)))
    return Message(seq, capture, publish, flags, tuple(joints))


def encode(message):
    """Encodes a Message into a datagram (for tests and simulators of a tracker)."""
    out = bytearray(_HEADER.pack(b"MCAP", VERSION, len(message.joints), message.sequence,
                                 message.capture_ns, message.publish_ns, message.flags, 0))
    for j in message.joints:
        out += _RECORD.pack(j.index, j.type, 1 if j.valid else 0, *j.a, *j.q)
    out += _CRC.pack(zlib.crc32(bytes(out)) & 0xFFFFFFFF)
    return bytes(out)
