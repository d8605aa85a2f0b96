"""Turning points of a tangential recording measured by the displacement channel.

The Masing loop is most sensitive at its turning points ``x0 ± A`` (PHYSICS.md §1: the branch
from a turn ``x_r`` is ``f_r ± 2 f((x - x_r)/2)``), so the analysis fits them rather than taking
the extremes of noisy samples, and lets the displacement channel measure them as well:

- :func:`turning_point_prior`: on an averaged loop, the bins either side of each turn are
  regressed on ``|φ|`` and ``φ²`` (φ: phase from the turn), unbiased for rounded (sine) and
  sharp (triangle) turns alike;
- :func:`virgin_nodes`, :func:`virgin_amplitude`: the same regression on the raw samples
  around each turn of a recording that starts at rest.

Errors. A regression intercept has a noise error (from the residuals, or from the
cycle-to-cycle spread, whichever is larger) and a truncation error: the quadratic only
approximates the turn's shape over the window. The truncation error does not average out
over cycles, and with a noise-free displacement channel it is all there is, so it is
estimated from the data: the intercepts of two nested windows differ by ``1 - ρ⁴`` of the
wider window's truncation error (ρ: width ratio; the first neglected term of a rounded turn
is of fourth order, Richardson) plus noise of known variance ``var(narrow) - var(wide)``
(nested least squares); the excess of the squared difference over that variance, scaled by
``1 / (1 - ρ⁴)²``, is added to the variance.
"""

from __future__ import annotations

import contextlib
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .preprocess import AveragedLoop, Reversals

#: bins either side of a turn in the regression of an averaged loop's turning point
TIP_BINS = 4


def _truncation_var(
    c_wide: float, v_wide: float, c_narrow: float, v_narrow: float, ratio: float
) -> float:
    """Variance to add for the wide window's truncation error (see the module docstring).

    ``ratio``: narrow / wide window. The first neglected term of a rounded turn is of fourth
    order, so the narrow window keeps ``ratio⁴`` of the wide one's error and the difference
    is ``1 - ratio⁴`` of it (Richardson).
    """
    d2 = max((c_wide - c_narrow) ** 2 - max(v_narrow - v_wide, 0.0), 0.0)
    return d2 / (1.0 - ratio**4) ** 2


def nanmean(v: np.ndarray) -> float:
    """``np.nanmean`` of a short array with its arithmetic (NaN as 0 in the sum, divided by
    the count of the others), without its dispatch (a tenth of the call)."""
    nan = np.isnan(v)
    return float(np.where(nan, 0.0, v).sum() / (v.size - int(nan.sum())))


#: the designs of :func:`_tip_fit` last made, by the arrays they were made from (those are
#: kept with them, so that an ``id`` is not reused while its entry lives)
_DESIGNS: dict[tuple[int, ...], tuple[Any, ...]] = {}
_KEPT_DESIGNS = 16


def _tip_design(
    loop: AveragedLoop, first: int, k: int
) -> tuple[np.ndarray, np.ndarray, float, float]:
    """What :func:`_tip_fit` needs besides the bins' displacement: the bins' indices, the
    regressors, the bins' noise variance and ``inv(XᵀX)[0, 0]``. They depend on the phases
    and the spread only: a loop whose displacement alone differs (the drift covariance's
    shifted loop) reuses them."""
    n = loop.x.size
    assert loop.phase_mean is not None and loop.phase_sq is not None
    key = (id(loop.phase_mean), id(loop.phase_sq), id(loop.x_std), loop.n_cycles, n, first, k)
    got = _DESIGNS.get(key)
    if got is not None and got[0] is loop.phase_mean and got[1] is loop.phase_sq:
        if got[2] is loop.x_std:
            return got[3]
    idx = np.arange(first - k, first + k) % n  # k bins either side of the turn
    turn = first / n  # phase of the turn: 0 (peak) or 1/2 (valley)
    pm, p2 = loop.phase_mean[idx], loop.phase_sq[idx]
    before = np.arange(2 * k) < k
    ref = np.where(before & (turn == 0.0), 1.0, turn)  # bins before the peak sit just below 1
    m1 = np.abs(pm - ref)
    m2 = p2 - 2.0 * ref * pm + ref * ref
    X = np.column_stack([np.ones(2 * k), m1, m2])
    sb = loop.x_std[idx] / math.sqrt(loop.n_cycles)
    s2_bins = nanmean(sb**2) if np.any(np.isfinite(sb)) else 0.0
    inv00 = float(np.linalg.inv(X.T @ X)[0, 0])
    design = (idx, X, s2_bins, inv00)
    if len(_DESIGNS) >= _KEPT_DESIGNS:
        with contextlib.suppress(KeyError, StopIteration, RuntimeError):  # (another thread)
            del _DESIGNS[next(iter(_DESIGNS))]
    _DESIGNS[key] = (loop.phase_mean, loop.phase_sq, loop.x_std, design)
    return design


