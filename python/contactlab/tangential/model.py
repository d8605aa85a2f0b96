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

import numpy as np
from scipy.optimize import brentq

from ..masing import Masing


def steady_loop_force(model: Masing, x: np.ndarray, x0: float, amplitude: float) -> np.ndarray:
    """Steady-state force along one averaged cycle.

    ``x`` holds ``n`` (even) phase bins with the peak between the last and the first bin and
    the valley between bins ``n/2 - 1`` and ``n/2``, already monotone on each half. The turning
    points are ``x0 ± amplitude`` (fit parameters: the measured extremes are biased by noise);
    bins beyond them are clipped. The operator is primed to the top on the virgin curve and the
    cycle pushed twice; the second pass is returned.
    """
    n = x.size
    h = n // 2
    top, bot = amplitude, -amplitude
    u = np.clip(x - x0, bot, top)
    one = np.concatenate([[top], u[:h], [bot], u[h:]])
    out = model.force(np.concatenate([[0.0, top], one, one]))
    second = out[2 + one.size :]
    return np.concatenate([second[1 : h + 1], second[h + 2 :]])


def steady_signal_force(
    model: Masing,
    x: np.ndarray,
    x0: float,
    amplitude: float,
    peaks: np.ndarray,
    valleys: np.ndarray,
    first_is_peak: bool,
) -> np.ndarray:
    """Force along a recording in the steady state of its outer loop ``x0 ± amplitude``.

    ``x`` is the (monotone-projected) path; the samples at ``peaks``/``valleys`` are set to the
    turning points and the rest clipped into the loop. Primed to ``(top, bottom)`` or
    ``(bottom, top)`` depending on the direction of the first turn.
    """
    top, bot = amplitude, -amplitude
    u = np.clip(x - x0, bot, top)
    u[peaks] = top
    u[valleys] = bot
    prime = [0.0, top, bot] if first_is_peak else [0.0, bot, top]
    return model.force(np.concatenate([prime, u]))[3:]


def virgin_signal_force(model: Masing, x: np.ndarray, x0: float) -> np.ndarray:
    """Force along a recording that starts at rest at displacement ``x0``."""
    return model.force(np.concatenate([[0.0], x - x0]))[1:]


def area_ratio(z: float) -> float:
    """``E / (4 A f(A))`` of a symmetric Masing loop as a function of ``z = ac·A``.

    0 for a line (``≈ z/6`` for small ``z``), 1 for the Coulomb rectangle.
    """
    if z < 1e-4:
        return z / 6.0
    g = -math.expm1(-z)
    return 2.0 * ((z - g) / (z * g) - 0.5)


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
