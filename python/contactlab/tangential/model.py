"""Masing model predictions for fitting tangential recordings (PHYSICS.md §1).

Every prediction runs the Rust Masing operator (``contactlab.Masing(...).force``) on a
displacement path; nothing here re-implements the branches. Three histories:

- ``steady_loop_force``: a periodic (averaged) cycle in its steady state; the operator is
  primed on the virgin curve to the top and the cycle is pushed twice; the second pass is the
  steady loop, centred at force zero (the fit adds an ``offset``).
- ``steady_signal_force``: a whole recording in the steady state of its outer loop.

In both, the turning points ``x0 ± A`` are fit parameters rather than the measured extremes:
the maximum of noisy samples overestimates the amplitude, and the Masing loop is most
sensitive exactly there (errors-in-variables bias of several standard errors otherwise).
``x0`` is the paper's branch shift.

- ``virgin_signal_force``: a recording that starts at rest, at displacement ``x0``, on the
  virgin curve.

Also :func:`initial_guess`, from the loop's size and area alone (its area ratio
``E / (4 A h_m)`` depends on ``ac·A`` only).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ..errors import InputError
from ..masing import Masing


def steady_loop_force(
    model: Masing,
    x: np.ndarray,
    x0: float,
    amplitude: float,
    x_var: np.ndarray | None = None,
) -> np.ndarray:
    """Steady-state force along one averaged cycle.

    ``x`` holds ``n`` (even) phase bins with the peak between the last and the first bin and
    the valley between bins ``n/2 - 1`` and ``n/2``, already monotone on each half. The turning
    points are ``x0 ± amplitude`` (fit parameters: the measured extremes are biased by noise);
    bins beyond them are clipped. The operator is primed to the top on the virgin curve and the
    cycle pushed twice; the second pass is returned.

    ``x_var`` (the spread of the true displacement inside each bin) adds the second-order
    term of a bin mean, ``½ h''(x̄) var(x)``: a bin's mean force is not the force at its mean
    displacement where the branch curves (``h'' = ±½ h0 ac² exp(-ac u)`` on the branches of the
    exponential curve, ``u`` half the distance from the branch's turn).
    """
    n = x.size
    h = n // 2
    top, bot = amplitude, -amplitude
    u = np.clip(x - x0, bot, top)
    # the path (0, top), then the cycle (top, descending bins, bot, ascending bins) twice,
    # filled into one array
    m = n + 2
    path = np.empty(2 + 2 * m)
    path[0], path[1] = 0.0, top
    for a in (2, 2 + m):
        path[a] = top
        path[a + 1 : a + 1 + h] = u[:h]
        path[a + 1 + h] = bot
        path[a + 2 + h : a + m] = u[h:]
    out = model.force(path)
    second = out[2 + m :]
    F = np.concatenate([second[1 : h + 1], second[h + 2 :]])
    if x_var is not None and model.is_exponential:
        # from the turn that starts each branch (np.concatenate: np.r_ costs ~20 µs a call)
        dist = np.concatenate([top - u[:h], u[h:] - bot])
        ac, h0 = np.float64(model.ac), np.float64(model.h0)
        with np.errstate(over="ignore", invalid="ignore"):  # a fit straying to a huge ac
            curv = 0.5 * h0 * np.square(ac) * np.exp(-0.5 * ac * dist)
            curv[h:] *= -1.0  # descending branches curve up, ascending ones down
            corr = 0.5 * curv * x_var
        if not np.isfinite(corr).all():
            # ac so large that the branch turns within a bin: the term (a bin mean's force is
            # never beyond ±h0 of its neighbours') is bounded by h0, and 0 where x_var is
            corr = np.where(np.isnan(corr), 0.0, np.clip(corr, -h0, h0))
        F = F + corr
    return F


def turn_nodes(x: np.ndarray, peaks: np.ndarray, valleys: np.ndarray) -> tuple[np.ndarray, ...]:
    """Where to insert the turning points into a sampled path: between each extreme sample
    and its larger (peaks) or smaller (valleys) neighbour, where the true turn lies.

    Returns ``(positions, is_peak)`` for :func:`steady_signal_force`, sorted; computed once
    from the data so the model stays a smooth function of the fit parameters.
    """
    n = x.size
    pos, top = [], []
    for idx, sign in ((peaks, 1.0), (valleys, -1.0)):
        for i in np.asarray(idx, dtype=np.int64):
            left = sign * x[i - 1] if i > 0 else -np.inf
            right = sign * x[i + 1] if i + 1 < n else -np.inf
            pos.append(i + 1 if right >= left else i)
            top.append(sign > 0)
    order = np.argsort(pos, kind="stable")
    return np.asarray(pos, dtype=np.int64)[order], np.asarray(top, dtype=bool)[order]


def steady_signal_force(
    model: Masing,
    x: np.ndarray,
    x0: float,
    amplitude: float,
    nodes: tuple[np.ndarray, ...],
    first_is_peak: bool,
) -> np.ndarray:
    """Force along a recording in the steady state of its outer loop ``x0 ± amplitude``.

    ``x`` is the (monotone-projected) path, clipped into the loop; the turning points are
    inserted as extra path nodes at ``nodes`` (from :func:`turn_nodes`), so no sample is
    moved. Primed to ``(top, bottom)`` or ``(bottom, top)`` by the direction of the first turn.
    """
    top, bot = amplitude, -amplitude
    u = np.clip(x - x0, bot, top)
    pos, is_top = nodes
    path = np.insert(u, pos, np.where(is_top, top, bot))
    keep = np.ones(path.size, dtype=bool)
    keep[pos + np.arange(pos.size)] = False
    prime = [0.0, top, bot] if first_is_peak else [0.0, bot, top]
    return model.force(np.concatenate([prime, path]))[3:][keep]


def virgin_signal_force(
    model: Masing,
    x: np.ndarray,
    x0: float,
    nodes: tuple[np.ndarray, ...] | None = None,
) -> np.ndarray:
    """Force along a recording that starts at rest at displacement ``x0``.

    ``nodes = (positions, values)`` inserts measured turning points into the path (see
    :func:`turn_values`); the model is returned at the samples only.
    """
    if nodes is None:
        return model.force(np.concatenate([[0.0], x - x0]))[1:]
    pos, val = nodes
    path = np.insert(x, pos, val)
    keep = np.ones(path.size, dtype=bool)
    keep[pos + np.arange(pos.size)] = False
    return model.force(np.concatenate([[0.0], path - x0]))[1:][keep]


def turn_values(
    t: np.ndarray, x: np.ndarray, centres: np.ndarray, half_window: float
) -> np.ndarray:
    """Displacement at each turn, by regressing the samples within ``half_window`` of the
    turn instant on ``|Δt|`` and ``Δt²`` (unbiased for rounded and sharp turns alike; the
    largest noisy sample would overestimate the excursion)."""
    out = np.empty(centres.size)
    for k, tc in enumerate(centres):
        sel = np.abs(t - tc) <= half_window
        dt = t[sel] - tc
        if dt.size < 4:
            out[k] = np.nan
            continue
        X = np.column_stack([np.ones(dt.size), np.abs(dt), dt * dt])
        coef, *_ = np.linalg.lstsq(X, x[sel], rcond=None)
        out[k] = coef[0]
    return out


def area_ratio(z: float) -> float:
    """``E / (4 A f(A))`` of a symmetric Masing loop as a function of ``z = ac·A``.

    0 for a line (``≈ z/6`` for small ``z``), 1 for the Coulomb rectangle.
    """
    if z < 1e-4:
        return z / 6.0
    g = -math.expm1(-z)
    return 2.0 * ((z - g) / (z * g) - 0.5)


#: ``scipy.optimize.brentq``'s default relative tolerance (4 machine epsilons)
_BRENTQ_RTOL = 4 * np.finfo(float).eps


def brentq(
    f: Callable[[float], float],
    a: float,
    b: float,
    *,
    xtol: float = 2e-12,
    rtol: float = _BRENTQ_RTOL,
    maxiter: int = 100,
) -> float:
    """A root of ``f`` in ``[a, b]`` (``f(a)``, ``f(b)`` of opposite signs) by Brent's method:
    ``scipy.optimize.brentq``'s iteration step by step (its C code's interpolation,
    extrapolation and bisection rules and tolerances), so the same root to the last bit,
    without importing :mod:`scipy.optimize` (half a second under the interpreter lock, paid
    by the first window of every streamed analysis). Returns the last iterate after
    ``maxiter`` steps; :class:`InputError` when the signs do not bracket a root."""
    xpre, xcur = float(a), float(b)
    xblk = fblk = spre = scur = 0.0
    fpre, fcur = float(f(xpre)), float(f(xcur))
    if fpre == 0:
        return xpre
    if fcur == 0:
        return xcur
    if math.copysign(1.0, fpre) == math.copysign(1.0, fcur):
        raise InputError(f"f({a}) and f({b}) have the same sign: no root bracketed")
    for _ in range(maxiter):
        if fpre != 0 and fcur != 0 and math.copysign(1.0, fpre) != math.copysign(1.0, fcur):
            xblk, fblk = xpre, fpre
            spre = scur = xcur - xpre
        if abs(fblk) < abs(fcur):
            xpre, xcur, xblk = xcur, xblk, xcur
            fpre, fcur, fblk = fcur, fblk, fcur
        delta = (xtol + rtol * abs(xcur)) / 2
        sbis = (xblk - xcur) / 2
        if fcur == 0 or abs(sbis) < delta:
            return xcur
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:  # interpolate
                stry = -fcur * (xcur - xpre) / (fcur - fpre)
            else:  # extrapolate
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            if 2 * abs(stry) < min(abs(spre), 3 * abs(sbis) - delta):  # a good short step
                spre, scur = scur, stry
            else:  # bisect
                spre = scur = sbis
        else:  # bisect
            spre = scur = sbis
        xpre, fpre = xcur, fcur
        xcur += scur if abs(scur) > delta else (delta if sbis > 0 else -delta)
        fcur = float(f(xcur))
    return xcur


def initial_guess(amplitude: float, half_force_range: float, energy: float) -> tuple[float, float]:
    """``(h0, ac)`` reproducing a loop's amplitude, peak force and area."""
    A = amplitude
    hm = max(half_force_range, 1e-300)
    r = energy / (4.0 * A * hm) if A > 0 else 0.0
    lo, hi = 1e-3, 60.0
    if r <= area_ratio(lo):
        z = lo
    elif r >= area_ratio(hi):
        z = hi
    else:
        z = brentq(lambda zz: area_ratio(zz) - r, lo, hi, xtol=1e-10)
    ac = z / A
    h0 = hm / -math.expm1(-z)
    return h0, ac
