"""Codec of the UDP datagram, versions 1 and 2 (all fields little-endian):

    offset size field
    0      4    magic b"MCAP"
    4      2    version (1, or 2)
    6      2    J, number of joint records
    8      8    sequence number (uint64)
    16     8    capture timestamp, ns, CLOCK_MONOTONIC (trigger of the frame)
    24     8    publish timestamp, ns, same clock
    32     4    flags (bit 0: every body of the model was found; bit 1: the state is
                predicted by the tracker to publish + lead_us)
    36     4    lead_us: with flag bit 1 the lead in microseconds, else 0
    40     32*J joint records: uint16 index, uint8 type (0 ball, 1 hinge), uint8 valid,
                float32 a0 a1 a2 (radians), float32 qw qx qy qz
    40+32J 4    CRC-32 (zlib.crc32) of all bytes before it

Version 2 records are 72 bytes: the 32 bytes above, then uint8 solved_by (0 none, 1 poses,
2 chain), uint8 rate_valid, 2 reserved bytes, float32 sd of a0 a1 a2 (radians), float32
da0 da1 da2 (rad/s, the tracker's causal rates), float32 their sds (rad/s); the CRC follows
at 40 + 72 J.

Receivers drop datagrams whose magic, version, length or CRC do not match: decode()
raises DecodeError with `reason` one of "short", "magic", "version", "length", "crc".
"""
import struct
import zlib
from collections import namedtuple

VERSION = 1
VERSION_2 = 2
BALL = 0
HINGE = 1
FLAG_ALL_BODIES_FOUND = 1
FLAG_PREDICTED = 2
MAX_JOINTS = 32

_HEADER = struct.Struct("<4sHHQqqII")
_RECORD = struct.Struct("<HBB3f4f")
_TAIL_V2 = struct.Struct("<BBxx3f3f3f")
_RECORD_BYTES = {VERSION: _RECORD.size, VERSION_2: _RECORD.size + _TAIL_V2.size}
_CRC = struct.Struct("<I")

JointRecord = namedtuple("JointRecord", "index type valid a q solved_by sd rate_valid rate rate_sd",
                         defaults=(None, None, False, None, None))
JointRecord.__doc__ = ("One joint: index in model.yaml, type (BALL/HINGE), valid (bool), "
                       "a = (a0, a1, a2) radians, q = (qw, qx, qy, qz) of R_parent^T R_child; "
                       "version 2 only (else None/False): solved_by (0 none, 1 poses, 2 chain), "
                       "sd of a (radians), rate_valid, rate = (da0, da1, da2) rad/s, rate_sd")

Message = namedtuple("Message", "sequence capture_ns publish_ns flags joints version lead_us",
                     defaults=(VERSION, 0))
Message.__doc__ = ("One decoded datagram; joints is a tuple of JointRecord; lead_us: with "
                   "flags & FLAG_PREDICTED, the state is predicted to publish_ns + lead_us us.")


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
    magic, version, count, seq, capture, publish, flags, lead_us = _HEADER.unpack_from(data, 0)
    if magic != b"MCAP":
        raise DecodeError("magic", "magic %r is not b'MCAP'" % magic)
    if version not in _RECORD_BYTES:
        raise DecodeError("version", "version %d is not 1 or 2" % version)
    record_bytes = _RECORD_BYTES[version]
    body = _HEADER.size + record_bytes * count
    if count > MAX_JOINTS or len(data) != body + _CRC.size:
        raise DecodeError("length", "%d bytes do not fit J=%d" % (len(data), count))
    (crc,) = _CRC.unpack_from(data, body)
    if crc != zlib.crc32(data[:body]) & 0xFFFFFFFF:
        raise DecodeError("crc", "CRC-32 mismatch")
    joints = []
    for j in range(count):
        at = _HEADER.size + record_bytes * j
        index, jtype, valid, a0, a1, a2, qw, qx, qy, qz = _RECORD.unpack_from(data, at)
        record = JointRecord(index, jtype, bool(valid), (a0, a1, a2), (qw, qx, qy, qz))
        if version == VERSION_2:
            t = _TAIL_V2.unpack_from(data, at + _RECORD.size)
            record = record._replace(solved_by=t[0], sd=tuple(t[2:5]), rate_valid=bool(t[1]),
                                     rate=tuple(t[5:8]), rate_sd=tuple(t[8:11]))
        joints.append(record)
    lead_us = lead_us if flags & FLAG_PREDICTED and lead_us <= 0xFFFF else 0
    return Message(seq, capture, publish, flags, tuple(joints), version, lead_us)


def encode(message):
    """Encodes a Message into a datagram of message.version (for tests and simulators)."""
    version = message.version
    if version not in _RECORD_BYTES:
        raise ValueError("version %r is not 1 or 2" % (version,))
    out = bytearray(_HEADER.pack(b"MCAP", version, len(message.joints), message.sequence,
                                 message.capture_ns, message.publish_ns, message.flags,
                                 message.lead_us if message.flags & FLAG_PREDICTED else 0))
    for j in message.joints:
        out += _RECORD.pack(j.index, j.type, 1 if j.valid else 0, *j.a, *j.q)
        if version == VERSION_2:
            out += _TAIL_V2.pack(j.solved_by or 0, 1 if j.rate_valid else 0,
                                 *(j.sd or (0.0, 0.0, 0.0)), *(j.rate or (0.0, 0.0, 0.0)),
                                 *(j.rate_sd or (0.0, 0.0, 0.0)))
    out += _CRC.pack(zlib.crc32(bytes(out)) & 0xFFFFFFFF)
    return bytes(out)
