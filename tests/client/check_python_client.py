#!/usr/bin/env python3
"""Test of the installed Python client module `mocap_client` (standard library only).

  check_python_client.py --mocap PATH --cmake PATH --build DIR

1. Installs the module with the package (cmake --install DIR --component python) into a
   temporary prefix and imports it from there (lib/python3/dist-packages).
2. Offline: decode() accepts what encode() writes and rejects every corruption the spec
   names (magic, version, length, CRC) with the right reason; a Receiver fed datagrams
   over loopback counts sequence gaps, stale repeats and rejections.
3. Live: `python3 -m mocap_client --port P` receives a `mocap run --duration 2 --udp
   127.0.0.1:P` and prints CSV whose rows are well-formed and whose sequence numbers
   increase with gaps that add up to the printed gap column.
"""
import argparse
import csv
import io
import math
import os
import socket
import subprocess
import sys
import tempfile
import time


def fail(msg):
    print("FAIL: " + msg, file=sys.stderr)
    sys.exit(1)


def free_udp_port():
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def offline_checks(mc):
    joints = (mc.JointRecord(0, mc.BALL, True, (0.1, -0.2, 0.3), (1.0, 0.0, 0.0, 0.0)),
              mc.JointRecord(1, mc.HINGE, False, (0.5, 0.0, 0.0), (0.9, 0.1, 0.0, 0.0)))
    msg = mc.Message(7, 1000, 2000, 1, joints)
    data = mc.encode(msg)
    if len(data) != 40 + 64 + 4:
        fail("encoded length %d" % len(data))
    got = mc.decode(data)
    if got.sequence != 7 or got.capture_ns != 1000 or got.flags != 1 or len(got.joints) != 2:
        fail("decode header %r" % (got,))
    if abs(got.joints[0].a[1] + 0.2) > 1e-7 or got.joints[1].valid or got.joints[1].type != mc.HINGE:
        fail("decode joints %r" % (got.joints,))
    bad = {
        "magic": b"XCAP" + data[4:],
        "version": data[:4] + b"\x03\x00" + data[6:],
        "length": data[:-1],
        "crc": data[:50] + bytes([data[50] ^ 1]) + data[51:],
        "short": data[:10],
    }
    for reason, d in bad.items():
        try:
            mc.decode(d)
            fail("corruption %s was accepted" % reason)
        except mc.DecodeError as e:
            if e.reason != reason:
                fail("corruption %s rejected as %s" % (reason, e.reason))
    # Version 2: quality and rates per joint (72-byte records).
    v2 = msg._replace(version=mc.VERSION_2, joints=(
        joints[0]._replace(solved_by=1, sd=(0.001, 0.002, 0.003), rate_valid=True,
                           rate=(1.5, -2.5, 0.25), rate_sd=(0.01, 0.02, 0.03)),
        joints[1]._replace(solved_by=0)))
    data2 = mc.encode(v2)
    if len(data2) != 40 + 2 * 72 + 4 or data2[4] != 2:
        fail("v2 encoded length %d" % len(data2))
    got2 = mc.decode(data2)
    r0 = got2.joints[0]
    if (got2.version != 2 or r0.solved_by != 1 or not r0.rate_valid or abs(r0.rate[1] + 2.5) > 1e-6
            or abs(r0.rate_sd[2] - 0.03) > 1e-7 or abs(r0.sd[0] - 0.001) > 1e-9
            or got2.joints[1].rate_valid):
        fail("v2 decode %r" % (got2,))
    # predict(): joint 0 moves with its rates, joint 1 (no rates) is not predicted.
    p = mc.predict(got2, got2.capture_ns + 10_000_000)
    a0 = got2.joints[0].a[0] + 1.5 * 0.010
    if (not p.joints[0].predicted or abs(p.joints[0].a[0] - a0) > 1e-6
            or abs(p.joints[0].sd[2] - math.hypot(0.003, 0.03 * 0.010)) > 1e-7
            or p.joints[1].predicted or abs(p.dt_s - 0.010) > 1e-12):
        fail("predict %r" % (p,))
    try:
        mc.predict(got2, got2.capture_ns + 60_000_000)
        fail("predict beyond the horizon was accepted")
    except mc.BeyondHorizon:
        pass
    if got.version != 1 or got.joints[0].rate is not None:
        fail("v1 decode carries no rates: %r" % (got,))
    for reason, d in {"length": data2[:-1], "version": data2[:4] + b"\x03\x00" + data2[6:],
                      "crc": data2[:100] + bytes([data2[100] ^ 4]) + data2[101:]}.items():
        try:
            mc.decode(d)
            fail("v2 corruption %s was accepted" % reason)
        except mc.DecodeError as e:
            if e.reason != reason:
                fail("v2 corruption %s rejected as %s" % (reason, e.reason))
    with mc.Receiver("127.0.0.1", 0) as rx:
        tx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        for seq in (10, 11, 14, 14, 12):
            tx.sendto(mc.encode(msg._replace(sequence=seq)), ("127.0.0.1", rx.port))
        tx.sendto(bad["crc"], ("127.0.0.1", rx.port))
        deadline = time.monotonic() + 5
        while rx.counters.datagrams < 6 and time.monotonic() < deadline:
            rx.wait(0.1)
        c = rx.counters
        if (c.accepted, c.dropped_frames, c.stale, c.rejected["crc"]) != (3, 2, 2, 1):
            fail("receiver counters %r" % (c,))
        if rx.latest().sequence != 14 or rx.gap() != 2 or rx.age_s() is None:
            fail("latest %r gap %d" % (rx.latest(), rx.gap()))
        tx.close()


