"""mocap_client: receive the joint angles that `mocap run` publishes over UDP.

Pure Python (standard library only). Decodes the UDP datagram version 1 of the mocap
interface specification (little-endian header, 32-byte joint records, CRC-32 as zlib's
crc32) and keeps the newest message, counting sequence gaps (frames dropped on the way)
and every rejected datagram by reason.

    from mocap_client import Receiver
    rx = Receiver(port=7755)
    while True:
        if rx.wait(0.1) and rx.latest() is not None:
            msg = rx.latest()
            print(msg.sequence, rx.age_s(), [j.a for j in msg.joints if j.valid])

`python3 -m mocap_client [--host H] [--port N] [--count N] [--duration S]` prints CSV.
"""
from .datagram import (DecodeError, JointRecord, Message, VERSION, decode, encode,
                       HINGE, BALL)
from .receiver import Counters, Receiver

__all__ = ["BALL", "HINGE", "VERSION", "Counters", "DecodeError", "JointRecord", "Message",
           "Receiver", "decode", "encode"]
__version__ = "1.0.0"
