"""Plain numpy references of kernels of contactlab.tangential (kept verbatim from the
package, where they served only the tests): the phase knots as a loop, the phase derivative
and the NaN-aware spread of folded cycles, the monotone path through SciPy's isotonic
regression, and the numpy detrending of a window.
"""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np


def phase_knots_loop(rev: Any) -> tuple[np.ndarray, np.ndarray]:
    """The plain-loop reference of ``contactlab.tangential.preprocess.phase_knots``."""
    pt, vt = rev.peak_times, rev.valley_times
    knots_t, knots_p = [], []
    for k, tp in enumerate(pt):
        knots_t.append(tp)
        knots_p.append(float(k))
        later = vt[vt > tp]
        if k + 1 < pt.size and later.size and later[0] < pt[k + 1]:
            knots_t.append(later[0])
            knots_p.append(k + 0.5)
    return np.asarray(knots_t), np.asarray(knots_p)


def dphase(v: np.ndarray, n: int) -> np.ndarray:
    """Derivative of bin values along phase (periodic central difference); the numpy
    reference of the gradient ``PhaseFold.spread`` applies (tests)."""
    return (np.roll(v, -1) - np.roll(v, 1)) * (n / 2.0)


def spread(a: np.ndarray) -> np.ndarray:
    """Standard deviation over axis 0 ignoring NaN; NaN where fewer than 2 values (the numpy
    reference of ``PhaseFold.spread``, tests)."""
    ok = np.isfinite(a)
    k = ok.sum(axis=0)
    z = np.where(ok, a, 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = z.sum(axis=0) / k
        var = (np.where(ok, a - mean, 0.0) ** 2).sum(axis=0) / (k - 1)
    return np.where(k >= 2, np.sqrt(var), np.nan)


def monotone_path_scipy(x: np.ndarray, turns: np.ndarray) -> np.ndarray:
    """The SciPy reference of ``contactlab.tangential.preprocess.monotone_path``."""
    from scipy.optimize import isotonic_regression

    xa = np.asarray(x, dtype=float)
    out = xa.copy()
    edges = np.unique(np.r_[0, np.asarray(turns, dtype=np.int64), xa.size])
    for a, b in itertools.pairwise(edges):
        seg = xa[a:b]
        if seg.size < 2:
            continue
        # Direction from the stretch's ends; the turn at a belongs to the stretch after it.
        rising = seg[-1] >= seg[0] if b == xa.size else xa[min(b, xa.size - 1)] >= seg[0]
        out[a:b] = isotonic_regression(seg, increasing=bool(rising)).x
    return out


def detrended(v: np.ndarray, tt: np.ndarray, tm: float, slope: float) -> np.ndarray:
    """``v - slope * (tt - tm)`` in numpy (the reference of ``_core.detrend_pair``, tests)."""
    out = np.subtract(tt, tm)
    np.multiply(out, -slope, out=out)
    np.add(v, out, out=out)
    return out
