#!/usr/bin/env python3
"""Independent decoder of the UDP datagram, version 1, written from the spec
(/work/shared/spec/interfaces.md, "Live output") with only `struct` and `zlib`.

It never imports or calls project code: it checks datagrams produced by the project's
C++ encoder against the message fields they were encoded from.

  decode_datagram.py --writer PATH_TO_write_datagrams   (ctest: generate, decode, compare)
  decode_datagram.py DATAGRAMS_FILE EXPECTED_FILE        (compare existing files)

Exit 0 when every datagram decodes and every field matches; 1 otherwise (each
mismatch is printed). The self-check at the end proves the comparison can fail: a
changed expected field, a flipped payload byte (CRC) and a wrong length must be caught.
"""
import os
import struct
import subprocess
import sys
import tempfile
import zlib

HEADER = struct.Struct("<4sHHQqqII")  # magic, version, J, seq, capture, publish, flags, reserved
RECORD = struct.Struct("<HBB3f4f")  # index, type, valid, a0 a1 a2, qw qx qy qz
CRC = struct.Struct("<I")
assert HEADER.size == 40 and RECORD.size == 32


class DecodeError(Exception):
    pass


def decode(data):
    """Returns a dict of the datagram's fields, or raises DecodeError (the spec's drops)."""
    if len(data) < HEADER.size + CRC.size:
        raise DecodeError("too short: %d bytes" % len(data))
    magic, version, count, seq, capture, publish, flags, reserved = HEADER.unpack_from(data, 0)
    if magic != b"MCAP":
        raise DecodeError("bad magic %r" % magic)
    if version != 1:
        raise DecodeError("bad version %d" % version)
    if len(data) != 40 + 32 * count + 4:
        raise DecodeError("bad length %d for J=%d" % (len(data), count))
    (crc,) = CRC.unpack_from(data, 40 + 32 * count)
    if crc != zlib.crc32(data[: 40 + 32 * count]) & 0xFFFFFFFF:
        raise DecodeError("bad CRC")
    if reserved != 0:
        raise DecodeError("reserved field is %d, not 0" % reserved)
    joints = [RECORD.unpack_from(data, 40 + 32 * j) for j in range(count)]
    return {"seq": seq, "capture_ns": capture, "publish_ns": publish, "flags": flags,
            "joints": joints}


def f32(text):
    """The float32 that a %.9g text denotes, exactly as the decoder sees it."""
    return struct.unpack("<f", struct.pack("<f", float(text)))[0]


def parse_expected(line):
    t = line.split()
    exp = {"seq": int(t[0]), "capture_ns": int(t[1]), "publish_ns": int(t[2]),
           "flags": int(t[3]), "joints": []}
    count = int(t[4])
    if len(t) != 5 + 10 * count:
        raise ValueError("expected line has %d tokens for J=%d" % (len(t), count))
    for j in range(count):
        r = t[5 + 10 * j: 15 + 10 * j]
        exp["joints"].append((int(r[0]), int(r[1]), int(r[2])) + tuple(f32(x) for x in r[3:]))
    return exp


def same_float(a, b):
    # Bit-exact, so that -0.0 != 0.0 is caught as well.
    return struct.pack("<f", a) == struct.pack("<f", b)


def compare(got, exp):
    """List of mismatches (empty when equal)."""
    bad = []
    for key in ("seq", "capture_ns", "publish_ns", "flags"):
        if got[key] != exp[key]:
            bad.append("%s: decoded %r, expected %r" % (key, got[key], exp[key]))
    if len(got["joints"]) != len(exp["joints"]):
        bad.append("J: decoded %d, expected %d" % (len(got["joints"]), len(exp["joints"])))
        return bad
    names = ("index", "type", "valid", "a0", "a1", "a2", "qw", "qx", "qy", "qz")
    for j, (g, e) in enumerate(zip(got["joints"], exp["joints"])):
        for k, name in enumerate(names):
            equal = g[k] == e[k] if k < 3 else same_float(g[k], e[k])
            if not equal:
                bad.append("joint %d %s: decoded %r, expected %r" % (j, name, g[k], e[k]))
    return bad


def read_datagrams(path):
    with open(path, "rb") as f:
        blob = f.read()
    out, pos = [], 0
    while pos < len(blob):
        (n,) = struct.unpack_from("<I", blob, pos)
        out.append(blob[pos + 4: pos + 4 + n])
        pos += 4 + n
    return out


def check_files(datagrams_path, expected_path):
    datagrams = read_datagrams(datagrams_path)
    with open(expected_path) as f:
        expected = [parse_expected(line) for line in f if line.strip()]
    if len(datagrams) != len(expected) or not datagrams:
        print("FAIL: %d datagrams, %d expected messages" % (len(datagrams), len(expected)))
        return 1
    failures = 0
    for i, (d, e) in enumerate(zip(datagrams, expected)):
        try:
            bad = compare(decode(d), e)
        except DecodeError as err:
            bad = ["rejected: %s" % err]
        for b in bad:
            print("FAIL datagram %d: %s" % (i, b))
        failures += bool(bad)

    # Self-check: the comparison and the validation can fail.
    d, e = datagrams[-1], expected[-1]
    wrong = dict(e, seq=e["seq"] ^ 1)
    if not compare(decode(d), wrong):
        print("FAIL self-check: a changed sequence number was not detected")
        failures += 1
    if e["joints"]:
        j0 = list(e["joints"][0])
        j0[3] = f32(repr(j0[3] + 1.0)) if abs(j0[3]) < 1e30 else 0.5
        if not compare(decode(d), dict(e, joints=[tuple(j0)] + e["joints"][1:])):
            print("FAIL self-check: a changed angle was not detected")
            failures += 1
    flipped = bytearray(d)
    flipped[20] ^= 0x01
    for name, bad_bytes in (("flipped byte", bytes(flipped)), ("truncated", d[:-1]),
                            ("bad magic", b"MCAQ" + d[4:])):
        try:
            decode(bad_bytes)
            print("FAIL self-check: %s datagram was accepted" % name)
            failures += 1
        except DecodeError:
            pass
    print("%d datagrams checked, %d failed" % (len(datagrams), failures))
    return 1 if failures else 0


def main(argv):
    if len(argv) == 3 and argv[1] == "--writer":
        with tempfile.TemporaryDirectory() as tmp:
            bin_path, txt_path = os.path.join(tmp, "d.bin"), os.path.join(tmp, "d.txt")
            subprocess.run([argv[2], bin_path, txt_path, "200"], check=True)
            return check_files(bin_path, txt_path)
    if len(argv) == 3:
        return check_files(argv[1], argv[2])
    print(__doc__)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv))
