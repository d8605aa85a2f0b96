"""Loop preprocessing for tangential recordings: reversals, period averaging, scatter.

The paper (*Experimental investigation of tangential contact stiffness and equivalent damping*,
§3.1) averages the measured loops "over the periods in order to eliminate noise". Here:

1. **Reversals** by a hysteresis (Schmitt) threshold: the displacement must cross a band of
   half-width ``rel_threshold`` × amplitude around the centre before a turn counts, so noise
   never creates spurious reversals. The instant of each turn is the midpoint of the two band
   crossings around it (interpolated), which is far less noisy than the arg-max of noisy data.
2. **Phase**: ``[peak_k, valley_k]`` maps linearly onto phase ``[k, k + 1/2]`` and
   ``[valley_k, peak_{k+1}]`` onto ``[k + 1/2, k + 1]``.
3. **Averaging** by phase bins: each sample of a complete cycle falls in exactly one of
   ``n_points`` bins; the averaged loop is the mean ``(x, F)`` of each bin. No interpolation, so
   the bins' noise stays independent (what an honest fit error needs).
4. **Scatter**: the same averages per cycle give the cycle-to-cycle spread of every bin, and
   per-cycle amplitude, peak-to-peak force and loop area (``∮ F dx``).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from .. import _core
from .._arrays import as_1d, median
from ..errors import InputError
from ..reversals import excursions


@dataclass(frozen=True)
class Reversals:
    """Turning points of a displacement signal.

    ``peaks`` and ``valleys`` are sample indices of the extreme samples; ``peak_times`` and
    ``valley_times`` the refined instants (s, or sample units when no time was given).
    ``threshold`` is the band half-width used (same unit as ``x``).
    """

    peaks: np.ndarray
    valleys: np.ndarray
    peak_times: np.ndarray
    valley_times: np.ndarray
    threshold: float
    centre: float
    edges: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=np.int64))

    @property
    def turns(self) -> np.ndarray:
        """Every turning index in order, including the unconfirmed extremes of the first and
        last stretch (``edges``): what a monotone projection of the path needs."""
        return np.unique(np.r_[self.peaks, self.valleys, self.edges]).astype(np.int64)

    @property
    def first_is_peak(self) -> bool:
        if self.peaks.size == 0:
            return False
        return self.valleys.size == 0 or self.peaks[0] < self.valleys[0]

    @property
    def first(self) -> int:
        """Index of the first reversal (0 when there is none)."""
        cand = [a[0] for a in (self.peaks, self.valleys) if a.size]
        return int(min(cand)) if cand else 0


def _crossing_times(t: np.ndarray, x: np.ndarray, i: np.ndarray, level: np.ndarray) -> np.ndarray:
    """Times at which ``x`` crosses ``level`` between samples ``i-1`` and ``i`` (linear; the
    time of sample ``i`` where the two samples are equal, ``t[0]`` for ``i = 0``)."""
    i = np.asarray(i, dtype=np.int64)
    ip = np.maximum(i - 1, 0)
    x0, x1 = x[ip], x[i]
    flat = x1 == x0
    a = (level - x0) / np.where(flat, 1.0, x1 - x0)
    tc = t[ip] + np.clip(a, 0.0, 1.0) * (t[i] - t[ip])
    return np.where(i <= 0, t[0], np.where(flat, t[i], tc))


#: above this many samples :func:`tail_percentiles` selects from the tails only
_TAIL_SELECT_ABOVE = 1 << 15


def tail_percentiles(x: np.ndarray, q: float = 0.5) -> tuple[float, float]:
    """The ``q`` and ``100 - q`` percentiles of ``x`` (finite; the numbers of
    ``np.percentile``, its linear method) without partitioning all of ``x``: the order
    statistics they interpolate come from :func:`contactlab._core.order_stats`, which selects
    them from the samples beyond a subsample's thresholds (one pass in Rust, where numpy's
    selection took a partition of a subsample and two boolean masks of ``x``). numpy's
    interpolation of them is kept as it is; ``np.percentile`` itself for short ``x``."""
    sel = _tail_ranks(x.size, q)
    if sel is None:
        lo, hi = np.percentile(x, [q, 100.0 - q])
        return float(lo), float(hi)
    ranks, g = sel
    return _lerp_tails(_core.order_stats(np.ascontiguousarray(x, dtype=float), ranks), g)


def _tail_ranks(n: int, q: float = 0.5) -> tuple[list[int], np.ndarray] | None:
    """The order statistics :func:`tail_percentiles` interpolates for ``n`` samples (their
    ranks and numpy's fractions between them), None where it takes ``np.percentile``."""
    qq = np.array([q, 100.0 - q]) / 100.0
    vi = (n - 1) * qq  # numpy's virtual index of the linear method
    i0 = np.floor(vi).astype(np.int64)
    g = vi - i0
    if n <= _TAIL_SELECT_ABOVE or not (0 <= i0[0] and i0[1] + 1 < n):
        return None
    return [int(i0[0]), int(i0[0]) + 1, int(i0[1]), int(i0[1]) + 1], g


def _lerp_tails(v: np.ndarray, g: np.ndarray) -> tuple[float, float]:
    """The two percentiles from the order statistics ``v`` of :func:`_tail_ranks`."""
    out = []
    for a, b, t in ((v[0], v[1], g[0]), (v[2], v[3], g[1])):
        d = b - a
        out.append(float(b - d * (1.0 - t) if t >= 0.5 else a + d * t))  # numpy's _lerp
    return out[0], out[1]


def find_reversals(
    x: np.ndarray,
    t: np.ndarray | None = None,
    *,
    rel_threshold: float = 0.5,
    threshold: float | None = None,
    checked: bool = False,
) -> Reversals:
    """Reversal points of ``x`` with a hysteresis threshold.

    Parameters
    ----------
    x : array
        Displacement samples.
    t : array, optional
        Time stamps (default: sample index).
    rel_threshold : float, default 0.5
        Band half-width as a fraction of the robust amplitude (half the 0.5-99.5 percentile
        range). Noise peaks smaller than the band never count as reversals.
    threshold : float, optional
        Absolute band half-width (overrides ``rel_threshold``).
    checked : bool
        ``x`` and ``t`` are float64 arrays of one length, finite, ``t`` increasing (the
        caller checked them: a window's samples, scanned once instead of once a step).

    Examples
    --------
    >>> import numpy as np
    >>> x = np.sin(np.linspace(0, 6.5 * np.pi, 651))
    >>> r = find_reversals(x + 0.05 * np.cos(50 * np.arange(651)))
    >>> r.peaks.size, r.valleys.size
    (3, 3)
    """
    if checked:
        xa = np.asarray(x, dtype=float)
        ta = np.arange(xa.size, dtype=float) if t is None else np.asarray(t, dtype=float)
    else:
        xa = as_1d(x, "x")
        ta = np.arange(xa.size, dtype=float) if t is None else as_1d(t, "t")
    if ta.size != xa.size:
        raise InputError(f"t has {ta.size} samples but x has {xa.size}")
    lo_p, hi_p = tail_percentiles(xa)
    # (x scanned finite by as_1d unless the caller checked it)
    return _reversals(xa, ta, (lo_p, hi_p), rel_threshold, threshold, finite=not checked)


def _reversals(
    xa: np.ndarray,
    ta: np.ndarray,
    percentiles: tuple[float, float],
    rel_threshold: float,
    threshold: float | None,
    *,
    finite: bool = False,
) -> Reversals:
    """:func:`find_reversals` of checked float64 ``xa``, ``ta`` whose 0.5 and 99.5
    percentiles (:func:`tail_percentiles`) are ``percentiles``; ``finite``: ``xa`` was
    scanned finite already (the reversal detector does not scan it again)."""
    lo_p, hi_p = percentiles
    centre = 0.5 * (lo_p + hi_p)
    amp = 0.5 * (hi_p - lo_p)
    if threshold is None:
        if not 0 < rel_threshold < 1:
            raise InputError(f"rel_threshold must be in (0, 1), got {rel_threshold}")
        threshold = rel_threshold * amp
    if not threshold > 0:
        raise InputError(f"the displacement does not move (amplitude {amp:g}); no reversals")
    # Excursions beyond the band (Rust detector): +1 = above it since the last time below.
    ex = excursions(xa, centre, float(threshold), finite=finite)
    empty = np.empty(0, dtype=np.int64)
    if len(ex) == 0:
        return Reversals(empty, empty, np.empty(0), np.empty(0), float(threshold), centre)
    # An extreme is confirmed only when the signal has left it through the band; the last
    # excursion's turn is unconfirmed unless it crossed the centre before the end, and the
    # first may be cut by the recording's start.
    edge = np.zeros(len(ex), dtype=bool)
    edge[0] = ex.start[0] == 0
    edge[-1] |= not bool(ex.returned[-1])
    up = ex.sign > 0
    level = np.where(up, centre + threshold, centre - threshold)
    j = np.minimum(ex.last_beyond + 1, xa.size - 1)  # first sample back inside the band
    # the crossings into and out of the band in one call (elementwise: the same numbers as
    # two calls; 106 -> 94 us for a window's 2100 excursions)
    m = len(ex)
    tc = _crossing_times(ta, xa, np.concatenate([ex.start, j]), np.concatenate([level, level]))
    t_mid = 0.5 * (tc[:m] + tc[m:])
    peak, valley = ~edge & up, ~edge & ~up
    return Reversals(
        ex.extreme[peak].astype(np.int64),
        ex.extreme[valley].astype(np.int64),
        t_mid[peak],
        t_mid[valley],
        float(threshold),
        float(centre),
        ex.extreme[edge].astype(np.int64),
    )


@dataclass(frozen=True)
class CycleScatter:
    """Cycle-to-cycle scatter: one value per complete cycle (peak to next peak)."""

    amplitude: np.ndarray  # half the x range of the cycle's bin-averaged loop, m
    force_range: np.ndarray  # half the F range of the cycle's loop, N
    energy: np.ndarray  # area of the cycle's own samples (closed polygon), J
    period: np.ndarray  # s
    mean_force: np.ndarray  # mean force over the cycle (mean of its bin means), N
    time: np.ndarray  # middle of the cycle (mean of its two peak instants), s
    mean_x: np.ndarray | None = None  # mean displacement over the cycle, m

    @property
    def n_cycles(self) -> int:
        return int(self.amplitude.size)

    def summary(self) -> dict[str, dict[str, float]]:
        """Mean, standard deviation and standard error of the mean of each quantity."""
        out = {}
        for k in ("amplitude", "force_range", "energy", "period", "mean_force"):
            v = getattr(self, k)
            sd = float(np.std(v, ddof=1)) if v.size > 1 else float("nan")
            out[k] = {"mean": float(np.mean(v)), "std": sd, "sem": sd / np.sqrt(v.size)}
        return out


@dataclass(frozen=True)
class AveragedLoop:
    """A loop averaged over cycles by phase bins (peak at phase 0, valley at 1/2).

    ``x``, ``F``: bin means; ``count``: samples per bin; ``x_std``, ``F_std``: spread of the
    per-cycle bin means across cycles; ``phase``: bin centres in [0, 1).
    """

    phase: np.ndarray
    x: np.ndarray
    F: np.ndarray
    count: np.ndarray
    x_std: np.ndarray
    F_std: np.ndarray
    scatter: CycleScatter
    reversals: Reversals
    cycle_start: int  # first and last sample index of the averaged stretch
    cycle_end: int
    phase_mean: np.ndarray | None = None  # mean phase (within the cycle) of each bin's samples
    phase_sq: np.ndarray | None = None  # mean squared phase of each bin's samples
    cycle_bounds: np.ndarray | None = None  # first sample of each cycle, and the end
    x_var: np.ndarray | None = None  # variance of the samples' x inside each bin (all cycles)
    t_mean: np.ndarray | None = None  # mean time stamp of each bin's samples (all cycles)
    # per cycle Σ (∂A/∂F_i)², Σ (∂A/∂x_i)² of the loop area of the samples folded
    sensitivity: tuple[np.ndarray, np.ndarray] | None = field(
        default=None, repr=False, compare=False
    )

    @property
    def n_cycles(self) -> int:
        return self.scatter.n_cycles

    @property
    def amplitude(self) -> float:
        return 0.5 * float(self.x.max() - self.x.min())

    @property
    def descending(self) -> np.ndarray:
        """Mask of the bins on the descending branch (peak to valley)."""
        return self.phase < 0.5


def phase_knots(rev: Reversals) -> tuple[np.ndarray, np.ndarray]:
    """Knots ``(time, phase)``: peak k at phase k, the valley after it at k + 1/2 (the first
    valley after the peak, when it comes before the next peak)."""
    pt, vt = np.asarray(rev.peak_times, dtype=float), np.asarray(rev.valley_times, dtype=float)
    n = pt.size
    j = np.searchsorted(vt, pt, side="right")  # the first valley later than each peak
    ok = np.zeros(n, dtype=bool)
    if n > 1 and vt.size:
        jj = np.minimum(j[:-1], vt.size - 1)
        ok[:-1] = (j[:-1] < vt.size) & (vt[jj] < pt[1:])
    kt = np.empty(n + int(ok.sum()))
    kp = np.empty_like(kt)
    pos = np.arange(n) + np.r_[0, np.cumsum(ok)[:-1]] if n else np.empty(0, dtype=np.int64)
    kt[pos], kp[pos] = pt, np.arange(n, dtype=float)
    if ok.any():
        kt[pos[ok] + 1] = vt[j[ok]]
        kp[pos[ok] + 1] = np.flatnonzero(ok) + 0.5
    return kt, kp


#: turns either side whose instants are averaged into a turn's phase knot
SMOOTH_TURNS = 4


#: a turn instant is smoothed only when the line moves it by at most this fraction of the
#: median interval between turns (:func:`smooth_turn_times`)
SMOOTH_TOLERANCE = 0.05


def smooth_turn_times(times: np.ndarray, k: int = SMOOTH_TURNS) -> np.ndarray:
    """Turn instants (peaks, or valleys) averaged over the ``k`` turns either side: a
    straight line through the ``2k + 1`` turns around each (the centred mean inside, the
    end lines' values at the ends), so a steady drive's turns keep their instants.

    Each instant comes from the band crossings of two pairs of noisy samples, so the samples
    there decide their own phase: a sample whose noise moved the crossing falls in another
    bin, and the bins next to the crossings are biased in ``x`` (not in ``F``). With 1 %
    displacement noise those bins' residuals grew to 5σ at 2000 cycles (the averaged fit's
    residuals 2.0-2.2x its noise, a misfit warning on a model that fits). Averaging over
    ``2k + 1`` turns dilutes each sample's share of its phase ``2k + 1`` fold (and the
    jitter of the instants ``sqrt(2k + 1)`` fold). Fewer than ``2k + 1`` turns: unchanged.

    Only a drive whose turns come evenly is smoothed: an instant the line moves by more
    than :data:`SMOOTH_TOLERANCE` of the median interval between turns keeps its own (a
    multisine's or a random drive's turns are no straight line: the measured Bouc-Wen
    multisine's amplitude read 29 µm instead of 684 µm with every instant smoothed; noise
    moves a steady drive's instants by well under 1 % of the period)."""
    v = np.asarray(times, dtype=float)
    n, w = v.size, 2 * k + 1
    if n < w or k < 1:
        return v
    out = v.copy()
    c = np.concatenate([[0.0], np.cumsum(v)])
    out[k : n - k] = (c[w:] - c[: n - w + 1]) / w
    j = np.arange(w, dtype=float)
    for sl, idx in ((slice(0, w), np.arange(k)), (slice(n - w, n), np.arange(w - k, w))):
        b, a = np.polyfit(j, v[sl], 1)
        out[sl][idx] = a + b * j[idx]
    tol = SMOOTH_TOLERANCE * float(median(np.diff(v)))
    return np.where(np.abs(out - v) <= tol, out, v)


def phase_of(t: np.ndarray, rev: Reversals) -> tuple[np.ndarray, int, int]:
    """Phase of each sample of the complete cycles; returns ``(phase, start, end)`` where
    samples ``start:end`` are covered (phase ``k + φ`` for cycle ``k``, φ in [0, 1))."""
    kt, kp = phase_knots(rev)
    start = int(np.searchsorted(t, kt[0], side="left"))
    end = int(np.searchsorted(t, kt[-1], side="left"))
    ph = np.interp(t[start:end], kt, kp)
    return ph, start, end


def period_means(t: np.ndarray, v: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Time average of ``v`` between consecutive ``edges`` (trapezoid rule, interpolated at
    the edges). For a periodic signal this does not depend on where the period starts, so
    the jitter of the turn instants does not leak into it (as sample-counting would).
    One pass in Rust with numpy's arithmetic (``cumsum`` of the trapezoids, ``interp`` at the
    edges)."""
    return _core.period_means(t, v, np.ascontiguousarray(edges, dtype=float))


def average_loop(
    x: np.ndarray,
    F: np.ndarray,
    t: np.ndarray | None = None,
    *,
    n_points: int | None = None,
    rel_threshold: float = 0.5,
    threshold: float | None = None,
    min_cycles: int = 2,
    checked: bool = False,
) -> AveragedLoop:
    """Average a tangential recording's loops over its periods.

    Parameters
    ----------
    x, F : array
        Displacement and force.
    t : array, optional
        Time stamps (default: sample index).
    n_points : int, optional
        Phase bins per cycle (default: the median samples per cycle, at most 400, at least 16).
    rel_threshold, threshold
        Reversal band, see :func:`find_reversals`.
    min_cycles : int, default 2
        Fewer complete cycles raise :class:`InputError`.
    checked : bool
        ``x``, ``F`` and ``t`` are float64 arrays of one length, finite, ``t`` increasing
        (see :func:`find_reversals`; the fold checks them again in its pass).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.linspace(0, 5, 5001)
    >>> x = np.sin(2 * np.pi * t); F = np.cos(2 * np.pi * t)
    >>> loop = average_loop(x, F, t, n_points=100)
    >>> loop.n_cycles, round(loop.amplitude, 2)
    (4, 1.0)
    """
    if checked:
        xa, Fa = np.asarray(x, dtype=float), np.asarray(F, dtype=float)
        ta = np.arange(xa.size, dtype=float) if t is None else np.asarray(t, dtype=float)
    else:
        xa = as_1d(x, "x")
        Fa = as_1d(F, "F")
        ta = np.arange(xa.size, dtype=float) if t is None else as_1d(t, "t")
    if Fa.size != xa.size:
        raise InputError(f"x has {xa.size} samples but F has {Fa.size}")
    if ta.size != xa.size:
        raise InputError(f"t has {ta.size} samples but x has {xa.size}")
    rev = find_reversals(xa, ta, rel_threshold=rel_threshold, threshold=threshold, checked=True)
    return _fold_loop(xa, Fa, ta, rev, n_points=n_points, min_cycles=min_cycles)


def _fold_loop(
    xa: np.ndarray,
    Fa: np.ndarray,
    ta: np.ndarray,
    rev: Reversals,
    *,
    n_points: int | None,
    min_cycles: int,
    scan: _core.WindowScan | None = None,
    period_means: bool = True,
) -> AveragedLoop:
    """:func:`average_loop` of checked ``xa``, ``Fa``, ``ta`` whose reversals are ``rev``;
    ``scan``: :func:`contactlab._core.detrend_pair_scan_into`'s clean scan of them, which
    stands for the fold's check pass. ``period_means=False``: the per-cycle means of F and x
    (``scatter.mean_force``, ``scatter.mean_x``) are not computed and are NaN (the fold runs
    no trapezoid chain: 1.9 ns a sample, 6 % of a streamed window); every other number is
    the same."""
    n_cyc = max(int(rev.peaks.size) - 1, 0)
    if n_cyc < min_cycles:
        raise InputError(
            f"only {n_cyc} complete cycle(s) (peak to peak) found with a reversal band of "
            f"±{rev.threshold:.3g} m around x = {rev.centre:.3g} m; "
            f"at least {min_cycles} are needed"
        )
    kt, kp = phase_knots(
        replace(
            rev,
            peak_times=smooth_turn_times(rev.peak_times),
            valley_times=smooth_turn_times(rev.valley_times),
        )
    )
    start = int(np.searchsorted(ta, kt[0], side="left"))
    end = int(np.searchsorted(ta, kt[-1], side="left"))
    if n_points is None:
        # about two samples of every cycle per bin, so no bin is left empty by jitter
        n_points = 2 * int(np.clip(median(np.diff(rev.peaks)) / 2, 16, 400) // 2)
    if n_points < 8:
        raise InputError(f"n_points must be >= 8, got {n_points}")
    # One call in Rust: phase by interpolating the knots, bin sums overall and per cycle (no
    # per-sample temporaries; the bins are numpy.interp's), the cycles' bounds, loop areas and
    # their noise sensitivities, the period means between the peaks.
    edges = rev.peak_times if period_means else _NO_EDGES
    wf = _core.fold_window(ta, xa, Fa, kt, kp, int(n_points), n_cyc, edges, scan)
    return _loop_of_fold(wf, rev, int(n_points), start, end)


#: no period edges: a fold that computes no period means
_NO_EDGES = np.empty(0)


def _loop_of_fold(
    wf: _core.WindowFold, rev: Reversals, n_points: int, start: int, end: int
) -> AveragedLoop:
    count = wf.count
    if np.any(count == 0):
        raise InputError(
            f"{int(np.sum(count == 0))} of {n_points} phase bins are empty: the recording has "
            f"too few samples per cycle for n_points={n_points}; lower n_points"
        )
    xm = wf.sum_x / count
    Fm = wf.sum_F / count
    phim = wf.sum_phase / count
    # Per-cycle bin means (cycles x bins) spread from cycle to cycle. Where the samples of a
    # cycle sit inside a bin differs from cycle to cycle; on a steep branch that alone spreads
    # the per-cycle means: it is removed to first order (gradient along phase, periodic), so
    # the spread measures noise and real cycle-to-cycle change. In Rust over the fold's cells
    # with the arithmetic of ``spread`` and ``dphase`` of tests/fold_reference.py (numpy).
    # sample index where each cycle starts (a cycle without samples starts where the next
    # does), and where the last one ends; the area of the cycle's own samples (bin means
    # would cut the corners at the turns)
    scatter = CycleScatter(
        amplitude=wf.amplitude,
        force_range=wf.force_range,
        energy=wf.energy,
        period=np.diff(rev.peak_times),
        mean_force=_per_cycle(wf.mean_F, rev),
        mean_x=_per_cycle(wf.mean_x, rev),
        time=0.5 * (rev.peak_times[:-1] + rev.peak_times[1:]),
    )
    phase = (np.arange(n_points) + 0.5) / n_points
    x_var = np.clip(wf.sum_xx / count - xm * xm, 0.0, None)
    return AveragedLoop(
        phase,
        xm,
        Fm,
        count,
        wf.x_std,
        wf.F_std,
        scatter,
        rev,
        start,
        end,
        phim,
        wf.sum_phase2 / count,
        wf.bounds,
        x_var,
        wf.sum_t / count,
        sensitivity=(wf.sens_F, wf.sens_x),
    )


def _per_cycle(means: np.ndarray, rev: Reversals) -> np.ndarray:
    """A fold's period means, or NaN for each cycle where it computed none (no edges)."""
    if means.size == 0 and rev.peak_times.size > 1:
        return np.full(rev.peak_times.size - 1, np.nan)
    return means


def negated_loop(loop: AveragedLoop) -> AveragedLoop:
    """The loop of ``-F`` (the same samples' fold with the force negated): exactly what
    :func:`average_loop` gives for ``-F`` (negation commutes with every sum, mean, spread and
    loop area: no second fold)."""
    sc = loop.scatter
    return replace(
        loop,
        F=-loop.F,
        scatter=replace(sc, energy=-sc.energy, mean_force=-sc.mean_force),
    )


def monotone_path(x: np.ndarray, turns: np.ndarray) -> np.ndarray:
    """Project ``x`` on monotone branches between the turning indices ``turns``.

    Each stretch between consecutive turns is replaced by its isotonic (least-squares
    monotone) regression, rising or falling as the stretch goes. Fed to the Masing operator,
    the projected path has no noise-made micro-reversals: sensor noise on ``x`` would otherwise
    open spurious inner loops with the full initial stiffness and bias the fit.

    One Rust call (:func:`contactlab._core.monotone_path`: the pool-adjacent-violators
    algorithm in the arithmetic of ``scipy.optimize.isotonic_regression``, whose numbers it
    gives, without importing SciPy: half a second, under the interpreter lock, in the first
    window of a streamed analysis; ``monotone_path_scipy`` of tests/fold_reference.py is
    the reference).

    Examples
    --------
    >>> monotone_path(np.array([0.0, 2.0, 1.0, 3.0, 2.0, 1.5, 1.6, 0.0]), np.array([3]))
    array([0.  , 1.5 , 1.5 , 3.  , 2.  , 1.55, 1.55, 0.  ])
    """
    xa = np.ascontiguousarray(x, dtype=float)
    return _core.monotone_path(xa, _path_edges(turns, xa.size))


def _path_edges(turns: np.ndarray, n: int) -> np.ndarray:
    """The stretches' bounds: 0, the turns inside the signal, ``n`` (sorted, distinct)."""
    t = np.asarray(turns, dtype=np.int64)
    # np.unique's numbers; np.unique itself imports numpy.ma (20 ms under the interpreter
    # lock in the first window of a streamed analysis)
    e = np.sort(np.r_[0, t[(t > 0) & (t < n)], n].astype(np.int64))
    return e[np.r_[True, e[1:] != e[:-1]]]
