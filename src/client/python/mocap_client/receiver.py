"""UDP receiver of mocap's datagram v1: keeps the newest valid message.

Semantics match the C++ client (client/udp_receiver.h): a datagram is accepted only when
it decodes and its sequence number is newer than the last accepted one; a jump of more
than one adds the missing frames to `dropped_frames`; an older or repeated sequence is
`stale`, unless its capture time moved forward (the tracker restarted: `restarts`).
"""
import select
import socket
import time

from .datagram import DecodeError, decode

_MAX_DATAGRAM = 40 + 32 * 32 + 4


class Counters:
    """Counts of everything the receiver saw (plain attributes)."""

    __slots__ = ("datagrams", "accepted", "rejected", "stale", "dropped_frames", "restarts")

    def __init__(self):
        self.datagrams = 0
        self.accepted = 0
        self.rejected = {"short": 0, "magic": 0, "version": 0, "length": 0, "crc": 0}
        self.stale = 0
        self.dropped_frames = 0
        self.restarts = 0

    def rejected_total(self):
        return sum(self.rejected.values())

    def __repr__(self):
        return ("Counters(datagrams=%d, accepted=%d, rejected=%r, stale=%d, dropped_frames=%d, "
                "restarts=%d)" % (self.datagrams, self.accepted, self.rejected, self.stale,
                                  self.dropped_frames, self.restarts))


class Receiver:
    """Binds HOST:PORT (port 0: an ephemeral port, see `port`) and receives datagrams.

    Call poll() (non-blocking) or wait(timeout_s) regularly; latest() is the newest
    accepted Message (None before the first), age_s() its age on CLOCK_MONOTONIC (valid
    when tracker and receiver share a machine), gap() the frames dropped between the
    last two accepted messages.
    """

    def __init__(self, host="0.0.0.0", port=7755):
        self._sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            self._sock.bind((host, port))
        except OSError as e:
            self._sock.close()
            raise OSError(e.errno, "cannot bind %s:%d: %s" % (host, port, e.strerror)) from None
        self._sock.setblocking(False)
        self.port = self._sock.getsockname()[1]
        self.counters = Counters()
        self._latest = None
        self._last_gap = 0

    def close(self):
        self._sock.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def fileno(self):
        return self._sock.fileno()

    def latest(self):
        return self._latest

    def gap(self):
        return self._last_gap

    def age_s(self, now_ns=None):
        """Seconds since the trigger of the latest message (None before the first)."""
        if self._latest is None:
            return None
        now = time.monotonic_ns() if now_ns is None else now_ns
        return (now - self._latest.capture_ns) * 1e-9

    def feed(self, data):
        """Handles one datagram's bytes; True when it became latest()."""
        c = self.counters
        c.datagrams += 1
        try:
            m = decode(data)
        except DecodeError as e:
            c.rejected[e.reason] += 1
            return False
        last = self._latest
        if last is not None and m.sequence <= last.sequence:
            if m.capture_ns > last.capture_ns and m.sequence < last.sequence:
                c.restarts += 1
                self._last_gap = 0
            else:
                c.stale += 1
                return False
        elif last is not None:
            self._last_gap = m.sequence - last.sequence - 1
            c.dropped_frames += self._last_gap
        c.accepted += 1
        self._latest = m
        return True

    def poll(self, on_message=None):
        """Reads every pending datagram without blocking; returns how many were accepted.

        on_message(message, gap), if given, is called for every accepted message in order
        (gap: frames dropped just before it), not only for the newest.
        """
        accepted = 0
        while True:
            try:
                data = self._sock.recv(_MAX_DATAGRAM + 1)
            except (BlockingIOError, InterruptedError):
                return accepted
            if self.feed(data):
                accepted += 1
                if on_message is not None:
                    on_message(self._latest, self._last_gap)

    def wait(self, timeout_s, on_message=None):
        """Waits up to timeout_s for data, then polls; returns how many were accepted."""
        ready, _, _ = select.select([self._sock], [], [], max(0.0, timeout_s))
        return self.poll(on_message) if ready else 0
