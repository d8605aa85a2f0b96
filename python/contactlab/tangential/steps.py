"""The named steps of :func:`contactlab.tangential.analyze_tangential`, each testable alone.

The analysis (*Experimental investigation of tangential contact stiffness and equivalent
damping*: averaged loops, eq. 1/6 fitted; PHYSICS.md §1) runs

1. :func:`detrend` — period averaging and removal of linear force/displacement drifts;
2. :func:`fit_data` — what the fit sees (averaged bins or samples, monotone path, turns);
3. :func:`start_values` — starting parameters from the loop's size and area;
4. :class:`Residuals` + :func:`fit` — the weighted residuals (errors in variables, the
   displacement channel's own measurement of the turning points) and the fits;
5. :func:`drift_covariance`, :func:`turn_covariance`, :func:`fixed_amplitude_covariance`
   (in :mod:`.covariance`, named here too) —
   the errors of inputs the fit took as exact, carried into the covariance through the fit's
   linear response ``G = -(JᵀJ)⁻¹Jᵀ ∂r/∂u`` (``cov += G Σ_u Gᵀ``);
6. :func:`amplitude_estimate` — the amplitude and its error.

Identifiability, derived quantities and warnings are in :mod:`.regime` and :mod:`.analysis`.
Perturbations of the inputs (for the covariance terms) are explicit keyword arguments of
:meth:`Residuals.residual`, never hidden state.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from .. import _core
from ..errors import InputError
from ..fitting import FitResult, Parameter, least_squares_fit
from ..masing import Masing, loop_area

# steps 5 and 6 live in .covariance; named here too, as the steps of the analysis
from .covariance import (
    Amplitude,
    amplitude_estimate,
    drift_covariance,
    fixed_amplitude_covariance,
    propagate,
    propagate_many,
    turn_covariance,
)
from .model import (
    initial_guess,
    steady_loop_force,
    steady_signal_force,
    turn_nodes,
    virgin_signal_force,
)
from .preprocess import AveragedLoop, Reversals, average_loop, find_reversals, monotone_path
from .turns import VirginTurns, turning_point_prior, virgin_nodes
from .uncertainty import path_slope, trend, x_noise_var


@functools.lru_cache(maxsize=16)
def _branch_signs(n: int) -> np.ndarray:
    """``+1`` on the descending bins ``0:n/2`` of an averaged loop, ``-1`` on the ascending
    ones (read-only; one array per bin count: the fit's model and derivatives are evaluated
    a few dozen times a window on the same bins)."""
    sg = np.where(np.arange(n) < n // 2, 1.0, -1.0)
    sg.flags.writeable = False
    return sg


def model_of(v: dict[str, float]) -> Masing:
    """The Masing model of a parameter set in the fit's parametrisation ``(k0, ac)``."""
    return Masing(v["k0"] / v["ac"], v["ac"])


# -- 1. averaging and drift --------------------------------------------------------------


@dataclass(frozen=True)
class Drift:
    """Linear drifts removed before the fit (``(slope, stderr)`` per channel) and the time
    axis they were removed on (``t - t_mid``)."""

    force: tuple[float, float]
    displacement: tuple[float, float]
    tt: np.ndarray
    t_mid: float


@dataclass(frozen=True)
class Detrended:
    x: np.ndarray
    F: np.ndarray
    loop: AveragedLoop | None
    drift: Drift | None

    @property
    def force_drift(self) -> tuple[float, float]:
        return self.drift.force if self.drift is not None else (0.0, 0.0)

    @property
    def displacement_drift(self) -> tuple[float, float]:
        return self.drift.displacement if self.drift is not None else (0.0, 0.0)


