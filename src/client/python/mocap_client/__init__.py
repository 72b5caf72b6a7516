"""mocap_client: receive the joint angles that `mocap run` publishes over UDP.

Pure Python (standard library only). Decodes the UDP datagrams versions 1 and 2 of the
mocap interface specification (little-endian header, 32-byte joint records, or 72-byte
records with quality and joint rates; CRC-32 as zlib's crc32) and keeps the newest message, counting sequence gaps (frames dropped on the way)
and every rejected datagram by reason.

    from mocap_client import Receiver
    rx = Receiver(port=7755)
    while True:
        if rx.wait(0.1) and rx.latest() is not None:
            msg = rx.latest()
            print(msg.sequence, rx.age_s(), [j.a for j in msg.joints if j.valid])

predict(msg, time.monotonic_ns()) extrapolates a version-2 message to now (predict.py).

`python3 -m mocap_client [--host H] [--port N] [--count N] [--duration S]` prints CSV.
"""
from .datagram import (DecodeError, JointRecord, Message, VERSION, VERSION_2, decode, encode,
                       HINGE, BALL)
from .predict import BeyondHorizon, Prediction, PredictedJoint, predict
from .receiver import Counters, Receiver

__all__ = ["BALL", "HINGE", "VERSION", "VERSION_2", "BeyondHorizon", "Counters", "DecodeError",
           "JointRecord", "Message", "PredictedJoint", "Prediction", "Receiver", "decode", "encode",
           "predict"]
__version__ = "1.1.0"
