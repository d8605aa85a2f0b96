"""Steps 5 and 6 of :func:`contactlab.tangential.analyze_tangential` (see
:mod:`contactlab.tangential.steps`): the errors of the inputs the fit took as exact, carried
into the covariance through the fit's linear response ``G = -(JᵀJ)⁻¹Jᵀ ∂r/∂u``
(``cov += G Σ_u Gᵀ``), and the amplitude with its error.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from ..fitting import FitResult, add_covariance
from .preprocess import average_loop
from .turns import turning_point_prior, virgin_amplitude

if TYPE_CHECKING:
    from .steps import Drift, FitData, Residuals

__all__ = [
    "Amplitude",
    "amplitude_estimate",
    "drift_covariance",
    "fixed_amplitude_covariance",
    "propagate",
    "propagate_many",
    "turn_covariance",
]


# -- 5. covariance of inputs taken as exact ----------------------------------------------


def _response(raw: FitResult, cols: list[np.ndarray]) -> np.ndarray:
    """``G = -(JᵀJ)⁻¹Jᵀ [∂r]``: the fit's linear response to input perturbations."""
    return -np.linalg.lstsq(raw.jac, np.column_stack(cols), rcond=None)[0]


def drift_covariance(
    raw: FitResult,
    res: Residuals,
    drift: Drift | None,
    *,
    rel_threshold: float,
    min_cycles: int,
) -> FitResult:
    """The drifts were estimated (from per-cycle means) and removed before the fit, which
    then took the data as exact. Carry their errors into the covariance: the residuals are
    linear in the removed trend, ``cov += G diag(σ_s²) Gᵀ`` (independent channels)."""
    d = res.data
    if drift is None or d.loop is None or raw.jac is None or raw.covar is None:
        return raw
    tt, tm = drift.tt, drift.t_mid
    # each bin's mean of (t - tm): what a unit slope removed from that bin (the loop was
    # averaged on these x and t: its bins' mean time is that mean, no second fold needed)
    if d.loop.t_mean is not None and d.loop.t_mean.size == d.loop.x.size:
        T_bin = d.loop.t_mean - tm
    else:
        T_bin = average_loop(
            d.x,
            tt - tm,
            d.t,
            n_points=d.loop.x.size,
            rel_threshold=rel_threshold,
            min_cycles=min_cycles,
        ).F
    T = T_bin if d.on == "averaged" else tt - tm
    vals0 = raw.values
    base = res.residual(vals0)
    cols = []
    s_f, s_x = drift.force[1], drift.displacement[1]
    if s_f > 0 and math.isfinite(s_f):
        cols.append(res.residual(vals0, dF=-s_f * T) - base)
    if s_x > 0 and math.isfinite(s_x):
        vn = None
        if d.vnodes is not None:
            at = tt[np.minimum(d.vnodes.positions, tt.size - 1)] - tm
            vn = (d.vnodes.positions, d.vnodes.values - s_x * at)
        tips = None
        if res.prior is not None:
            tips = turning_point_prior(replace(d.loop, x=d.loop.x - s_x * T_bin))
        cols.append(res.residual(vals0, xp=d.xpath - s_x * T, vn=vn, tips=tips) - base)
    if not cols:
        return raw
    G = _response(raw, cols)
    return add_covariance(raw, G @ G.T)


def turn_covariance(raw: FitResult, res: Residuals) -> tuple[FitResult, np.ndarray | None]:
    """The path around each measured turn is its local regression, and a virgin-history fit
    holds the turn values fixed: carry each regression's error (three independent 1σ modes
    per turn, the turns independent) into the covariance, ``cov += Σ g gᵀ``.

    Returns the fit and, for a virgin-history fit, ``Cov(θ, A)`` through the shared turns.
    """
    d = res.data
    measured = d.measured
    if measured is None or raw.jac is None or raw.covar is None:
        return raw, None
    vals0 = raw.values
    base = res.residual(vals0)
    cols = []
    d_amp = []  # the same modes move the amplitude (half the peak-valley distance)
    n_pk = max(int(measured.is_peak.sum()), 1)
    n_vl = max(int((~measured.is_peak).sum()), 1)
    for j, (lo, hi, dpath, dval) in enumerate(measured.modes):
        share = 0.5 / n_pk if measured.is_peak[j] else -0.5 / n_vl
        for m_ in range(dval.size):
            d_amp.append(share * dval[m_])
            moved = measured.values.copy()
            moved[j] += dval[m_]
            xp_j = d.xpath.copy()
            xp_j[lo:hi] += dpath[:, m_]
            vn_j = None if d.steady else (measured.positions, moved)
            cols.append(res.residual(vals0, xp=xp_j, vn=vn_j) - base)
    G = _response(raw, cols)
    raw = add_covariance(raw, G @ G.T)
    return raw, (None if d.steady else G @ np.asarray(d_amp))


