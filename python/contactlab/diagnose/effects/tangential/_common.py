"""Shared helpers of the tangential effects: the record's scales as the plausibility
arguments quote them."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

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


def fixed(d: Prepared, key: str, make: Callable[[], Any]) -> Any:
    """An array of the model evaluation that depends on the recording only (not on the
    fitted parameters): computed on the first evaluation, then reused by every fit on ``d``
    (the fits evaluate the model thousands of times)."""
    cache = d.extra.setdefault("fixed", {})
    k = (key, d.t.size)
    if k not in cache:
        cache[k] = make()
    return cache[k]


#: entries of the small per-recording memos below (index sets, load-fluctuation terms)
_MEMO_KEEP = 64


def memo(d: Prepared, name: str) -> dict[Any, Any]:
    cache = d.extra.setdefault(name, {})
    if len(cache) >= _MEMO_KEEP:
        cache.clear()
    return cache


def delay_support(d: Prepared, at: np.ndarray, tau: float) -> np.ndarray:
    """The samples a delayed prediction at the samples ``at`` needs: for each shifted time
    ``t[at] - tau`` the two samples that bracket it as :func:`numpy.interp` finds them
    (``t[j] <= t < t[j+1]``, the first or last sample off the ends); ``at`` itself when
    ``tau`` is 0. Kept per ``(tau, at)``: a fit's Jacobian steps every other parameter at
    the same delay."""
    if tau == 0.0:
        return at
    rows_memo = memo(d, "delay_rows")
    key = (tau, id(at))
    hit = rows_memo.get(key)
    if hit is not None and hit[0] is at:  # (the array is held: its id is not reused)
        return hit[1]
    n = d.t.size
    j = np.searchsorted(d.t, d.t[at] - tau, side="right") - 1
    need = np.zeros(n, bool)
    need[np.clip(j, 0, n - 1)] = True
    need[np.clip(j + 1, 0, n - 1)] = True
    rows = np.flatnonzero(need)
    rows_memo[key] = (at, rows)
    return rows
