"""Analysis of a tangential recording: average, fit ``h0, ac`` through the Rust Masing operator,
derive energy, damping and stiffness with propagated uncertainty, and say what is identified.

Implements the procedure of *Experimental investigation of tangential contact stiffness and
equivalent damping* (loops averaged over periods, eq. 1/6 fitted), with PHYSICS.md §1's
corrected energy ``E(A)``, equivalent damping ``c_e·ω = E / (π A²)`` (eq. 17), local stiffness
``f'(x)`` (eq. 18) and global stiffness ``f(A)/A`` (eq. 19).

Fitting is done in the parameters ``(k0 = h0·ac, ac, offset, x0, A)``: ``k0``, the initial
stiffness, is what a small loop determines; ``ac`` is determined only by the loop's curvature.
The covariance is transformed to ``(h0, ac)`` for reporting. The turning points ``x0 ± A``
are parameters (the paper's branch shift ``x0``), not the extremes of the noisy samples: those
overestimate the amplitude, and the loop is most sensitive exactly there. The displacement
channel's own measurement of the turning points (a regression of the bins next to each turn)
enters the fit as two extra residuals, so both channels locate them.

Inputs the fit takes as exact carry their own errors into the covariance, each through the
fit's linear response ``G = -(JᵀJ)⁻¹Jᵀ ∂r/∂u`` to the input ``u`` (``cov += G Σ_u Gᵀ``,
:func:`contactlab.fitting.add_covariance`):

- the linear force and displacement drifts removed before the fit (estimated from the
  per-cycle means, with their standard errors);
- a fixed amplitude (``fit_amplitude=False``: the displacement channel's turn regression,
  with ``Cov(θ, A)`` kept for the derived quantities);
- the measured turning points of a recording that starts at rest (``history="virgin"``: each
  turn's local regression, which also forms the denoised path around it).

Whole-signal fits are errors-in-variables problems: displacement noise ``σx`` moves each
sample along its branch, a force error ``k σx`` that is largest just after each turn (``k =
h0·ac``). Each residual is weighted by its effective variance ``σF² + (k σx)²``, with ``σx``
estimated from the data (``meta["x_noise"]``). A recording starting at rest is fitted only up
to its last confirmed turn. The turning points' errors include the truncation of their
regressions (:mod:`contactlab.tangential.turns`), which matters with a clean displacement
channel. Over many noise seeds about 95 % of the 2σ intervals of ``h0``, ``ac``, ``h0·ac``,
``E`` and ``A`` hold the truth (tests/test_tangential*.py; a whole-signal fit at 1 %
displacement noise: 94-95 %).

When the relative standard errors of ``h0`` or ``ac`` exceed ``max_rel_stderr`` (the paper's
steel case: amplitude ≪ 1/ac, the loop is nearly a straight line) the analysis reports them
as not identifiable and gives ``h0·ac`` with its error, plus a one-sided bound on each.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import replace
from typing import Any

import numpy as np

from .._arrays import as_1d
from .._range import check_channel
from ..errors import ContactLabWarning, InputError
from ..fitting import Parameter, add_covariance, least_squares_fit
from ..io import Recording
from ..masing import Masing, loop_area
from .model import (
    initial_guess,
    steady_loop_force,
    steady_signal_force,
    turn_nodes,
    virgin_signal_force,
)
from .preprocess import AveragedLoop, average_loop, find_reversals, monotone_path
from .result import TangentialAnalysis
from .turns import turning_point_prior, virgin_amplitude, virgin_nodes
from .uncertainty import (
    correl as _correl,
)
from .uncertainty import (
    numeric_energy as _numeric_energy,
)
from .uncertainty import (
    path_slope as _path_slope,
)
from .uncertainty import (
    propagate_fit as _propagate_fit,
)
from .uncertainty import (
    reparametrize as _reparametrize,
)
from .uncertainty import (
    trend as _trend,
)
from .uncertainty import (
    x_noise_var as _x_noise_var,
)

#: ``ac·A`` above which the loop is taken to have reached gross sliding (branch slope at the
#: turn below e^-3 = 5 % of the initial stiffness: the force has plateaued near ±h0)
GROSS_SLIDING_Z = 3.0
#: loop area / (4 A × half force range) above which a loop counts as nearly rectangular
GROSS_SLIDING_AREA_RATIO = 0.6


def _inputs(
    recording: Recording | None, t: Any, x: Any, F: Any
) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, str]:
    if recording is not None:
        if any(v is not None for v in (t, x, F)):
            raise InputError("give either a recording or t/x/F arrays, not both")
        if not isinstance(recording, Recording):
            raise InputError(f"expected a contactlab.io.Recording, got {type(recording).__name__}")
        for ch in ("x", "F"):
            if ch not in recording.data:
                raise InputError(
                    f"{recording.source}: no {ch!r} channel; a tangential recording needs x "
                    f"and F (channels: {sorted(recording.data)})"
                )
        for ch, unit in (("x", "m"), ("F", "N")):
            check_channel(recording[ch], ch, unit, recording.source)
        return recording["x"], recording["F"], recording.t, recording.source
    if x is None or F is None:
        raise InputError("give a recording, or the arrays x (m) and F (N)")
    xa = as_1d(x, "x")
    Fa = as_1d(F, "F")
    if xa.size != Fa.size:
        raise InputError(f"x has {xa.size} samples but F has {Fa.size}")
    ta = None
    if t is not None:
        ta = as_1d(t, "t")
        if ta.size != xa.size:
            raise InputError(f"t has {ta.size} samples but x has {xa.size}")
        if np.any(np.diff(ta) <= 0):
            i = int(np.argmax(np.diff(ta) <= 0)) + 1
            raise InputError(f"t[{i}] = {ta[i]} does not increase")
    check_channel(xa, "x", "m")
    check_channel(Fa, "F", "N")
    return xa, Fa, ta, "<arrays>"


def _model(v: dict[str, float]) -> Masing:
    return Masing(v["k0"] / v["ac"], v["ac"])


def analyze_tangential(
    recording: Recording | None = None,
    *,
    t: Any = None,
    x: Any = None,
    F: Any = None,
    on: str = "averaged",
    history: str = "steady",
    fit_offset: bool = True,
    fit_x0: bool | None = None,
    n_points: int | None = None,
    rel_threshold: float = 0.5,
    min_cycles: int = 2,
    max_rel_stderr: float = 0.2,
    fit_amplitude: bool = True,
    detrend: bool = True,
    invert_force: bool | None = None,
    initial: dict[str, float] | None = None,
    warn: bool = True,
) -> TangentialAnalysis:
    """Fit the Masing model to a tangential recording and derive the paper's quantities.

    Parameters
    ----------
    recording : Recording, optional
        With channels ``x`` (m) and ``F`` (N); or pass ``x``, ``F`` (and ``t``) directly.
    on : {"averaged", "signal"}
        Fit the period-averaged loop (the paper's way; noise averaged out, one cycle of
        bins) or every sample of the signal.
    history : {"steady", "virgin"}
        For ``on="signal"``: the recording is in the steady state of its outer loop (the fit
        then starts at the first reversal), or it starts at rest on the virgin curve.
    fit_offset : bool
        Fit a force offset (load-cell zero / loop centre). Otherwise it is 0.
    fit_x0 : bool, optional (default True)
        Fit the branch shift ``x0`` (the paper's eq. 1): on a steady loop the centre of the
        turning points ``x0 ± A``, for ``history="virgin"`` the displacement at rest.
    fit_amplitude : bool, default True
        On a steady loop, fit the turning points' half distance ``A`` instead of taking the
        extremes of noisy data (which overestimate it and bias ``h0``, ``ac``).
    detrend : bool, default True
        Remove linear force and displacement drifts (load cell, thermal drift of the
        displacement sensor) estimated from the per-cycle means (needs 3 complete cycles;
        reported as ``force_drift``, N/s, and ``displacement_drift``, m/s).
    invert_force : bool, optional
        Analyse ``-F``. By default this is done (with a warning) when the force falls as the
        displacement rises, i.e. the load cell counts the other way.
    n_points : int, optional
        Phase bins of the averaged loop (default: samples per cycle, 16..400).
    rel_threshold : float
        Reversal band as a fraction of the amplitude (see ``find_reversals``).
    min_cycles : int
        Minimum number of complete cycles for averaging.
    max_rel_stderr : float, default 0.2
        ``h0`` and ``ac`` count as identified only when both relative standard errors are
        below this (5σ from zero). Near the limit ``h0 = k0 / ac`` is far from linear in
        ``ac``, so first-order errors stop being trustworthy well before ``ac`` reaches zero
        (at 28 % the 2σ range of ``h0`` already spans a factor 2.3).
    initial : dict, optional
        Starting values ``{"h0": ..., "ac": ...}`` (default: from the loop's size and area).
    warn : bool
        Issue :class:`ContactLabWarning` for each warning (they are kept in ``.warnings``
        either way).

    Returns
    -------
    TangentialAnalysis

    Examples
    --------
    >>> from contactlab.tangential import synthetic_recording
    >>> rec = synthetic_recording(h0=20.0, ac=1e5, amplitude=10e-6, n_cycles=5, seed=0)
    >>> res = analyze_tangential(rec)
    >>> res.identifiable, abs(res.fit.params["h0"].value - 20) < 3 * res.fit.params["h0"].stderr
    (True, True)
    """
    xa, Fa, ta, source = _inputs(recording, t, x, F)
    if on not in ("averaged", "signal"):
        raise InputError(f"on must be 'averaged' or 'signal', got {on!r}")
    if history not in ("steady", "virgin"):
        raise InputError(f"history must be 'steady' or 'virgin', got {history!r}")
    if on == "averaged" and history == "virgin":
        raise InputError("history='virgin' applies to on='signal'; an averaged loop is steady")
    steady = history == "steady"
    pre_warns: list[str] = []
    xc = xa - xa.mean()
    inverted = float(xc @ (Fa - Fa.mean())) < 0
    if invert_force is None:
        invert_force = inverted
        if inverted:
            pre_warns.append(
                "the force falls as the displacement rises (sensor sign convention): "
                "analysed -F; pass invert_force=False to keep the sign"
            )
    if invert_force:
        Fa = -Fa
    if fit_x0 is None:
        fit_x0 = True
    if n_points is not None and (n_points < 8 or n_points % 2):
        raise InputError(f"n_points must be even and >= 8, got {n_points}")
    loop: AveragedLoop | None = None
    try:
        loop = average_loop(
            xa, Fa, ta, n_points=n_points, rel_threshold=rel_threshold, min_cycles=min_cycles
        )
    except InputError:
        if on == "averaged":
            raise
    drift = (0.0, 0.0)
    x_drift = (0.0, 0.0)
    drift_ref: tuple[np.ndarray, float] | None = None
    if detrend and loop is not None and loop.n_cycles >= 3:
        # Slow sensor drift shows as a trend in the per-cycle means (a steady loop has the
        # same mean force and displacement every cycle). Remove both and average again.
        sc = loop.scatter
        tt = ta if ta is not None else np.arange(xa.size, dtype=float)
        tm = float(np.mean(sc.time))
        drift = _trend(sc.time, sc.mean_force)
        drift_ref = (tt, tm)
        Fa = Fa - drift[0] * (tt - tm)
        if sc.mean_x is not None:
            x_drift = _trend(sc.time, sc.mean_x)
            xa = xa - x_drift[0] * (tt - tm)
        loop = average_loop(
            xa, Fa, ta, n_points=n_points, rel_threshold=rel_threshold, min_cycles=min_cycles
        )
    scatter = loop.scatter if loop is not None else None

    # -- data the fit sees --------------------------------------------------------------
    if on == "averaged":
        assert loop is not None
        xd, Fd, w = loop.x, loop.F, np.sqrt(loop.count)
        td = None
        start = 0
        h = xd.size // 2
        xpath = monotone_path(xd, np.array([h]))
        bin_var = None
        if loop.x_var is not None and loop.n_cycles > 1:
            # spread of the true x inside a bin: the samples' spread less the sensor noise
            s2x = float(np.nanmean(loop.x_std**2 * loop.count / loop.n_cycles))
            bin_var = np.clip(loop.x_var - s2x, 0.0, None)
        rev = loop.reversals
    else:
        rev = (
            loop.reversals
            if loop is not None
            else find_reversals(xa, ta, rel_threshold=rel_threshold)
        )
        if rev.peaks.size + rev.valleys.size == 0:
            raise InputError("no reversal found in x: the recording holds no loop")
        start = rev.first if steady else 0
        xd, Fd, td = xa, Fa, ta
        w = np.ones(xa.size)
        xpath = monotone_path(xa, rev.turns)
    lo_x, hi_x = float(np.min(xpath[start:])), float(np.max(xpath[start:]))
    amplitude0 = 0.5 * (hi_x - lo_x)
    centre0 = 0.5 * (hi_x + lo_x)
    if not amplitude0 > 0:
        raise InputError("the displacement does not move: amplitude is 0")

    # -- starting values ------------------------------------------------------------------
    guide = loop
    if guide is None:  # signal fit of a short recording: one cycle still guides the start
        try:
            guide = average_loop(xa, Fa, ta, rel_threshold=rel_threshold, min_cycles=1)
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
    h0_init, ac_init = initial_guess(amplitude0, hm0, e0)
    if initial:
        h0_init = float(initial.get("h0", h0_init))
        ac_init = float(initial.get("ac", ac_init))
    if not (h0_init > 0 and ac_init > 0):
        raise InputError(f"initial h0, ac must be > 0, got {h0_init}, {ac_init}")
    prior = turning_point_prior(loop) if (steady and loop is not None) else None
    # a fixed amplitude comes from the displacement channel's turn regression (the range of
    # bin means or samples is biased: bins cut the tips, noise widens the extremes)
    a_fixed = prior[1] if (prior is not None and not fit_amplitude) else amplitude0
    params = [
        Parameter("k0", h0_init * ac_init, min=1e-9 * h0_init * ac_init, unit="N/m"),
        Parameter("ac", ac_init, min=1e-9 * ac_init, unit="1/m"),
        Parameter(
            "offset", off0 if fit_offset else 0.0, vary=fit_offset, unit="N", scale=max(hm0, 1e-300)
        ),
    ]
    if steady:
        params.append(
            Parameter(
                "x0",
                centre0,
                vary=fit_x0,
                min=centre0 - amplitude0,
                max=centre0 + amplitude0,
                unit="m",
                scale=amplitude0,
            )
        )
        params.append(
            Parameter(
                "amplitude",
                amplitude0 if fit_amplitude else a_fixed,
                vary=fit_amplitude,
                min=0.5 * amplitude0,
                max=1.5 * amplitude0,
                unit="m",
            )
        )
    else:
        params.append(
            Parameter("x0", float(xa[0]), vary=fit_x0, unit="m", scale=max(amplitude0, 1e-300))
        )

    stop = None
    if on == "signal" and not steady:
        # An unconfirmed last extreme (no centre crossing after it) has no measured turn: the
        # projected path's extreme there is the most outlying noisy sample, and every sample
        # after it would follow a branch started from that outlier. The operator is causal,
        # so dropping those samples leaves the rest of the fit exact.
        confirmed = np.r_[rev.peaks, rev.valleys]
        late = rev.edges[rev.edges > (confirmed.max() if confirmed.size else 0)]
        if late.size:
            stop = int(late[-1])
    sl = slice(start, stop)
    first_is_peak = rev.first_is_peak
    # measured turns: the path around each is replaced by its local regression (denoised;
    # their errors are carried into the covariance below); a virgin-history fit also holds
    # the turns' values, a steady one fits x0 ± A instead
    measured = virgin_nodes(xa, ta, xpath, rev) if on == "signal" else None
    nodes = turn_nodes(xpath, rev.peaks, rev.valleys) if on == "signal" and steady else None
    vnodes = measured if not steady else None

    def predict(v: dict[str, float], xp: np.ndarray | None = None, vn: Any = None) -> np.ndarray:
        m = _model(v)
        xp = xpath if xp is None else xp
        if on == "averaged":
            Fm = steady_loop_force(m, xp, v["x0"], v["amplitude"], bin_var)
        elif steady:
            Fm = steady_signal_force(m, xp, v["x0"], v["amplitude"], nodes, first_is_peak)
        else:
            nd = (None if vnodes is None else vnodes.nodes) if vn is None else vn
            Fm = virgin_signal_force(m, xp, v["x0"], nd)
        return Fm + v["offset"]

    def residual(
        v: dict[str, float],
        xp: np.ndarray | None = None,
        vn: Any = None,
        dF: np.ndarray | None = None,
    ) -> np.ndarray:
        Fdat = Fd if dF is None else Fd + dF
        return (predict(v, xp, vn)[sl] - Fdat[sl]) * w[sl]

    raw = least_squares_fit(residual, params)
    x_noise = math.nan
    if on == "signal":
        # Errors in variables: the displacement noise σx moves every sample along its branch,
        # a force error k·σx with the local stiffness k (h0·ac just after a turn, much less
        # further on), heteroscedastic and largest exactly where the loop's shape is decided.
        # Weight each residual by its effective variance σF² + (k σx)² (σx from the data,
        # σF from the unweighted fit's residuals) and refit.
        s2x = _x_noise_var(xa, loop)
        x_noise = math.sqrt(s2x)
        if s2x > 0:
            v1 = raw.values
            Fm = predict(v1)
            k2 = _path_slope(Fm, xpath, v1["k0"])[sl] ** 2 * s2x
            r2 = float(np.mean((Fm - Fd)[sl] ** 2))
            s2F = max(r2 - float(np.mean(k2)), 0.05 * r2)
            w = np.ones(Fd.size)
            w[sl] = np.sqrt(s2F / (s2F + k2))
            start_w = [replace(p, value=min(max(v1[p.name], p.min), p.max)) for p in params]
            raw = least_squares_fit(residual, start_w)
            for p, p0 in zip(raw.params.values(), params, strict=True):
                p.init_value = p0.value if p0.vary else None
    extra: list[tuple[str, float]] = []
    s_f = 1.0

    def full_residual(
        v: dict[str, float],
        xp: np.ndarray | None = None,
        vn: Any = None,
        dF: np.ndarray | None = None,
        tips: tuple[float, float, float] | None = None,
    ) -> np.ndarray:
        r = residual(v, xp, vn, dF)
        if not extra:
            return r
        tp = prior if tips is None else tips
        assert tp is not None
        meas = {"x0": tp[0], "amplitude": tp[1]}
        pr = [(v[k] - meas[k]) / prior[2] * s_f for k, _ in extra]  # type: ignore[index]
        return np.concatenate([r, pr])

    if prior is not None and (fit_amplitude or fit_x0):
        # The displacement channel measures the turning points too. Add that measurement as
        # two more residuals, in the force residuals' units (their scale from the first fit),
        # and refit from the first solution.
        s_f = math.sqrt(raw.redchi) if raw.redchi > 0 else 1.0
        x0_d, a_d, _sig = prior
        if fit_x0:
            extra.append(("x0", x0_d))
        if fit_amplitude:
            extra.append(("amplitude", a_d))

        start_params = [replace(p, value=raw.params[p.name].value) for p in params]
        for p in start_params:
            p.value = min(max(p.value, p.min), p.max)
        raw = least_squares_fit(full_residual, start_params)
        for p, p0 in zip(raw.params.values(), params, strict=True):
            p.init_value = p0.value if p0.vary else None

    if drift_ref is not None and raw.jac is not None and raw.covar is not None:
        # The drifts were estimated (from per-cycle means) and removed before the fit, which
        # then took the data as exact. Carry their errors into the covariance:
        # G = ∂θ/∂s = -(JᵀJ)⁻¹Jᵀ ∂r/∂s (the residuals are linear in the removed trend),
        # cov += G diag(σ_s²) Gᵀ; the two slopes come from independent channels.
        tt, tm = drift_ref
        assert loop is not None  # drifts are estimated from its cycles
        # each bin's mean of (t - tm): what a unit slope removed from that bin
        T_bin = average_loop(
            xa, tt - tm, ta, n_points=loop.x.size, rel_threshold=rel_threshold,
            min_cycles=min_cycles,
        ).F  # fmt: skip
        T = T_bin if on == "averaged" else tt - tm
        vals0 = raw.values
        base = full_residual(vals0)
        cols = []
        if drift[1] > 0 and math.isfinite(drift[1]):
            cols.append(full_residual(vals0, dF=-drift[1] * T) - base)
        if x_drift[1] > 0 and math.isfinite(x_drift[1]):
            dx = x_drift[1] * T
            vn = None
            if vnodes is not None:
                at = tt[np.minimum(vnodes.positions, tt.size - 1)] - tm
                vn = (vnodes.positions, vnodes.values - x_drift[1] * at)
            tips = None
            if extra and loop is not None:
                tips = turning_point_prior(replace(loop, x=loop.x - x_drift[1] * T_bin))
            cols.append(full_residual(vals0, xp=xpath - dx, vn=vn, tips=tips) - base)
        if cols:
            G = -np.linalg.lstsq(raw.jac, np.column_stack(cols), rcond=None)[0]
            raw = add_covariance(raw, G @ G.T)
    c_theta_amp: np.ndarray | None = None
    if measured is not None and raw.jac is not None and raw.covar is not None:
        # The path around each measured turn is its local regression, and a virgin-history
        # fit holds the turn values fixed: carry each regression's error (three
        # independent 1σ modes per turn, the turns independent) into the covariance,
        # cov += Σ g gᵀ with g = -(JᵀJ)⁻¹Jᵀ ∂r for each mode.
        vals0 = raw.values
        base = full_residual(vals0)
        cols = []
        d_amp = []  # the same modes move the amplitude (half the peak-valley distance)
        n_pk = max(int(measured.is_peak.sum()), 1)
        n_vl = max(int((~measured.is_peak).sum()), 1)
        for j, (lo, hi, dpath, dval) in enumerate(measured.modes):
            share = 0.5 / n_pk if measured.is_peak[j] else -0.5 / n_vl
            for m_ in range(dval.size):
                d_amp.append(share * dval[m_])
                moved = measured.values.copy()
                moved[j] += dval[m_]
                xp_j = xpath.copy()
                xp_j[lo:hi] += dpath[:, m_]
                vn_j = None if steady else (measured.positions, moved)
                cols.append(full_residual(vals0, xp=xp_j, vn=vn_j) - base)
        G = -np.linalg.lstsq(raw.jac, np.column_stack(cols), rcond=None)[0]
        raw = add_covariance(raw, G @ G.T)
        if not steady:
            c_theta_amp = G @ np.asarray(d_amp)  # Cov(θ, A) through the shared turns
    g_amp: np.ndarray | None = None  # ∂θ/∂A when the amplitude was fixed from the x channel
    if steady and not fit_amplitude and prior is not None and raw.jac is not None:
        vals0 = raw.values
        col = full_residual(dict(vals0, amplitude=vals0["amplitude"] + prior[2]))
        g_amp = -np.linalg.lstsq(raw.jac, col - full_residual(vals0), rcond=None)[0]
        if raw.covar is not None:
            raw = add_covariance(raw, np.outer(g_amp, g_amp))
        g_amp = g_amp / prior[2]
    fit = _reparametrize(raw)
    vals = raw.values
    model = _model(vals)
    F_model = predict(vals)
    if steady and fit_amplitude:
        amplitude = float(vals["amplitude"])
        amplitude_stderr = float(raw.params["amplitude"].stderr or math.nan)
        a_extra = 0.0  # its error is in the covariance already
    else:
        amplitude = float(vals["amplitude"]) if steady else amplitude0
        if scatter is not None and scatter.n_cycles > 1:
            amplitude_stderr = float(
                np.std(scatter.amplitude, ddof=1) / math.sqrt(scatter.n_cycles)
            )
        else:
            amplitude_stderr = 0.0
        if steady and prior is not None:
            amplitude_stderr = prior[2]
        elif not steady:
            va, va_se = virgin_amplitude(xa, ta, rev)
            if math.isfinite(va) and math.isfinite(va_se):
                amplitude, amplitude_stderr = va, va_se
                if c_theta_amp is not None and va_se > 0:
                    g_amp = c_theta_amp / va_se**2  # so that Cov(θ, A) = g_amp σ_A²
        a_extra = amplitude_stderr

    # -- identifiability ------------------------------------------------------------------
    ph0, pac = fit.params["h0"], fit.params["ac"]
    rel_h0 = ph0.rel_stderr if ph0.stderr is not None else math.inf
    rel_ac = pac.rel_stderr if pac.stderr is not None else math.inf
    k0 = raw.params["k0"]
    rel_k0 = k0.rel_stderr if k0.stderr is not None else math.inf
    corr = _correl(fit, "h0", "ac")
    z = pac.value * amplitude
    at_bound = pac.value <= raw.params["ac"].min * 1.0001
    identifiable = bool(rel_h0 < max_rel_stderr and rel_ac < max_rel_stderr and not at_bound)
    ac_up = pac.value + 2 * pac.stderr if pac.stderr is not None else math.inf
    h0_lo = k0.value / ac_up if math.isfinite(ac_up) and ac_up > 0 else 0.0
    if identifiable:
        msg = (
            f"h0 and ac are identified (relative errors {100 * rel_h0:.1f}% and "
            f"{100 * rel_ac:.1f}%, correlation {corr:+.3f}, ac·A = {z:.3g})"
        )
    else:
        msg = (
            f"h0 and ac are NOT separately identifiable from this loop: ac·A = {z:.3g} "
            f"(the loop is {'nearly linear, a pure stiffness' if z < 0.5 else 'too noisy'}); "
            f"relative errors h0 {100 * rel_h0:.0f}%, ac {100 * rel_ac:.0f}%, correlation "
            f"{corr:+.3f}. Identified: h0·ac = {k0.value:.6g} ± {k0.stderr or math.nan:.3g} N/m"
            f" ({100 * rel_k0:.2f}%); ac < {ac_up:.3g} 1/m and h0 > {h0_lo:.3g} N (2σ)."
        )
        for p in (ph0, pac):
            p.identifiable = False
            p.note = "not separately identifiable: only h0·ac is (see identifiability)"
    identifiability = {
        "h0": identifiable,
        "ac": identifiable,
        "h0_ac": bool(rel_k0 < max_rel_stderr),
        "rel_stderr_h0": float(rel_h0),
        "rel_stderr_ac": float(rel_ac),
        "rel_stderr_h0_ac": float(rel_k0),
        "correlation_h0_ac": float(corr),
        "ac_times_amplitude": float(z),
        "condition": float(raw.condition),
        "max_rel_stderr": float(max_rel_stderr),
        "message": msg,
    }

    # -- derived quantities ---------------------------------------------------------------
    def energy(v: dict[str, float], A: float) -> float:
        return float(_model(v).loop_energy(A))

    def _propagate(fn: Any) -> tuple[float, float]:
        # the amplitude comes from the fit (with its covariance) when it was fitted
        if steady and fit_amplitude:
            return _propagate_fit(raw, lambda v, _A: fn(v, v["amplitude"]), amplitude, 0.0)
        return _propagate_fit(raw, fn, amplitude, a_extra, g_amp)

    derived: dict[str, tuple[float, float]] = {}
    derived["h0_ac"] = (float(k0.value), float(k0.stderr) if k0.stderr is not None else math.nan)
    derived["energy_per_cycle"] = _propagate(energy)
    derived["equivalent_damping"] = _propagate(lambda v, A: energy(v, A) / (math.pi * A * A))
    derived["k_local0"] = derived["h0_ac"]
    derived["k_local_amplitude"] = _propagate(lambda v, A: float(_model(v).local_stiffness(A)))
    derived["k_global"] = _propagate(lambda v, A: float(_model(v).global_stiffness(A)))
    derived["peak_force"] = _propagate(lambda v, A: float(_model(v).virgin(A)))
    if loop is not None:
        e_num, e_sem = _numeric_energy(loop, xa, Fa)
        if drift[1] > 0 and scatter is not None:
            # a drift error δs opens every cycle's polygon by δs·T·A
            period = float(np.mean(scatter.period))
            e_sem = math.hypot(e_sem, drift[1] * period * amplitude)
    else:
        e_num = loop_area(xa[start:], Fa[start:])
        e_sem = math.nan
    derived["energy_per_cycle_numeric"] = (float(e_num), e_sem)
    a2 = math.pi * amplitude**2
    derived["equivalent_damping_numeric"] = (float(e_num / a2), e_sem / a2)
    derived["force_drift"] = drift
    derived["displacement_drift"] = x_drift
    if not identifiable:
        derived["h0_lower_bound"] = (float(h0_lo), math.nan)
        derived["ac_upper_bound"] = (float(ac_up), math.nan)

    # -- warnings -------------------------------------------------------------------------
    warns: list[str] = pre_warns + list(raw.notes)
    hm_data = 0.5 * float(np.ptp(loop.F if loop is not None else Fa))
    ratio = e_num / (4 * amplitude * hm_data) if hm_data > 0 else 0.0
    if (identifiable and z > GROSS_SLIDING_Z) or ratio > GROSS_SLIDING_AREA_RATIO:
        warns.append(
            f"amplitude {amplitude:.3g} m leaves the pre-sliding regime (gross sliding): "
            f"ac·A = {z:.3g}, loop area is {100 * ratio:.0f}% of the rectangle 4·A·h_m, the "
            f"force plateaus near ±h0; the pre-sliding model and its ac describe the loop poorly"
        )
    if not identifiable:
        warns.append(msg)
    if not raw.success:
        warns.append(f"the fit did not converge: {raw.message}")
    if loop is not None and on == "averaged" and loop.n_cycles > 2:
        # Is the misfit larger than the cycle-to-cycle noise explains?
        per_cycle = loop.count / loop.n_cycles
        noise_var = float(np.nanmean(loop.F_std**2 * per_cycle))
        if noise_var > 0 and raw.redchi > 4.0 * noise_var:
            warns.append(
                f"the residuals are {math.sqrt(raw.redchi / noise_var):.1f}× the cycle-to-cycle "
                "noise: the exponential Masing model misses systematic features of this loop"
            )
    if warn:
        for wtxt in warns:
            warnings.warn(wtxt, ContactLabWarning, stacklevel=2)

    return TangentialAnalysis(
        fit=fit,
        model=model,
        amplitude=float(amplitude),
        amplitude_stderr=amplitude_stderr,
        loop=loop,
        scatter=scatter,
        identifiable=identifiable,
        identifiability=identifiability,
        derived=derived,
        warnings=warns,
        on=on,
        history=history,
        x=np.asarray(xd),
        F=np.asarray(Fd),
        F_model=F_model,
        weights=w,
        t=td,
        source=source,
        meta={"fit_start": start, "invert_force": bool(invert_force), "x_noise": x_noise},
    )