def fixed_amplitude_covariance(
    raw: FitResult, res: Residuals, prior: tuple[float, float, float] | None, fit_amplitude: bool
) -> tuple[FitResult, np.ndarray | None]:
    """A steady fit that held the amplitude at the displacement channel's measurement:
    ``cov += g gᵀ σ_A²`` with ``g = ∂θ/∂A``; returns the fit and ``g`` (per metre)."""
    if not res.data.steady or fit_amplitude or prior is None or raw.jac is None:
        return raw, None
    vals0 = raw.values
    col = res.residual(dict(vals0, amplitude=vals0["amplitude"] + prior[2]))
    g_amp = _response(raw, [col - res.residual(vals0)])[:, 0]
    if raw.covar is not None:
        raw = add_covariance(raw, np.outer(g_amp, g_amp))
    return raw, g_amp / prior[2]


# -- 6. amplitude ------------------------------------------------------------------------


@dataclass(frozen=True)
class Amplitude:
    value: float
    stderr: float
    extra: float  # error to propagate beside the fit covariance (0 when fitted)
    g_amp: np.ndarray | None  # Cov(θ, A) = g_amp σ_A²
    fitted: bool


def amplitude_estimate(
    raw: FitResult,
    data: FitData,
    prior: tuple[float, float, float] | None,
    *,
    fit_amplitude: bool,
    g_amp: np.ndarray | None,
    c_theta_amp: np.ndarray | None,
) -> Amplitude:
    """The amplitude: fitted (its error in the covariance), held at the turn regression, or
    for a virgin-history fit the turns' local regressions (:func:`virgin_amplitude`)."""
    vals = raw.values
    sc = data.loop.scatter if data.loop is not None else None
    se = 0.0  # the standard error of the mean of the cycles' own amplitudes
    if sc is not None and sc.n_cycles > 1:
        se = float(np.std(sc.amplitude, ddof=1) / math.sqrt(sc.n_cycles))
    if data.steady and fit_amplitude:
        # the fit's error, or the spread of the cycles' amplitudes where that is larger (a
        # rig whose stroke wanders from cycle to cycle: the measured friction frame in gross
        # sliding read 1629.1 ± 0.009 µm from cycles of 1613-1648 µm); reported only, the
        # other quantities keep the fit's covariance
        fse = raw.params["amplitude"].stderr
        fse = float(fse) if fse is not None and math.isfinite(fse) else math.nan
        rep = max(fse, se) if math.isfinite(fse) else fse
        return Amplitude(float(vals["amplitude"]), rep, 0.0, None, True)
    amplitude = float(vals["amplitude"]) if data.steady else data.amplitude0
    if data.steady and prior is not None:
        # the turn regression's error (the averaged loop's tips), or the spread of the
        # cycles' own amplitudes where that is larger (a rig whose stroke wanders from cycle
        # to cycle: gross sliding read 1629.1 ± 0.009 µm from cycles of 1613-1648 µm)
        se = max(prior[2], se)
    elif not data.steady:
        va, va_se = virgin_amplitude(data.x, data.t, data.rev)
        if math.isfinite(va) and math.isfinite(va_se):
            amplitude, se = va, va_se
            if c_theta_amp is not None and va_se > 0:
                g_amp = c_theta_amp / va_se**2  # so that Cov(θ, A) = g_amp σ_A²
    return Amplitude(amplitude, se, se, g_amp, False)


def propagate(raw: FitResult, amp: Amplitude, fn: Any) -> tuple[float, float]:
    """Value and error of ``fn(values, A)`` from the fit covariance and the amplitude."""
    from .uncertainty import propagate_fit

    if amp.fitted:
        return propagate_fit(raw, lambda v, _A: fn(v, v["amplitude"]), amp.value, 0.0)
    return propagate_fit(raw, fn, amp.value, amp.extra, amp.g_amp)


def propagate_many(
    raw: FitResult, amp: Amplitude, names: tuple[str, ...], fn: Any
) -> dict[str, tuple[float, float]]:
    """:func:`propagate` of each element of the vector ``fn(values, A)`` (named ``names``):
    one set of perturbed parameter values for all of them (the same steps, hence the same
    numbers as one :func:`propagate` per element) where the amplitude is fitted; one
    :func:`propagate` per element where it is not (its extra error term is scalar)."""
    if amp.fitted:
        val, err = raw.propagate(lambda v: fn(v, v["amplitude"]))
        vals, errs = np.atleast_1d(val), np.atleast_1d(err)
        return {n: (float(vals[i]), float(errs[i])) for i, n in enumerate(names)}
    return {
        n: propagate(raw, amp, lambda v, A, i=i: float(fn(v, A)[i])) for i, n in enumerate(names)
    }
