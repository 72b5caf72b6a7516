"""python3 -m mocap_client [--host H] [--port N] [--count N] [--duration S]

Prints every received message's joint angles as CSV on stdout, one row per joint and
message (gap: frames dropped just before that message):
seq,capture_ns,age_ms,gap,flags,joint,type,valid,a0_deg,a1_deg,a2_deg,qw,qx,qy,qz
(the columns of `mocap echo --format csv` without its quality columns, which the UDP
datagram v1 does not carry). A summary of the counters goes to stderr at the end.
Exit code 2 with a one-line message when the port cannot be bound.
"""
import argparse
import math
import signal
import sys
import time

from .datagram import HINGE
from .receiver import Receiver

HEADER = "seq,capture_ns,age_ms,gap,flags,joint,type,valid,a0_deg,a1_deg,a2_deg,qw,qx,qy,qz"


def rows(msg, age_ms, gap):
    for j in msg.joints:
        yield "%d,%d,%.3f,%d,%d,%d,%s,%d,%.6f,%.6f,%.6f,%.9f,%.9f,%.9f,%.9f" % (
            msg.sequence, msg.capture_ns, age_ms, gap, msg.flags, j.index,
            "hinge" if j.type == HINGE else "ball", 1 if j.valid else 0,
            math.degrees(j.a[0]), math.degrees(j.a[1]), math.degrees(j.a[2]), *j.q)


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python3 -m mocap_client",
                                 description="Print mocap's UDP joint angles as CSV")
    ap.add_argument("--host", default="0.0.0.0", help="address to bind (default 0.0.0.0)")
    ap.add_argument("--port", type=int, default=7755, help="UDP port (default 7755)")
    ap.add_argument("--count", type=int, default=0, help="stop after N messages (0: no limit)")
    ap.add_argument("--duration", type=float, default=0.0, help="stop after S seconds (0: none)")
    a = ap.parse_args(argv)
    if a.count < 0 or a.duration < 0 or not 0 <= a.port <= 65535:
        print("mocap_client: --count, --duration must be >= 0 and --port 0..65535", file=sys.stderr)
        return 2
    try:
        rx = Receiver(a.host, a.port)
    except OSError as e:
        print("mocap_client: %s" % e.strerror, file=sys.stderr)
        return 2
    stop = []
    signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
    print(HEADER, flush=True)
    t0 = time.monotonic()
    printed = 0
    def on_message(msg, gap):
        nonlocal printed
        if a.count and printed >= a.count:
            return
        age_ms = (time.monotonic_ns() - msg.capture_ns) * 1e-6
        sys.stdout.write("".join(r + "\n" for r in rows(msg, age_ms, gap)))
        printed += 1

    try:
        while not stop and (a.count == 0 or printed < a.count):
            if a.duration and time.monotonic() - t0 >= a.duration:
                break
            if rx.wait(0.05, on_message):
                sys.stdout.flush()
    except KeyboardInterrupt:
        pass
    finally:
        rx.close()
    c = rx.counters
    print("mocap_client: %d messages, %d frames dropped (sequence gaps), %d rejected, %d stale, "
          "%d tracker restarts" % (c.accepted, c.dropped_frames, c.rejected_total(), c.stale,
                                   c.restarts), file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
