"""Long tangential records kept every q-th sample, with what the model needs from the raw
rate: the turning points between the kept samples (:class:`~._signal.Knots`) and, for a
channel delay, the input at shifted times.

:func:`contactlab.diagnose.workflow.subsample_long` keeps every q-th sample of a long record
and computes everything the candidates see (filtered input, derivatives, cycles) at the raw
rate; :class:`RawInput` holds those raw-rate arrays. :func:`knots_at` gives the knots for
kept samples at any (fractional) raw positions, :func:`delayed` the recording as the model
sees it a delay ``tau`` earlier: the model evaluated there *is* the full-rate model shifted
by ``tau`` (interpolated between raw samples, as :func:`~._signal.shift` does at the raw
rate), where interpolating the model between kept samples would miss by ``(π q / s)²`` of
the force at ``s`` samples per cycle.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from ._family import Prepared
from ._signal import Knots, local_extrema

#: longest record diagnosed sample by sample (:data:`contactlab.diagnose._prepare.MAX_SAMPLES`,
#: where it is described; defined here so that the errors-in-variables simulation reads it
#: without importing the preparation)
MAX_SAMPLES = 24_000

#: shifted recordings kept per delay (a fit steps the other parameters at one delay)
_DELAYED_KEEP = 4
#: sample sets (fits, folds) whose spans are kept
_SPANS_KEEP = 64


@dataclass(frozen=True)
class RawInput:
    """The raw-rate arrays behind a kept record: times ``t0 + i·dt``, the input the
    candidates see (``u``, filtered), its derivatives, the turning points (raw indices of the
    first sample, the local extrema of ``u`` and the reversals, sorted), the reversals, and
    the factor."""

    t0: float
    dt: float
    u: np.ndarray
    ud: np.ndarray
    udd: np.ndarray
    turns: np.ndarray
    reversals: np.ndarray
    q: int

    @classmethod
    def build(
        cls,
        t0: float,
        dt: float,
        u: np.ndarray,
        ud: np.ndarray,
        udd: np.ndarray,
        reversals: np.ndarray,
        q: int,
        limit: int,
    ) -> tuple[RawInput, bool]:
        """With the turning points of ``u``: all its local extrema and the reversals, or,
        when the extrema are more than ``limit`` (noise left in the input), the reversals
        only — the second value says which (True: all)."""
        rev = np.asarray(reversals, dtype=np.int64)
        ext = local_extrema(u)
        exact = ext.size <= limit
        # the first sample too: the element starts at the origin, so it may be a turn
        turns = np.union1d(np.union1d(ext, rev) if exact else rev, [0])
        return cls(t0, dt, u, ud, udd, turns, rev, q), exact


def knots_at(raw: RawInput, pos: np.ndarray) -> Knots:
    """:class:`~._signal.Knots` for kept samples at the ascending raw positions ``pos``
    (fractional when shifted): every turning point before the last kept sample and not
    on a kept sample, at its raw position."""
    r = raw.turns[raw.turns < pos[-1]]
    k = np.searchsorted(pos, r, side="left")  # the first kept sample at or after the knot
    off = pos[k] != r
    r, k = r[off], k[off]
    # the kept sample j moves up by the knots at or before it (k is sorted, within 0..size-1):
    # a running count, not a binary search per kept sample
    grid = np.arange(pos.size) + np.cumsum(np.bincount(k, minlength=pos.size))[: pos.size]
    merged = np.empty(pos.size + k.size)  # (numpy.insert would sort the positions)
    merged[grid] = pos
    merged[k + np.arange(k.size)] = r
    rev = raw.reversals[raw.reversals <= pos[-1]]
    turns = np.searchsorted(merged, raw.turns[raw.turns <= pos[-1]])
    t = raw.t0 + raw.dt * merged
    return Knots(k, raw.u[r], grid, t, np.searchsorted(merged, rev), turns)


class Span:
    """What the values at some kept samples need of a merged sequence: the positions
    ``index`` in it of those samples and of every turning point (None: all of it),
    the positions ``rows`` of the samples asked for within that, the reversals' positions,
    the times, and ``token`` (telling apart spans of equal length in caches)."""

    _tokens = itertools.count(1)

    def __init__(self, kn: Knots, rows: np.ndarray | None) -> None:
        if rows is None:
            self.index, self.rows, self.reversals, self.t = None, kn.grid, kn.reversals, kn.t
            self.token = 0
        else:
            keep = np.zeros(kn.size, bool)  # (a mask: a sorted union without a sort)
            keep[kn.turns] = True
            keep[kn.reversals] = True
            keep[kn.grid[rows]] = True
            self.index = np.flatnonzero(keep)
            self.rows = np.searchsorted(self.index, kn.grid[rows])
            self.reversals = np.searchsorted(self.index, kn.reversals)
            self.t = kn.t[self.index]
            self.token = next(self._tokens)
        self.size = kn.size if self.index is None else self.index.size
        self.anchors: tuple[np.ndarray, np.ndarray] | None = None  # filled by the model


def span(d: Prepared, kn: Knots, rows: np.ndarray | None) -> Span:
    """:class:`Span` of the kept record ``d`` for the samples ``rows`` (all when None), kept
    per ``rows`` (a fit asks for the same samples thousands of times)."""
    memo = d.extra.setdefault("spans", {})
    key = None if rows is None else id(rows)
    hit = memo.get(key)
    if hit is not None and hit[0] is rows:  # (the array is held: its id is not reused)
        return hit[1]
    if len(memo) >= _SPANS_KEEP:
        memo.clear()
    out = Span(kn, rows)
    memo[key] = (rows, out)
    return out


def _at(pos: np.ndarray, n: int, *arrays: np.ndarray) -> list[np.ndarray]:
    """Each of ``arrays`` (``n`` samples) at the fractional indices ``pos`` (within
    ``[0, n - 1]``), linearly."""
    i = np.minimum(pos.astype(np.int64), n - 2)
    f = pos - i
    return [a[i] + f * (a[i + 1] - a[i]) for a in arrays]


def _at_shift(q: int, s: float, m: int, n: int, *arrays: np.ndarray) -> list[np.ndarray]:
    """:func:`_at` at the positions ``k·q - s``, ``k = 0..m-1``, clipped to ``[0, n - 1]``:
    every position between two raw samples has the same fraction, so the interior is two
    strided views of each array (no gather); the clipped ends take the end samples."""
    i0 = int(np.floor(-s))
    f = -s - i0  # in [0, 1): position k·q + i0 + f
    k_lo = max(0, -(i0 // q))  # the first k with k·q + i0 >= 0
    k_hi = min(m - 1, (n - 2 - i0) // q)  # the last with k·q + i0 + 1 <= n - 1
    out = []
    for a in arrays:
        v = np.empty(m)
        v[:k_lo] = a[0]
        if k_hi >= k_lo:
            lo = a[k_lo * q + i0 : k_hi * q + i0 + 1 : q]
            hi = a[k_lo * q + i0 + 1 : k_hi * q + i0 + 2 : q]
            v[k_lo : k_hi + 1] = lo + f * (hi - lo)
        v[max(k_hi + 1, k_lo) :] = a[n - 1]
        out.append(v)
    return out


def delayed(d: Prepared, tau: float) -> Prepared:
    """The kept record ``d`` as the model sees it ``tau`` earlier: input, derivatives and
    knots at the raw positions ``i·q - tau/dt`` (held at the ends), times shifted, the
    output and the cycles as they are; the model on it without the delay is the delayed
    model at the kept samples. Kept per ``tau``."""
    raw: RawInput = d.extra["raw_input"]
    memo = d.extra.setdefault("delayed", {})
    hit = memo.get(tau)
    if hit is not None:
        return hit
    n = raw.u.size
    pos = np.clip(np.arange(d.t.size) * float(raw.q) - tau / raw.dt, 0.0, n - 1.0)
    ts = raw.t0 + raw.dt * pos
    extra = {k: d.extra[k] for k in ("x_mid", "x_half") if k in d.extra}
    extra["knots"] = knots_at(raw, pos)
    # times from the record's start (drifts, load fluctuation), as the full-rate model has
    extra["fixed"] = {("t_rel", d.t.size): ts - d.t[0]}
    u, ud, udd = _at_shift(raw.q, tau / raw.dt, d.t.size, n, raw.u, raw.ud, raw.udd)
    out = Prepared(ts, u, d.y, d.dt, d.window, ud, udd, d.cycles, extra)
    if len(memo) >= _DELAYED_KEEP:
        memo.clear()
    memo[tau] = out
    return out


def _hermite(pos: np.ndarray, n: int, a: np.ndarray, da: np.ndarray, dt: float) -> np.ndarray:
    """``a`` (``n`` samples ``dt`` apart, slopes ``da``) at the fractional indices ``pos``
    (within ``[0, n - 1]``) by its cubic Hermite interpolant: continuous in value and slope."""
    i = np.minimum(pos.astype(np.int64), n - 2)
    f = pos - i
    g = 1.0 - f
    return (
        (1.0 + 2.0 * f) * g * g * a[i]
        + f * g * g * dt * da[i]
        + f * f * (3.0 - 2.0 * f) * a[i + 1]
        - f * f * g * dt * da[i + 1]
    )


def shifted(d: Prepared, tau: float) -> Prepared:
    """The kept normal-contact record ``d`` as the model sees it ``tau`` earlier: the
    pressure and its slope at the raw positions ``i·q - tau/dt`` (held at the ends, by the
    cubic Hermite between raw samples), times shifted by ``tau`` (still equally spaced),
    the output and the cycles as they are; the model on it without the delay is the delayed
    model at the kept samples (:func:`delayed` for a tangential record). Kept per ``tau``."""
    raw: RawInput = d.extra["raw_input"]
    memo = d.extra.setdefault("shifted", {})
    hit = memo.get(tau)
    if hit is not None:
        return hit
    n = raw.u.size
    pos = np.arange(d.t.size) * float(raw.q) - tau / raw.dt
    ts = raw.t0 + raw.dt * pos
    pc = np.clip(pos, 0.0, n - 1.0)
    # cubic Hermite between raw samples (their slopes known): the model is then smooth in
    # tau; linearly interpolated, it has a kink at every whole sample of delay, where a fit's
    # Gauss-Newton steps stall (a delay of 9.39 ms was stuck at 10.00 ms, at 1 kHz)
    u = _hermite(pc, n, raw.u, raw.ud, raw.dt)
    ud = _hermite(pc, n, raw.ud, raw.udd, raw.dt)
    (udd,) = _at(pc, n, raw.udd)
    extra = {k: d.extra[k] for k in ("omega", "delta_r") if k in d.extra}
    extra["u_slope"] = ud
    out = Prepared(ts, u, d.y, d.dt, d.window, ud, udd, d.cycles, extra)
    if len(memo) >= _DELAYED_KEEP:
        memo.clear()
    memo[tau] = out
    return out