def detrend(
    x: np.ndarray,
    F: np.ndarray,
    t: np.ndarray | None,
    *,
    on: str,
    enabled: bool,
    n_points: int | None,
    rel_threshold: float,
    min_cycles: int,
    first: AveragedLoop | None = None,
) -> Detrended:
    """Average the loop; with ``enabled`` and ≥ 3 cycles remove the linear force and
    displacement drifts seen in the per-cycle means and average again.

    A whole-signal fit (``on="signal"``) goes on without an averaged loop when there are too
    few cycles; an averaged fit then raises :class:`InputError`. ``first``: the loop of
    ``x, F`` averaged with the same options already (not averaged again).
    """
    loop: AveragedLoop | None = first
    try:
        if loop is None:
            loop = average_loop(
                x, F, t, n_points=n_points, rel_threshold=rel_threshold, min_cycles=min_cycles
            )
    except InputError:
        if on == "averaged":
            raise
    if not (enabled and loop is not None and loop.n_cycles >= 3):
        return Detrended(x, F, loop, None)
    # Slow sensor drift shows as a trend in the per-cycle means (a steady loop has the same
    # mean force and displacement every cycle). Remove both and average again.
    sc = loop.scatter
    tt = t if t is not None else np.arange(x.size, dtype=float)
    tm = float(np.mean(sc.time))
    f_drift = trend(sc.time, sc.mean_force)
    F = F - f_drift[0] * (tt - tm)
    x_drift = (0.0, 0.0)
    if sc.mean_x is not None:
        x_drift = trend(sc.time, sc.mean_x)
        x = x - x_drift[0] * (tt - tm)
    loop = average_loop(
        x, F, t, n_points=n_points, rel_threshold=rel_threshold, min_cycles=min_cycles
    )
    return Detrended(x, F, loop, Drift(f_drift, x_drift, tt, tm))


# -- 2. the data the fit sees ------------------------------------------------------------


@dataclass(frozen=True)
class FitData:
    """Data of the fit: ``xd, Fd`` (averaged bins or samples) with base weights ``w``, the
    noise-free monotone path ``xpath`` fed to the operator, the fitted stretch ``start:stop``
    and what the model needs about the turns."""

    on: str
    steady: bool
    x: np.ndarray  # the whole (detrended) displacement signal
    F: np.ndarray
    t: np.ndarray | None
    loop: AveragedLoop | None
    xd: np.ndarray
    Fd: np.ndarray
    w: np.ndarray
    td: np.ndarray | None
    xpath: np.ndarray
    rev: Reversals
    start: int
    stop: int | None
    bin_var: np.ndarray | None
    nodes: tuple[np.ndarray, ...] | None
    measured: VirginTurns | None
    amplitude0: float
    centre0: float

    @property
    def sl(self) -> slice:
        return slice(self.start, self.stop)

    @property
    def vnodes(self) -> VirginTurns | None:
        """Turn values a virgin-history fit holds fixed."""
        return None if self.steady else self.measured


def _bin_var(loop: AveragedLoop) -> np.ndarray | None:
    if loop.x_var is None or loop.n_cycles <= 1:
        return None
    # spread of the true x inside a bin: the samples' spread less the sensor noise
    s2 = loop.x_std**2 * loop.count / loop.n_cycles
    if not np.any(np.isfinite(s2)):  # no bin with a spread (found by fuzzing: a warning)
        return None
    s2x = float(np.nanmean(s2))
    return np.clip(loop.x_var - s2x, 0.0, None)


def _virgin_stop(rev: Reversals) -> int | None:
    # An unconfirmed last extreme (no centre crossing after it) has no measured turn: the
    # projected path's extreme there is the most outlying noisy sample, and every sample
    # after it would follow a branch started from that outlier. The operator is causal, so
    # dropping those samples leaves the rest of the fit exact.
    confirmed = np.r_[rev.peaks, rev.valleys]
    late = rev.edges[rev.edges > (confirmed.max() if confirmed.size else 0)]
    return int(late[-1]) if late.size else None


