"""Least-squares fits with lmfit-style results: parameters with standard errors, correlations,
χ², AIC/BIC and an honest account of what the data identify.

Built on :func:`scipy.optimize.least_squares` (its bounded trust-region path, the one every
fit with bounds and a finite-difference Jacobian takes, as :mod:`contactlab._trf`: the same
numbers without importing :mod:`scipy.optimize`). The covariance is ``(JᵀJ)⁻¹`` from a central
difference Jacobian at the optimum, scaled by the reduced χ² (``scale_covar=True``, the lmfit
default, right when the residuals are unweighted or their scale is unknown). ``(JᵀJ)⁻¹`` is
taken by SVD: a direction of parameter space the data do not constrain (singular value below
``rcond`` times the largest) is reported, and the parameters along it are flagged not
identifiable, instead of being given a meaningless tiny or huge error.

AIC and BIC follow lmfit: ``n ln(χ²/n) + 2k`` and ``n ln(χ²/n) + k ln n``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ._arrays import next_fast_len
from ._lsq import STATUS, Scaled, check_params, end_checks, polish, sumsq
from .errors import InputError

#: a relative standard error at or above this (1000 %) says the data do not determine the
#: value: the text report writes "not identifiable" instead of a figure such as "± nan" or
#: "-0.0158 +/- 47.4 s" (issue 31)
UNDETERMINED_REL_STDERR = 10.0


@dataclass
class Parameter:
    """A fit parameter.

    Parameters
    ----------
    name : str
    value : float
        Initial value before the fit, best-fit value after it.
    stderr : float or None
        Standard error (None when fixed or when the data do not determine it).
    vary : bool
        Fitted (True) or held fixed (False).
    min, max : float
        Bounds for the fit.
    identifiable : bool or None
        Whether the data determine the parameter (None before a fit or when fixed).
    note : str
        A human-readable remark (why it is not identifiable, what is identified instead).
    unit : str
        SI unit, for reports.
    init_value : float, optional
        Set by the fit: the starting value.
    scale : float, optional
        Typical size of the parameter's changes (default ``|value|``, or 1 when the value is
        0). Give it for a parameter that starts at 0 but lives on a tiny or huge scale.
    """

    name: str
    value: float
    stderr: float | None = None
    vary: bool = True
    min: float = -math.inf
    max: float = math.inf
    identifiable: bool | None = None
    note: str = ""
    unit: str = ""
    init_value: float | None = None
    scale: float | None = None

    @property
    def fixed(self) -> bool:
        return not self.vary

    @property
    def rel_stderr(self) -> float | None:
        """``stderr / |value|`` (None when unknown or the value is 0)."""
        if self.stderr is None or self.value == 0:
            return None
        return abs(self.stderr / self.value)

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "value": json_number(self.value),
            "stderr": json_number(self.stderr),
            "vary": self.vary,
            "min": json_number(self.min),
            "max": json_number(self.max),
            "identifiable": self.identifiable,
            "note": self.note,
            "unit": self.unit,
            "init_value": json_number(self.init_value),
        }


def json_number(v: Any) -> Any:
    """JSON-safe number: NaN and ±inf become None."""
    if v is None:
        return None
    v = float(v)
    return v if math.isfinite(v) else None


@dataclass
class FitResult:
    """Outcome of a least-squares fit, in the manner of lmfit's ``MinimizerResult``.

    ``covar`` and ``correl`` are square arrays over ``var_names`` (the varied parameters, in
    order); ``correl_dict()`` gives them by name. ``residual`` is the residual vector at the
    optimum as returned by the residual function.
    """

    params: dict[str, Parameter]
    var_names: list[str]
    covar: np.ndarray | None
    correl: np.ndarray | None
    chisqr: float
    redchi: float
    aic: float
    bic: float
    ndata: int
    nvarys: int
    success: bool
    status: int
    message: str
    nfev: int
    residual: np.ndarray
    jac: np.ndarray | None = None
    singular_values: np.ndarray | None = None
    condition: float = math.nan
    scale_covar: bool = True
    notes: list[str] = field(default_factory=list)

    @property
    def nfree(self) -> int:
        return self.ndata - self.nvarys

    @property
    def values(self) -> dict[str, float]:
        return {k: p.value for k, p in self.params.items()}

    def correl_dict(self) -> dict[str, dict[str, float]]:
        """Correlations ``{a: {b: r}}`` between varied parameters (a ≠ b)."""
        if self.correl is None:
            return {}
        out: dict[str, dict[str, float]] = {}
        for i, a in enumerate(self.var_names):
            out[a] = {b: float(self.correl[i, j]) for j, b in enumerate(self.var_names) if j != i}
        return out

    def propagate(
        self, fn: Callable[[dict[str, float]], Any], *, rel_step: float = 1e-6
    ) -> tuple[Any, Any]:
        """Value and standard error of a derived quantity ``fn(values)`` (first order).

        ``fn`` takes the dict of all parameter values and returns a float or an array; its
        gradient with respect to the varied parameters is taken by central differences and
        ``stderr = sqrt(g C gᵀ)``. Returns ``(value, stderr)``; the error is NaN when there is
        no covariance.
        """
        base = self.values
        val = np.asarray(fn(base), dtype=float)
        if self.covar is None or not self.var_names:
            return _scalar(val), _scalar(np.full_like(val, np.nan))
        grads = []
        for name in self.var_names:
            v = base[name]
            h = rel_step * (abs(v) if v != 0 else 1.0)
            up = dict(base, **{name: v + h})
            dn = dict(base, **{name: v - h})
            grads.append((np.asarray(fn(up), float) - np.asarray(fn(dn), float)) / (2 * h))
        g = np.stack([np.reshape(x, -1) for x in grads], axis=1)  # (m, k)
        var = np.einsum("mi,ij,mj->m", g, self.covar, g)
        err = np.sqrt(np.clip(var, 0.0, None)).reshape(val.shape)
        return _scalar(val), _scalar(err)

    def report(self, *, min_correl: float = 0.1) -> str:
        """A text report like lmfit's ``fit_report``."""
        lines = [
            "[[Fit Statistics]]",
            f"    success            = {self.success}",
            f"    message            = {self.message}",
            f"    # function evals   = {self.nfev}",
            f"    # data points      = {self.ndata}",
            f"    # variables        = {self.nvarys}",
            f"    chi-square         = {self.chisqr:.6g}",
            f"    reduced chi-square = {self.redchi:.6g}",
            f"    Akaike info crit   = {self.aic:.6g}",
            f"    Bayesian info crit = {self.bic:.6g}",
            f"    Jacobian condition = {self.condition:.3g}",
            "[[Variables]]",
        ]
        for p in self.params.values():
            unit = f" {p.unit}" if p.unit else ""
            if not p.vary:
                lines.append(f"    {p.name}: {p.value:.8g}{unit} (fixed)")
                continue
            rel = p.rel_stderr if p.stderr is not None else None
            if p.stderr is None or not math.isfinite(p.stderr):
                err = "(not identifiable: no finite standard error)"
            elif rel is not None and not rel < UNDETERMINED_REL_STDERR:
                err = (
                    f"(not identifiable: standard error {p.stderr:.2g}, over "
                    f"{100 * UNDETERMINED_REL_STDERR:.0f} % of the value)"
                )
            else:
                err = f"+/- {p.stderr:.4g}" + (f" ({100 * rel:.2f}%)" if rel is not None else "")
            flag = "" if p.identifiable is not False else "  [NOT IDENTIFIABLE]"
            init = f" (init = {p.init_value:.6g})" if p.init_value is not None else ""
            lines.append(f"    {p.name}: {p.value:.8g} {err}{unit}{init}{flag}")
            if p.note:
                lines.append(f"        note: {p.note}")
        if self.correl is not None and len(self.var_names) > 1:
            pairs = []
            for i, a in enumerate(self.var_names):
                for j in range(i + 1, len(self.var_names)):
                    r = float(self.correl[i, j])
                    if abs(r) >= min_correl:
                        pairs.append((abs(r), f"    C({a}, {self.var_names[j]}) = {r:+.4f}"))
            if pairs:
                lines.append(f"[[Correlations]] (unreported correlations are < {min_correl})")
                lines += [s for _, s in sorted(pairs, reverse=True)]
        if self.notes:
            lines.append("[[Notes]]")
            lines += [f"    {n}" for n in self.notes]
        return "\n".join(lines)

    def to_dict(self) -> dict[str, Any]:
        """JSON-safe dict (NaN/inf become None)."""
        return {
            "params": {k: p.to_dict() for k, p in self.params.items()},
            "var_names": list(self.var_names),
            "covar": None if self.covar is None else _nested(self.covar),
            "correl": self.correl_dict() or None,
            "chisqr": json_number(self.chisqr),
            "redchi": json_number(self.redchi),
            "aic": json_number(self.aic),
            "bic": json_number(self.bic),
            "ndata": self.ndata,
            "nvarys": self.nvarys,
            "success": bool(self.success),
            "status": int(self.status),
            "message": self.message,
            "nfev": int(self.nfev),
            "condition": json_number(self.condition),
            "scale_covar": self.scale_covar,
            "notes": list(self.notes),
        }


