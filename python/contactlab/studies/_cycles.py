"""Cycles of a long recording, found while it streams past: crossings and per-cycle quantities.

A cycle runs from one upward crossing of the drive channel (``x`` of a tangential recording,
``p`` of a normal one) to the next. Crossings are found with a Schmitt trigger: the signal
must fall below ``centre - band`` before an upward passage of ``centre + band`` counts, so
noise at the level cannot count twice. ``centre`` and ``band`` come from each block's range
(blocks of at least :data:`MIN_BLOCK` samples, so at least one cycle of a slow test), and
follow a slowly drifting or shrinking amplitude.

Per cycle: the loop energy ∮ F dx (trapezoids, closed by the chord from the cycle's last
sample back to its first, i.e. the area of the polygon of the samples, as
:func:`contactlab.loop_area` computes it), the displacement amplitude (half its range) and
the force offset (centre of its range). Everything is vectorised over a block; the state
carried between blocks is a few scalars. :func:`block_cycles` is the one kernel to swap for a
compiled one.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

#: smallest block the thresholds are judged on (samples)
MIN_BLOCK = 1 << 16
#: half width of the trigger band as a fraction of the block's half range
BAND = 0.25


@dataclass
class CycleState:
    """What :func:`block_cycles` carries from one block to the next."""

    level: int = 0  # +1 above the band, -1 below, 0 not yet known
    have_crossing: bool = False
    x_cross: float = 0.0
    F_cross: float = 0.0
    t_cross: float = 0.0
    acc: float = 0.0  # ∮ F dx since the last crossing, up to the previous sample
    x_prev: float = float("nan")
    F_prev: float = float("nan")
    x_max: float = -np.inf
    x_min: float = np.inf
    F_max: float = -np.inf
    F_min: float = np.inf


@dataclass
class Cycles:
    """Complete cycles found in a block (arrays of equal length) and every crossing."""

    crossings: np.ndarray  # global sample index of each upward crossing in the block
    start: np.ndarray = field(default_factory=lambda: np.empty(0))  # s
    end: np.ndarray = field(default_factory=lambda: np.empty(0))  # s
    energy: np.ndarray = field(default_factory=lambda: np.empty(0))
    amplitude: np.ndarray = field(default_factory=lambda: np.empty(0))
    offset: np.ndarray = field(default_factory=lambda: np.empty(0))


def _segment_extrema(v: np.ndarray, starts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Max and min of ``v`` over ``[starts[k], starts[k+1])`` (last to the end); starts > 0
    strictly increasing (reduceat would return a lone element for an empty segment)."""
    return np.maximum.reduceat(v, starts), np.minimum.reduceat(v, starts)


def block_cycles(
    t: np.ndarray,
    x: np.ndarray,
    F: np.ndarray,
    drive: np.ndarray,
    offset: int,
    s: CycleState,
    levels: tuple[float, float] | None = None,
) -> Cycles:
    """Crossings of ``drive`` and the cycles they complete in one block; updates ``s``.

    ``x``/``F`` are the loop's abscissa and ordinate (``x, F`` or ``delta, p``), ``drive`` the
    channel whose crossings mark the cycles, ``offset`` the global index of the block's first
    sample. ``levels = (low, high)`` fixes the trigger band (default: from the block's range).
    """
    n = x.size
    if levels is None:
        lo_d, hi_d = (float(drive.min()), float(drive.max())) if n else (0.0, 0.0)
        centre, half = 0.5 * (hi_d + lo_d), 0.5 * (hi_d - lo_d) * BAND
        low, high = centre - half, centre + half
    else:
        low, high = float(levels[0]), float(levels[1])
        half = 0.5 * (high - low)
    mark = np.zeros(n, dtype=np.int8)
    mark[drive >= high] = 1
    mark[drive <= low] = -1
    idx = np.where(mark != 0, np.arange(n), -1)
    np.maximum.accumulate(idx, out=idx)
    if n == 0:
        return Cycles(crossings=np.empty(0, dtype=np.int64))
    filled = np.where(idx >= 0, mark[np.maximum(idx, 0)], np.int8(s.level))
    before = np.empty(n, dtype=np.int8)
    before[0] = s.level
    before[1:] = filled[:-1]
    ups = np.flatnonzero((filled == 1) & (before == -1))
    if not half > 0.0:  # a constant block has no crossing
        ups = ups[:0]
    s.level = int(filled[-1]) if n else s.level

    # trapezoid increments into each sample (the first from the previous block's last)
    d = np.empty(n)
    d[1:] = 0.5 * (F[1:] + F[:-1]) * np.diff(x)
    d[0] = 0.5 * (F[0] + s.F_prev) * (x[0] - s.x_prev) if np.isfinite(s.x_prev) else 0.0
    cum = np.cumsum(d)
    cum += s.acc
    out = Cycles(crossings=ups + offset)
    if ups.size:
        c_at = cum[ups]
        raw = np.diff(np.r_[0.0, c_at])
        xs = np.r_[s.x_cross, x[ups]]
        Fs = np.r_[s.F_cross, F[ups]]
        ts = np.r_[s.t_cross, t[ups]]
        energy = raw + 0.5 * (Fs[1:] + Fs[:-1]) * (xs[:-1] - xs[1:])
        # extrema per cycle: the segment before the first crossing joins the carried extrema
        starts = np.r_[0, ups] if ups[0] > 0 else ups
        xmax, xmin = _segment_extrema(x, starts)
        fmax, fmin = _segment_extrema(F, starts)
        if ups[0] > 0:
            first = (
                max(s.x_max, xmax[0]),
                min(s.x_min, xmin[0]),
                max(s.F_max, fmax[0]),
                min(s.F_min, fmin[0]),
            )
            xmax, xmin, fmax, fmin = xmax[1:], xmin[1:], fmax[1:], fmin[1:]
        else:
            first = (s.x_max, s.x_min, s.F_max, s.F_min)
        # cycle k ends at ups[k]: its extrema are those of the segment before ups[k]
        cx_max = np.r_[first[0], xmax[:-1]]
        cx_min = np.r_[first[1], xmin[:-1]]
        cf_max = np.r_[first[2], fmax[:-1]]
        cf_min = np.r_[first[3], fmin[:-1]]
        keep = slice(0 if s.have_crossing else 1, None)
        out.start, out.end = ts[:-1][keep], ts[1:][keep]
        out.energy = energy[keep]
        out.amplitude = 0.5 * (cx_max - cx_min)[keep]
        out.offset = 0.5 * (cf_max + cf_min)[keep]
        s.have_crossing = True
        last = int(ups[-1])
        s.x_cross, s.F_cross, s.t_cross = float(x[last]), float(F[last]), float(t[last])
        s.acc = float(cum[-1] - c_at[-1])
        s.x_max, s.x_min, s.F_max, s.F_min = (
            float(xmax[-1]),
            float(xmin[-1]),
            float(fmax[-1]),
            float(fmin[-1]),
        )
    elif n:
        s.acc = float(cum[-1])
        s.x_max, s.x_min = max(s.x_max, float(x.max())), min(s.x_min, float(x.min()))
        s.F_max, s.F_min = max(s.F_max, float(F.max())), min(s.F_min, float(F.min()))
    if n:
        s.x_prev, s.F_prev = float(x[-1]), float(F[-1])
    return out


__all__ = ["BAND", "MIN_BLOCK", "CycleState", "Cycles", "block_cycles"]
