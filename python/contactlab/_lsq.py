"""The solver steps behind :func:`contactlab.fitting.least_squares_fit`: SciPy's bounded
trust-region solver (or a given one) to the minimum's neighbourhood, then Gauss-Newton steps
that polish the end point until they stop paying (a trust check and a parabola line search
on zigzags), and the overflow-safe norms of the residuals."""

from __future__ import annotations

import math
import threading
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, Any

import numpy as np

from . import _trf
from .errors import ConvergenceError, InputError

if TYPE_CHECKING:
    from collections.abc import Mapping

    from .fitting import Parameter

#: SciPy's ``least_squares`` messages by status (for a solver given to
#: :func:`least_squares_fit`)
STATUS = {
    0: "The maximum number of function evaluations is exceeded.",
    1: "`gtol` termination condition is satisfied.",
    2: "`ftol` termination condition is satisfied.",
    3: "`xtol` termination condition is satisfied.",
    4: "Both `ftol` and `xtol` termination conditions are satisfied.",
}


def run_solver(
    solver: Callable[..., tuple[Any, int, int]],
    fun: Callable[[np.ndarray], np.ndarray],
    z0: np.ndarray,
    names: list[str],
    scale: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    fixed: dict[str, float],
    rscale: float,
    ftol: float,
    xtol: float,
    gtol: float,
    max_nfev: int | None,
) -> tuple[np.ndarray, np.ndarray, int, int]:
    """A given solver's end point, its scaled residuals, evaluations and status."""
    budget = int(max_nfev) if max_nfev is not None else 100 * len(names)
    z, nfev, status = solver(z0, names, scale, lo, hi, fixed, rscale, ftol, xtol, gtol, budget)
    z = np.clip(np.asarray(z, dtype=np.float64).reshape(-1), lo, hi)
    return z, fun(z), int(nfev), int(status)


def scipy_solve(
    fun: Callable[[np.ndarray], np.ndarray],
    z0: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    analytic: Callable[[np.ndarray], np.ndarray] | None,
    loss: str,
    ftol: float,
    xtol: float,
    gtol: float,
    max_nfev: int | None,
    workers: Callable[[Callable[[Any], Any], Iterable[Any]], Iterable[Any]] | None = None,
) -> tuple[np.ndarray, np.ndarray, int, Any]:
    bounded = not np.all((lo == -np.inf) & (hi == np.inf))
    eps = float(np.finfo(float).eps)
    try:
        if loss == "linear" and bounded and min(ftol, xtol, gtol) >= eps:
            # the same trial points and end point as scipy's (contactlab._trf), without the
            # half second (and ~45 MB) of importing scipy.optimize, also with an analytic
            # Jacobian (a window of a streamed analysis whose native solver stopped at a
            # kink imported it mid-run, 13 % of the GIL's time and the peak memory)
            sol = _trf.solve(fun, z0, lo, hi, ftol, xtol, gtol, max_nfev, workers, analytic)
            return sol.x, np.asarray(sol.fun, dtype=np.float64), int(sol.status), sol
        from scipy.optimize import least_squares

        sol = least_squares(
            fun,
            z0,
            jac=analytic if analytic is not None else "2-point",
            bounds=(lo, hi),
            method="trf",
            x_scale=1.0,
            loss=loss,
            ftol=ftol,
            xtol=xtol,
            gtol=gtol,
            max_nfev=max_nfev,
            workers=workers,
        )
    except InputError as exc:
        raise ConvergenceError(
            f"the model rejected the parameters the solver tried ({exc}); tighten the bounds"
        ) from exc
    return sol.x, np.asarray(sol.fun, dtype=np.float64), int(sol.status), sol


def rms(r: np.ndarray) -> float:
    """Root mean square without overflow or underflow of the squares."""
    m = float(np.max(np.abs(r))) if r.size else 0.0
    if not (m > 0 and math.isfinite(m)):
        return m
    return m * float(np.sqrt(np.mean((r / m) ** 2)))


def sumsq(r: np.ndarray) -> float:
    """``r @ r`` (inf when it exceeds the float range, rather than a warning)."""
    with np.errstate(over="ignore"):
        return r.size * rms(r) ** 2 if r.size else 0.0


#: largest remaining Gauss-Newton step, in standard errors, of a fit reported as converged
TRUST_STEP = 0.25
#: the polish's Gauss-Newton step is shortened or lengthened (:func:`polish`) when the
#: parabola of the cost along it puts the minimum this far (as a fraction of the step) from
#: its end
LINE_SEARCH_OFF = 0.2


