"""Which regime a tangential loop is in, and what the data identify there.

PHYSICS.md §1: on a Masing branch with the exponential virgin curve the slope at the turn is
``h0 ac e^{-ac A}``, a fraction ``e^{-z}`` (``z = ac·A``) of the initial stiffness: the share
of the contact that still sticks when the amplitude is reached. Regimes:

- **pre-sliding** (``z < 1``, more than 37 % of the initial stiffness left at the turn):
  microslip; with both ``h0`` and ``ac`` identified, or (``z ≪ 1``) only ``h0·ac``;
- **transition** (``1 ≤ z < 3``);
- **gross sliding** (``z ≥ 3``, slope below e⁻³ = 5 %): the force plateaus at ±h0, so the
  plateau measures ``h0`` directly (mean force over the part of each stroke beyond the point
  where the branch has covered 95 % of its swing; error from the stroke-to-stroke scatter of
  the plateau levels), while ``ac`` is only bounded from below: an exponential branch covers 95 %
  of its swing ``2 h0`` within ``Δx₉₅ = 2 ln 20 / ac``; noise, averaging and compliance of the
  rig only lengthen the measured ``Δx₉₅``, so ``ac ≥ 2 ln 20 / Δx₉₅``;
- **stick-slip**: gross sliding with sticking segments at the reversals (velocity within its
  noise for much longer than a smooth turn stays there) at least at half of them; the largest
  force while stuck (the breakaway force: static friction) is reported beside the sliding
  plateau (kinetic friction).

``z`` comes from the fit when it identifies ``h0`` and ``ac``; otherwise from the loop's
shape, by inverting the area ratio ``E / (4 A h_m)`` of a Masing loop
(:func:`~contactlab.tangential.model.area_ratio`), which needs no fit.

The velocity for stick detection is a Savitzky-Golay derivative with the window chosen by
Lepski's rule (:mod:`contactlab.tangential.frame`); its noise ``σv`` follows from the
displacement noise (fourth differences) and the filter's coefficients. A sample "sticks" when
``|v| < 3 σv``; a smooth sinusoidal turn of amplitude A at ω stays below that for
``2·3σv / (A ω²)``; a stick is a run at least ``STICK_DWELL_FACTOR`` times longer (and ≥ 4
samples), within a quarter period of a reversal, during which the force changes (by more than
``STICK_FORCE_SHARE`` of the loop's force half-range). A still stretch where the force stands
still too is a dwell of the drive (a stage resting at its stroke ends) and is counted apart.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .frame import difference_noise, lepski_window, savgol_coefficients, savgol_derivative
from .model import area_ratio
from .preprocess import AveragedLoop, Reversals

PRE_SLIDING_Z = 1.0
GROSS_SLIDING_Z = 3.0
#: fraction of the branch's swing that defines the end of the transition to the plateau
PLATEAU_FRACTION = 0.95
#: a plateau found from the stroke's last sixth (a long, compliant transition) changes by less
#: than this share of the swing from Δx₉₅ on (an exponential branch that reaches 95 % of its
#: swing by 1.5 A, ac·A ≳ 4, changes by under 7 % there)
PLATEAU_FLATNESS = 0.10
#: a stick lasts this many times longer than a smooth turn spends below the velocity threshold
STICK_DWELL_FACTOR = 3.0
VELOCITY_SIGMAS = 3.0
#: share of the reversals that must show a stick for the loop to count as stick-slip
STICK_SHARE = 0.5
#: sliding has set in once the speed reaches this fraction of the stroke's peak speed A ω
SLIDE_ONSET = 0.1
#: a still stretch at a reversal is a stick only where the force changes while the position
#: stands (by more than this share of the loop's force half-range); position and force both
#: still is a dwell of the drive (a stage resting at its stroke ends), not sticking
STICK_FORCE_SHARE = 0.25


def z_from_area_ratio(ratio: float) -> float:
    """``z = ac·A`` of the Masing loop with area ratio ``E / (4 A h_m)`` (0 … 1)."""
    from scipy.optimize import brentq

    lo, hi = 1e-4, 200.0
    if not math.isfinite(ratio) or ratio <= area_ratio(lo):
        return 0.0
    if ratio >= area_ratio(hi):
        return math.inf
    return float(brentq(lambda z: area_ratio(z) - ratio, lo, hi, xtol=1e-8))


@dataclass(frozen=True)
class Plateau:
    """Sliding plateau of a gross-sliding loop: ``h0`` (half the distance between the two
    plateau levels) with its standard error, the levels' mid-point ``offset``, the branch
    length ``dx95`` to 95 % of the swing and the bound ``ac ≥ ac_lower_bound``."""

    h0: float
    h0_stderr: float
    offset: float
    dx95: float
    ac_lower_bound: float
    n_up: int
    n_down: int


def velocity(t: np.ndarray | None, x: np.ndarray) -> tuple[np.ndarray, float, int]:
    """Savitzky-Golay velocity (Lepski window), the stick threshold ``3 σv`` and the window
    (samples)."""
    tt = np.arange(x.size, dtype=float) if t is None else t
    dt = float(np.median(np.diff(tt), overwrite_input=True))  # partitions its own copy
    sx = difference_noise(x)
    window = min(lepski_window(x, dt, sx), max(5, (x.size // 2) * 2 - 1))
    v = savgol_derivative(x, window, 1, dt)
    thr = VELOCITY_SIGMAS * sx * float(np.linalg.norm(savgol_coefficients(window, 1, dt)))
    if not thr > 0:  # no measurable noise: a smooth turn crosses zero within a sample
        thr = 1e-9 * float(np.max(np.abs(v)))
    return v, thr, window


def _first_crossing(
    u: np.ndarray, phase: np.ndarray, F: np.ndarray, level: float, rising: bool
) -> float | None:
    """Distance from the reversal at which the branch (bins in phase order) first passes
    ``level``."""
    o = np.argsort(phase)
    hit = (F[o] >= level) if rising else (F[o] <= level)
    if not np.any(hit):
        return None
    return float(max(u[o][int(np.argmax(hit))], 0.0))


def _reach(
    loop: AveragedLoop,
    desc: np.ndarray,
    u_d: np.ndarray,
    u_a: np.ndarray,
    amplitude: float,
    ref: tuple[float, float],
    limit: float,
    flat: bool,
) -> float | None:
    """``Δx₉₅`` of the averaged loop's branches against reference levels taken over
    ``ref`` (in units of the amplitude, distance from the turn), or None where a branch does
    not reach 95 % of its swing within ``limit`` amplitudes (or, with ``flat``, changes by
    more than ``PLATEAU_FLATNESS`` of the swing beyond that point)."""
    mid_d = (u_d > ref[0] * amplitude) & (u_d <= ref[1] * amplitude)
    mid_a = (u_a > ref[0] * amplitude) & (u_a <= ref[1] * amplitude)
    if not (np.any(mid_d) and np.any(mid_a)):
        return None
    lo, hi = float(np.mean(loop.F[desc][mid_d])), float(np.mean(loop.F[~desc][mid_a]))
    swing = hi - lo
    if not swing > 0:
        return None
    d1 = _first_crossing(
        u_d, loop.phase[desc], loop.F[desc], hi - PLATEAU_FRACTION * swing, rising=False
    )
    d2 = _first_crossing(
        u_a, loop.phase[~desc], loop.F[~desc], lo + PLATEAU_FRACTION * swing, rising=True
    )
    if d1 is None or d2 is None:
        return None
    dx95 = max(d1, d2)
    if dx95 > limit * amplitude:
        return None
    if flat:
        beyond_d, beyond_a = u_d >= dx95, u_a >= dx95
        for u, f in (
            (u_d[beyond_d], loop.F[desc][beyond_d]),
            (u_a[beyond_a], loop.F[~desc][beyond_a]),
        ):
            if u.size < 3 or not np.ptp(u) > 0:
                return None
            slope = np.polyfit(u, f, 1)[0]
            if abs(slope) * float(np.ptp(u)) > PLATEAU_FLATNESS * swing:
                return None
    return dx95


def plateau(
    loop: AveragedLoop, x: np.ndarray, F: np.ndarray, v: np.ndarray, thr: float
) -> Plateau | None:
    """The plateau of a loop (see the module docstring); None when the branches do not
    reach one before the middle third of the stroke.

    The reference levels are the branches' mean force over the middle third of the stroke;
    each branch's ``Δx₉₅`` is where it first covers 95 % of the swing between them. The
    plateau level of each stroke is the median force of its sliding samples (``|v| > thr``)
    beyond ``Δx₉₅``: a stick holds x while F reverses, and those samples are not sliding;
    the median keeps the slips at the stroke's ends from pulling the level.
    """
    xmax, xmin = float(loop.x.max()), float(loop.x.min())
    amplitude = 0.5 * (xmax - xmin)
    if not amplitude > 0:
        return None
    desc = loop.descending
    u_d, u_a = xmax - loop.x[desc], loop.x[~desc] - xmin
    # the reference levels: the branches' mean force over the middle third of the stroke;
    # failing that (a long, compliant transition: a rig's or a stage's, not an exponential
    # branch's), over its last sixth, where the branch must then be flat (it changes by less
    # than 10 % of the swing from Δx₉₅ on) and reach 95 % of its swing by three quarters
    dx95 = None
    for ref, limit, flat in (((2 / 3, 4 / 3), 2 / 3, False), ((5 / 3, 2.0), 1.5, True)):
        dx95 = _reach(loop, desc, u_d, u_a, amplitude, ref, limit, flat)
        if dx95 is not None:
            break
    if dx95 is None:
        return None
    sliding = np.abs(v) > thr
    rev = loop.reversals
    turns = np.sort(np.r_[rev.peaks, rev.valleys])
    ups, downs = [], []
    for a, b in itertools.pairwise(turns):
        s = 1.0 if x[b] > x[a] else -1.0
        u = s * (x[a : b + 1] - x[a])
        sel = (u > dx95) & sliding[a : b + 1]
        if np.count_nonzero(sel) >= 2:
            (ups if s > 0 else downs).append(float(np.median(F[a : b + 1][sel])))
    if len(ups) < 2 or len(downs) < 2:
        return None
    up, dn = np.asarray(ups), np.asarray(downs)
    h0 = 0.5 * float(up.mean() - dn.mean())
    if not h0 > 0:
        return None
    se = 0.5 * math.sqrt(float(up.var(ddof=1)) / up.size + float(dn.var(ddof=1)) / dn.size)
    smallest = float(np.min(np.abs(np.diff(loop.x))[np.abs(np.diff(loop.x)) > 0]))
    ac_lo = 2.0 * math.log(1.0 / (1.0 - PLATEAU_FRACTION)) / max(dx95, smallest)
    return Plateau(h0, se, 0.5 * float(up.mean() + dn.mean()), dx95, ac_lo, up.size, dn.size)


@dataclass(frozen=True)
class StickSlip:
    """Sticking segments found at the reversals: ``durations`` (s) and ``breakaway`` force
    (the largest ``|F - offset|`` while stuck: the static friction the drive had to overcome,
    N), over ``n_turns`` reversals; the velocity
    threshold used and how long a smooth turn stays below it."""

    n_turns: int
    durations: np.ndarray
    breakaway: np.ndarray
    velocity_threshold: float
    smooth_dwell: float
    turns_with_stick: int
    #: reversals where position and force both stood still (the drive dwelled): not sticks
    turns_with_dwell: int = 0

    @property
    def share(self) -> float:
        return self.turns_with_stick / self.n_turns if self.n_turns else 0.0

    @property
    def present(self) -> bool:
        return self.n_turns >= 2 and self.share >= STICK_SHARE

    def to_dict(self) -> dict[str, Any]:
        n = self.breakaway.size
        sem = float(np.std(self.breakaway, ddof=1) / math.sqrt(n)) if n > 1 else math.nan
        return {
            "n_reversals": self.n_turns,
            "reversals_with_stick": self.turns_with_stick,
            "stick_duration": float(np.mean(self.durations)) if n else math.nan,
            "breakaway_force": float(np.mean(self.breakaway)) if n else math.nan,
            "breakaway_force_stderr": sem,
            "velocity_threshold": self.velocity_threshold,
            "smooth_turn_dwell": self.smooth_dwell,
            "reversals_with_dwell": self.turns_with_dwell,
        }


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """``[start, end)`` of each run of True."""
    d = np.diff(np.r_[0, mask.astype(np.int8), 0])
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1), strict=True))


def long_runs(mask: np.ndarray, min_len: int) -> list[tuple[int, int]]:
    """``[start, end)`` of each run of True at least ``min_len`` long (the short ones, most
    of a noisy record's, dropped in numpy before any Python loop sees them)."""
    d = np.diff(np.r_[np.int8(0), mask.astype(np.int8), np.int8(0)])
    starts, ends = np.flatnonzero(d == 1), np.flatnonzero(d == -1)
    keep = (ends - starts) >= min_len
    return list(zip(starts[keep].tolist(), ends[keep].tolist(), strict=True))


def _break_time(x: np.ndarray, a: int, b: int, end: int, window: int, sigma: float) -> float | None:
    """Sample (fractional) at which a stuck plate starts to move with a jump of its
    acceleration (the friction force dropping from static to kinetic), or None.

    ``x`` is flat before the break and departs as ``c2 s² + c3 s³`` after it (``s`` samples
    since the break), fitted by least squares with the break on a grid of tenths of a sample
    between a window before the stick's end and the onset of sliding. Without a drop the
    acceleration grows from zero (``c2 = 0``); the jump is taken as shown only when freeing
    ``c2`` lowers the squared error by more than :func:`break_threshold` ``· σ²`` (``σ``: the
    displacement noise).
    """
    hi = min(end + window, x.size)
    lo = max(a + 4, b - window)
    first = max(a, lo - 2 * window)
    if hi - lo < 3:
        return None
    i = np.arange(first, hi, dtype=float)
    xs = x[first:hi]
    best: dict[bool, tuple[float, float]] = {}

    def search(grid: np.ndarray) -> None:
        for tb in grid:
            sv = np.clip(i - tb, 0.0, None)
            for quad in (True, False):
                cols = [np.ones_like(i), sv**2, sv**3] if quad else [np.ones_like(i), sv**3]
                design = np.column_stack(cols)
                coef, *_ = np.linalg.lstsq(design, xs, rcond=None)
                rss = float(np.sum((design @ coef - xs) ** 2))
                if rss < best.get(quad, (np.inf, 0.0))[0]:
                    best[quad] = (rss, float(tb))

    stop = min(end + 2, hi - 1)
    if stop - lo <= _FINE_SEARCH:
        search(np.arange(lo, stop, 0.1))
    else:
        # a long search (each position a least-squares fit over the whole span: quadratic in
        # the span): whole samples first, then tenths about each model's best
        search(np.arange(lo, stop, 1.0))
        for quad in (True, False):
            c = best[quad][1]
            search(np.arange(max(lo, c - 0.9), min(stop, c + 1.0), 0.1))
    # the break is searched over many positions: the likelihood-ratio threshold is the χ²(1)
    # quantile at a 1 % false-alarm rate shared among the whole samples searched (Bonferroni;
    # a fixed 9 σ² read a drop into 1 in 5 sticks without one and put breakaway 8-10 % high)
    positions = max(int(min(end + 2, hi - 1) - lo), 1)
    if True not in best or best[False][0] - best[True][0] <= break_threshold(positions) * sigma**2:
        return None
    return best[True][1]


#: break searches spanning up to this many samples run on tenths of a sample throughout
_FINE_SEARCH = 200


def break_threshold(positions: int) -> float:
    """χ²(1) quantile for a 1 % false-alarm rate over ``positions`` break positions."""
    from scipy.special import chdtri  # chi2.isf(q, df) is chdtri(df, q); scipy.stats costs 0.5 s

    return float(chdtri(1, 0.01 / positions))


def smooth_peak(g: np.ndarray, window: int) -> float:
    """Largest value of ``g`` read off a quadratic fitted over half a window either side of
    its largest sample: the largest of noisy samples overshoots the force by about twice its
    noise (static equal to kinetic friction: the plateau's noise after the stick), the
    quadratic averages over the peak instead."""
    k = int(np.argmax(g))
    h = max(window // 2, 2)
    lo, hi = max(k - h, 0), min(k + h + 1, g.size)
    if hi - lo < 5:
        return float(g[k])
    i = np.arange(lo, hi, dtype=float) - k
    q = np.polynomial.Polynomial.fit(i, g[lo:hi], 2).convert()
    _, c1, c2 = [*q.coef, 0.0, 0.0][:3]
    at = [i[0], i[-1]]
    if c2 < 0:  # a maximum inside the span: the vertex
        at.append(float(np.clip(-c1 / (2.0 * c2), i[0], i[-1])))
    return float(np.max(q(np.array(at))))


def _breakaway(
    f: np.ndarray,
    x: np.ndarray,
    v: np.ndarray,
    span: tuple[int, int],
    window: int,
    sliding: float,
    sigma: float,
    reach: int | None = None,
) -> float:
    """Breakaway force of the stick ``span = [a, b)`` (``f``: the force about the plateaus'
    midline; ``sigma``: the displacement noise; ``reach``: how far past the stick, in
    samples, sliding may start; None: anywhere).

    Two things lower a plain maximum of ``|f|`` over the stuck samples. (1) A real joint
    creeps before it slides: the velocity leaves the stick band while the force still rises
    (the measured frame's plate creeps at 0.1-0.8 mm/s for ~60 ms before sliding), so the
    search runs on to the onset of sliding, the first sample after the stick where ``|v|``
    reaches :data:`SLIDE_ONSET` of the stroke's peak speed. (2) The force drops at breakaway
    (static to kinetic friction) and a force reconstructed from the displacement's second
    derivative (``M x''`` of :func:`~contactlab.tangential.frame.frame_friction_force`)
    smears that drop over its window (the same Lepski window as the velocity's), half a
    window before the plate moves: about half the drop is lost. While stuck the force is a
    smooth ramp (the drive's sinusoid), so a quadratic is fitted on the stuck samples clear
    of that half window and read at the instant the displacement starts to move with a jump
    of its acceleration (:func:`_break_time`; without a jump there is no drop to recover).
    The larger of that and the maximum (:func:`smooth_peak`: not the largest noisy sample)
    is the breakaway force.
    """
    a, b = span
    n = f.size
    end = b
    # the onset of sliding: at most `reach` samples on (a quarter period; on a record that
    # never slides, noise say, the search would otherwise run to its end)
    stop = n if reach is None else min(n, b + reach)
    while end < stop and abs(v[end]) < sliding:
        end += 1
    peak = smooth_peak(np.abs(f[a : min(end + 1, n)]), window)
    if reach is not None and end >= stop:
        return peak  # no sliding within reach of the stick: no break to look for
    tb = _break_time(x, a, b, end, window, sigma)
    if tb is None:
        return peak
    clear = int(min(b, math.floor(tb))) - (window // 2 + 1)
    if clear - a < 8:
        return peak
    sign = 1.0 if np.mean(f[clear - 4 : clear]) >= 0 else -1.0
    i = np.arange(a, clear, dtype=float) - clear
    ramp = np.polynomial.Polynomial.fit(i, sign * f[a:clear], 2)
    return max(peak, float(ramp(tb - clear)))


def stick_slip(
    t: np.ndarray | None,
    x: np.ndarray,
    F: np.ndarray,
    rev: Reversals,
    v: np.ndarray,
    thr: float,
    window: int,
    offset: float = 0.0,
) -> StickSlip | None:
    """Sticking segments near the reversals (module docstring); None without two turns."""
    turns = np.sort(np.r_[rev.peaks, rev.valleys]).astype(np.int64)
    if turns.size < 2 or x.size < 20:
        return None
    tt = np.arange(x.size, dtype=float) if t is None else t
    peaks_t = rev.peak_times if rev.peak_times.size >= 2 else rev.valley_times
    if peaks_t.size >= 2:
        period = float(np.median(np.diff(peaks_t)))
    else:
        period = 2.0 * float(np.median(np.diff(tt[turns])))
    amp = 0.5 * float(np.ptp(x[turns[0] : turns[-1] + 1]))
    omega = 2.0 * math.pi / period
    dt = float(np.median(np.diff(tt), overwrite_input=True))  # partitions its own copy
    smooth = 2.0 * thr / (amp * omega**2) if amp > 0 else math.inf
    min_len = max(4, math.ceil(STICK_DWELL_FACTOR * smooth / dt))
    spans: dict[int, list[int]] = {}  # turn -> [first stuck sample, end, stuck samples]
    # |v| < thr as two comparisons: no whole-record float temporary
    for a, b in long_runs((v < thr) & (v > -thr), min_len):
        mid = tt[(a + b - 1) // 2]
        k = int(np.argmin(np.abs(tt[turns] - mid)))
        if abs(tt[turns[k]] - mid) > 0.25 * period + 0.5 * (b - a) * dt:
            continue
        sp = spans.setdefault(k, [a, b, 0])
        sp[0], sp[1], sp[2] = min(sp[0], a), max(sp[1], b), sp[2] + (b - a)
    dwells = _drop_dwells(spans, F, turns)
    durations, breakaway = [], []
    sliding = SLIDE_ONSET * amp * omega
    sx = difference_noise(x) if spans else 0.0  # only the breakaway search needs it
    reach = max(4 * window, math.ceil(0.25 * period / dt)) if dt > 0 else x.size
    f = F - offset if spans else F  # once, not a whole-record copy per stick
    for a, b, n_stuck in spans.values():
        durations.append(n_stuck * dt)
        breakaway.append(_breakaway(f, x, v, (a, b), window, max(sliding, thr), sx, reach))
    hit = spans
    return StickSlip(
        int(turns.size),
        np.asarray(durations),
        np.asarray(breakaway),
        float(thr),
        float(smooth),
        len(hit),
        dwells,
    )


def _drop_dwells(spans: dict[int, list[int]], F: np.ndarray, turns: np.ndarray) -> int:
    """Remove from ``spans`` the still stretches over which the force stood still too (a
    dwell of the drive: sticking is the position standing while the force changes); returns
    how many were removed. The force's change over a stretch is its range there, against the
    loop's force half-range (robust: 1st to 99th percentile over the reversals' span)."""
    if not spans:
        return 0
    lo, hi = np.percentile(F[turns[0] : turns[-1] + 1], [1.0, 99.0])
    half = 0.5 * float(hi - lo)
    dwell = [
        k for k, (a, b, _n) in spans.items() if not float(np.ptp(F[a:b])) > STICK_FORCE_SHARE * half
    ]
    for k in dwell:
        del spans[k]
    return len(dwell)


@dataclass
class Regime:
    """The regime verdict (``name``: "pre-sliding", "transition", "gross sliding" or
    "stick-slip"), ``z = ac·A`` and where it came from, the plateau and the sticks."""

    name: str
    reason: str
    z: float
    z_source: str
    area_ratio: float
    plateau: Plateau | None = None
    stick: StickSlip | None = None
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def sliding(self) -> bool:
        return self.name in ("gross sliding", "stick-slip")

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {
            "regime": self.name,
            "regime_reason": self.reason,
            "ac_times_amplitude_regime": self.z,
            "ac_times_amplitude_source": self.z_source,
            "loop_area_ratio": self.area_ratio,
        }
        if self.stick is not None:
            d["stick_slip"] = self.stick.to_dict()
        return d


def classify(
    *,
    z_fit: float | None,
    ratio: float,
    loop: AveragedLoop | None,
    x: np.ndarray,
    F: np.ndarray,
    t: np.ndarray | None,
    rev: Reversals,
    x_raw: np.ndarray | None = None,
) -> Regime:
    """Decide the regime from ``z`` (the fit's when identified, else the area ratio's), the
    plateau and the sticks. ``x_raw``: the displacement before drift removal, for the
    velocity (a removed drift would make a stuck plate creep at the drift's rate)."""
    if z_fit is not None and math.isfinite(z_fit):
        z, src = float(z_fit), "fit"
    else:
        z, src = z_from_area_ratio(ratio), "loop area"
    xv = x if x_raw is None else x_raw
    v, thr, window = velocity(t, xv) if xv.size >= 20 else (np.zeros(xv.size), 0.0, 5)
    # a plateau is looked for from the transition on: a transition that is not exponential
    # (a compliant rig, a stage) can reach one while the fitted ac·A reads below 3
    pl = plateau(loop, x, F, v, thr) if (loop is not None and z >= PRE_SLIDING_Z) else None
    st = stick_slip(t, x, F, rev, v, thr, window, pl.offset if pl is not None else 0.0)
    zt = f"ac·A = {z:.3g} (from the {src}; loop area {100 * ratio:.0f}% of the rectangle 4·A·h_m)"
    if not math.isfinite(z):  # an area no friction loop of this size encloses
        zt = (
            f"ac·A undetermined (the loop area is {100 * ratio:.0f}% of the rectangle "
            "4·A·h_m, which bounds any friction loop)"
        )
    if z < PRE_SLIDING_Z:
        return Regime("pre-sliding", f"pre-sliding (microslip): {zt}", z, src, ratio, None, st)
    if (z < GROSS_SLIDING_Z and pl is None) or (pl is None and src != "fit"):
        why = "" if z < GROSS_SLIDING_Z else "; no plateau over the middle of the stroke"
        return Regime(
            "transition", f"transition towards gross sliding: {zt}{why}", z, src, ratio, pl, st
        )
    if pl is None:
        text = (
            f"gross sliding: {zt}; the branches flatten to under 5% of the initial stiffness "
            "before the turns (h0 and ac from the fit)"
        )
    else:
        text = (
            f"gross sliding: {zt}; the force plateaus at ±{pl.h0:.4g} N beyond "
            f"{pl.dx95:.3g} m of each stroke"
        )
    name = "gross sliding"
    if st is not None and st.turns_with_dwell:
        text += (
            f"; the drive dwells at {st.turns_with_dwell} of {st.n_turns} reversals (position "
            "and force both still): a rest of the stage, not sticking"
        )
    if st is not None and st.present:
        sd = st.to_dict()
        name = "stick-slip"
        text = (
            f"stick-slip: {text}; the displacement sticks at {st.turns_with_stick} of "
            f"{st.n_turns} reversals for {sd['stick_duration']:.3g} s on average (a smooth "
            f"turn: {st.smooth_dwell:.2g} s) and breaks away at {sd['breakaway_force']:.3g} N"
        )
    return Regime(name, text, z, src, ratio, pl, st)


__all__ = [
    "GROSS_SLIDING_Z",
    "PRE_SLIDING_Z",
    "Plateau",
    "Regime",
    "StickSlip",
    "classify",
    "long_runs",
    "plateau",
    "stick_slip",
    "velocity",
    "z_from_area_ratio",
]
