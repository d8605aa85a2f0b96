"""Shared helpers of the tangential effects: the record's scales as the plausibility
arguments quote them."""

from __future__ import annotations

import numpy as np

from ..._family import Prepared

_INF = np.inf


def period(d: Prepared) -> float:
    """The excitation period, s."""
    return float(d.cycles.period_samples * d.dt)


def amplitude(d: Prepared) -> float:
    """Half the displacement's range, m."""
    return 0.5 * float(np.ptp(d.u))


def peak_speed(d: Prepared) -> float:
    """The 99th percentile of ``|ẋ|`` (m/s): the sliding speed the record reaches."""
    return float(np.percentile(np.abs(d.ud), 99.0))


def peak_acceleration(d: Prepared) -> float:
    """The 99th percentile of ``|ẍ|`` (m/s²)."""
    return float(np.percentile(np.abs(d.udd), 99.0))


def meta(d: Prepared) -> dict:
    """The recording's own meta (a reconstructed force, a frame), as the workflow kept it."""
    m = d.extra.get("meta")
    return m if isinstance(m, dict) else {}


def reconstructed(d: Prepared) -> str | None:
    """Why the force was computed from the displacement itself (a frame's equation of
    motion, ``meta["frame"]`` / ``meta["same_clock"]``), or None."""
    m = meta(d)
    if isinstance(m.get("frame"), dict):
        return "the force was reconstructed from the displacements of a frame (--frame)"
    if m.get("same_clock"):
        return "the force was computed from the displacement's own samples (same clock)"
    return None


def turning_points(x: np.ndarray, band: float) -> np.ndarray:
    """Indices of the turning points of ``x``: the extremes between which ``x`` moves back
    by more than ``band`` (a hysteresis of ``band`` ignores the noise's wiggles), the
    start-up's small turns included (the record's cycle split skips those)."""
    out: list[int] = []
    if x.size < 3:
        return np.array(out, dtype=int)
    ext = 0  # index of the running extreme
    direction = 0  # +1 rising, -1 falling, 0 not yet known
    xs = x.tolist()
    for i in range(1, len(xs)):
        v = xs[i]
        if direction >= 0 and v > xs[ext]:
            ext = i
            direction = direction or (1 if v - xs[0] > band else 0)
        elif direction <= 0 and v < xs[ext]:
            ext = i
            direction = direction or (-1 if xs[0] - v > band else 0)
        elif direction > 0 and xs[ext] - v > band:
            out.append(ext)
            ext, direction = i, -1
        elif direction < 0 and v - xs[ext] > band:
            out.append(ext)
            ext, direction = i, 1
    return np.array(out, dtype=int)


#: the turning points' hysteresis: this many input-noise standard deviations, at least this
#: share of the displacement's range
TURN_SIGMAS, TURN_SHARE = 6.0, 1e-3


def actual_turns(ctx) -> np.ndarray:
    """The actual turning points of the history an element runs over (``ctx.xm``): on a
    whole record, :func:`turning_points` of the filtered input (kept per record); on a kept
    record, its reversals (the knots keep the turns between the samples)."""
    d = ctx.d
    if ctx.sp is not None:
        return ctx.sp.reversals
    band = max(TURN_SIGMAS * float(d.extra.get("u_noise", 0.0)), TURN_SHARE * float(np.ptp(d.u)))
    return ctx.fixed("turning_points", lambda: turning_points(d.u, band))