def step_in_stderr(step: np.ndarray, J: np.ndarray, var: float) -> float:
    """The largest ``|step|`` in units of its parameter's standard error (Jacobian ``J``,
    residual variance ``var``); inf when the errors cannot be computed."""
    if not np.all(np.isfinite(J)):
        return np.inf
    try:
        cov = np.linalg.pinv(J.T @ J, rcond=1e-13) * var
    except np.linalg.LinAlgError:
        return np.inf
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    if not np.all(sd > 0):
        return np.inf
    return float(np.max(np.abs(step) / sd))


def polish(
    fun: Callable[[np.ndarray], np.ndarray],
    jacobian: Callable[[np.ndarray], np.ndarray],
    z: np.ndarray,
    r: np.ndarray,
    J: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    names: list[str],
    stop: float = 0.0,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool, int, str]:
    """Gauss-Newton steps from the solver's end point until they stop paying, then the trust
    check: the step still possible must be a negligible fraction of each parameter's standard
    error, or the fit is reported ``success=False`` naming the parameter.

    The trust-region solver stops on *relative* changes, which can leave a slow, ill-
    conditioned fit (NIST's ENSO, Lanczos, MGH17) several digits short of its minimum while
    reporting success. Parameters at a bound are held there.
    """
    cost = float(r @ r)
    nfree = r.size - len(names)
    prev: np.ndarray | None = None  # the last step taken
    for _ in range(30):
        step = gn_step(J, r, z, lo, hi)
        if step is None or not np.any(step):
            break
        if stop > 0 and nfree > 0 and step_in_stderr(step, J, cost / nfree) < stop:
            break
        z_new = np.clip(z + step, lo, hi)
        try:
            r_new = fun(z_new)
        except InputError:
            break  # the model refuses the step's end (a parameter at its closed bound)
        if not np.all(np.isfinite(r_new)):
            break
        cost_new = float(r_new @ r_new)
        # a step that turns back on the previous one: its length from the cost along it, a
        # parabola through the cost here, its slope (2 rᵀJ·step) and the cost at the step's
        # end. Gauss-Newton's curvature omits the residual's own (Σ r ∇²r), which a model
        # missing structure (a residual of many σ) and an oscillating term (a load
        # fluctuation's frequency, whose phase drifts over the record) make large: the full
        # steps then overshoot and zigzag about the minimum, shrinking by a few per cent a
        # step (30 steps, each a central-difference Jacobian, on a 1e6-sample record). One
        # evaluation more at the parabola's minimum when it lies off the full step, kept
        # when it is lower.
        slope = 2.0 * float(r @ (J @ (z_new - z)))
        curv = cost_new - cost - slope
        back = prev is not None and float(prev @ (z_new - z)) < 0
        prev = z_new - z
        if back and slope < 0 and curv > 0:
            alpha = -slope / (2.0 * curv)
            if abs(alpha - 1.0) > LINE_SEARCH_OFF:
                z_alt = np.clip(z + alpha * (z_new - z), lo, hi)
                try:
                    r_alt = fun(z_alt)
                except InputError:
                    r_alt = None
                if r_alt is not None and np.all(np.isfinite(r_alt)):
                    cost_alt = float(r_alt @ r_alt)
                    if cost_alt < cost_new:
                        z_new, r_new, cost_new = z_alt, r_alt, cost_alt
        if cost_new > cost:
            break
        moved = np.max(np.abs(z_new - z) / np.maximum(np.abs(z), 1e-300))
        try:
            J_new = jacobian(z_new)
        except InputError:
            break
        z, r, cost, J = z_new, r_new, cost_new, J_new
        if moved < 1e-14:
            break
    # trust: one more step from here, measured in standard errors
    step = gn_step(J, r, z, lo, hi)
    if step is not None and nfree > 0 and np.all(np.isfinite(J)):
        try:
            cov = np.linalg.pinv(J.T @ J, rcond=1e-13) * (cost / nfree)
        except np.linalg.LinAlgError:
            cov = None
        if cov is not None:
            sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
            with np.errstate(divide="ignore", invalid="ignore"):
                ratio = np.where(sd > 0, np.abs(step) / sd, 0.0)
            # a step below 1e-10 of the value is rounding noise whatever the error says
            # (an exact fit's standard errors are themselves rounding noise)
            ratio[np.abs(step) <= 1e-10 * np.abs(z)] = 0.0
            worst = int(np.argmax(ratio))
            # A model with kinks (reversal points that move with the parameters) leaves
            # Gauss-Newton steps of a few hundredths of a standard error that no solver
            # removes; a quarter of a standard error changes no reported digit that matters.
            if ratio[worst] > TRUST_STEP:
                return (
                    z,
                    r,
                    J,
                    False,
                    -2,
                    f"not converged: a further Gauss-Newton step would move {names[worst]} "
                    f"by {ratio[worst]:.2g} standard errors (the minimum is not reached; "
                    "try other starting values or bounds)",
                )
    return z, r, J, True, 1, f"converged (Gauss-Newton step below {TRUST_STEP:g} standard errors)"


