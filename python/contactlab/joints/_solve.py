"""A Levenberg-Marquardt solver on the normal equations for the joint-law fits.

A joint fit has ~1e5 residuals and a handful of parameters: SciPy's trust-region solver
takes a singular-value decomposition of the whole ``m × n`` Jacobian at every iteration
(~50 ms of CPU at 1e5 × 7, more than the law's own evaluation with its sensitivities),
where Levenberg-Marquardt needs only ``JᵀJ`` (n × n) and ``Jᵀr``. The solver here is handed
to :func:`contactlab.fitting.least_squares_fit` as its ``solver``: the Gauss-Newton polish,
the trust check and the covariance that follow it are the package's usual ones (so an end
point this solver leaves short of the minimum is finished or reported there), and a failed
end point makes ``least_squares_fit`` decide with SciPy's solver from the same start.

Bounds are kept by projecting each trial point onto the box; Marquardt's scaling (the
diagonal of ``JᵀJ``) makes the damping invariant to the parameters' units.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from ..errors import InputError


def lm_solver(
    residual: Callable[[Mapping[str, float]], np.ndarray],
    jacobian: Callable[[Mapping[str, float]], Mapping[str, np.ndarray]],
) -> Callable[..., tuple[np.ndarray, int, int]]:
    """A ``solver`` for :func:`contactlab.fitting.least_squares_fit` from the fit's residual
    and analytic Jacobian (both taking the parameter values by name)."""

    def solver(z0: np.ndarray, names: list[str], scale: np.ndarray, lo: np.ndarray,
               hi: np.ndarray, fixed: dict[str, float], rscale: float, ftol: float,
               xtol: float, gtol: float, budget: int) -> tuple[np.ndarray, int, int]:  # fmt: skip
        def values(z: np.ndarray) -> dict[str, float]:
            v = dict(fixed)
            v.update({n: float(zi * s) for n, zi, s in zip(names, z, scale, strict=True)})
            return v

        def fun(z: np.ndarray) -> np.ndarray | None:
            try:
                with np.errstate(all="ignore"):
                    r = np.asarray(residual(values(z)), dtype=float) / rscale
            except InputError:
                return None
            return r if np.all(np.isfinite(r)) else None

        def jac(z: np.ndarray) -> np.ndarray:
            cols = jacobian(values(z))
            J = [np.asarray(cols[n], dtype=float) * s for n, s in zip(names, scale, strict=True)]
            return np.column_stack(J) / rscale

        # positive parameters with no upper bound (stiffnesses, forces, velocities) are
        # searched in log z: a step towards 0 is then a factor, never a jump onto the bound
        logs = (lo > 0) & np.isinf(hi)
        z0 = np.clip(z0, lo, hi)

        def to_z(u: np.ndarray) -> np.ndarray:
            with np.errstate(over="ignore"):
                return np.where(logs, np.exp(np.where(logs, u, 0.0)), u)

        def fun_u(u: np.ndarray) -> np.ndarray | None:
            return fun(to_z(u))

        def jac_u(u: np.ndarray) -> np.ndarray:
            z = to_z(u)
            return jac(z) * np.where(logs, z, 1.0)

        with np.errstate(divide="ignore"):
            u0 = np.where(logs, np.log(np.where(logs, z0, 1.0)), z0)
            ulo = np.where(logs, np.log(np.where(logs, lo, 1.0)), lo)
        uhi = np.where(logs, np.inf, hi)
        u, nfev, status = _iterate(fun_u, jac_u, u0, ulo, uhi, ftol, xtol, gtol, budget)
        return to_z(u), nfev, status

    return solver


def _gn_step_negligible(A: np.ndarray, g: np.ndarray, cost: float, m: int) -> bool:
    """True when the undamped Gauss-Newton step is below 0.05 standard errors in every
    parameter: the minimum is reached for every purpose (the polish that follows takes the
    last digits). A slow valley (a weakly determined damping) otherwise costs hundreds of
    evaluations for relative cost changes just above ``ftol``."""
    nfree = m - A.shape[0]
    if nfree <= 0:
        return False
    cov = np.linalg.pinv(A) * (cost / nfree)
    se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    step = -np.linalg.pinv(A) @ g
    ok = se > 0
    return bool(np.all(np.abs(step[ok]) <= 0.05 * se[ok]))


def _iterate(fun: Callable[[np.ndarray], np.ndarray | None], jac: Callable[[np.ndarray], Any],
             z: np.ndarray, lo: np.ndarray, hi: np.ndarray, ftol: float, xtol: float,
             gtol: float, budget: int) -> tuple[np.ndarray, int, int]:  # fmt: skip
    """Projected Levenberg-Marquardt; ``(z, evaluations, status)`` with the status codes of
    ``scipy.optimize.least_squares`` (0: budget spent, 1: gtol, 2: ftol, 3: xtol)."""
    r = fun(z)
    if r is None:
        return z, 1, -1
    nfev, lam = 1, 1e-3
    cost = float(r @ r)
    J = jac(z)
    while nfev < budget:
        A, g = J.T @ J, J.T @ r
        # active set: a parameter at a bound whose descent direction leaves the box is held
        # there for this step (its row and column dropped)
        free = ~(((z <= lo) & (g > 0)) | ((z >= hi) & (g < 0)))
        if not np.any(free):
            return z, nfev, 1
        Af, gf = A[np.ix_(free, free)], g[free]
        d = np.diag(Af).copy()
        d[d <= 0] = 1.0
        if np.max(np.abs(gf) / np.sqrt(d)) <= gtol * max(np.sqrt(cost), 1e-300):
            return z, nfev, 1
        if _gn_step_negligible(Af, gf, cost, r.size):
            return z, nfev, 2
        step = np.zeros_like(z)
        try:
            step[free] = np.linalg.solve(Af + lam * np.diag(d), -gf)
        except np.linalg.LinAlgError:
            lam *= 10.0
            continue
        # a step of at most a factor e² (log parameters) or twice the start value (scaled
        # ones): LM's damping alone lets a flat direction run off to overflow
        big = float(np.max(np.abs(step)))
        if big > 2.0:
            step *= 2.0 / big
        z_new = np.clip(z + step, lo, hi)
        moved = z_new - z
        if np.all(np.abs(moved) <= xtol * (xtol + np.abs(z))):
            return z, nfev, 3
        r_new = fun(z_new)
        nfev += 1
        cost_new = float(r_new @ r_new) if r_new is not None else np.inf
        if cost_new < cost:
            small = cost - cost_new <= ftol * cost
            z, r, cost = z_new, r_new, cost_new
            lam = max(lam / 5.0, 1e-12)
            if small:
                return z, nfev, 2
            J = jac(z)
        else:
            lam *= 4.0
            if lam > 1e16:
                return z, nfev, 3
    return z, nfev, 0
