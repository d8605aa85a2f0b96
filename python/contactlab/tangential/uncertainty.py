"""Uncertainty helpers of the tangential analysis: what the fit's covariance does not hold
by itself, and the transformations of it that the report needs.

- :func:`propagate_fit`: first-order error of a derived quantity ``fn(θ, A)``
  (energy ``E(A)``, damping ``E / (π A²)``, stiffness; PHYSICS.md §1 eqs. 17-19) from the
  fit covariance and a separately measured amplitude, with their correlation when the fit
  held ``A`` fixed;
- :func:`trend`: a drift and its standard error from per-cycle means;
- :func:`x_noise_var`, :func:`path_slope`: the ingredients of the effective-variance weights
  of a whole-signal fit (errors in variables: ``σF² + (k σx)²``);
- :func:`numeric_energy`: the loop area ``∮ F dx`` of the raw cycles and its error;
- :func:`reparametrize`: ``(h0·ac, ac) → (h0, ac)`` with the covariance transformed.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from .. import _core
from ..fitting import FitResult, Parameter, stderr_and_correl
from ..masing import loop_area
from .preprocess import AveragedLoop


def propagate_fit(
    fit: FitResult,
    fn: Any,
    amplitude: float,
    amplitude_stderr: float,
    g_amp: np.ndarray | None = None,
) -> tuple[float, float]:
    """Value and error of ``fn(values, A)``: fit covariance plus the amplitude's error.

    ``g_amp`` (over ``fit.var_names``) gives the covariance of the fitted parameters with the
    amplitude, ``Cov(θ, A) = g_amp σ_A²`` (``∂θ/∂A`` when the fit held ``A`` fixed at a
    measured value; from the shared turning points of a virgin-history fit); the term
    ``2 (∇θ fn · g_amp) ∂fn/∂A σ_A²`` is then included.
    """
    val, err = fit.propagate(lambda v: fn(v, amplitude))
    if amplitude_stderr > 0 and np.isfinite(amplitude_stderr):
        h = 1e-6 * amplitude
        d = (fn(fit.values, amplitude + h) - fn(fit.values, amplitude - h)) / (2 * h)
        var = err**2 + (d * amplitude_stderr) ** 2
        if g_amp is not None and fit.var_names:
            base = fit.values
            grad = []
            for name in fit.var_names:
                hv = 1e-6 * (abs(base[name]) or 1.0)
                up = fn(dict(base, **{name: base[name] + hv}), amplitude)
                dn = fn(dict(base, **{name: base[name] - hv}), amplitude)
                grad.append((up - dn) / (2 * hv))
            var += 2.0 * float(np.dot(grad, g_amp)) * d * amplitude_stderr**2
        err = math.sqrt(max(var, 0.0))
    return float(val), float(err)


def x_noise_var(x: np.ndarray, loop: AveragedLoop | None) -> float:
    """Variance of the displacement sensor's noise.

    Two estimates, each biased only upwards: the second differences of ``x``
    (``var(Δ²x) = 6 σx²`` for white noise, robust scale; the smooth drive adds its own
    curvature) and, when there is an averaged loop, the cycle-to-cycle spread of its bins
    (which also holds real cycle-to-cycle change and where samples fall in a bin). The
    smaller is taken.
    """
    est = []
    d2 = np.diff(x, 2)
    if d2.size >= 10:
        mad = float(np.median(np.abs(d2 - np.median(d2))))
        est.append((1.4826 * mad) ** 2 / 6.0)
    if loop is not None and loop.n_cycles > 1 and np.any(np.isfinite(loop.x_std)):
        est.append(float(np.nanmean(loop.x_std**2 * loop.count / loop.n_cycles)))
    return min(est) if est else 0.0


def path_slope(F: np.ndarray, x: np.ndarray, k_max: float) -> np.ndarray:
    """``|dF/dx|`` along a path (central differences), within ``[0, k_max]``; where the path
    barely moves (a turn, a pooled stretch) the initial stiffness ``k_max`` is taken."""
    dF = np.gradient(F)
    dx = np.gradient(x)
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.abs(dF / dx)
    k[~np.isfinite(k)] = k_max
    return np.clip(k, 0.0, k_max)


def trend(t: np.ndarray, v: np.ndarray) -> tuple[float, float]:
    """Least-squares slope of ``v`` against ``t`` and its standard error."""
    tm = float(np.mean(t))
    sxx = float(np.sum((t - tm) ** 2))
    slope = float(np.sum((t - tm) * (v - v.mean())) / sxx)
    res = v - v.mean() - slope * (t - tm)
    se = math.sqrt(float(res @ res) / (t.size - 2) / sxx) if t.size > 2 else math.nan
    return slope, se


def numeric_energy(loop: AveragedLoop, x: np.ndarray, F: np.ndarray) -> tuple[float, float]:
    """Energy per cycle as the mean area ``∮ F dx`` of the complete cycles' own samples, and
    its standard error.

    Each cycle's shoelace area is linear in each sample's ``F`` (and ``x``), with coefficients
    half the neighbours' difference in ``x`` (in ``F``), and sensor noise is independent from
    sample to sample, so the error follows from the per-sample noise variances, pooled over all
    phase bins from the cycle-to-cycle spread (many degrees of freedom, unlike the spread of a
    handful of per-cycle areas). Areas of raw samples, not of bin means, which would cut the
    corners at the turns.
    """
    e = loop.scatter.energy
    if loop.cycle_bounds is None or not np.any(np.isfinite(e)):
        return float(loop_area(loop.x, loop.F)), math.nan
    n = loop.n_cycles
    if n < 2:
        return float(np.nanmean(e)), math.nan
    per_cycle = loop.count / n
    vF, vx = loop.F_std**2 * per_cycle, loop.x_std**2 * per_cycle
    if not (np.any(np.isfinite(vF)) and np.any(np.isfinite(vx))):
        # no phase bin with a spread (found by fuzzing: numpy's "Mean of empty slice")
        return float(np.nanmean(e)), math.nan
    s2F = float(np.nanmean(vF))
    s2x = float(np.nanmean(vx))
    # per cycle Σ (∂A/∂F_i)² and Σ (∂A/∂x_i)² (∂A/∂F_i = (x_{i-1} - x_{i+1}) / 2,
    # ∂A/∂x_i = (F_{i+1} - F_{i-1}) / 2, cyclic in the cycle): one pass in Rust
    # (the loop's own, from the fold of these samples, when it carries them)
    if loop.sensitivity is not None and loop.sensitivity[0].size == n:
        g_F, g_x = loop.sensitivity
    else:
        bounds = [int(b) for b in loop.cycle_bounds[: n + 1]]
        g_F, g_x = _core.loop_area_sensitivity(
            np.ascontiguousarray(x, dtype=float), np.ascontiguousarray(F, dtype=float), bounds
        )
    with np.errstate(over="ignore", invalid="ignore"):  # 1e300-scale loops: err is NaN below
        var = float(np.sum(g_F) * s2F + np.sum(g_x) * s2x)
    err = math.sqrt(var) / n
    # Sampling also moves each cycle's polygon across the turns differently; when the areas
    # scatter more than the noise explains, their own spread is the better error.
    # (fewer than two finite cycle areas: no spread; numpy warned "Degrees of freedom <= 0",
    # found by fuzz: track)
    # (on the areas over their largest: 1e160-scale areas overflowed the squares)
    fin = e[np.isfinite(e)]
    big = float(np.max(np.abs(fin))) if fin.size else 0.0
    emp = (
        big * float(np.std(fin / big, ddof=1)) / math.sqrt(n)
        if fin.size > 1 and big > 0
        else (0.0 if fin.size > 1 else math.nan)
    )
    err = max(err, emp) if math.isfinite(emp) else err
    return float(np.nanmean(e)), err if math.isfinite(err) else math.nan


def correl(fit: FitResult, a: str, b: str) -> float:
    if fit.correl is None or a not in fit.var_names or b not in fit.var_names:
        return math.nan
    return float(fit.correl[fit.var_names.index(a), fit.var_names.index(b)])


def reparametrize(raw: FitResult) -> FitResult:
    """``(k0, ac, ...)`` → ``(h0, ac, ...)`` with the covariance transformed to first order."""
    k0, ac = raw.params["k0"].value, raw.params["ac"].value
    h0 = k0 / ac
    params: dict[str, Parameter] = {}
    pk = raw.params["k0"]
    params["h0"] = Parameter(
        "h0",
        h0,
        vary=True,
        min=0.0,
        unit="N",
        init_value=(pk.init_value / raw.params["ac"].init_value)
        if pk.init_value and raw.params["ac"].init_value
        else None,
    )
    for name, p in raw.params.items():
        if name != "k0":
            params[name] = replace(p)
    names = ["h0" if n == "k0" else n for n in raw.var_names]
    covar = correl = None
    if raw.covar is not None:
        T = np.eye(len(names))
        i_k, i_a = raw.var_names.index("k0"), raw.var_names.index("ac")
        # h0 = k0 / ac
        T[i_k, i_k] = 1.0 / ac
        T[i_k, i_a] = -k0 / ac**2
        covar = T @ raw.covar @ T.T
        d, correl = stderr_and_correl(covar)
        for i, n in enumerate(names):
            src = raw.params["k0" if n == "h0" else n]
            if src.stderr is None and src.identifiable is False:
                params[n].stderr = None
                params[n].identifiable = False
            else:
                params[n].stderr = float(d[i])
                params[n].identifiable = True
    out = replace(raw, params=params, var_names=names, covar=covar, correl=correl, jac=None)
    out.notes = [n.replace("k0", "h0·ac") for n in raw.notes]
    return out
