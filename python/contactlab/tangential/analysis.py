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
enters the fit as two extra residuals, so both channels locate them. Over many noise seeds
about 95 % of the 2σ intervals of ``h0``, ``ac``, ``E`` and ``A`` hold the truth (tests).

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
from ..errors import ContactLabWarning, InputError
from ..fitting import FitResult, Parameter, least_squares_fit
from ..io import Recording
from ..masing import Masing, loop_area
from .model import (
    initial_guess,
    steady_loop_force,
    steady_signal_force,
    turn_nodes,
    turn_values,
    virgin_signal_force,
)
from .preprocess import AveragedLoop, Reversals, average_loop, find_reversals, monotone_path
from .result import TangentialAnalysis

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
    return xa, Fa, ta, "<arrays>"


def _propagate_fit(
    fit: FitResult,
    fn: Any,
    amplitude: float,
    amplitude_stderr: float,
) -> tuple[float, float]:
    """Value and error of ``fn(values, A)``: fit covariance plus the amplitude's error."""
    val, err = fit.propagate(lambda v: fn(v, amplitude))
    if amplitude_stderr > 0 and np.isfinite(amplitude_stderr):
        h = 1e-6 * amplitude
        d = (fn(fit.values, amplitude + h) - fn(fit.values, amplitude - h)) / (2 * h)
        err = math.sqrt(err**2 + (d * amplitude_stderr) ** 2)
    return float(val), float(err)


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
    if detrend and loop is not None and loop.n_cycles >= 3:
        # Slow sensor drift shows as a trend in the per-cycle means (a steady loop has the
        # same mean force and displacement every cycle). Remove both and average again.
        sc = loop.scatter
        tt = ta if ta is not None else np.arange(xa.size, dtype=float)
        tm = float(np.mean(sc.time))
        drift = _trend(sc.time, sc.mean_force)
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
                amplitude0,
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

    sl = slice(start, None)
    first_is_peak = rev.first_is_peak
    nodes = turn_nodes(xpath, rev.peaks, rev.valleys) if on == "signal" and steady else None
    vnodes = _virgin_nodes(xa, ta, xpath, rev) if on == "signal" and not steady else None

    def predict(v: dict[str, float]) -> np.ndarray:
        m = _model(v)
        if on == "averaged":
            Fm = steady_loop_force(m, xpath, v["x0"], v["amplitude"], bin_var)
        elif steady:
            Fm = steady_signal_force(m, xpath, v["x0"], v["amplitude"], nodes, first_is_peak)
        else:
            Fm = virgin_signal_force(m, xpath, v["x0"], vnodes)
        return Fm + v["offset"]

    def residual(v: dict[str, float]) -> np.ndarray:
        return (predict(v)[sl] - Fd[sl]) * w[sl]

    raw = least_squares_fit(residual, params)
    prior = _turning_point_prior(loop) if (steady and loop is not None) else None
    if prior is not None and (fit_amplitude or fit_x0):
        # The displacement channel measures the turning points too. Add that measurement as
        # two more residuals, in the force residuals' units (their scale from the first fit),
        # and refit from the first solution.
        s_f = math.sqrt(raw.redchi) if raw.redchi > 0 else 1.0
        x0_d, a_d, sig = prior
        extra = []
        if fit_x0:
            extra.append(("x0", x0_d))
        if fit_amplitude:
            extra.append(("amplitude", a_d))

        def residual_with_prior(v: dict[str, float]) -> np.ndarray:
            pr = [(v[k] - d) / sig * s_f for k, d in extra]
            return np.concatenate([residual(v), pr])

        start_params = [replace(p, value=raw.params[p.name].value) for p in params]
        for p in start_params:
            p.value = min(max(p.value, p.min), p.max)
        raw = least_squares_fit(residual_with_prior, start_params)
        for p, p0 in zip(raw.params.values(), params, strict=True):
            p.init_value = p0.value if p0.vary else None
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
        return _propagate_fit(raw, fn, amplitude, a_extra)

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
        meta={"fit_start": start, "invert_force": bool(invert_force)},
    )


def _trend(t: np.ndarray, v: np.ndarray) -> tuple[float, float]:
    """Least-squares slope of ``v`` against ``t`` and its standard error."""
    tm = float(np.mean(t))
    sxx = float(np.sum((t - tm) ** 2))
    slope = float(np.sum((t - tm) * (v - v.mean())) / sxx)
    res = v - v.mean() - slope * (t - tm)
    se = math.sqrt(float(res @ res) / (t.size - 2) / sxx) if t.size > 2 else math.nan
    return slope, se