def _nested(a: np.ndarray) -> list[list[Any]]:
    return [[json_number(v) for v in row] for row in a]


def _scalar(a: np.ndarray) -> Any:
    return float(a) if a.ndim == 0 else a


def _as_params(params: Any) -> dict[str, Parameter]:
    if isinstance(params, Mapping):
        out = {}
        for k, v in params.items():
            if isinstance(v, Parameter):
                if v.name != k:
                    raise InputError(f"parameter stored under {k!r} is named {v.name!r}")
                out[k] = _copied(v)
            else:
                out[k] = Parameter(k, float(v))
        return out
    if isinstance(params, Iterable):
        out = {}
        for p in params:
            if not isinstance(p, Parameter):
                raise InputError(f"expected Parameter objects, got {type(p).__name__}")
            out[p.name] = _copied(p)
        return out
    raise InputError(f"params must be a dict or a list of Parameter, got {type(params).__name__}")


def least_squares_fit(
    residual_fn: Callable[[dict[str, float]], Any],
    params: Mapping[str, Parameter | float] | Iterable[Parameter],
    *,
    scale_covar: bool = True,
    rcond: float = 1e-8,
    max_rel_stderr: float | None = None,
    loss: str = "linear",
    max_nfev: int | None = None,
    ftol: float = 1e-10,
    xtol: float = 1e-10,
    gtol: float = 1e-10,
    jac_rel_step: float = 1e-6,
    jac: Callable[[dict[str, float]], Mapping[str, Any]] | None = None,
    solver: Callable[..., tuple[Any, int, int]] | None = None,
    workers: Callable[[Callable[[Any], Any], Iterable[Any]], Iterable[Any]] | None = None,
    polish_stop: float = 0.0,
) -> FitResult:
    """Minimise ``sum(residual_fn(values)**2)`` over the varied parameters.

    Parameters
    ----------
    residual_fn : callable
        ``residual_fn({name: value, ...}) -> 1-D array`` of (weighted) residuals. It receives
        every parameter, fixed ones included.
    params : dict or list of Parameter (or dict name -> initial value)
        Initial values, bounds and which to vary. Not modified.
    scale_covar : bool, default True
        Scale the covariance by the reduced χ² (residuals of unknown scale). Use False when
        the residuals are already divided by their true standard deviations.
    rcond : float
        Relative singular-value cut-off of the Jacobian: directions below it are not
        identifiable.
    max_rel_stderr : float, optional
        Flag a parameter not identifiable when its relative standard error exceeds this.
    loss, max_nfev, ftol, xtol, gtol
        Passed to :func:`scipy.optimize.least_squares`.
    jac_rel_step : float
        Relative step of the central-difference Jacobian used for the covariance.
    jac : callable, optional
        Analytic derivatives ``jac(values) -> {name: ∂residual/∂name}`` (arrays of the
        residual's length) for at least the varied parameters: the solver, the polishing
        steps and the covariance use them instead of finite differences.
    solver : callable, optional
        Replaces SciPy's trust-region solver (e.g. a compiled Levenberg–Marquardt of a
        known model: ``steps.Residuals.solver``). Called as ``solver(z0, names, scale, lo,
        hi, fixed, rscale, ftol, xtol, gtol, max_nfev)`` in the scaled variables
        ``z = value / scale`` (bounds ``lo, hi`` scaled, residuals divided by ``rscale``);
        returns ``(z, nfev, status)`` with the status codes of ``least_squares`` (0: the
        evaluation budget ran out, reported as not converged). The polishing steps, the
        trust check and the covariance are the same as after SciPy's solver.
    workers : map-like callable, optional
        Evaluates the finite-difference Jacobians' columns (SciPy's solver's and the
        covariance's) as ``workers(fn, items)``, e.g. a thread pool's ``map`` when
        ``residual_fn`` releases the GIL: the same numbers as evaluated one by one.
    polish_stop : float
        The Gauss-Newton steps that follow the solver stop once the next step is below this
        many standard errors in every parameter (each step costs a central-difference
        Jacobian); 0, the default, steps on while the cost falls (to rounding).

    Returns
    -------
    FitResult
        ``success=False`` with the solver's message when it did not converge; malformed input
        (non-finite residuals at the start, bad bounds) raises :class:`InputError`.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.linspace(0, 1, 50)
    >>> y = 2.0 * x + 1.0 + 0.01 * np.sin(37 * x)
    >>> res = least_squares_fit(lambda p: p["a"] * x + p["b"] - y, {"a": 1.0, "b": 0.0})
    >>> round(res.params["a"].value, 2), res.success
    (2.0, True)
    """
    ps = _as_params(params)
    start = [_copied(p) for p in ps.values()] if solver is not None else []
    check_params(ps)
    pb = Scaled(ps, residual_fn, jac, jac_rel_step, workers)
    names, lo, hi = pb.names, pb.lo, pb.hi
    z0, r0 = pb.start()
    ndata, rscale, fun = pb.ndata, pb.rscale, pb.fun
    if not names:
        chisqr = sumsq(r0)
        return _finish(ps, [], None, r0, chisqr, ndata, True, 0, "no varied parameters", pb.nfev)
    if ndata < len(names):
        raise InputError(f"{ndata} residuals cannot determine {len(names)} parameters")
    z, rs, status, sol = pb.solve(solver, z0, loss, ftol, xtol, gtol, max_nfev)
    success = status > 0 if sol is None else bool(sol.success)
    message = STATUS.get(status, "") if sol is None else str(sol.message)
    J = pb.jacobian(z)
    if success and loss == "linear":
        z, rs, J, success, status, message = polish(
            fun, pb.jacobian, z, rs, J, lo, hi, names, polish_stop
        )
    r, chisqr, notes, (success, status, message) = end_checks(
        J, rs, z, rscale, (success, status, message)
    )
    res = _finish(
        ps, names, (J, pb.scale, rscale) if np.all(np.isfinite(J)) else None, r, chisqr,
        ndata, success, status, message, pb.nfev, values=pb.values_of(z),
        scale_covar=scale_covar, rcond=rcond, max_rel_stderr=max_rel_stderr,
    )  # fmt: skip
    if notes:
        for n in names:
            res.params[n].stderr = None
        res.notes.extend(notes)
    if solver is not None and not res.success:
        # the given solver's end point failed (its budget, or the trust check where the
        # model has kinks near the minimum): SciPy's solver from the same start decides, so
        # a fit converges or fails exactly as without a solver
        ref = least_squares_fit(
            residual_fn, start, scale_covar=scale_covar, rcond=rcond,
            max_rel_stderr=max_rel_stderr, loss=loss, max_nfev=max_nfev, ftol=ftol,
            xtol=xtol, gtol=gtol, jac_rel_step=jac_rel_step, jac=jac, workers=workers,
        )  # fmt: skip
        ref.nfev += res.nfev
        return ref
    return res