def fit_data(
    det: Detrended, t: np.ndarray | None, *, on: str, steady: bool, rel_threshold: float
) -> FitData:
    """Step 2: the averaged loop's bins (``on="averaged"``) or every sample, the monotone
    path between the turns, and the fitted stretch (a steady fit starts at the first turn,
    a virgin-history fit stops at its last confirmed one)."""
    xa, Fa, loop = det.x, det.F, det.loop
    bin_var = None
    if on == "averaged":
        if loop is None:
            raise InputError("an averaged fit needs an averaged loop (at least 2 cycles)")
        xd, Fd, w, td = loop.x, loop.F, np.sqrt(loop.count), None
        start = 0
        xpath = monotone_path(xd, np.array([xd.size // 2]))
        bin_var = _bin_var(loop)
        rev = loop.reversals
    else:
        rev = (
            loop.reversals
            if loop is not None
            else find_reversals(xa, t, rel_threshold=rel_threshold)
        )
        if rev.peaks.size + rev.valleys.size == 0:
            raise InputError("no reversal found in x: the recording holds no loop")
        start = rev.first if steady else 0
        xd, Fd, td = xa, Fa, t
        w = np.ones(xa.size)
        xpath = monotone_path(xa, rev.turns)
    lo_x, hi_x = float(np.min(xpath[start:])), float(np.max(xpath[start:]))
    amplitude0 = 0.5 * (hi_x - lo_x)
    if not amplitude0 > 0:
        raise InputError("the displacement does not move: amplitude is 0")
    stop = _virgin_stop(rev) if (on == "signal" and not steady) else None
    # measured turns: the path around each is replaced by its local regression (denoised;
    # their errors are carried into the covariance); a virgin-history fit also holds the
    # turns' values, a steady one fits x0 ± A instead
    measured = virgin_nodes(xa, t, xpath, rev) if on == "signal" else None
    nodes = turn_nodes(xpath, rev.peaks, rev.valleys) if on == "signal" and steady else None
    return FitData(
        on=on,
        steady=steady,
        x=xa,
        F=Fa,
        t=t,
        loop=loop,
        xd=xd,
        Fd=Fd,
        w=w,
        td=td,
        xpath=xpath,
        rev=rev,
        start=start,
        stop=stop,
        bin_var=bin_var,
        nodes=nodes,
        measured=measured,
        amplitude0=amplitude0,
        centre0=0.5 * (hi_x + lo_x),
    )


# -- 3. starting values ------------------------------------------------------------------


@dataclass(frozen=True)
class StartValues:
    params: list[Parameter]
    prior: tuple[float, float, float] | None  # turn regression: (x0, A, σ)
    half_force_range: float


def start_values(
    data: FitData,
    *,
    rel_threshold: float,
    fit_offset: bool,
    fit_x0: bool,
    fit_amplitude: bool,
    initial: dict[str, float] | None,
) -> StartValues:
    """Step 3: ``(k0, ac, offset, x0, A)`` from the loop's half force range and area
    (:func:`~contactlab.tangential.model.initial_guess`), the turning-point prior of a
    steady loop, bounds and scales."""
    xa, Fa, t, loop = data.x, data.F, data.t, data.loop
    guide = loop
    if guide is None:  # signal fit of a short recording: one cycle still guides the start
        try:
            guide = average_loop(xa, Fa, t, rel_threshold=rel_threshold, min_cycles=1)
        except InputError:
            guide = None
    if guide is not None:
        hm0 = 0.5 * float(guide.F.max() - guide.F.min())
        e0 = loop_area(guide.x, guide.F)
        off0 = 0.5 * float(guide.F.max() + guide.F.min())
    else:
        hm0 = 0.5 * float(np.ptp(Fa))
        e0 = 0.0
        off0 = float(np.mean(Fa))
    a0, c0 = data.amplitude0, data.centre0
    h0_init, ac_init = initial_guess(a0, hm0, e0)
    if initial:
        h0_init = float(initial.get("h0", h0_init))
        ac_init = float(initial.get("ac", ac_init))
    if not (h0_init > 0 and ac_init > 0):
        raise InputError(f"initial h0, ac must be > 0, got {h0_init}, {ac_init}")
    prior = turning_point_prior(loop) if (data.steady and loop is not None) else None
    # a fixed amplitude comes from the displacement channel's turn regression (the range of
    # bin means or samples is biased: bins cut the tips, noise widens the extremes)
    a_fixed = prior[1] if (prior is not None and not fit_amplitude) else a0
    k0 = h0_init * ac_init
    # ac·A at most 1e6 (a rectangle within a millionth of the stroke: no loop tells more; on a
    # noise-only record the fit would run on until ac² overflows)
    ac_max = max(_Z_MAX / a0, 10.0 * ac_init) if a0 > 0 else math.inf
    params = [
        Parameter("k0", k0, min=1e-9 * k0, unit="N/m"),
        Parameter("ac", ac_init, min=1e-9 * ac_init, max=ac_max, unit="1/m"),
        Parameter(
            "offset", off0 if fit_offset else 0.0, vary=fit_offset, unit="N", scale=max(hm0, 1e-300)
        ),
    ]
    if data.steady:
        params.append(
            Parameter("x0", c0, vary=fit_x0, min=c0 - a0, max=c0 + a0, unit="m", scale=a0)
        )
        params.append(
            Parameter(
                "amplitude",
                a0 if fit_amplitude else a_fixed,
                vary=fit_amplitude,
                min=0.5 * a0,
                max=1.5 * a0,
                unit="m",
            )
        )
    else:
        params.append(Parameter("x0", float(xa[0]), vary=fit_x0, unit="m", scale=max(a0, 1e-300)))
    return StartValues(params, prior, hm0)


# -- 4. residuals and fit ----------------------------------------------------------------


@dataclass(frozen=True)
class PriorRows:
    """The displacement channel's measurement of the turning points as extra residual rows,
    in the force residuals' units (``scale`` = the first fit's residual scale)."""

    names: tuple[str, ...]
    x0: float
    amplitude: float
    sigma: float
    scale: float


#: evaluations of an averaged model :meth:`Residuals.predict` keeps
_KEPT_MODELS = 4


@dataclass(frozen=True)
class Residuals:
    """Weighted residuals ``(model - data) · w`` of a parameter set, plus the prior rows.

    The keyword arguments of :meth:`predict` and :meth:`residual` perturb one input (path,
    fixed turn values, force data, measured turning points): the covariance steps take
    finite differences with them.
    """

    data: FitData
    w: np.ndarray
    prior: PriorRows | None = None
    #: the averaged model's last few evaluations at unperturbed inputs, by parameter values
    #: (:meth:`predict`); shared by the copies ``dataclasses.replace`` makes (other weights
    #: or prior rows: the model does not depend on them)
    models: dict[Any, tuple[FitData, np.ndarray]] = field(
        default_factory=dict, repr=False, compare=False
    )

    def predict(
        self,
        v: dict[str, float],
        *,
        xp: np.ndarray | None = None,
        vn: tuple[np.ndarray, np.ndarray] | None = None,
    ) -> np.ndarray:
        """The model force at the bins (``on="averaged"``) or samples for the parameter
        values ``v``; ``xp`` and ``vn`` perturb the path and the fixed turn values.

        An averaged model at the data's own path is kept for the last few parameter sets:
        the analysis evaluates it again at the fits' end points (the second fit's start, the
        drift covariance's base, the reported model), 5 of a window's 11 evaluations. A copy
        is returned, the same numbers."""
        d = self.data
        if xp is None and vn is None and d.on == "averaged":
            # (floats by their bits: -0.0 is not 0.0 here)
            key = (id(d), tuple((k, x.hex() if type(x) is float else x) for k, x in v.items()))
            hit = self.models.get(key)
            if hit is not None and hit[0] is d:
                return hit[1].copy()
            F = self._predict(v, None, None)
            if len(self.models) >= _KEPT_MODELS:
                del self.models[next(iter(self.models))]
            self.models[key] = (d, F)
            return F.copy()
        return self._predict(v, xp, vn)

    def _predict(
        self,
        v: dict[str, float],
        xp: np.ndarray | None,
        vn: tuple[np.ndarray, np.ndarray] | None,
    ) -> np.ndarray:
        d = self.data
        m = model_of(v)
        xp = d.xpath if xp is None else xp
        if d.on == "averaged":
            Fm = steady_loop_force(m, xp, v["x0"], v["amplitude"], d.bin_var)
            Fm = Fm + _beyond_turns(v, xp, d.bin_var)
        elif d.steady:
            Fm = steady_signal_force(m, xp, v["x0"], v["amplitude"], d.nodes, d.rev.first_is_peak)
        else:
            nd = vn if vn is not None else (None if d.vnodes is None else d.vnodes.nodes)
            Fm = virgin_signal_force(m, xp, v["x0"], nd)
        return Fm + v["offset"]

    def residual(
        self,
        v: dict[str, float],
        *,
        xp: np.ndarray | None = None,
        vn: tuple[np.ndarray, np.ndarray] | None = None,
        dF: np.ndarray | None = None,
        tips: tuple[float, float, float] | None = None,
    ) -> np.ndarray:
        d = self.data
        sl = d.sl
        Fdat = d.Fd if dF is None else d.Fd + dF
        r = (self.predict(v, xp=xp, vn=vn)[sl] - Fdat[sl]) * self.w[sl]
        pr = self.prior
        if pr is None:
            return r
        meas = {"x0": pr.x0, "amplitude": pr.amplitude}
        if tips is not None:
            meas = {"x0": tips[0], "amplitude": tips[1]}
        rows = [(v[k] - meas[k]) / pr.sigma * pr.scale for k in pr.names]
        return np.concatenate([r, rows])

    def __call__(self, v: dict[str, float]) -> np.ndarray:
        return self.residual(v)

    def jacobian(self, v: dict[str, float]) -> dict[str, np.ndarray]:
        """Analytic ``∂residual/∂(k0, ac, offset, x0, amplitude)`` of an averaged fit
        (:meth:`residual` unperturbed), from the steady loop's branches in closed form
        (PHYSICS.md §1): with ``h(y) = (k0/ac)(1 - e^{-ac y})``, ``u = x - x0`` and
        ``s`` half the distance from the branch's turn (``(A - u)/2`` descending, ``(u + A)/2``
        ascending), ``F = ±(h(A) - 2 h(s))`` plus the bins' curvature term
        ``±¼ k0 ac e^{-ac s} var(x)`` (:func:`~contactlab.tangential.model.steady_loop_force`,
        which runs the Masing operator, and :func:`_beyond_turns`; tests check both against
        it and finite differences)."""
        d = self.data
        if d.on != "averaged":
            raise InputError("analytic derivatives are those of an averaged fit")
        k0, ac, x0, A = v["k0"], v["ac"], v["x0"], v["amplitude"]
        xp = d.xpath
        n = xp.size
        raw = xp - x0
        u = np.clip(raw, -A, A)
        inside = (raw > -A) & (raw < A)
        du_dx0 = np.where(inside, -1.0, 0.0)
        du_dA = np.where(raw >= A, 1.0, np.where(raw <= -A, -1.0, 0.0))
        sg = _branch_signs(n)  # descending, then ascending bins
        s = 0.5 * (A - sg * u)
        ds_dA = 0.5 * (1.0 - sg * du_dA)
        ds_dx0 = -0.5 * sg * du_dx0
        e, eA = np.exp(-ac * s), math.exp(-ac * A)
        hA, hs = -k0 / ac * math.expm1(-ac * A), -k0 / ac * np.expm1(-ac * s)
        dk0 = sg * (hA - 2.0 * hs) / k0
        dac = sg * (_h_ac(k0, ac, A) - 2.0 * _h_ac(k0, ac, s))
        dA = sg * (k0 * eA - 2.0 * k0 * e * ds_dA)
        dx0 = sg * (-2.0 * k0 * e * ds_dx0)
        if d.bin_var is not None:
            G = sg * 0.25 * k0 * ac * e * d.bin_var
            dk0 = dk0 + G / k0
            dac = dac + G * (1.0 / ac - s)
            dA = dA - ac * G * ds_dA
            dx0 = dx0 - ac * G * ds_dx0
        beyond = _beyond_turns(v, xp, d.bin_var, derivatives=True)
        if beyond is not None:
            dk0, dac, dx0, dA = dk0 + beyond[0], dac + beyond[1], dx0 + beyond[2], dA + beyond[3]
        sl, w = d.sl, self.w[d.sl]
        cols = {"k0": dk0, "ac": dac, "offset": np.ones(n), "x0": dx0, "amplitude": dA}
        out = {k: c[sl] * w for k, c in cols.items()}
        pr = self.prior
        if pr is not None:
            for k in out:
                rows = [(pr.scale / pr.sigma if k == name else 0.0) for name in pr.names]
                out[k] = np.concatenate([out[k], rows])
        return out

    def solver(self) -> Callable[..., tuple[np.ndarray, int, int]] | None:
        """The compiled Levenberg–Marquardt solver of this averaged fit
        (:func:`contactlab._core.fit_steady_loop`: the residuals and derivatives of
        :meth:`jacobian` in closed form with the bins beyond a turn continued as
        :func:`_beyond_turns` does, the whole solve with the interpreter lock released),
        as :func:`~contactlab.fitting.least_squares_fit`'s ``solver``; None where the fit is
        not an averaged one over all bins (the SciPy solver then runs)."""
        d = self.data
        if d.on != "averaged" or d.start != 0 or d.stop is not None:
            return None
        pr = self.prior
        prior = None
        if pr is not None:
            prior = (
                pr.x0 if "x0" in pr.names else None,
                pr.amplitude if "amplitude" in pr.names else None,
                pr.sigma,
                pr.scale,
            )
        x = np.ascontiguousarray(d.xpath, dtype=np.float64)
        F = np.ascontiguousarray(d.Fd, dtype=np.float64)
        w = np.ascontiguousarray(self.w, dtype=np.float64)
        bv = None if d.bin_var is None else np.ascontiguousarray(d.bin_var, dtype=np.float64)

        def solve(
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
            max_nfev: int,
        ) -> tuple[np.ndarray, int, int]:
            pos = {n: i for i, n in enumerate(_ORDER)}
            values, vary = [0.0] * 5, [False] * 5
            sc, lower, upper = [1.0] * 5, [-math.inf] * 5, [math.inf] * 5
            for n, v in fixed.items():
                values[pos[n]] = float(v)
            for j, n in enumerate(names):
                i = pos[n]
                values[i], vary[i] = float(z0[j] * scale[j]), True
                sc[i], lower[i], upper[i] = float(scale[j]), float(lo[j]), float(hi[j])
            setup = (values, vary, sc, lower, upper)
            got, nfev, status = _core.fit_steady_loop(
                x, F, w, bv, prior, setup, (rscale, ftol, xtol, gtol), max_nfev
            )
            z = np.array([got[pos[n]] / scale[j] for j, n in enumerate(names)])
            return z, nfev, status

        return solve


def _beyond_turns(
    v: dict[str, float], xp: np.ndarray, bin_var: np.ndarray | None, *, derivatives: bool = False
) -> Any:
    """What the branches' tangent continuation adds to :func:`steady_loop_force` at the bins
    beyond the turning points ``x0 ± A`` (0 elsewhere), where the operator clips them; with
    ``derivatives``, its derivatives ``(k0, ac, x0, A)`` instead (None: no bin beyond).

    A bin's mean displacement carries the sensor's noise (``σx² / count``), so the bins next
    to a turn, whose true distance from it is far below that noise on a finely binned loop,
    often read beyond the fitted turn. Clipped there, they would lose the force error their
    noise makes and keep it only when it falls inside: the fitted turn then follows the
    inward errors (a truncated sample), an amplitude biased low by a fraction of the bins'
    noise, ∝ 1/(number of cycles) (1 % noise on x: -0.17 % at 3 cycles, z -0.4). On the
    branch's tangent at the turn (force and slope continuous, the curvature term's too) the
    force error stays linear in the noise at every bin, and its mean vanishes. The compiled
    solver (``rust/core/src/loop_fit.rs``) continues the bins the same way; a first version
    that left it clipping and let the polish move the fit took 10 → 21 ms a 10⁶-sample
    window.

    With ``s = (A ∓ (x - x0)) / 2`` (descending, ascending bins) and ``s_c`` its clipped
    value (0 or ``A``), the loop's force ``±(h(A) - 2 h(s) + ¼ k0 ac e^{-ac s} var)`` goes on
    as ``∓ k0 e^{-ac s_c} (2 + ¼ ac² var) (s - s_c)``.
    """
    k0, ac, x0, A = v["k0"], v["ac"], v["x0"], v["amplitude"]
    n = xp.size
    sg = _branch_signs(n)
    s = 0.5 * (A - sg * (xp - x0))
    if s.min() >= 0.0 and s.max() <= A:  # no bin beyond a turn (the usual case: two
        # reductions instead of the clip, difference and test below; NaN goes on there)
        return None if derivatives else np.zeros(n)
    far = s > A  # beyond the turn that ends the branch
    sc = np.clip(s, 0.0, A)
    dd = s - sc
    if not np.any(dd):
        return None if derivatives else np.zeros(n)
    vv = 0.0 if bin_var is None else bin_var
    with np.errstate(over="ignore", invalid="ignore"):
        ec = np.exp(-ac * sc)
        q = 2.0 + 0.25 * ac * ac * vv
        add = -sg * k0 * ec * q * dd
        if not derivatives:
            return np.where(np.isfinite(add), add, 0.0)
        out = (
            add / k0,
            -sg * k0 * dd * ec * (0.5 * ac * vv - sc * q),
            -0.5 * k0 * q * ec,
            -sg * k0 * q * ec * ((0.5 - far) - ac * dd * far),
        )
    return tuple(np.where((dd != 0) & np.isfinite(c), c, 0.0) for c in out)


#: the largest ac·A a fit may reach
_Z_MAX = 1e6

#: parameter order of the compiled steady-loop fit
_ORDER = ("k0", "ac", "offset", "x0", "amplitude")


def _h_ac(k0: float, ac: float, y: Any) -> Any:
    """``∂h(y)/∂ac`` of ``h(y) = (k0/ac)(1 - e^{-ac y})`` at fixed ``k0``:
    ``(k0/ac²) g(ac·y)``, ``g(q) = q e^{-q} - (1 - e^{-q})``, by its series below q = 1e-3
    (``-q²/2 + q³/3 - q⁴/8 + q⁵/30``, truncation below 1e-14 relative), where the two terms
    cancel (a nearly linear loop, ac → 0)."""
    q = ac * np.asarray(y, dtype=float)
    with np.errstate(over="ignore", invalid="ignore"):
        big = q * np.exp(-q) + np.expm1(-q)
    small = q * q * (-0.5 + q * (1.0 / 3.0 + q * (-1.0 / 8.0 + q / 30.0)))
    return k0 / ac**2 * np.where(np.abs(q) < 1e-3, small, big)


def _restart(params: list[Parameter], raw: FitResult) -> list[Parameter]:
    """``params`` started from a fit's solution (clipped into their bounds)."""
    return [replace(p, value=min(max(raw.params[p.name].value, p.min), p.max)) for p in params]


def _keep_init(raw: FitResult, params: list[Parameter]) -> None:
    for p, p0 in zip(raw.params.values(), params, strict=True):
        p.init_value = p0.value if p0.vary else None


def eiv_weights(res: Residuals, raw: FitResult, s2x: float) -> np.ndarray:
    """Errors-in-variables weights ``sqrt(σF² / (σF² + (k σx)²))`` on the fitted stretch.

    The displacement noise σx moves every sample along its branch, a force error k·σx with
    the local stiffness k (h0·ac just after a turn, much less further on), heteroscedastic
    and largest exactly where the loop's shape is decided. σF comes from the unweighted
    fit's residuals less the part the x noise explains (at least 5 % of them).
    """
    d = res.data
    v1 = raw.values
    Fm = res.predict(v1)
    k2 = path_slope(Fm, d.xpath, v1["k0"])[d.sl] ** 2 * s2x
    r2 = float(np.mean((Fm - d.Fd)[d.sl] ** 2))
    s2F = max(r2 - float(np.mean(k2)), 0.05 * r2)
    w = np.ones(d.Fd.size)
    w[d.sl] = np.sqrt(s2F / (s2F + k2))
    return w


def branch_slope(v: dict[str, float], xpath: np.ndarray) -> np.ndarray:
    """Local stiffness ``|dF/dx|`` of the steady loop ``v`` at each averaged bin (bins
    ``0:n/2`` descending, ``n/2:n`` ascending): ``k0·exp(-ac·s)`` with ``s`` half the distance
    from the branch's turn (PHYSICS.md §1; the exact slope, where finite differences of the
    bins straddle the turns)."""
    n = xpath.size
    h = n // 2
    top, bot = v["amplitude"], -v["amplitude"]
    u = np.clip(xpath - v["x0"], bot, top)
    dist = np.concatenate([top - u[:h], u[h:] - bot])
    with np.errstate(over="ignore", under="ignore"):
        return v["k0"] * np.exp(-0.5 * v["ac"] * dist)


def loop_noise(loop: AveragedLoop) -> tuple[np.ndarray, np.ndarray]:
    """Per-sample noise variances of each averaged bin, force and displacement, from the
    cycle-to-cycle spread of the per-cycle bin means (``std² · count / n_cycles``)."""
    per_cycle = loop.count / max(loop.n_cycles, 1)
    return loop.F_std**2 * per_cycle, loop.x_std**2 * per_cycle


def averaged_eiv_weights(res: Residuals, raw: FitResult) -> np.ndarray | None:
    """Errors-in-variables weights of an averaged fit: ``sqrt(count · σF² / (σF² + (k σx)²))``.

    A bin's mean displacement carries the sensor noise ``σx / sqrt(count)``, which the model
    turns into a force error ``k σx / sqrt(count)`` (``k``: the branch's local stiffness,
    ``h0·ac`` just after a turn, :func:`branch_slope`); with a noisy displacement channel
    the bins next to the turns are the noisiest, and equal weights (``sqrt(count)``) both
    lose precision and misstate it (an h0 error 1.7-2.2x its scatter at 1 % x noise).
    ``σF²`` and ``σx²`` are the pooled cycle-to-cycle spreads of the bins (``σF²`` at least
    5 % of the total, so that no bin dominates where the branch is flat). None when the loop
    has no spread to estimate them from."""
    d = res.data
    loop = d.loop
    if loop is None or loop.n_cycles < 3:
        return None
    vF, vx = loop_noise(loop)
    if not (np.any(np.isfinite(vF)) and np.any(np.isfinite(vx))):
        return None
    s2F, s2x = float(np.nanmean(vF)), float(np.nanmean(vx))
    k2 = branch_slope(raw.values, d.xpath) ** 2 * s2x
    if not (np.all(np.isfinite(k2)) and s2F + float(np.mean(k2)) > 0):
        return None
    s2F = max(s2F, 0.05 * (s2F + float(np.mean(k2))))
    return np.sqrt(loop.count * s2F / (s2F + k2))


def fit(
    res: Residuals,
    start: StartValues,
    *,
    fit_x0: bool,
    fit_amplitude: bool,
    native: bool = True,
) -> tuple[FitResult, Residuals, float]:
    """Step 4: least squares; a whole-signal fit is refitted with errors-in-variables weights
    (σx estimated from the data), then the turning-point prior rows are added and the fit
    repeated from the solution. Returns ``(fit, final residuals, σx)``.

    An averaged fit is solved by the compiled Levenberg–Marquardt (:meth:`Residuals.solver`,
    without the interpreter lock) unless ``native=False``: SciPy's trust-region solver, the
    reference the tests compare it with. Both end in the same Gauss-Newton polish and
    covariance (:func:`~contactlab.fitting.least_squares_fit`)."""
    params = start.params

    def jac(r: Residuals) -> Any:
        # an averaged loop's derivatives in closed form (about 10x fewer model evaluations)
        return r.jacobian if r.data.on == "averaged" else None

    def solver(r: Residuals) -> Any:
        return r.solver() if native else None

    raw = least_squares_fit(res, params, jac=jac(res), solver=solver(res))
    x_noise = math.nan
    d = res.data
    with_prior = start.prior is not None and (fit_amplitude or fit_x0)
    s_f = math.sqrt(raw.redchi) if raw.redchi > 0 else 1.0
    if d.on == "averaged":
        w_eiv = averaged_eiv_weights(res, raw)
        if w_eiv is not None:
            res = replace(res, w=w_eiv)
            if with_prior:
                # one fit with the new weights and the prior rows (not one after the other:
                # a fit less a window, 2.5 ms of 45 on 1e6 samples); the rows' scale from
                # the reweighted residuals at the first solution
                r = res({k: p.value for k, p in raw.params.items()})
                nfree = r.size - raw.nvarys
                chi = float(r @ r) / nfree if nfree > 0 else math.nan
                s_f = math.sqrt(chi) if math.isfinite(chi) and chi > 0 else 1.0
            else:
                raw = least_squares_fit(
                    res, _restart(params, raw), jac=jac(res), solver=solver(res)
                )
                _keep_init(raw, params)
    elif d.on == "signal":
        s2x = x_noise_var(d.x, d.loop)
        x_noise = math.sqrt(s2x)
        if s2x > 0:
            res = replace(res, w=eiv_weights(res, raw, s2x))
            raw = least_squares_fit(res, _restart(params, raw))
            _keep_init(raw, params)
            s_f = math.sqrt(raw.redchi) if raw.redchi > 0 else 1.0
    if with_prior:
        assert start.prior is not None
        names = tuple(n for n, on in (("x0", fit_x0), ("amplitude", fit_amplitude)) if on)
        x0_d, a_d, sig = start.prior
        res = replace(res, prior=PriorRows(names, x0_d, a_d, sig, s_f))
        raw = least_squares_fit(res, _restart(params, raw), jac=jac(res), solver=solver(res))
        _keep_init(raw, params)
    return raw, res, x_noise


__all__ = [
    "Amplitude",
    "Detrended",
    "Drift",
    "FitData",
    "PriorRows",
    "Residuals",
    "StartValues",
    "amplitude_estimate",
    "averaged_eiv_weights",
    "branch_slope",
    "detrend",
    "drift_covariance",
    "eiv_weights",
    "fit",
    "fit_data",
    "fixed_amplitude_covariance",
    "loop_noise",
    "model_of",
    "propagate",
    "propagate_many",
    "start_values",
    "turn_covariance",
]