def _virgin_nodes(
    x: np.ndarray, t: np.ndarray | None, xpath: np.ndarray, rev: Reversals
) -> tuple[np.ndarray, np.ndarray] | None:
    """Measured turning points for a virgin-history fit, inserted between samples (where
    the turn lies), with the projected path clipped so that no sample passes its turn."""
    tt = np.arange(x.size, dtype=float) if t is None else t
    times = np.r_[rev.peak_times, rev.valley_times]
    if times.size == 0:
        return None
    is_peak = np.r_[np.ones(rev.peaks.size, bool), np.zeros(rev.valleys.size, bool)]
    idx = np.r_[rev.peaks, rev.valleys].astype(np.int64)
    gaps = np.diff(np.sort(times))
    half = 0.1 * float(np.median(gaps)) if gaps.size else 0.05 * float(tt[-1] - tt[0])
    vals = turn_values(tt, x, times, half)
    pos, val = [], []
    for i, p_, v in zip(idx, is_peak, vals, strict=True):
        if not np.isfinite(v):
            continue
        sign = 1.0 if p_ else -1.0
        left = sign * xpath[i - 1] if i > 0 else -np.inf
        right = sign * xpath[i + 1] if i + 1 < x.size else -np.inf
        pos.append(i + 1 if right >= left else i)
        val.append(v)
        # no sample beyond its turn (noise would make the operator turn twice)
        near = np.abs(tt - tt[i]) <= half
        xpath[near] = np.minimum(xpath[near], v) if p_ else np.maximum(xpath[near], v)
    if not pos:
        return None
    order = np.argsort(pos, kind="stable")
    return np.asarray(pos, dtype=np.int64)[order], np.asarray(val, dtype=float)[order]


def _numeric_energy(loop: AveragedLoop, x: np.ndarray, F: np.ndarray) -> tuple[float, float]:
    """Energy per cycle as the mean area ``∮ F dx`` of the complete cycles' own samples, and
    its standard error.

    Each cycle's shoelace area is linear in each sample's ``F`` (and ``x``), with coefficients
    half the neighbours' difference in ``x`` (in ``F``), and sensor noise is independent from
    sample to sample, so the error follows from the per-sample noise variances, pooled over all
    phase bins from the cycle-to-cycle spread (many degrees of freedom, unlike the spread of a
    handful of per-cycle areas). Areas of raw samples, not of bin means, which would cut the
    corners at the turns.
    """
    e = loop.scatter.energy
    if loop.cycle_bounds is None or not np.any(np.isfinite(e)):
        return float(loop_area(loop.x, loop.F)), math.nan
    n = loop.n_cycles
    if n < 2:
        return float(np.nanmean(e)), math.nan
    per_cycle = loop.count / n
    s2F = float(np.nanmean(loop.F_std**2 * per_cycle))
    s2x = float(np.nanmean(loop.x_std**2 * per_cycle))
    var = 0.0
    for k in range(n):
        a, b = int(loop.cycle_bounds[k]), int(loop.cycle_bounds[k + 1])
        xs, Fs = x[a:b], F[a:b]
        dA_dF = 0.5 * (np.roll(xs, 1) - np.roll(xs, -1))
        dA_dx = 0.5 * (np.roll(Fs, -1) - np.roll(Fs, 1))
        var += float(np.sum(dA_dF**2) * s2F + np.sum(dA_dx**2) * s2x)
    err = math.sqrt(var) / n
    # Sampling also moves each cycle's polygon across the turns differently; when the areas
    # scatter more than the noise explains, their own spread is the better error.
    emp = float(np.nanstd(e, ddof=1)) / math.sqrt(n)
    err = max(err, emp) if math.isfinite(emp) else err
    return float(np.nanmean(e)), err if math.isfinite(err) else math.nan