def _finish(
    ps: dict[str, Parameter],
    names: list[str],
    jac: tuple[np.ndarray, np.ndarray, float] | None,
    r: np.ndarray,
    chisqr: float,
    ndata: int,
    success: bool,
    status: int,
    message: str,
    nfev: int,
    *,
    values: dict[str, float] | None = None,
    scale_covar: bool = True,
    rcond: float = 1e-8,
    max_rel_stderr: float | None = None,
) -> FitResult:
    k = len(names)
    nfree = ndata - k
    redchi = chisqr / nfree if nfree > 0 else math.nan
    tiny = np.finfo(float).tiny
    n2ll = ndata * math.log(max(chisqr / ndata, tiny))
    aic = n2ll + 2 * k
    bic = n2ll + math.log(ndata) * k
    if values is not None:
        for n, v in values.items():
            ps[n].value = v
    covar = correl = sv = None
    cond = math.nan
    notes: list[str] = []
    Jfull = None
    if jac is not None:
        Js, scale, rscale = jac  # d(r / rscale) / d(value / scale)
        with np.errstate(over="ignore"):
            Jfull = Js * rscale / scale  # d r / d value
        _U, s, Vt = np.linalg.svd(Js, full_matrices=False)
        sv = s
        with np.errstate(over="ignore"):  # a denormal smallest value: inf (fuzz: track)
            cond = float(s[0] / s[-1]) if s[-1] > 0 else math.inf
        keep = s > rcond * s[0] if s[0] > 0 else np.zeros_like(s, bool)
        if not keep.all():
            for idx in np.flatnonzero(~keep):
                v = Vt[idx]
                involved = [names[i] for i in np.flatnonzero(np.abs(v) > 0.1)]
                what = (
                    f"the combination of {', '.join(involved)}"
                    if len(involved) > 1
                    else ", ".join(involved)
                )
                rel = s[idx] / s[0] if s[0] > 0 else 0.0
                notes.append(
                    f"the data do not determine {what}: the fit is {rel:.1e} times as sensitive "
                    "to it as to its best-determined direction (singular values "
                    f"{s[idx]:.3g} vs {s[0]:.3g})"
                )
                for n in involved:
                    ps[n].identifiable = False
        inv = (Vt[keep].T / s[keep] ** 2) @ Vt[keep]
        # in the scaled residuals rscale cancels from (JᵀJ)⁻¹·χ²/ν; unscaled (weights given
        # as 1/σ) the covariance is (JᵀJ)⁻¹ of the original residuals
        if scale_covar and nfree > 0:
            factor = sumsq(r / rscale) / nfree
        else:
            factor = 1.0 / rscale**2
        cov_s = inv * factor
        covar = cov_s * np.outer(scale, scale)
        d, correl = stderr_and_correl(covar)
        for i, n in enumerate(names):
            p = ps[n]
            if p.identifiable is False:
                p.stderr = None
                continue
            p.stderr = float(d[i])
            p.identifiable = True
            if max_rel_stderr is not None and p.rel_stderr is not None:
                if p.rel_stderr > max_rel_stderr:
                    p.identifiable = False
                    p.note = p.note or (
                        f"relative standard error {100 * p.rel_stderr:.0f}% exceeds "
                        f"{100 * max_rel_stderr:.0f}%"
                    )
            at_bound = (p.value <= p.min) or (p.value >= p.max)
            if at_bound:
                notes.append(f"{n} ended at a bound ({p.value}); its error is not reliable")
    return FitResult(
        params=ps,
        var_names=list(names),
        covar=covar,
        correl=correl,
        chisqr=chisqr,
        redchi=redchi,
        aic=aic,
        bic=bic,
        ndata=ndata,
        nvarys=k,
        success=success,
        status=status,
        message=message,
        nfev=nfev,
        residual=r,
        jac=Jfull,
        singular_values=sv,
        condition=cond,
        scale_covar=scale_covar,
        notes=notes,
    )


