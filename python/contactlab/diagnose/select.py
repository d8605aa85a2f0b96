"""Fitting candidate models and choosing among them.

Every candidate model (the current model plus one more effect) is fitted with the recording
split into folds of whole excitation cycles (cycle k goes to fold k mod K; a cycle is held
out from the fit that predicts it, while the model is still simulated over the full history,
as hysteresis needs). On a tangential record the start-up, the samples before the input's
first maximum (the virgin curve from rest, a shaker's start-up transient), is a held-out
unit of its own in fold K - 1, as cycle -1 would be (:func:`heldout_unit`; issue 29: a
displacement offset has 64-86 % of its information there on the rig at 10 kHz, 12-50
cycles, which no fold judged before). "Cycles" below are these units. The held-out error
is what ranks candidates. A candidate is accepted
only if all three hold:

1. its held-out mean-square error is lower by at least ``min_gain · σ²``, where σ is the
   noise level estimated from the data (:func:`contactlab.diagnose._signal.noise_rms`);
2. that improvement is consistent across held-out cycles: the per-cycle log ratios
   ``ln(MSE_current / MSE_candidate)`` have ``mean / standard error > z`` (cycles, not
   samples, are the independent units, so slowly varying residuals do not inflate the
   evidence; ratios, not differences, so that cycles of large amplitude or rate — where
   rate-dependent effects are largest — do not swamp the others). Families whose effects
   concentrate in some excitation blocks by their physics (``proportional_gain``: a
   normal joint's channel delay shows only where ω² differs from the blocks' mean, once
   the Kelvin-Voigt damping has absorbed its first-order phase) may pass this rule instead
   by :func:`proportional_t`: the held-out gain per cycle is expected in proportion to how
   far the candidate moves the prediction in that cycle, and its t statistic uses the
   scatter about that proportion, still with cycles as the units;
3. the Bayesian information criterion of the fit to all data decreases;
4. the gain is at least :data:`MIN_RELATIVE_GAIN` of the current model's held-out MSE: when
   a model is still far from the noise (a misspecified base on a real measurement), a
   systematic residual of many σ lets almost any candidate shave a sliver off it with
   significance, which is no evidence of that effect.

The accepted candidate with the largest held-out gain wins.

Errors in variables (families with a ``noise_variance``, the normal contact): the model is
driven by the measured input, so its prediction carries the input's noise as the model
filters it, ``T(θ)`` per sample (:func:`noise_term`). A model that filters more (more
damping, a delay interpolating between samples) would win by that alone. Fits minimise the
corrected sum ``Σ r² - n T(θ)``, unbiased for every candidate, and the rules above compare
a candidate's held-out errors as if it passed the current model's ``T``. A held-out cycle
carries the ``T`` of the fold fit that predicted it (:attr:`Trial.cycle_noise`), which the
comparison subtracts: a fold fit of a delay model may sit at another damping and delay than
the fit to all data and pass a quarter σ² more of the input noise (measured at 1 % x noise),
which the full fit's ``T`` would have charged to the candidate as a loss.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import ConvergenceError, InputError
from ..fitting import Parameter, least_squares_fit
from ._family import Family, ParamSpec, Prepared
from ._parallel import column_map, in_column, pmap


@dataclass
class FitOut:
    """Parameters fitted on a subset of samples, with standard errors from the Jacobian."""

    params: dict[str, float]
    stderr: dict[str, float]
    rss: float
    mse: float  # weighted mean square: rss over the sum of the weights
    n: int
    nfree: int
    success: bool
    message: str
    nfev: int

    @property
    def bic(self) -> float:
        return float(self.n * np.log(max(self.rss, 1e-300) / self.n) + self.nfree * np.log(self.n))


#: residuals a single fit works on at most (longer masks are strided)
FIT_SAMPLES = 5000


def sample_weight(d: Prepared) -> np.ndarray:
    """Likelihood weight of each sample (errors in variables), 1 when none is set.

    ``w = σy² / (σy² + (s σu)²)``: the output noise ``σy`` against the input noise ``σu`` seen
    through the local slope ``s = |dy/du|`` of the base model (set by the workflow after the
    base fit, :func:`contactlab.diagnose.workflow.eiv_weight`). Where a steep branch turns
    the input noise into output error (right after a reversal, a sticking phase of a
    rectangular loop) a sample counts less, the same for every candidate.
    """
    w = d.extra.get("weight")
    return np.ones(d.y.size) if w is None else w


def noise_term(family: Family, p: dict[str, float], effects: tuple[str, ...], d: Prepared) -> float:
    """Output variance per sample that the input's sensor noise causes through the model
    ``θ`` (``T(θ) = ∫ S_u |H_θ|²``; the family's ``noise_variance``, 0 when it has none or
    the input carries no measurable noise).

    Errors in variables: the model is driven by the measured input, so its prediction
    carries the input noise filtered by the model itself, and a model that filters more
    (more damping, a delay interpolating between samples) shows a smaller error for that
    reason alone. ``E[Σ r²] = n (σy² + bias² + T(θ))``, so the corrected sum of squares
    ``Σ r² - n T(θ)`` is unbiased for every candidate; fits minimise it (:func:`fit`) and
    :func:`judge` compares held-out errors with it.
    """
    f = getattr(family, "noise_variance", None)
    return 0.0 if f is None else float(f(p, effects, d))


def noise_bound(family: Family, p: dict[str, float], d: Prepared) -> float:
    """An upper bound of :func:`noise_term` over the damping and delay at the stiffness in
    ``p`` (the family's ``noise_variance_bound``; 0 when it has none)."""
    f = getattr(family, "noise_variance_bound", None)
    return 0.0 if f is None else float(f(p, d))


def specs_for(family: Family, effects: tuple[str, ...]) -> list[ParamSpec]:
    out = list(family.base_params)
    for e in effects:
        out.extend(family.candidates[e].params)
    return out


#: the Gauss-Newton polish after a candidate's solver stops once its next step is below
#: this many standard errors (:func:`contactlab.fitting.least_squares_fit`'s ``polish_stop``)
#: for a family with ``quick_polish`` (normal and tangential contact): every held-out and
#: in-sample error moves by far less than the noise, and each step is a central-difference
#: Jacobian (half of the model evaluations of a long normal diagnosis went to these)
POLISH_STOP = 0.01
#: the solver's relative tolerances (``ftol``, ``xtol``) for such a family: the Gauss-Newton
#: polish takes its end point to within POLISH_STOP standard errors of the minimum whichever
#: way the solver stops, and the trust check still applies (1e-8 before: 703 model
#: evaluations of a 1e6-sample asymmetric diagnosis, 592 with this)
QUICK_TOL = 1e-6


def fit(
    family: Family,
    effects: tuple[str, ...],
    d: Prepared,
    mask: np.ndarray,
    start: dict[str, float],
    scales: dict[str, float],
) -> FitOut:
    """Least-squares fit of the base and effect parameters on the samples in ``mask``.

    Runs :func:`contactlab.fitting.least_squares_fit`. Each parameter is passed as
    ``w = (value - start) / typical + 1`` — centred at 1 and of order 1 per typical change —
    because that function scales each variable by its initial value, which would be
    meaningless for an effect starting at its "absent" value 0. Parameters ``start`` lacks
    begin at their absent value; standard errors are mapped back (``inf`` where the fitting
    layer reports a parameter as not identifiable).
    """
    specs = specs_for(family, effects)
    names = [s.name for s in specs]
    sc = {s.name: scales[s.name] if s.name in scales else scales[s.scale] for s in specs}
    x0 = _inside({s.name: float(start.get(s.name, s.null)) for s in specs}, specs, sc, True)
    # long records: the fit sees every stride-th sample of the mask (the solver's work grows
    # with the number of residuals); held-out errors are still taken on every sample, and
    # the standard errors are those of the strided fit: its estimate uses those samples only
    # (they were scaled down to the full count, sqrt(stride) too small: on 20 fresh seeds the
    # force offset's z scattered with SD 2.57, 2.17 on 195k-sample kept records)
    n_all = int(np.count_nonzero(mask))
    stride = -(-n_all // FIT_SAMPLES)
    if stride > 1:
        mask = mask & (np.arange(mask.size) % stride == 0)
    idx = np.flatnonzero(mask)  # the samples the fit sees (a gather is cheaper than a mask)
    y = d.y[idx]
    # residuals in units of the output's RMS: the solver's gradient tolerance is absolute,
    # and a displacement residual in metres (1e-9) would stop it at the first step
    ys = float(np.sqrt(np.mean(y * y))) or 1.0
    sw = np.sqrt(sample_weight(d)[idx]) / ys  # errors in variables (see sample_weight)
    spent = d.extra.get("evaluations")  # the workflow's budget counter (EvaluationCounter)
    searched = 0
    search = getattr(family, "search_start", None)
    if search is not None and noise_bound(family, x0, d) == 0.0:
        # a family's own search of a parameter the solver crawls along (normal_load's
        # frequency, with its linear amplitudes projected out): the solver starts there
        x0, searched = search(effects, d, idx, y, sw, x0)
        if spent is not None and not in_column():
            spent.tick(searched)
        x0 = _inside(x0, specs, sc, False)
    params = [
        Parameter(
            s.name,
            1.0,
            min=(s.lower - x0[s.name]) / sc[s.name] + 1.0,
            max=(s.upper - x0[s.name]) / sc[s.name] + 1.0,
            unit=s.unit,
        )
        for s in specs
    ]
    lo = {s.name: s.lower for s in specs}
    hi = {s.name: s.upper for s in specs}

    def value(w: dict[str, float]) -> dict[str, float]:
        # clipped: the affine map back can step a rounding error past a bound (h0 = -3e-17)
        # (min/max of floats: np.clip's per-call overhead is felt over thousands of calls)
        return {n: min(max(float(x0[n] + (w[n] - 1.0) * sc[n]), lo[n]), hi[n]) for n in names}

    # errors in variables (corrected least squares, see noise_term): the objective is
    # Σ w r² - n T(θ), passed to the solver as one more residual √(n (C - T(θ))) with C a
    # constant above any T the fit reaches (the input noise through the model's compliance
    # at half the starting stiffness or more), so no candidate wins by filtering the input
    c_top = 4.0 * noise_bound(family, x0, d)
    n_fit = float(np.sum(sample_weight(d)[idx]))
    resid = _residual(family, effects, d, idx, y, sw, value, spent, c_top, n_fit, ys)
    # the corrected fits (normal contact) converge within 12–30 solver evaluations; one that
    # has not within 100 is not going to, and its finite-difference Jacobians at 400 cost
    # seconds on a long record (2813 model evaluations measured on one run-away fit)
    budget = 100 if c_top > 0 else 400
    # a family whose model evaluations release the GIL for milliseconds (normal contact's
    # integrator) has its Jacobians' columns evaluated on threads: the same numbers
    cols = column_map(spent) if getattr(family, "parallel_jacobian", False) else None
    quick = getattr(family, "quick_polish", False)
    tol = QUICK_TOL if quick else 1e-8
    res = least_squares_fit(
        resid, params, ftol=tol, xtol=tol, gtol=1e-8, max_nfev=budget, workers=cols,
        polish_stop=POLISH_STOP if quick else 0.0,
    )  # fmt: skip
    w = {n: res.params[n].value for n in names}
    chisqr = float(res.chisqr) * ys * ys
    resid_vec, jac = res.residual, res.jac
    rss = chisqr
    if c_top > 0:  # the corrected sum of squares, Σ w r² - n T(θ) (never below a tenth of Σ w r²)
        raw = float(np.sum(resid_vec[:-1] ** 2)) * ys * ys
        t_end = noise_term(family, value(w), effects, d)
        if not np.isfinite(t_end):  # (a stiffness fitted to zero: its compliance unbounded)
            raise ConvergenceError(
                f"the fit of {' + '.join(('base', *effects))} ended at a degenerate point "
                f"({', '.join(f'{n} = {v:.3g}' for n, v in value(w).items())}): the input "
                "noise through the model is unbounded — the record does not determine it"
            )
        rss = max(raw - n_fit * t_end, 0.1 * raw)
        resid_vec = resid_vec[:-1]
        jac = None if jac is None else jac[:-1]
    # the errors scale with the corrected residual, not with the constant C the solver saw
    shrink = float(np.sqrt(rss / chisqr)) if chisqr > 0 else 1.0
    lag = int(d.cycles.period_samples // stride) if n_all == d.y.size else None
    se = _stderr(res, names, sc, shrink, lag, resid_vec, jac)
    wsum = float(np.sum(sw * sw)) * ys * ys
    return FitOut(
        value(w), se, rss, rss / wsum, res.ndata, res.nvarys, res.success, res.message,
        res.nfev + searched,
    )  # fmt: skip


def _stderr(
    res: Any,
    names: list[str],
    sc: dict[str, float],
    shrink: float,
    lag: int | None,
    resid_vec: np.ndarray,
    jac: np.ndarray | None,
) -> dict[str, float]:
    """Standard errors of a fit in the parameters' units (``inf``: not identifiable),
    scaled by ``shrink`` and, for the fit to all data (``lag``: the period in fitted
    samples; None otherwise), inflated for the residual's correlation over ``lag``."""
    infl = dict.fromkeys(names, 1.0)
    if lag is not None and jac is not None:  # the fit to all data: its errors are reported
        infl.update(zip(res.var_names, stderr_inflation(jac, resid_vec, lag), strict=True))
    return {
        n: (
            res.params[n].stderr * sc[n] * shrink * infl[n]
            if res.params[n].stderr is not None
            else np.inf
        )
        for n in names
    }


def _inside(
    x0: dict[str, float], specs: list[ParamSpec], sc: dict[str, float], typical: bool
) -> dict[str, float]:
    """Starting values strictly inside the bounds, so a start at "absent" (often a bound)
    can move; ``typical``: a value with no "absent" (a time constant, NaN) starts at a
    typical one, 0.3 of its scale."""
    out = dict(x0)
    for s in specs:
        v = float(out[s.name])
        if typical and not np.isfinite(v):
            v = 0.3 * sc[s.name]
        span = s.upper - s.lower if np.isfinite(s.upper - s.lower) else sc[s.name]
        out[s.name] = float(np.clip(v, s.lower + 1e-6 * span, s.upper - 1e-6 * span))
    return out


def _residual(
    family: Family,
    effects: tuple[str, ...],
    d: Prepared,
    idx: np.ndarray,
    y: np.ndarray,
    sw: np.ndarray,
    value: Any,
    spent: Any,
    c_top: float,
    n_fit: float,
    ys: float,
) -> Any:
    """The solver's residual of :func:`fit`: weighted model minus data at the samples
    ``idx`` (the model at those samples only for a family that ``predicts_at``), and, for
    the errors-in-variables correction (``c_top`` > 0), the one more residual
    ``√(n (C - T(θ)))``; each call counted against the budget."""
    at = getattr(family, "predicts_at", False)

    def plain(w: dict[str, float]) -> np.ndarray:
        if spent is not None and not in_column():
            spent.tick()
        if at:
            return (family.predict(value(w), effects, d, at=idx) - y) * sw  # type: ignore[call-arg]
        return (family.predict(value(w), effects, d)[idx] - y) * sw

    if c_top <= 0:
        return plain

    def resid(w: dict[str, float]) -> np.ndarray:
        extra = n_fit * max(c_top - noise_term(family, value(w), effects, d), 0.0)
        return np.append(plain(w), np.sqrt(extra) / ys)

    return resid


def correlation_time(r: np.ndarray, lag: int) -> float:
    """Integrated autocorrelation time ``1 + 2 Σ ρ_l`` of a residual, in samples (1 for white).

    Geyer's initial positive sequence: lags are summed in pairs ``ρ_l + ρ_(l+1)`` while a pair
    is positive, up to ``lag``; ``n / time`` is the number of effectively independent samples.
    """
    r = r - np.mean(r)
    n = r.size
    if n < 4 or not np.any(r):
        return 1.0
    f = np.fft.rfft(r, 2 * n)
    ac = np.fft.irfft(f * np.conj(f), 2 * n)[: min(int(lag), n - 2) + 2]
    rho = ac / ac[0]
    total = 1.0
    for ell in range(1, rho.size - 1, 2):
        pair = float(rho[ell] + rho[ell + 1])
        if not pair > 0:
            break
        total += 2.0 * pair
    return total


def stderr_inflation(jac: np.ndarray, r: np.ndarray, lag: int) -> np.ndarray:
    """Factors (>= 1) by which residual autocorrelation widens each parameter's error.

    The least-squares covariance ``s² (JᵀJ)⁻¹`` holds for independent residuals. A model that
    misses part of a measurement (a real loop it cannot follow everywhere) leaves a residual
    correlated over many samples, and then far fewer independent residuals back the fit
    than there are samples. Two corrections, the larger one per parameter, never below 1:

    - the sandwich ``(JᵀJ)⁻¹ S (JᵀJ)⁻¹ · n/(n-p)`` with ``S`` the long-run covariance of the
      scores ``g_t = J_t r_t`` (Newey-West: Bartlett weights ``1 - l/(L+1)`` up to ``L`` =
      ``lag`` samples, one excitation period), against the plain covariance;
    - the effective number of independent residuals ``n / τ`` (:func:`correlation_time`),
      i.e. ``√τ``: a residual that repeats from cycle to cycle (a systematic misfit) has
      scores that cancel across the cycle, which the sandwich alone would miss.
    """
    n, k = jac.shape
    if n <= k or k == 0:
        return np.ones(k)
    g = jac * r[:, None]
    S = g.T @ g
    for ell in range(1, min(int(lag), n - 1) + 1):
        c = g[ell:].T @ g[:-ell]
        S += (1.0 - ell / (lag + 1.0)) * (c + c.T)
    ainv = np.linalg.pinv(jac.T @ jac)
    plain = np.diag(ainv) * float(r @ r) / (n - k)
    sand = np.diag(ainv @ S @ ainv) * n / (n - k)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(plain > 0, sand / plain, 1.0)
    ratio = np.nan_to_num(ratio, nan=1.0, posinf=1.0)
    return np.sqrt(np.maximum(np.maximum(ratio, correlation_time(r, lag)), 1.0))


@dataclass
class Trial:
    """A candidate model evaluated by cross-validation over cycles, then fitted to all data."""

    effects: tuple[str, ...]
    full: FitOut
    prediction: np.ndarray  # held-out prediction for held-out samples, full fit elsewhere
    heldout: np.ndarray  # boolean mask of samples that were held out
    cycle_mse: np.ndarray  # held-out MSE per cycle
    heldout_rms: float
    heldout_peak: float
    energy_error: float
    fitted: np.ndarray  # prediction of the fit to all data
    extra: dict[str, Any] = field(default_factory=dict)

    def full_residual(self, d: Prepared) -> np.ndarray:
        """Residual (model minus measurement) of the fit to all data."""
        return self.fitted - d.y

    @property
    def heldout_mse(self) -> float:
        return self.heldout_rms**2

    @property
    def noise_term(self) -> float:
        """:func:`noise_term` of the fit to all data (0 when not known)."""
        return float(self.extra.get("noise_term", 0.0))

    @property
    def heldout_noise(self) -> float:
        """:func:`noise_term` the held-out errors carry: each held-out sample's from the
        fold fit that predicted it, weighted as :attr:`heldout_rms` (0 when not known)."""
        return float(self.extra.get("heldout_noise", self.noise_term))

    @property
    def cycle_noise(self) -> np.ndarray | float:
        """:func:`noise_term` each held-out cycle of :attr:`cycle_mse` carries (that of the
        fold fit that predicted it)."""
        return self.extra.get("cycle_noise", self.noise_term)

    @property
    def sample_noise(self) -> np.ndarray | float:
        """:func:`noise_term` per sample of :attr:`prediction` (a held-out sample's from the
        fold fit that predicted it, the full fit's elsewhere)."""
        return self.extra.get("sample_noise", self.noise_term)


#: the start-up (the samples before the input's first maximum) is a held-out unit of its
#: own when it spans at least this share of the dominant period (shorter: a record cut just
#: before a maximum, too few samples for a unit of the per-cycle statistics)
STARTUP_MIN_PERIOD = 0.2
#: ... and when the record starts from rest: both channels start (a straight line through
#: their first samples, read at the first) within this share of their half range (over the
#: start-up and the first two cycles) of that range's centre. A contact from rest starts
#: at the centre of its motion with the force at the loops' centre (a sensor's zero moves
#: both alike); a record cut from a running test starts elsewhere on its loop, in a state
#: the model simulated from rest does not hold. Measured (x / F): the friction frame
#: +0.68 / -0.52 and +0.98 / -0.79, the microtribometer -1.00 / 0.00 (out); the friction
#: damper's harmonic tests -0.05 to -0.07 / +0.07 to +0.31; the rig simulator from rest
#: (40 records, half with a shaker, fs 1-10 kHz, ac·A 0.3-5, noise 2 %) at most 0.23
#: (its x sensor's filters settle over the first samples)
STARTUP_CENTRE = 0.3
#: ... less its first samples, this share of the period: there a candidate's velocity or
#: acceleration is read from one side of a window at the record's first sample
STARTUP_EDGE = 0.05


def _from_rest(d: Prepared, first: int, maxima: np.ndarray) -> bool:
    """Whether the record starts from rest (:data:`STARTUP_CENTRE`)."""
    end = int(maxima[min(2, maxima.size - 1)])
    k = max(3, min(10, int(0.02 * float(d.cycles.period_samples))))
    if end <= k:
        return False
    chans = [np.asarray(d.u, float)]
    if d.y is not None:
        chans.append(np.asarray(d.y, float))
    i = np.arange(k, dtype=float)
    for v in chans:
        seg = v[:end]
        half = 0.5 * float(np.ptp(seg))
        if not (half > 0 and np.isfinite(half)):
            return False
        # the value at the first sample: a straight line through the first k (the noise
        # averaged, a steep start followed)
        start = float(np.polyfit(i, v[:k], 1)[1])
        off = start - 0.5 * (float(np.max(seg)) + float(np.min(seg)))
        if abs(off) > STARTUP_CENTRE * half:
            return False
    return True


def startup_mask(d: Prepared) -> np.ndarray:
    """The start-up's samples: before the input's first maximum (``d.cycles.cycle == -1``
    there), where a record from rest loads the contact along its virgin curve and a
    shaker's drive builds its amplitude. All False when the record has no maximum, the
    start-up is shorter than :data:`STARTUP_MIN_PERIOD` of the period, or the record does
    not start from rest (:data:`STARTUP_CENTRE`)."""
    cyc = np.asarray(d.cycles.cycle)
    out = np.zeros(cyc.size, bool)
    maxima = np.asarray(d.cycles.reversals)[np.asarray(d.cycles.is_max, bool)]
    if maxima.size == 0:
        return out
    first = int(maxima[0])
    if first < max(3.0, STARTUP_MIN_PERIOD * float(d.cycles.period_samples)):
        return out
    if not _from_rest(d, first, maxima):
        return out
    edge = min(first, int(np.ceil(STARTUP_EDGE * float(d.cycles.period_samples))))
    out[edge:first] = cyc[edge:first] < 0
    return out


def heldout_unit(d: Prepared) -> np.ndarray:
    """The held-out unit of each sample (the units of the per-cycle statistics of rule 2):
    cycle ``k`` (from one maximum of the input to the next) is unit ``k + 1``; the
    start-up (:func:`startup_mask`) is unit 0 where the family holds it out
    (``d.extra["heldout_startup"]``, set by the tangential family: issue 29, a record from
    rest shows a displacement offset, a drift's first state and a mass's start mostly
    there); -1: in no unit (the incomplete last cycle; the start-up otherwise)."""
    cyc = np.asarray(d.cycles.cycle)
    unit = np.where(cyc >= 0, cyc + 1, -1)
    if d.extra.get("heldout_startup", False):
        unit[startup_mask(d)] = 0
    return unit


def unit_fold(unit: np.ndarray, folds: int) -> np.ndarray:
    """The fold of each held-out unit (:func:`heldout_unit`): cycle ``k`` in fold ``k mod
    folds``, the start-up (unit 0, "cycle -1") in fold ``folds - 1``; -1 stays -1."""
    unit = np.asarray(unit)
    return np.where(unit >= 0, (unit - 1) % folds, -1)


def fold_masks(d: Prepared, folds: int) -> list[np.ndarray]:
    """Test masks: cycle k (from one maximum of the input to the next) in fold k mod folds,
    and the start-up where it is a held-out unit (:func:`heldout_unit`) in fold
    ``folds - 1`` (as cycle -1 would be)."""
    if d.cycles.n_cycles < 2 * folds:
        raise InputError(
            f"the recording has {d.cycles.n_cycles} complete excitation cycles; the "
            f"discrepancy workflow needs at least {2 * folds} to hold cycles out"
        )
    fold = unit_fold(heldout_unit(d), folds)
    return [fold == k for k in range(folds)]


def _cycle_samples(cyc: np.ndarray, ids: np.ndarray) -> list[slice] | list[np.ndarray]:
    """The samples of each cycle in ``ids``: slices when every cycle is one run of samples
    (as :func:`contactlab.diagnose._signal.find_cycles` numbers them), else masks."""
    runs = np.flatnonzero(np.diff(cyc)) + 1
    starts = np.r_[0, runs]
    ends = np.r_[runs, cyc.size]
    label = cyc[starts]
    own = label[np.isin(label, ids)]
    if np.unique(own).size != own.size or own.size != ids.size:  # a cycle in pieces
        return [cyc == k for k in ids]
    where = dict(zip(label.tolist(), zip(starts.tolist(), ends.tolist(), strict=True), strict=True))
    return [slice(*where[k]) for k in ids.tolist()]


def _loop_energies(
    family: Family, d: Prepared, sels: list[Any], pred: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Loop energy of each cycle ``sels`` (:func:`_cycle_samples`), measured and predicted.

    With a family's ``loop_energies(u, y, bounds)`` (all cycles in one call of the Rust
    kernel that ``loop_energy`` calls once per cycle: the same numbers) when the cycles are
    runs in order of at least 3 samples and the prediction is finite; the measured ones are
    kept per recording and set of cycles (every trial of a diagnosis asks for the same).
    Otherwise cycle by cycle with ``loop_energy`` (which also says what is not finite)."""
    batch = getattr(family, "loop_energies", None)
    runs = [(s.start, s.stop) for s in sels if isinstance(s, slice)]
    bounds = [i for r in runs for i in r]
    ok = (
        batch is not None
        and len(runs) == len(sels)
        and all(b - a >= 3 for a, b in runs)
        and bool(np.all(np.diff(bounds) >= 0))
        and bool(np.all(np.isfinite(pred)))
    )
    if not ok:
        e_meas = [family.loop_energy(d.u[sel], d.y[sel]) for sel in sels]
        e_mod = [family.loop_energy(d.u[sel], pred[sel]) for sel in sels]
        return np.array(e_meas), np.array(e_mod)
    memo = d.extra.setdefault("loop_energies", {})
    key = tuple(bounds)
    hit = memo.get(key)
    if hit is None:
        u = np.ascontiguousarray(d.u, dtype=np.float64)
        y = np.ascontiguousarray(d.y, dtype=np.float64)
        if len(memo) >= 16:
            memo.clear()
        hit = memo[key] = (u, batch(u, y, bounds)[0::2])  # (every other: the gaps between)
    u, e_meas = hit
    e_mod = batch(u, np.ascontiguousarray(pred, dtype=np.float64), bounds)[0::2]
    return e_meas.copy(), e_mod


def evaluate(
    family: Family,
    effects: tuple[str, ...],
    d: Prepared,
    start: dict[str, float],
    scales: dict[str, float],
    folds: int = 2,
    full: FitOut | None = None,
    parallel: bool = False,
) -> Trial:
    """Cross-validated held-out errors and the fit to all data of one model (``full``, when
    that fit is at hand already). With ``parallel`` the fold fits run on threads
    (:func:`contactlab.diagnose._parallel.pmap`; the same results)."""
    masks = fold_masks(d, folds)
    if full is None:
        full = fit(family, effects, d, np.ones(d.y.size, bool), start, scales)
    fitted = family.predict(full.params, effects, d)
    pred = fitted.copy()
    heldout = np.zeros(d.y.size, bool)
    t_full = noise_term(family, full.params, effects, d)
    # errors in variables: a held-out sample carries the input noise as the fold fit that
    # predicted it passes it (its damping and delay), not as the fit to all data does
    t_sample = np.full(d.y.size, t_full)

    def fold_prediction(test: np.ndarray) -> tuple[np.ndarray, float]:
        f = fit(family, effects, d, ~test, full.params, scales)
        return family.predict(f.params, effects, d), noise_term(family, f.params, effects, d)

    held = pmap(fold_prediction, masks) if parallel else [fold_prediction(m) for m in masks]
    for test, (p, t_fold) in zip(masks, held, strict=True):
        pred[test] = p[test]
        t_sample[test] = t_fold
        heldout |= test
    err = pred - d.y
    wt = sample_weight(d)
    cyc = heldout_unit(d)
    ids = np.unique(cyc[heldout])
    sels = _cycle_samples(cyc, ids)
    # the products once over the record, each cycle's sum over its samples (the same
    # numbers as the products per cycle: elementwise, and summed over the same run)
    w_err2, w_noise = wt * err**2, wt * t_sample
    w_sum = [np.sum(wt[sel]) for sel in sels]
    cycle_mse = np.array([np.sum(w_err2[sel]) / w for sel, w in zip(sels, w_sum, strict=True)])
    cycle_noise = np.array([np.sum(w_noise[sel]) / w for sel, w in zip(sels, w_sum, strict=True)])
    # loop energies over the closed cycles only (the start-up is no loop)
    loops = [sel for sel, k in zip(sels, ids.tolist(), strict=True) if k > 0]
    e_meas_a, e_mod_a = _loop_energies(family, d, loops, pred)
    denom = float(np.sum(np.abs(e_meas_a)))
    energy_error = float(np.sum(np.abs(e_mod_a - e_meas_a)) / denom) if denom > 0 else np.nan
    eh, wh = err[heldout], wt[heldout]
    return Trial(
        effects,
        full,
        pred,
        heldout,
        cycle_mse,
        float(np.sqrt(np.sum(wh * eh * eh) / np.sum(wh))),
        float(np.max(np.abs(eh))),
        energy_error,
        fitted,
        {
            "noise_term": t_full,
            "heldout_noise": float(np.sum(wh * t_sample[heldout]) / np.sum(wh)),
            "cycle_noise": cycle_noise,
            "sample_noise": t_sample,
        },
    )


@dataclass(frozen=True)
class Verdict:
    """Comparison of a candidate with the current model."""

    name: str
    heldout_rms: float
    gain: float  # held-out MSE reduction in units of the noise variance
    t_stat: float
    delta_bic: float
    accepted: bool
    reason: str

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "heldout_rms": self.heldout_rms,
            "gain_over_noise_var": self.gain,
            "t_stat": self.t_stat,
            "delta_bic": self.delta_bic,
            "accepted": self.accepted,
            "reason": self.reason,
        }


#: rule 4: the smallest held-out gain, as a fraction of the current held-out MSE
MIN_RELATIVE_GAIN = 0.01


def _noise_of(trial: Any, what: str = "heldout_noise") -> Any:
    """A trial's input-noise term its held-out errors carry (``what``: ``heldout_noise``,
    ``cycle_noise`` or ``sample_noise`` of :class:`Trial`; 0 for an object that has none)."""
    return getattr(trial, what, 0.0)


def proportional_t(current: Trial, cand: Trial, d: Prepared) -> float:
    """t statistic of the held-out gain with per-cycle gains proportional to the change.

    Per held-out cycle ``c``, with ``r`` the current model's held-out residual and ``Δ`` the
    candidate's held-out prediction minus the current one (weights ``w`` of
    :func:`sample_weight`): ``N_c = Σ w r Δ``, ``D_c = Σ w Δ²``. The held-out squared error
    falls by ``Σ (2 N_c - D_c)``, i.e. it falls iff ``ĝ = ΣN / ΣD > 1/2`` (the residual's
    share along the candidate's move exceeds half the move). ``ĝ``'s standard error is the
    cluster (cycle) sandwich ``√(m/(m-1) Σ (N_c - ĝ D_c)²) / ΣD`` over the ``m`` cycles;
    returns ``(ĝ - 1/2) / se`` (``-inf`` when the candidate does not move the prediction).
    """
    r = d.y - current.prediction
    delta = cand.prediction - current.prediction
    w = sample_weight(d)
    held = current.heldout & cand.heldout
    cyc = np.where(held, heldout_unit(d), -1)
    ids = np.unique(cyc[cyc >= 0])
    if ids.size < 3:
        return -np.inf
    idx = np.searchsorted(ids, cyc[cyc >= 0])
    # errors in variables: the candidate's error is read as if it carried the current
    # model's input-noise term (:func:`noise_term`), i.e. each sample gains (T_c - T)/2 in N
    dt_half = 0.5 * (_noise_of(cand, "sample_noise") - _noise_of(current, "sample_noise"))
    n_c = np.bincount(idx, (w * (r * delta + dt_half))[cyc >= 0], ids.size)
    d_c = np.bincount(idx, (w * delta * delta)[cyc >= 0], ids.size)
    total = float(np.sum(d_c))
    if not total > 0:
        return -np.inf
    g = float(np.sum(n_c)) / total
    m = ids.size
    se = float(np.sqrt(m / (m - 1) * np.sum((n_c - g * d_c) ** 2))) / total
    return (g - 0.5) / se if se > 0 else (np.inf if g > 0.5 else -np.inf)


def judge(
    name: str,
    current: Trial,
    cand: Trial,
    sigma: float,
    z: float,
    min_gain: float,
    d: Prepared | None = None,
    rel_scale: float = 1.0,
    strong: tuple[float, float] | None = None,
) -> Verdict:
    """Apply the three acceptance rules of the module docstring (rule 2's proportional
    form when ``d`` is given: the family's ``proportional_gain``; ``rel_scale``: the share
    of rule 4's :data:`MIN_RELATIVE_GAIN` the candidate must reach, its effects'
    ``relative_gain_scale``, :func:`contactlab.diagnose.search.relative_gain_scale`;
    ``strong``: ``(factor, z_strong)``, the family's ``strong_gain``: a held-out gain of at
    least ``factor`` times ``min_gain`` passes rule 2 at ``t > z_strong``)."""
    # errors in variables: the candidate's held-out errors are compared as if it passed the
    # input noise as the current model does (corrected least squares, :func:`noise_term`)
    # (each held-out error with the noise term of the fold fit that made it)
    shift = float(_noise_of(cand)) - float(_noise_of(current))
    c_shift = _noise_of(cand, "cycle_noise") - _noise_of(current, "cycle_noise")
    cand_cycle = np.maximum(cand.cycle_mse - c_shift, 1e-3 * cand.cycle_mse)
    cand_mse = cand.heldout_mse - shift
    ratio = np.log(current.cycle_mse / cand_cycle)
    gain = float(current.heldout_mse - cand_mse) / sigma**2
    sd = float(np.std(ratio, ddof=1)) if ratio.size > 1 else np.inf
    t = float(np.mean(ratio) / (sd / np.sqrt(ratio.size))) if sd > 0 else np.inf
    if d is not None and not t > z:
        t = max(t, proportional_t(current, cand, d))
    dbic = cand.full.bic - current.full.bic
    rel = float(current.heldout_mse - cand_mse) / current.heldout_mse
    rel_floor = MIN_RELATIVE_GAIN * (1.0 if d is None else float(d.extra.get("gain_scale", 1.0)))
    rel_floor *= float(rel_scale)
    if gain < min_gain:
        reason = f"held-out gain {gain:.3g} σ² below {min_gain:g} σ²"
    elif rel < rel_floor:
        reason = (
            f"held-out gain {100 * rel:.2g} % of the remaining error (below "
            f"{100 * rel_floor:.2g} %): a sliver of a larger misfit"
        )
    elif not (t > z or _strong_pass(gain, t, min_gain, strong)):
        reason = f"gain not significant across held-out cycles (t = {t:.2f} <= {z:g})"
        if strong is not None and gain >= strong[0] * min_gain:
            reason = (
                f"gain not significant across held-out cycles (t = {t:.2f} <= {strong[1]:g}, "
                f"the threshold of a gain {strong[0]:g} times the floor)"
            )
    elif not dbic < 0:
        reason = f"BIC does not decrease (ΔBIC = {dbic:+.1f})"
    else:
        reason = "accepted"
    return Verdict(name, cand.heldout_rms, gain, t, dbic, reason == "accepted", reason)


def _strong_pass(
    gain: float, t: float, min_gain: float, strong: tuple[float, float] | None
) -> bool:
    """Rule 2 for a large held-out gain (a family's ``strong_gain``, ``(factor,
    z_strong)``): the gain is at least ``factor`` times the floor ``min_gain`` and consistent
    across the held-out cycles at ``t > z_strong``. The per-cycle t has the cycles as its
    units: on a record of 5-10 cycles, or for an effect whose gain sits in the first cycles
    by its physics (a creep settling), it stays below ``z`` for gains far above anything
    the noise draws (normal contact: calibrated on clean records,
    :data:`contactlab.diagnose.candidates_normal.STRONG_GAIN`)."""
    if strong is None or not min_gain > 0.0:
        return False
    factor, z_strong = strong
    return bool(gain >= factor * min_gain and t > z_strong)


def gain_where(d: Prepared, current: Trial, cand: Trial, where: np.ndarray) -> float:
    """The held-out gain of ``cand`` over ``current`` on the samples ``where`` only, per
    held-out sample of the whole record (output units squared: compare two candidates'
    on one record): ``Σ w (r² - (r - Δ)²)`` over the samples held out by both and in
    ``where``, ``r`` the current model's held-out residual, ``Δ`` the candidate's held-out
    prediction minus the current one, ``w`` the likelihood weights
    (:func:`sample_weight`)."""
    r = d.y - current.prediction
    delta = cand.prediction - current.prediction
    held = current.heldout & cand.heldout
    n = max(int(np.count_nonzero(held)), 1)
    g = sample_weight(d) * (2.0 * r * delta - delta * delta)
    return float(np.sum(g[held & where])) / n