def _tip(loop: AveragedLoop, first: int, k: int) -> tuple[float, float] | None:
    """Displacement at a turn and its standard error, from the ``k`` bins on either side.

    The turn lies on the boundary before bin ``first``. Bin means are regressed on the mean
    ``|φ|`` and ``φ²`` of each bin's samples (φ: phase from the turn), so the estimate is
    unbiased for a rounded (sine) turn and for a sharp (triangle) one alike, and not pulled
    by noise as the largest sample or bin would be.
    """
    n = loop.x.size
    idx = np.r_[np.arange(first - k, first), np.arange(first, first + k)] % n
    turn = first / n  # phase of the turn: 0 (peak) or 1/2 (valley)
    pm, p2 = loop.phase_mean[idx], loop.phase_sq[idx]
    before = np.r_[np.ones(k, bool), np.zeros(k, bool)]
    ref = np.where(before & (turn == 0.0), 1.0, turn)  # bins before the peak sit just below 1
    m1 = np.abs(pm - ref)
    m2 = p2 - 2.0 * ref * pm + ref * ref
    X = np.column_stack([np.ones(2 * k), m1, m2])
    y = loop.x[idx]
    coef, *_ = np.linalg.lstsq(X, y, rcond=None)
    resid = y - X @ coef
    dof = 2 * k - 3
    s2_fit = float(resid @ resid) / dof if dof > 0 else 0.0
    sb = loop.x_std[idx] / math.sqrt(loop.n_cycles)
    s2_bins = float(np.nanmean(sb**2)) if np.any(np.isfinite(sb)) else 0.0
    s2 = max(s2_fit, s2_bins)
    var0 = s2 * float(np.linalg.inv(X.T @ X)[0, 0])
    if not np.isfinite(var0):
        return None
    return float(coef[0]), math.sqrt(var0)


def _turning_point_prior(loop: AveragedLoop) -> tuple[float, float, float] | None:
    """Turning points measured by the displacement channel: ``(x0, A, σ)``.

    ``x0 = (top + bottom) / 2`` and ``A = (top - bottom) / 2`` from :func:`_tip`; with equal
    weights both have ``σ = sqrt(σ_top² + σ_bot²) / 2`` and no correlation.
    """
    n = loop.x.size
    k = 4
    if loop.n_cycles < 2 or n < 4 * k or loop.phase_mean is None or loop.phase_sq is None:
        return None
    top = _tip(loop, 0, k)
    bot = _tip(loop, n // 2, k)
    if top is None or bot is None:
        return None
    sig = 0.5 * math.hypot(top[1], bot[1])
    if not (sig > 0 and math.isfinite(sig)):
        return None
    return 0.5 * (top[0] + bot[0]), 0.5 * (top[0] - bot[0]), sig


def _correl(fit: FitResult, a: str, b: str) -> float:
    if fit.correl is None or a not in fit.var_names or b not in fit.var_names:
        return math.nan
    return float(fit.correl[fit.var_names.index(a), fit.var_names.index(b)])


def _reparametrize(raw: FitResult) -> FitResult:
    """``(k0, ac, ...)`` → ``(h0, ac, ...)`` with the covariance transformed to first order."""
    k0, ac = raw.params["k0"].value, raw.params["ac"].value
    h0 = k0 / ac
    params: dict[str, Parameter] = {}
    pk = raw.params["k0"]
    params["h0"] = Parameter(
        "h0",
        h0,
        vary=True,
        min=0.0,
        unit="N",
        init_value=(pk.init_value / raw.params["ac"].init_value)
        if pk.init_value and raw.params["ac"].init_value
        else None,
    )
    for name, p in raw.params.items():
        if name != "k0":
            params[name] = replace(p)
    names = ["h0" if n == "k0" else n for n in raw.var_names]
    covar = correl = None
    if raw.covar is not None:
        T = np.eye(len(names))
        i_k, i_a = raw.var_names.index("k0"), raw.var_names.index("ac")
        # h0 = k0 / ac
        T[i_k, i_k] = 1.0 / ac
        T[i_k, i_a] = -k0 / ac**2
        covar = T @ raw.covar @ T.T
        d = np.sqrt(np.clip(np.diag(covar), 0.0, None))
        with np.errstate(divide="ignore", invalid="ignore"):
            correl = covar / np.outer(d, d)
        correl[~np.isfinite(correl)] = 0.0
        np.fill_diagonal(correl, 1.0)
        for i, n in enumerate(names):
            src = raw.params["k0" if n == "h0" else n]
            if src.stderr is None and src.identifiable is False:
                params[n].stderr = None
                params[n].identifiable = False
            else:
                params[n].stderr = float(d[i])
                params[n].identifiable = True
    out = replace(raw, params=params, var_names=names, covar=covar, correl=correl, jac=None)
    out.notes = [n.replace("k0", "h0·ac") for n in raw.notes]
    return out