def add_covariance(fit: FitResult, extra: np.ndarray, *, note: str | None = None) -> FitResult:
    """A copy of ``fit`` whose covariance includes ``extra`` (over ``fit.var_names``).

    For error sources the residuals do not show: an input the fit took as exact but that was
    estimated beforehand with its own error ``Σ_u`` (a drift removed from the data, a
    calibration). With ``G = ∂θ/∂u`` (the fitted parameters' response to the input), that
    error adds ``G Σ_u Gᵀ`` to the covariance. Standard errors and correlations are updated;
    a parameter flagged not identifiable stays so.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.linspace(0, 1, 20)
    >>> y = 2 * x + 1 + 0.01 * np.cos(40 * x)
    >>> fit = least_squares_fit(lambda p: p["a"] * x + p["b"] - y, {"a": 1.0, "b": 0.0})
    >>> out = add_covariance(fit, np.diag([0.0, 1e-4]))
    >>> round(out.params["b"].stderr, 4) >= 0.01
    True
    """
    if fit.covar is None:
        return fit
    extra = np.asarray(extra, dtype=float)
    k = len(fit.var_names)
    if extra.shape != (k, k) or not np.all(np.isfinite(extra)):
        raise InputError(f"extra covariance must be a finite {k}x{k} array, got {extra.shape}")
    return with_covariance(fit, fit.covar + 0.5 * (extra + extra.T), note=note)