def _tip_fit(loop: AveragedLoop, first: int, k: int) -> tuple[float, float] | None:
    idx, X, s2_bins, inv00 = _tip_design(loop, first, k)
    y = loop.x[idx]
    coef, *_ = np.linalg.lstsq(X, y, rcond=None)
    resid = y - X @ coef
    dof = 2 * k - 3
    s2_fit = float(resid @ resid) / dof if dof > 0 else 0.0
    s2 = max(s2_fit, s2_bins)
    var0 = s2 * inv00
    if not np.isfinite(var0):
        return None
    return float(coef[0]), var0


def tip(loop: AveragedLoop, first: int, k: int = TIP_BINS) -> tuple[float, float] | None:
    """Displacement at a turn of an averaged loop and its standard error.

    The turn lies on the boundary before bin ``first``; the ``k`` bins on either side are
    regressed on the mean ``|φ|`` and ``φ²`` of each bin's samples. The error includes the
    truncation error estimated from the ``k - 1`` bin window (module docstring).
    """
    wide = _tip_fit(loop, first, k)
    if wide is None:
        return None
    var = wide[1]
    if k >= 3:
        narrow = _tip_fit(loop, first, k - 1)
        if narrow is not None:
            var += _truncation_var(wide[0], wide[1], narrow[0], narrow[1], (k - 1) / k)
    return wide[0], math.sqrt(var)


