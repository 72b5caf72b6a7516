"""Latency-compensated prediction, as the C++ client's client/predict.h.

predict(message, t_ns) extrapolates the joint angles of one decoded message from its capture
time to the caller's CLOCK_MONOTONIC time t_ns (time.monotonic_ns(), the tracker's clock)
with the message's rates (UDP datagram version 2), and grows each standard deviation:
    a(t) = a + da * dt,   sd(t)^2 = sd_a^2 + (sd_da * dt)^2,   dt = t - capture.
Beyond the horizon (|dt| > horizon_s) it raises BeyondHorizon. A joint without known rates is
returned unchanged with predicted False. Angles are wrapped to (-pi, pi].
"""
import math
from collections import namedtuple

DEFAULT_HORIZON_S = 0.05

PredictedJoint = namedtuple("PredictedJoint", "index type predicted a sd")
PredictedJoint.__doc__ = ("One joint at the predicted time: predicted (bool: valid with known "
                          "rates), a = (a0, a1, a2) radians, sd (radians, or None without v2 "
                          "quality).")

Prediction = namedtuple("Prediction", "t_ns dt_s joints")


class BeyondHorizon(ValueError):
    """The message is too old (or too new) for the requested time."""


def _wrap(a):
    a = math.remainder(a, 2.0 * math.pi)
    return a + 2.0 * math.pi if a <= -math.pi else a


def predict(message, t_ns, horizon_s=DEFAULT_HORIZON_S):
    dt = (t_ns - message.capture_ns) * 1e-9
    if not abs(dt) <= horizon_s:
        raise BeyondHorizon("t is %.1f ms from the message's capture (horizon %.1f ms)"
                            % (dt * 1e3, horizon_s * 1e3))
    out = []
    for j in message.joints:
        known = bool(j.valid and j.rate_valid and j.rate is not None)
        if not known:
            out.append(PredictedJoint(j.index, j.type, False, tuple(j.a), j.sd))
            continue
        dofs = 1 if j.type == 1 else 3
        a = list(j.a)
        sd = list(j.sd) if j.sd is not None else [0.0, 0.0, 0.0]
        for k in range(dofs):
            a[k] = _wrap(a[k] + j.rate[k] * dt)
            sd[k] = math.hypot(sd[k], j.rate_sd[k] * dt)
        out.append(PredictedJoint(j.index, j.type, True, tuple(a), tuple(sd)))
    return Prediction(t_ns, dt, tuple(out))