def gn_step(
    J: np.ndarray, r: np.ndarray, z: np.ndarray, lo: np.ndarray, hi: np.ndarray
) -> np.ndarray | None:
    """The Gauss-Newton step ``-J⁺ r``, parameters at a bound held fixed (None if J is not
    finite)."""
    if not (np.all(np.isfinite(J)) and np.all(np.isfinite(r))):
        return None
    tol = 1e-12 * np.maximum(np.abs(z), 1.0)
    free = ~(((z - lo) <= tol) | ((hi - z) <= tol))
    step = np.zeros_like(z)
    if not free.any():
        return step
    sol, *_ = np.linalg.lstsq(J[:, free], -r, rcond=1e-13)
    step[free] = sol
    return step


def scale_of(p: Parameter) -> float:
    if p.scale is not None:
        if not (math.isfinite(p.scale) and p.scale > 0):
            raise InputError(f"parameter {p.name!r}: scale must be finite and > 0, got {p.scale}")
        return float(p.scale)
    return abs(p.value) if p.value != 0 else 1.0


def check_params(ps: dict[str, Parameter]) -> None:
    """Refuse non-finite starts, NaN bounds and empty ranges; note each start value."""
    for p in ps.values():
        if not math.isfinite(p.value):
            raise InputError(
                f"parameter {p.name!r} has a non-finite initial value {p.value}: the data or "
                "the start estimate derived from them are not usable (a constant channel, an "
                "overflow?)"
            )
        for side, bound in (("lower", p.min), ("upper", p.max)):
            if math.isnan(bound):
                raise InputError(
                    f"parameter {p.name!r}: the {side} bound is NaN (bounds derived from "
                    "data that have none, e.g. a constant or empty channel?); give a number, "
                    "or ±inf for no bound"
                )
        if p.vary and p.min >= p.max:
            raise InputError(
                f"parameter {p.name!r}: empty range [{p.min}, {p.max}] (min must be < max)"
            )
        if p.vary and not (p.min <= p.value <= p.max):
            raise InputError(
                f"parameter {p.name!r}: initial value {p.value} outside [{p.min}, {p.max}]"
            )
        p.init_value = p.value if p.vary else None


def end_checks(
    J: np.ndarray, rs: np.ndarray, z: np.ndarray, rscale: float, state: tuple[bool, int, str]
) -> tuple[np.ndarray, float, list[str], tuple[bool, int, str]]:
    """Residuals and χ² in the data's units at the end point, notes, and the (success,
    status, message) state: a Jacobian that overflows fails the fit."""
    with np.errstate(over="ignore"):
        r = rs * rscale
    with np.errstate(over="ignore"):
        chisqr = float(np.float64(sumsq(rs)) * np.float64(rscale) ** 2)
    notes = []
    if not np.all(np.isfinite(J)):
        msg = "the model is not finite next to the end point (its Jacobian overflows)"
        state = (False, -3, msg)
    elif rms(rs) < 1e5 * np.finfo(float).eps * rms(J @ z):
        # residuals at the rounding level of the model's values: the parameters are exact
        # to rounding, but χ² and so the standard errors are rounding noise (NIST Lanczos1)
        notes.append(
            "the residuals are at the floating-point rounding level of the model (an exact "
            "fit): standard errors are not determined"
        )
    return r, chisqr, notes, state