def turning_point_prior(loop: AveragedLoop) -> tuple[float, float, float] | None:
    """Turning points measured by the displacement channel: ``(x0, A, σ)``.

    ``x0 = (top + bottom) / 2`` and ``A = (top - bottom) / 2`` from :func:`tip`; with equal
    weights both have ``σ = sqrt(σ_top² + σ_bot²) / 2`` and no correlation.
    """
    n = loop.x.size
    k = TIP_BINS
    if loop.n_cycles < 2 or n < 4 * k or loop.phase_mean is None or loop.phase_sq is None:
        return None
    top = tip(loop, 0, k)
    bot = tip(loop, n // 2, k)
    if top is None or bot is None:
        return None
    sig = 0.5 * math.hypot(top[1], bot[1])
    if not (sig > 0 and math.isfinite(sig)):
        return None
    return 0.5 * (top[0] + bot[0]), 0.5 * (top[0] - bot[0]), sig


def _half_window(t: np.ndarray, rev: Reversals) -> float:
    times = np.sort(np.r_[rev.peak_times, rev.valley_times])
    gaps = np.diff(times)
    return 0.1 * float(np.median(gaps)) if gaps.size else 0.05 * float(t[-1] - t[0])


def _turn_fit(t: np.ndarray, x: np.ndarray, tc: float, half: float) -> tuple[float, float]:
    """Intercept and its variance of ``x ~ 1 + |Δt| + Δt²`` within ``half`` of ``tc``."""
    sel = np.abs(t - tc) <= half
    dt = t[sel] - tc
    if dt.size < 5:
        return math.nan, math.nan
    X = np.column_stack([np.ones(dt.size), np.abs(dt), dt * dt])
    coef, *_ = np.linalg.lstsq(X, x[sel], rcond=None)
    r = x[sel] - X @ coef
    s2 = float(r @ r) / (dt.size - 3)
    return float(coef[0]), s2 * float(np.linalg.inv(X.T @ X)[0, 0])


def virgin_amplitude(x: np.ndarray, t: np.ndarray | None, rev: Reversals) -> tuple[float, float]:
    """Half the distance between the mean measured peak and valley of a recording, and its
    standard error (noise and truncation, module docstring); NaN when a turn is missing.

    Each turn is regressed on the samples within a tenth of the half period around it
    (:func:`contactlab.tangential.model.turn_values`); the noise error of each mean is the
    larger of the turns' spread and the regressions' own error.
    """
    tt = np.arange(x.size, dtype=float) if t is None else t
    half = _half_window(tt, rev)
    means, variances = [], []
    for times in (rev.peak_times, rev.valley_times):
        wide = [_turn_fit(tt, x, tc, half) for tc in times]
        narrow = [_turn_fit(tt, x, tc, 0.7 * half) for tc in times]
        cw = np.array([c for c, _ in wide])
        vw = np.array([v for _, v in wide])
        cn = np.array([c for c, _ in narrow])
        vn = np.array([v for _, v in narrow])
        ok = np.isfinite(cw) & np.isfinite(vw)
        if not np.any(ok):
            return math.nan, math.nan
        m = int(ok.sum())
        var = float(np.mean(vw[ok])) / m
        if m > 1:
            var = max(var, float(np.var(cw[ok], ddof=1)) / m)
        both = ok & np.isfinite(cn) & np.isfinite(vn)
        if np.any(both):
            # a shared shape error, the same at every turn: it does not average over turns
            var += _truncation_var(
                float(np.mean(cw[both])),
                float(np.mean(vw[both])) / int(both.sum()),
                float(np.mean(cn[both])),
                float(np.mean(vn[both])) / int(both.sum()),
                0.7,
            )
        means.append(float(np.mean(cw[ok])))
        variances.append(var)
    return 0.5 * (means[0] - means[1]), 0.5 * math.sqrt(variances[0] + variances[1])


@dataclass(frozen=True)
class VirginTurns:
    """Measured turning points of a recording that starts at rest (see :func:`virgin_nodes`).

    ``positions`` (where each turn is inserted into the path) and ``values`` (m), sorted by
    position, with each value's standard error ``stderr``. ``modes[j] = (lo, hi, dpath,
    dvalue)``: the error of turn ``j``'s local regression as three independent 1σ modes
    (columns), each moving the denoised path ``lo:hi`` by ``dpath[:, m]`` and the turn by
    ``dvalue[m]``. ``is_peak``: peak (True) or valley.
    """

    positions: np.ndarray
    values: np.ndarray
    stderr: np.ndarray
    modes: list[tuple[int, int, np.ndarray, np.ndarray]]
    is_peak: np.ndarray

    @property
    def nodes(self) -> tuple[np.ndarray, np.ndarray]:
        """``(positions, values)`` for :func:`~contactlab.tangential.model.virgin_signal_force`."""
        return self.positions, self.values


def virgin_nodes(
    x: np.ndarray, t: np.ndarray | None, xpath: np.ndarray, rev: Reversals
) -> VirginTurns | None:
    """Measured turning points for a virgin-history fit, inserted between samples (where the
    turn lies), with the projected path near each turn replaced by the regression that
    measured it: a denoised path (clipping the noisy samples at the turn instead would pull
    them inward, as only those beyond it move), and no sample passes its turn. ``xpath`` is
    changed in place. The fit holds the turns fixed; the analysis carries their regressions'
    errors (``modes``) into its covariance."""
    tt = np.arange(x.size, dtype=float) if t is None else t
    times = np.r_[rev.peak_times, rev.valley_times]
    if times.size == 0:
        return None
    is_peak = np.r_[np.ones(rev.peaks.size, bool), np.zeros(rev.valleys.size, bool)]
    idx = np.r_[rev.peaks, rev.valleys].astype(np.int64)
    half = _half_window(tt, rev)
    pos, val, err, modes, peak = [], [], [], [], []
    for i, p_, tc in zip(idx, is_peak, times, strict=True):
        near = np.abs(tt - tc) <= half
        dt = tt[near] - tc
        if dt.size < 5:
            continue
        X = np.column_stack([np.ones(dt.size), np.abs(dt), dt * dt])
        coef, *_ = np.linalg.lstsq(X, x[near], rcond=None)
        smooth = X @ coef
        r = x[near] - smooth
        cov = float(r @ r) / (dt.size - 3) * np.linalg.inv(X.T @ X)
        lam, vec = np.linalg.eigh(0.5 * (cov + cov.T))
        L = vec * np.sqrt(np.clip(lam, 0.0, None))  # 1σ modes as columns
        v = float(coef[0])
        if not (np.isfinite(v) and np.all(np.isfinite(L))):
            continue
        sign = 1.0 if p_ else -1.0
        left = sign * xpath[i - 1] if i > 0 else -np.inf
        right = sign * xpath[i + 1] if i + 1 < x.size else -np.inf
        pos.append(i + 1 if right >= left else i)
        val.append(v)
        peak.append(bool(p_))
        err.append(math.sqrt(max(cov[0, 0], 0.0)))
        where = np.flatnonzero(near)
        modes.append((int(where[0]), int(where[-1]) + 1, X @ L, L[0].copy()))
        xpath[near] = np.minimum(smooth, v) if p_ else np.maximum(smooth, v)
    if not pos:
        return None
    order = np.argsort(pos, kind="stable")
    return VirginTurns(
        np.asarray(pos, dtype=np.int64)[order],
        np.asarray(val, dtype=float)[order],
        np.asarray(err, dtype=float)[order],
        [modes[k] for k in order],
        np.asarray(peak, dtype=bool)[order],
    )