def live_check(python_dir, mocap):
    port = free_udp_port()
    env = dict(os.environ, PYTHONPATH=python_dir)
    client = subprocess.Popen([sys.executable, "-m", "mocap_client", "--host", "127.0.0.1",
                               "--port", str(port), "--duration", "40", "--count", "60"],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    time.sleep(0.5)  # let it bind before the tracker sends
    # --loop-frames 10: the simulated cameras pre-render 10 frames (not 200) before starting.
    run = subprocess.run([mocap, "run", "--duration", "2", "--udp", "127.0.0.1:%d" % port,
                          "--loop-frames", "10", "--no-iceoryx", "--stats-interval", "0"],
                         capture_output=True, text=True, timeout=60)
    if run.returncode != 0:
        client.kill()
        fail("mocap run failed: %s" % run.stderr)
    out, err = client.communicate(timeout=30)
    if client.returncode != 0:
        fail("python3 -m mocap_client exited %d: %s" % (client.returncode, err))
    rows = list(csv.DictReader(io.StringIO(out)))
    if not rows or list(rows[0].keys())[:3] != ["seq", "capture_ns", "age_ms"]:
        fail("CSV output: %r" % out[:300])
    seqs = []
    for r in rows:
        s = int(r["seq"])
        if not seqs or seqs[-1] != s:
            if seqs and (s <= seqs[-1] or int(r["gap"]) != s - seqs[-1] - 1):
                fail("sequence %d after %d with gap %s" % (s, seqs[-1], r["gap"]))
            seqs.append(s)
        if r["type"] not in ("ball", "hinge") or r["valid"] not in ("0", "1"):
            fail("row %r" % r)
        for k in ("a0_deg", "a1_deg", "a2_deg", "qw", "age_ms"):
            float(r[k])
    if len(seqs) < 20:
        fail("only %d messages received from a 2 s run" % len(seqs))
    if not any(r["valid"] == "1" for r in rows):
        fail("no valid joint in %d rows" % len(rows))
    return len(seqs)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--mocap", required=True)
    ap.add_argument("--cmake", required=True)
    ap.add_argument("--build", required=True)
    a = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix="mocap_py_") as prefix:
        subprocess.run([a.cmake, "--install", a.build, "--prefix", prefix, "--component", "python"],
                       check=True, capture_output=True, timeout=60)
        python_dir = os.path.join(prefix, "lib", "python3", "dist-packages")
        if not os.path.isfile(os.path.join(python_dir, "mocap_client", "__main__.py")):
            fail("module not installed under %s" % python_dir)
        sys.path.insert(0, python_dir)
        import mocap_client as mc  # noqa: E402 (the installed copy)
        if not mc.__file__.startswith(prefix):
            fail("imported %s, not the installed module" % mc.__file__)
        offline_checks(mc)
        n = live_check(python_dir, a.mocap)
    print("ok: %d live messages" % n)


if __name__ == "__main__":
    main()