class Scaled:
    """The problem in scaled variables (value / scale, scale = |initial value| unless given)
    so that parameters that differ by orders of magnitude (h0 ~ 10 N, ac ~ 1e5 1/m) are
    equally well conditioned; the residuals are divided by ``rscale`` (set by the caller)."""

    def __init__(
        self,
        ps: dict[str, Parameter],
        residual_fn: Callable[[dict[str, float]], Any],
        jac: Callable[[dict[str, float]], Mapping[str, Any]] | None,
        jac_rel_step: float,
        workers: Callable[[Callable[[Any], Any], Iterable[Any]], Iterable[Any]] | None,
    ) -> None:
        self.ps, self.residual_fn, self.jac = ps, residual_fn, jac
        self.jac_rel_step, self.workers = jac_rel_step, workers
        self.names = [k for k, p in ps.items() if p.vary]
        self.scale = np.array([scale_of(ps[n]) for n in self.names])
        self.lo = np.array([ps[n].min for n in self.names]) / self.scale
        self.hi = np.array([ps[n].max for n in self.names]) / self.scale
        self.fixed = {k: p.value for k, p in ps.items() if not p.vary}
        self.nfev = 0
        self.counting = threading.Lock()  # ``workers`` may call raw_fun on several threads
        self.rscale = 1.0
        self.ndata = 0

    def start(self) -> tuple[np.ndarray, np.ndarray]:
        """``(z0, r0)`` at the start values; sets ``ndata`` and the residual scale."""
        z0 = np.array([self.ps[n].value for n in self.names]) / self.scale
        r0 = self.raw_fun(z0)
        if not np.all(np.isfinite(r0)):
            i = int(np.argmax(~np.isfinite(r0)))
            raise InputError(f"residual[{i}] is not finite at the initial parameter values")
        self.ndata = int(r0.size)
        # Residuals are scaled too (by their size at the start), so that the solver's
        # tolerances and χ² neither overflow nor underflow and a fit gives the same relative
        # result in any units (nN/nm to kN/mm): least_squares' gtol is absolute in the
        # cost's units.
        rscale = rms(r0)
        self.rscale = rscale if rscale > 0 and math.isfinite(rscale) else 1.0
        return z0, r0

    def solve(
        self,
        solver: Callable[..., tuple[Any, int, int]] | None,
        z0: np.ndarray,
        loss: str,
        ftol: float,
        xtol: float,
        gtol: float,
        max_nfev: int | None,
    ) -> tuple[np.ndarray, np.ndarray, int, Any]:
        """``(z, scaled residuals, status, scipy's result or None)`` of the given solver, else
        of SciPy's bounded trust-region solver, from ``z0``."""
        if solver is not None:
            z, rs, nfev_s, status = run_solver(
                solver,
                self.fun,
                z0,
                self.names,
                self.scale,
                self.lo,
                self.hi,
                self.fixed,
                self.rscale,
                ftol,
                xtol,
                gtol,
                max_nfev,
            )
            self.nfev += nfev_s
            return z, rs, status, None
        analytic = self.analytic if self.jac is not None else None
        return scipy_solve(
            self.fun, z0, self.lo, self.hi, analytic, loss, ftol, xtol, gtol, max_nfev, self.workers
        )

    def values_of(self, z: np.ndarray) -> dict[str, float]:
        v = dict(self.fixed)
        v.update({n: float(zi * s) for n, zi, s in zip(self.names, z, self.scale, strict=True)})
        return {k: v[k] for k in self.ps}

    def raw_fun(self, z: np.ndarray) -> np.ndarray:
        with self.counting:
            self.nfev += 1
        with np.errstate(all="ignore"):  # an overflowing trial step is refused below
            return np.asarray(self.residual_fn(self.values_of(z)), dtype=np.float64).reshape(-1)

    def fun(self, z: np.ndarray) -> np.ndarray:
        return self.raw_fun(z) / self.rscale

    def analytic(self, z: np.ndarray) -> np.ndarray:
        assert self.jac is not None
        with np.errstate(all="ignore"):  # a non-finite column is reported below
            cols = self.jac(self.values_of(z))
            return (
                np.column_stack(
                    [
                        np.asarray(cols[n], dtype=np.float64).reshape(-1) * s
                        for n, s in zip(self.names, self.scale, strict=True)
                    ]
                )
                / self.rscale
            )

    def jacobian(self, z: np.ndarray) -> np.ndarray:
        if self.jac is not None:
            return self.analytic(z)
        # central differences in the scaled variables (bounds respected by one-sided steps)
        names, lo, hi = self.names, self.lo, self.hi
        J = np.empty((self.ndata, len(names)))
        steps = []
        for j in range(len(names)):
            h = self.jac_rel_step * max(abs(z[j]), 1.0)
            up, dn = z.copy(), z.copy()
            up[j] = min(z[j] + h, hi[j])
            dn[j] = max(z[j] - h, lo[j])
            steps += [up, dn]
        f = list((self.workers or map)(self._fun_or_refused, steps))
        here: np.ndarray | None = None
        for j in range(len(names)):
            up, dn = steps[2 * j], steps[2 * j + 1]
            fu, fd = f[2 * j], f[2 * j + 1]
            refused = [v for v in (fu, fd) if isinstance(v, InputError)]
            if refused:
                # the model refuses a step's end (a parameter at its closed bound, such as a
                # Masing ac of 0 once the fit ran towards a straight line): a one-sided
                # difference from z on the side it accepts
                if len(refused) == 2:
                    raise refused[0]
                if here is None:
                    here = self.fun(z)
                if isinstance(fu, InputError):
                    fu, up = here, z
                else:
                    fd, dn = here, z
                if up[j] == dn[j]:
                    raise refused[0]
            assert not isinstance(fu, InputError) and not isinstance(fd, InputError)
            J[:, j] = (fu - fd) / (up[j] - dn[j])
        return J

    def _fun_or_refused(self, z: np.ndarray) -> np.ndarray | InputError:
        """:meth:`fun`, or the model's refusal of ``z`` (returned, not raised)."""
        try:
            return self.fun(z)
        except InputError as exc:
            return exc