def stderr_and_correl(covar: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Standard errors (the root of the covariance's diagonal, negative round-off clipped to
    zero) and the correlation matrix; a parameter with zero variance gets zero correlation
    with every other and 1 with itself."""
    d = np.sqrt(np.clip(np.diag(covar), 0.0, None))
    with np.errstate(divide="ignore", invalid="ignore"):
        correl = covar / np.outer(d, d)
    correl[~np.isfinite(correl)] = 0.0
    np.fill_diagonal(correl, 1.0)
    return d, correl


def _copied(p: Parameter) -> Parameter:
    """``dataclasses.replace(p)`` (a shallow copy), without its field-by-field constructor
    call for a plain :class:`Parameter` (a fit copies its parameters a few dozen times)."""
    if type(p) is not Parameter:
        return replace(p)
    q = object.__new__(Parameter)
    q.__dict__.update(p.__dict__)
    return q


def with_covariance(fit: FitResult, covar: np.ndarray, *, note: str | None = None) -> FitResult:
    """``fit`` with the parameter covariance ``covar``: standard errors and correlations
    follow from it, and ``note`` (if any) is added to the fit's notes."""
    d, correl = stderr_and_correl(covar)
    params = {n: _copied(p) for n, p in fit.params.items()}
    for i, n in enumerate(fit.var_names):
        if params[n].stderr is not None:
            params[n].stderr = float(d[i])
    notes = list(fit.notes) + ([note] if note else [])
    return replace(fit, params=params, covar=covar, correl=correl, notes=notes)


def stderr_ratio(fit: FitResult, covar: np.ndarray) -> np.ndarray:
    """The standard errors from ``covar`` over ``fit``'s own, where both are finite and
    the old one is not zero."""
    new = np.sqrt(np.clip(np.diag(covar), 0.0, None))
    old = np.sqrt(np.clip(np.diag(fit.covar), 0.0, None))
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = new / old
    return ratio[np.isfinite(ratio)]


def _lag_window_length(r: np.ndarray, nfft: int) -> int:
    """Lags the residuals (samples × channels) stay correlated over: the last lag at which
    the pooled autocorrelation, RMS-averaged over 128 lags, exceeds 2/√N (white noise's
    level is 1/√N), doubled so that the Bartlett taper keeps most of the tail; at least
    N/8, at most N/2."""
    n = r.shape[0]
    spec = np.abs(np.fft.rfft(r, nfft, axis=0)) ** 2
    acov = np.fft.irfft(spec.sum(axis=1), nfft)[: n // 2]
    if not acov[0] > 0:
        return 0
    rho2 = (acov / acov[0]) ** 2
    w = min(128, max(1, rho2.size))
    smooth = np.sqrt(np.convolve(rho2, np.ones(w) / w, mode="valid"))
    over = np.flatnonzero(smooth[1:] > 2.0 / math.sqrt(n))
    last = int(over[-1]) + 1 + w if over.size else 1
    # at least an eighth of the record: a lightly damped resonance driven by input noise
    # can carry little of the residuals' variance (hidden under white output noise) yet
    # most of it at the frequencies the parameters are sensitive to
    return min(max(2 * last, n // 8), n // 2)


def hac_covariance(
    fit: FitResult, *, channels: int = 1, lags: int | None = None, rcond: float = 1e-8
) -> FitResult:
    """A copy of ``fit`` whose covariance allows for correlated residuals (a sandwich).

    ``(JᵀJ)⁻¹ χ²/ν`` is right for independent residuals of equal variance. An output-error
    fit of a dynamic model (a structure's simulated response) has residuals correlated in
    time: noise on the input reaches them filtered by the structure (a resonant, slowly
    decaying correlation), as do sensor filters and unmodelled dynamics. Then the covariance
    is ``(JᵀJ)⁻¹ Jᵀ Ω J (JᵀJ)⁻¹`` with ``Ω`` the residuals' covariance, estimated here
    (stationary residuals) from their sample auto- and cross-covariances tapered by a
    Bartlett lag window (a Newey-West type estimate; positive semi-definite):
    ``Jᵀ Ω J = (1/N_fft) Σ_f Ĵ(f)ᴴ S(f) Ĵ(f)`` with ``S`` the tapered cross-spectrum of the
    channels, zero-padded so no lag wraps around. White residuals give back the usual
    covariance (up to the estimate's noise).

    Parameters
    ----------
    fit : FitResult
        With its Jacobian (``fit.jac``) and residual; returned unchanged without them.
    channels : int
        The residual vector is ``samples × channels`` flattened row by row (e.g. every DOF's
        displacement at each sample); channels may be correlated with each other.
    lags : int, optional
        Bartlett window half-length in samples; default from the residuals (the lag their
        autocorrelation stays above the white-noise level, doubled; at least N/8, at most
        N/2).
    rcond : float
        Singular-value cut-off, as in :func:`least_squares_fit`.

    Returns
    -------
    FitResult
        Standard errors, covariance and correlations replaced; a note gives the window and
        the ratio of the new standard errors to the white-noise ones. Parameters flagged not
        identifiable stay so.
    """
    J, r = fit.jac, np.asarray(fit.residual, dtype=float)
    k = len(fit.var_names)
    if J is None or fit.covar is None or k == 0 or r.size != J.shape[0]:
        return fit
    if channels < 1 or r.size % channels:
        raise InputError(f"{r.size} residuals do not split into {channels} channels")
    n = r.size // channels
    if n < 4 or not (np.all(np.isfinite(J)) and np.all(np.isfinite(r))):
        return fit
    Jc = J.reshape(n, channels, k)
    rc = r.reshape(n, channels)
    norms = np.linalg.norm(J, axis=0)
    norms[~(norms > 0)] = 1.0
    nfft0 = 1 << math.ceil(math.log2(2 * n))
    L = _lag_window_length(rc, nfft0) if lags is None else max(0, min(int(lags), n - 1))

    nfft = next_fast_len(n + L + 1)
    R = np.fft.rfft(rc, nfft, axis=0)  # (f, a)
    Jf = np.fft.rfft(Jc / norms, nfft, axis=0)  # (f, a, k)
    lag = np.arange(nfft)
    lag = np.minimum(lag, nfft - lag)
    taper = np.clip(1.0 - lag / (L + 1.0), 0.0, None)
    B = np.zeros((k, k))
    wts = np.full(nfft // 2 + 1, 2.0)  # rfft bins stand for their mirror images too
    wts[0] = 1.0
    if nfft % 2 == 0:
        wts[-1] = 1.0
    for a in range(channels):
        for b in range(channels):
            c_ab = np.fft.irfft(R[:, a] * np.conj(R[:, b]), nfft) / n  # lag l: r_a(t) r_b(t-l)
            S = np.fft.rfft(c_ab * taper, nfft)
            B += np.real(np.einsum("f,fi,fj->ij", wts * S, np.conj(Jf[:, a]), Jf[:, b]))
    B = 0.5 * (B + B.T) / nfft
    _U, s, Vt = np.linalg.svd(J / norms, full_matrices=False)
    keep = s > rcond * s[0] if s[0] > 0 else np.zeros_like(s, bool)
    Ainv = (Vt[keep].T / s[keep] ** 2) @ Vt[keep]
    dof = fit.ndata / max(fit.ndata - k, 1)
    covar = (Ainv @ B @ Ainv) * dof / np.outer(norms, norms)
    covar = 0.5 * (covar + covar.T)
    ratio = stderr_ratio(fit, covar)
    note = f"standard errors allow for correlated residuals (Bartlett lag window of {L} samples" + (
        f"; {ratio.min():.3g} to {ratio.max():.3g} × the white-noise ones)" if ratio.size else ")"
    )
    return with_covariance(fit, covar, note=note)
