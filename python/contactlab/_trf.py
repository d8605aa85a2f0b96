"""SciPy's trust-region reflective least-squares solver for bounded problems, without importing
:mod:`scipy.optimize`.

Importing :mod:`scipy.optimize` (and the :mod:`scipy.fft`, :mod:`scipy.linalg`,
:mod:`scipy.sparse` and :mod:`scipy.special` it pulls in) costs about half a second of CPU,
a sixth of the time a 1e6-sample ``contactlab diagnose`` may take (issue 9), while every fit
of a diagnosis uses one code path of it: :func:`scipy.optimize.least_squares` with
``method="trf"``, bounds, the linear loss, ``x_scale=1``, the exact trust-region solver and
a forward-difference (``"2-point"``) Jacobian. :func:`solve` is that path, transcribed from
SciPy 1.17 (``scipy/optimize/_lsq/trf.py``, ``common.py``, ``least_squares.py`` and
``_numdiff.py``; BSD-3-Clause, Copyright (c) 2001-2002 Enthought, Inc. 2003, SciPy
Developers) step for step: the same trial points in the same order, the same evaluation
count (``max_nfev`` counts the solver's own evaluations, not the Jacobian's columns), the
same end point and status. ``numpy.linalg.svd`` stands for ``scipy.linalg.svd`` (both
LAPACK's ``gesdd``; its factors put in the Fortran layout scipy's have).
``tests/base/test_trf.py`` checks it against SciPy on random problems.
:func:`contactlab.fitting.least_squares_fit` uses it where it applies and SciPy otherwise.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from math import copysign
from typing import Any

import numpy as np
from numpy.linalg import norm

EPS = np.finfo(float).eps

#: :func:`scipy.optimize.least_squares`' messages by status
MESSAGES = {
    -2: "Stopped because `callback` function raised `StopIteration` or returned `True`",
    -1: "Improper input parameters status returned from `leastsq`",
    0: "The maximum number of function evaluations is exceeded.",
    1: "`gtol` termination condition is satisfied.",
    2: "`ftol` termination condition is satisfied.",
    3: "`xtol` termination condition is satisfied.",
    4: "Both `ftol` and `xtol` termination conditions are satisfied.",
}


class Solution:
    """What :func:`solve` found: ``x``, the residuals ``fun`` there, ``status`` (SciPy's
    codes), ``success``, ``message``, ``nfev`` (the solver's evaluations) and ``njev``."""

    def __init__(self, x: np.ndarray, fun: np.ndarray, status: int, nfev: int, njev: int):
        self.x, self.fun, self.status, self.nfev, self.njev = x, fun, status, nfev, njev
        self.success = status > 0
        self.message = MESSAGES[status]


class _Cached:
    """SciPy's ``VectorFunction`` as the solver sees it: the residuals at the last point
    asked for are kept, and asked again (the Jacobian's base point, a zero step) they are
    not recomputed."""

    def __init__(self, fun: Callable[[np.ndarray], Any], x0: np.ndarray) -> None:
        self._fun = fun
        self.x = x0.astype(np.float64)
        self.f = self._call(self.x)

    def _call(self, x: np.ndarray) -> np.ndarray:
        return np.atleast_1d(self._fun(x.copy()))

    def at(self, x: np.ndarray) -> np.ndarray:
        if not np.array_equal(x, self.x):
            self.x = x.astype(np.float64)
            self.f = self._call(self.x)
        return self.f.copy()


def forward_jacobian(
    fun: Callable[[np.ndarray], np.ndarray],
    x0: np.ndarray,
    f0: np.ndarray,
    lb: np.ndarray,
    ub: np.ndarray,
    workers: Callable[[Callable[[Any], Any], Iterable[Any]], Iterable[Any]] | None = None,
) -> np.ndarray:
    """``approx_derivative(fun, x0, method="2-point", f0=f0, bounds=(lb, ub))``: forward
    differences of relative step ``√eps`` (``max(1, |x|)``), turned backward where the step
    would leave the bounds (or shortened to the bound where neither side fits)."""
    sign_x0 = (x0 >= 0).astype(float) * 2 - 1
    h = EPS**0.5 * sign_x0 * np.maximum(1.0, np.abs(x0))
    if not np.all((lb == -np.inf) & (ub == np.inf)):
        h_total = h * 1
        h_adjusted = h.copy()
        lower_dist = x0 - lb
        upper_dist = ub - x0
        x = x0 + h_total
        violated = (x < lb) | (x > ub)
        fitting = np.abs(h_total) <= np.maximum(lower_dist, upper_dist)
        h_adjusted[violated & fitting] *= -1
        forward = (upper_dist >= lower_dist) & ~fitting
        h_adjusted[forward] = upper_dist[forward] / 1
        backward = (upper_dist < lower_dist) & ~fitting
        h_adjusted[backward] = -lower_dist[backward] / 1
        h = h_adjusted
    n = x0.size

    def steps() -> Iterable[np.ndarray]:
        for i in range(n):
            x1 = np.copy(x0)
            x1[i] = x0[i] + h[i]
            yield x1

    f_evals = (workers or map)(fun, steps())
    dx = [(x0[i] + h[i]) - x0[i] for i in range(n)]
    df = [np.atleast_1d(f_eval) - f0 for f_eval in f_evals]
    J_transposed = np.empty((n, f0.size))
    for i, (delf, delx) in enumerate(zip(df, dx, strict=True)):
        J_transposed[i] = delf / delx
    if f0.size == 1:
        J_transposed = np.ravel(J_transposed)
    return J_transposed.T


def find_active_constraints(
    x: np.ndarray, lb: np.ndarray, ub: np.ndarray, rtol: float = 1e-10
) -> np.ndarray:
    active = np.zeros_like(x, dtype=int)
    if rtol == 0:
        active[x <= lb] = -1
        active[x >= ub] = 1
        return active
    lower_dist = x - lb
    upper_dist = ub - x
    lower_threshold = rtol * np.maximum(1, np.abs(lb))
    upper_threshold = rtol * np.maximum(1, np.abs(ub))
    lower_active = np.isfinite(lb) & (lower_dist <= np.minimum(upper_dist, lower_threshold))
    active[lower_active] = -1
    upper_active = np.isfinite(ub) & (upper_dist <= np.minimum(lower_dist, upper_threshold))
    active[upper_active] = 1
    return active


def make_strictly_feasible(
    x: np.ndarray, lb: np.ndarray, ub: np.ndarray, rstep: float = 1e-10
) -> np.ndarray:
    x_new = x.copy()
    active = find_active_constraints(x, lb, ub, rstep)
    lower_mask = np.equal(active, -1)
    upper_mask = np.equal(active, 1)
    if rstep == 0:
        x_new[lower_mask] = np.nextafter(lb[lower_mask], ub[lower_mask])
        x_new[upper_mask] = np.nextafter(ub[upper_mask], lb[upper_mask])
    else:
        x_new[lower_mask] = lb[lower_mask] + rstep * np.maximum(1, np.abs(lb[lower_mask]))
        x_new[upper_mask] = ub[upper_mask] - rstep * np.maximum(1, np.abs(ub[upper_mask]))
    tight_bounds = (x_new < lb) | (x_new > ub)
    x_new[tight_bounds] = 0.5 * (lb[tight_bounds] + ub[tight_bounds])
    return x_new


def _cl_scaling_vector(
    x: np.ndarray, g: np.ndarray, lb: np.ndarray, ub: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    v = np.ones_like(x)
    dv = np.zeros_like(x)
    mask = (g < 0) & np.isfinite(ub)
    v[mask] = ub[mask] - x[mask]
    dv[mask] = -1
    mask = (g > 0) & np.isfinite(lb)
    v[mask] = x[mask] - lb[mask]
    dv[mask] = 1
    return v, dv


def _phi_and_derivative(
    alpha: float, suf: np.ndarray, s: np.ndarray, Delta: float
) -> tuple[float, float]:
    denom = s**2 + alpha
    p_norm = norm(suf / denom)
    phi = p_norm - Delta
    phi_prime = -np.sum(suf**2 / denom**3) / p_norm
    return phi, phi_prime


def _solve_lsq_trust_region(
    n: int,
    m: int,
    uf: np.ndarray,
    s: np.ndarray,
    V: np.ndarray,
    Delta: float,
    initial_alpha: float | None = None,
    rtol: float = 0.01,
    max_iter: int = 10,
) -> tuple[np.ndarray, float, int]:
    suf = s * uf
    if m >= n:
        threshold = EPS * m * s[0]
        full_rank = s[-1] > threshold
    else:
        full_rank = False
    if full_rank:
        p = -V.dot(uf / s)
        if norm(p) <= Delta:
            return p, 0.0, 0
    alpha_upper = norm(suf) / Delta
    if full_rank:
        phi, phi_prime = _phi_and_derivative(0.0, suf, s, Delta)
        alpha_lower = -phi / phi_prime
    else:
        alpha_lower = 0.0
    if initial_alpha is None or (not full_rank and initial_alpha == 0):
        alpha = max(0.001 * alpha_upper, (alpha_lower * alpha_upper) ** 0.5)
    else:
        alpha = initial_alpha
    it = 0
    for it in range(max_iter):  # noqa: B007 (the count is returned)
        if alpha < alpha_lower or alpha > alpha_upper:
            alpha = max(0.001 * alpha_upper, (alpha_lower * alpha_upper) ** 0.5)
        phi, phi_prime = _phi_and_derivative(alpha, suf, s, Delta)
        if phi < 0:
            alpha_upper = alpha
        ratio = phi / phi_prime
        alpha_lower = max(alpha_lower, alpha - ratio)
        alpha -= (phi + Delta) * ratio / Delta
        if np.abs(phi) < rtol * Delta:
            break
    p = -V.dot(suf / (s**2 + alpha))
    p *= Delta / norm(p)
    return p, alpha, it + 1


def _update_tr_radius(
    Delta: float,
    actual_reduction: float,
    predicted_reduction: float,
    step_norm: float,
    bound_hit: bool,
) -> tuple[float, float]:
    if predicted_reduction > 0:
        ratio = actual_reduction / predicted_reduction
    elif predicted_reduction == actual_reduction == 0:
        ratio = 1
    else:
        ratio = 0
    if ratio < 0.25:
        Delta = 0.25 * step_norm
    elif ratio > 0.75 and bound_hit:
        Delta *= 2.0
    return Delta, ratio


def _build_quadratic_1d(
    J: np.ndarray,
    g: np.ndarray,
    s: np.ndarray,
    diag: np.ndarray | None = None,
    s0: np.ndarray | None = None,
) -> tuple[float, ...]:
    v = J.dot(s)
    a = np.dot(v, v)
    if diag is not None:
        a += np.dot(s * diag, s)
    a *= 0.5
    b = np.dot(g, s)
    if s0 is not None:
        u = J.dot(s0)
        b += np.dot(u, v)
        c = 0.5 * np.dot(u, u) + np.dot(g, s0)
        if diag is not None:
            b += np.dot(s0 * diag, s)
            c += 0.5 * np.dot(s0 * diag, s0)
        return a, b, c
    return a, b


def _minimize_quadratic_1d(a: float, b: float, lb: float, ub: float, c: float = 0) -> Any:
    t = [lb, ub]
    if a != 0:
        extremum = -0.5 * b / a
        if lb < extremum < ub:
            t.append(extremum)
    ta = np.asarray(t)
    y = ta * (a * ta + b) + c
    min_index = np.argmin(y)
    return ta[min_index], y[min_index]


def _evaluate_quadratic(
    J: np.ndarray, g: np.ndarray, s: np.ndarray, diag: np.ndarray | None = None
) -> Any:
    Js = J.dot(s)
    q = np.dot(Js, Js)
    if diag is not None:
        q += np.dot(s * diag, s)
    ell = np.dot(s, g)
    return 0.5 * q + ell


def _in_bounds(x: np.ndarray, lb: np.ndarray, ub: np.ndarray) -> bool:
    return bool(np.all((x >= lb) & (x <= ub)))


def _step_size_to_bound(
    x: np.ndarray, s: np.ndarray, lb: np.ndarray, ub: np.ndarray
) -> tuple[Any, np.ndarray]:
    non_zero = np.nonzero(s)
    s_non_zero = s[non_zero]
    steps = np.empty_like(x)
    steps.fill(np.inf)
    with np.errstate(over="ignore"):
        steps[non_zero] = np.maximum(
            (lb - x)[non_zero] / s_non_zero, (ub - x)[non_zero] / s_non_zero
        )
    min_step = np.min(steps)
    return min_step, np.equal(steps, min_step) * np.sign(s).astype(int)


def _intersect_trust_region(x: np.ndarray, s: np.ndarray, Delta: float) -> tuple[Any, Any]:
    a = np.dot(s, s)
    if a == 0:
        raise ValueError("`s` is zero.")
    b = np.dot(x, s)
    c = np.dot(x, x) - Delta**2
    if c > 0:
        raise ValueError("`x` is not within the trust region.")
    d = np.sqrt(b * b - a * c)
    q = -(b + copysign(d, b))
    t1 = q / a
    t2 = c / q
    return (t1, t2) if t1 < t2 else (t2, t1)


def _check_termination(
    dF: float, F: float, dx_norm: float, x_norm: float, ratio: float, ftol: float, xtol: float
) -> int | None:
    ftol_satisfied = dF < ftol * F and ratio > 0.25
    xtol_satisfied = dx_norm < xtol * (xtol + x_norm)
    if ftol_satisfied and xtol_satisfied:
        return 4
    if ftol_satisfied:
        return 2
    if xtol_satisfied:
        return 3
    return None


def _select_step(
    x: np.ndarray,
    J_h: np.ndarray,
    diag_h: np.ndarray,
    g_h: np.ndarray,
    p: np.ndarray,
    p_h: np.ndarray,
    d: np.ndarray,
    Delta: float,
    lb: np.ndarray,
    ub: np.ndarray,
    theta: float,
) -> tuple[np.ndarray, np.ndarray, Any]:
    if _in_bounds(x + p, lb, ub):
        p_value = _evaluate_quadratic(J_h, g_h, p_h, diag=diag_h)
        return p, p_h, -p_value
    p_stride, hits = _step_size_to_bound(x, p, lb, ub)
    r_h = np.copy(p_h)
    r_h[hits.astype(bool)] *= -1
    r = d * r_h
    p *= p_stride
    p_h *= p_stride
    x_on_bound = x + p
    _, to_tr = _intersect_trust_region(p_h, r_h, Delta)
    to_bound, _ = _step_size_to_bound(x_on_bound, r, lb, ub)
    r_stride = min(to_bound, to_tr)
    if r_stride > 0:
        r_stride_l = (1 - theta) * p_stride / r_stride
        r_stride_u = theta * to_bound if r_stride == to_bound else to_tr
    else:
        r_stride_l = 0
        r_stride_u = -1
    if r_stride_l <= r_stride_u:
        a, b, c = _build_quadratic_1d(J_h, g_h, r_h, s0=p_h, diag=diag_h)
        r_stride, r_value = _minimize_quadratic_1d(a, b, r_stride_l, r_stride_u, c=c)
        r_h *= r_stride
        r_h += p_h
        r = r_h * d
    else:
        r_value = np.inf
    p *= theta
    p_h *= theta
    p_value = _evaluate_quadratic(J_h, g_h, p_h, diag=diag_h)
    ag_h = -g_h
    ag = d * ag_h
    to_tr = Delta / norm(ag_h)
    to_bound, _ = _step_size_to_bound(x, ag, lb, ub)
    ag_stride = theta * to_bound if to_bound < to_tr else to_tr
    a, b = _build_quadratic_1d(J_h, g_h, ag_h, diag=diag_h)
    ag_stride, ag_value = _minimize_quadratic_1d(a, b, 0, ag_stride)
    ag_h *= ag_stride
    ag *= ag_stride
    if p_value < r_value and p_value < ag_value:
        return p, p_h, -p_value
    if r_value < p_value and r_value < ag_value:
        return r, r_h, -r_value
    return ag, ag_h, -ag_value


def solve(
    fun: Callable[[np.ndarray], Any],
    x0: np.ndarray,
    lb: np.ndarray,
    ub: np.ndarray,
    ftol: float,
    xtol: float,
    gtol: float,
    max_nfev: int | None,
    workers: Callable[[Callable[[Any], Any], Iterable[Any]], Iterable[Any]] | None = None,
    jac: Callable[[np.ndarray], Any] | None = None,
) -> Solution:
    """``scipy.optimize.least_squares(fun, x0, jac="2-point", bounds=(lb, ub),
    method="trf", x_scale=1.0, loss="linear", ftol=ftol, xtol=xtol, gtol=gtol,
    max_nfev=max_nfev, workers=workers)`` for bounds not all infinite and tolerances of at
    least the machine epsilon (:func:`contactlab.fitting.least_squares_fit` passes nothing
    else here); with a callable ``jac`` (a dense analytic Jacobian), ``jac=jac`` instead of
    the forward differences, as scipy calls it (after ``fun`` at the start, then at every
    accepted point)."""
    x0 = np.atleast_1d(np.asarray(x0)).astype(float)
    lb = np.asarray(lb, dtype=float)
    ub = np.asarray(ub, dtype=float)
    if np.all((lb == -np.inf) & (ub == np.inf)):
        raise ValueError("solve is the bounded variant: some bound must be finite")
    if np.any(lb >= ub):
        raise ValueError("Each lower bound must be strictly less than each upper bound.")
    if not _in_bounds(x0, lb, ub):
        raise ValueError("Initial guess is outside of provided bounds")
    x0 = make_strictly_feasible(x0, lb, ub)
    vf = _Cached(fun, x0)

    analytic = jac

    def jacobian(x: np.ndarray) -> np.ndarray:
        if analytic is not None:
            return np.atleast_2d(np.asarray(analytic(x), dtype=float))
        f0 = vf.at(x)  # (the residuals there: kept from the step that reached x)
        return np.atleast_2d(forward_jacobian(vf._call, vf.x.copy(), f0, lb, ub, workers))

    f0 = vf.at(x0)
    J0 = jacobian(x0)
    if not np.all(np.isfinite(f0)):
        raise ValueError("Residuals are not finite in the initial point.")
    x, f, status, nfev, njev = _trf_bounds(
        vf.at, jacobian, x0, f0, J0, lb, ub, ftol, xtol, gtol, max_nfev
    )
    return Solution(x, f, status, nfev, njev)


def _trf_bounds(
    fun: Callable[[np.ndarray], np.ndarray],
    jac: Callable[[np.ndarray], np.ndarray],
    x0: np.ndarray,
    f0: np.ndarray,
    J0: np.ndarray,
    lb: np.ndarray,
    ub: np.ndarray,
    ftol: float,
    xtol: float,
    gtol: float,
    max_nfev: int | None,
) -> tuple[np.ndarray, np.ndarray, int, int, int]:
    """SciPy's ``trf_bounds`` with ``x_scale = 1``, the linear loss, the exact trust-region
    solver, no callback."""
    x = x0.copy()
    f = f0
    f_true = f.copy()
    nfev = 1
    J = J0
    njev = 1
    m, n = J.shape
    cost = 0.5 * np.dot(f, f)
    g = J.T.dot(f)
    scale = np.resize(np.asarray(1.0), x0.shape)
    scale_inv = 1 / scale
    v, dv = _cl_scaling_vector(x, g, lb, ub)
    v[dv != 0] *= scale_inv[dv != 0]
    Delta = norm(x0 * scale_inv / v**0.5)
    if Delta == 0:
        Delta = 1.0
    g_norm = norm(g * v, ord=np.inf)
    f_augmented = np.zeros(m + n)
    J_augmented = np.empty((m + n, n))
    if max_nfev is None:
        max_nfev = x0.size * 100
    alpha = 0.0
    termination_status = None
    while True:
        v, dv = _cl_scaling_vector(x, g, lb, ub)
        g_norm = norm(g * v, ord=np.inf)
        if g_norm < gtol:
            termination_status = 1
        if termination_status is not None or nfev == max_nfev:
            break
        v[dv != 0] *= scale_inv[dv != 0]
        d = v**0.5 * scale
        diag_h = g * dv * scale
        g_h = d * g
        f_augmented[:m] = f
        J_augmented[:m] = J * d
        J_h = J_augmented[:m]
        J_augmented[m:] = np.diag(diag_h**0.5)
        if not np.all(np.isfinite(J_augmented)):  # (scipy.linalg.svd's check_finite)
            raise ValueError("array must not contain infs or NaNs")
        U, s, V = np.linalg.svd(J_augmented, full_matrices=False)
        # in LAPACK's (Fortran) layout, as scipy.linalg.svd returns them: the products
        # below then sum in the same order, to the last bit
        U, V = np.asfortranarray(U), np.asfortranarray(V)
        V = V.T
        uf = U.T.dot(f_augmented)
        theta = max(0.995, 1 - g_norm)
        actual_reduction = -1
        while actual_reduction <= 0 and nfev < max_nfev:
            p_h, alpha, _n_iter = _solve_lsq_trust_region(
                n, m, uf, s, V, Delta, initial_alpha=alpha
            )
            p = d * p_h
            step, step_h, predicted_reduction = _select_step(
                x, J_h, diag_h, g_h, p, p_h, d, Delta, lb, ub, theta
            )
            x_new = make_strictly_feasible(x + step, lb, ub, rstep=0)
            f_new = fun(x_new)
            nfev += 1
            step_h_norm = norm(step_h)
            if not np.all(np.isfinite(f_new)):
                Delta = 0.25 * step_h_norm
                continue
            cost_new = 0.5 * np.dot(f_new, f_new)
            actual_reduction = cost - cost_new
            Delta_new, ratio = _update_tr_radius(
                Delta,
                actual_reduction,
                predicted_reduction,
                step_h_norm,
                step_h_norm > 0.95 * Delta,
            )
            step_norm = norm(step)
            termination_status = _check_termination(
                actual_reduction, cost, step_norm, norm(x), ratio, ftol, xtol
            )
            if termination_status is not None:
                break
            alpha *= Delta / Delta_new
            Delta = Delta_new
        if actual_reduction > 0:
            x = x_new
            f = f_new
            f_true = f.copy()
            cost = cost_new
            J = jac(x)
            njev += 1
            g = J.T.dot(f)
    if termination_status is None:
        termination_status = 0
    return x, f_true, termination_status, nfev, njev
