"""Start-up and run-out transients of a tangential recording, from its cycles' amplitudes.

A rig ramps its stroke up when it starts and down when it stops. The steady analysis
averages every complete cycle into one loop, so cycles of a smaller (or larger) stroke at
either end of the record are averaged in with the steady ones and pull the loop's amplitude
and energy (an audit record with a 5 s ramp on a 300 s, 1 Hz test: amplitude −0.12 %,
energy −0.30 %, no word said). :func:`transient_cycles` finds such cycles: a run of cycles at
the start or the end whose amplitudes lie more than :data:`TRANSIENT_SIGMA` robust standard
deviations (1.4826 × the median absolute deviation of all cycles' amplitudes) from the
median amplitude. A single outlying cycle in the middle of the record is not a transient and
is left to the cycle-to-cycle scatter.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from .._arrays import median

#: a cycle whose amplitude is this many robust standard deviations from the median is not
#: steady (a steady record of 300 cycles has a chance of 2e-2 of one cycle beyond 4 sd at
#: either end, 1e-5 at 5)
TRANSIENT_SIGMA = 5.0
#: fewer cycles than this: too few for their scatter; from SHORT_MIN_CYCLES on, a short
#: record's end cycles are compared with the others by SHORT_SHARE of their amplitude instead
MIN_CYCLES = 6
#: a short record (SHORT_MIN_CYCLES .. MIN_CYCLES - 1 cycles): an end cycle whose amplitude
#: is more than this share off the median of all is a transient, when at least two cycles
#: remain that agree with each other to half of it (a damper test of 4-5 cycles starting
#: with one at 75 % of the stroke read its energy per cycle 4.5-9.3 % low, no word said)
SHORT_SHARE = 0.05
SHORT_MIN_CYCLES = 3
#: the robust standard deviation used is at least this fraction of the median amplitude
SCALE_FLOOR = 1e-4


@dataclass(frozen=True)
class Transient:
    """Leading (``lead``) and trailing (``trail``) transient cycles of a record of
    ``n_cycles``; ``steady``: the median amplitude and ``scale`` its robust standard
    deviation (m); ``shift``: the relative change of the mean cycle amplitude their
    averaging in makes (mean of all cycles / mean of the steady ones − 1); ``t_steady``:
    start of the first and end of the last steady cycle (s; their middles without the
    periods)."""

    lead: int
    trail: int
    n_cycles: int
    steady: float
    scale: float
    shift: float
    lead_range: tuple[float, float] | None
    trail_range: tuple[float, float] | None
    t_steady: tuple[float, float]
    #: the same for the cycles' own loop energies (NaN without them)
    energy_shift: float = math.nan
    #: found by the short-record rule (:data:`SHORT_SHARE`), not the cycles' scatter
    short: bool = False

    def message(self) -> str:
        """One sentence: which cycles, how far off, what it does and what to do."""
        parts = []
        if self.lead:
            lo, hi = self.lead_range or (math.nan, math.nan)
            parts.append(
                f"the first {self.lead} cycle{'s' if self.lead > 1 else ''} (amplitude "
                f"{_um(lo)}{'' if self.lead == 1 else '–' + _um(hi)} µm)"
            )
        if self.trail:
            lo, hi = self.trail_range or (math.nan, math.nan)
            parts.append(
                f"the last {self.trail} cycle{'s' if self.trail > 1 else ''} (amplitude "
                f"{_um(lo)}{'' if self.trail == 1 else '–' + _um(hi)} µm)"
            )
        what = " and ".join(parts)
        kind = (
            "a start-up transient"
            if self.lead and not self.trail
            else "a run-out transient"
            if self.trail and not self.lead
            else "start-up and run-out transients"
        )
        t0, t1 = self.t_steady
        energy = (
            f" and the mean cycle energy by {100 * self.energy_shift:+.2g} %"
            if math.isfinite(self.energy_shift)
            else ""
        )
        by = (
            f"by more than {100 * SHORT_SHARE:g} % of it (too few cycles for their scatter)"
            if self.short
            else f"by more than {TRANSIENT_SIGMA:g}× the cycles' scatter ({_um(self.scale)} µm)"
        )
        return (
            f"{what} of {self.n_cycles} differ from the steady amplitude {_um(self.steady)} µm "
            f"{by}: "
            f"{kind}, averaged in with the steady cycles, which moves the mean cycle "
            f"amplitude by {100 * self.shift:+.2g} %{energy}; for the steady loop cut the "
            f"record to t = {t0:.6g} .. {t1:.6g} s"
        )


def _um(v: float) -> str:
    return f"{1e6 * v:.4g}"


def transient_cycles(
    amplitude: np.ndarray,
    time: np.ndarray,
    period: np.ndarray | None = None,
    energy: np.ndarray | None = None,
    *,
    sigma: float = TRANSIENT_SIGMA,
) -> Transient | None:
    """The leading and trailing cycles whose amplitude is off the steady one (see the module
    docstring), or None (no such cycle, fewer than :data:`MIN_CYCLES` cycles, or the off
    cycles are more than a quarter of the record: a change of the stroke, which the
    cycle-to-cycle scatter and ``track`` show, not a transient at its ends).

    >>> a = np.r_[5.0, 12.0, np.full(20, 20.0) + 0.01 * np.sin(np.arange(20))] * 1e-6
    >>> tr = transient_cycles(a, np.arange(a.size) + 0.5)
    >>> tr.lead, tr.trail
    (2, 0)
    """
    a = np.asarray(amplitude, dtype=float)
    tt = np.asarray(time, dtype=float)
    pp = np.zeros_like(tt) if period is None else np.asarray(period, dtype=float)
    ee = np.full_like(tt, np.nan) if energy is None else np.asarray(energy, dtype=float)
    ok = np.isfinite(a) & np.isfinite(tt) & np.isfinite(pp)
    if a.size < MIN_CYCLES or not ok.all():
        a, tt, pp, ee = a[ok], tt[ok], pp[ok], ee[ok]
        if a.size < SHORT_MIN_CYCLES:
            return None
        if a.size < MIN_CYCLES:
            return _short_record(a, tt, pp, ee)
    med = float(median(a))
    scale = 1.4826 * float(median(np.abs(a - med)))
    # a noise-free record: the cycles' amplitudes (half the range of each cycle's binned
    # loop) differ by the binning, up to ~1e-4 relative; a transient is more than that
    scale = max(scale, SCALE_FLOOR * abs(med))
    if not (scale > 0 and math.isfinite(scale)):
        return None
    off = np.abs(a - med) > sigma * scale
    lead = int(np.argmin(off)) if not off.all() else a.size
    trail = int(np.argmin(off[::-1])) if not off.all() else a.size
    n = a.size
    if lead + trail == 0 or 4 * (lead + trail) > n:
        return None
    return _transient(a, tt, pp, ee, lead, trail, med, scale)


def _short_record(
    a: np.ndarray, tt: np.ndarray, pp: np.ndarray, ee: np.ndarray
) -> Transient | None:
    """:func:`transient_cycles` of a record of too few cycles for their scatter: end cycles
    more than :data:`SHORT_SHARE` off the median amplitude, with at least two cycles left
    that agree to half of that."""
    med = float(median(a))
    if not med > 0:
        return None
    off = np.abs(a - med) > SHORT_SHARE * med
    if off.all():
        return None
    lead, trail, n = int(np.argmin(off)), int(np.argmin(off[::-1])), a.size
    if lead + trail == 0 or n - lead - trail < 2:
        return None
    rest = a[lead : n - trail]
    if float(np.ptp(rest)) > 0.5 * SHORT_SHARE * float(median(rest)):
        return None  # no steady state among the others either: nothing to compare with
    tr = _transient(a, tt, pp, ee, lead, trail, float(median(rest)), SHORT_SHARE * med)
    return replace(tr, short=True)


def _transient(
    a: np.ndarray,
    tt: np.ndarray,
    pp: np.ndarray,
    ee: np.ndarray,
    lead: int,
    trail: int,
    med: float,
    scale: float,
) -> Transient:
    """The :class:`Transient` of ``lead`` and ``trail`` cycles off the steady ones."""
    n = a.size
    steady = slice(lead, n - trail)
    shift = float(np.mean(a)) / float(np.mean(a[steady])) - 1.0
    e_shift = math.nan
    if np.all(np.isfinite(ee)) and float(np.mean(ee[steady])) != 0.0:
        e_shift = float(np.mean(ee)) / float(np.mean(ee[steady])) - 1.0
    lr = (float(np.min(a[:lead])), float(np.max(a[:lead]))) if lead else None
    tr = (float(np.min(a[n - trail :])), float(np.max(a[n - trail :]))) if trail else None
    first, last = lead, n - trail - 1
    span = (float(tt[first] - pp[first] / 2), float(tt[last] + pp[last] / 2))
    return Transient(lead, trail, n, med, scale, shift, lr, tr, span, e_shift)


__all__ = ["MIN_CYCLES", "SCALE_FLOOR", "TRANSIENT_SIGMA", "Transient", "transient_cycles"]
