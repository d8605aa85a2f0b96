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
from typing import Any, NamedTuple

import numpy as np

from .._arrays import as_1d
from .._moved import forward
from .._options import takes_options
from .._physical import check_channel
from ..errors import ContactLabWarning, InputError
from ..fitting import FitResult
from ..io import Recording
from . import lag, steps
from .orientation import Orientation, orient
from .preprocess import AveragedLoop
from .quantities import (
    _refuse_no_loop,
    derived_quantities,
    identifiability,
    loop_area_ratio,
    misfit_ratio,
)
from .regime import GROSS_SLIDING_Z as REGIME_GROSS_Z
from .regime import PRE_SLIDING_Z, Regime, classify, z_from_area_ratio
from .result import TangentialAnalysis
from .uncertainty import reparametrize

#: ``ac·A`` above which the loop is taken to have reached gross sliding (branch slope at the
#: turn below e^-3 = 5 % of the initial stiffness: the force has plateaued near ±h0)
GROSS_SLIDING_Z = 3.0
#: loop area / (4 A × half force range) above which a loop counts as nearly rectangular
GROSS_SLIDING_AREA_RATIO = 0.6
#: above this ``E / (4 A h_m)`` the recorded cycles' mean area exceeds what a friction loop of
#: the averaged loop's size can enclose (a rectangle gives 1; noise and drift add a few %): the
#: cycles are not one repeated loop (a multisine's response gives 3.3)
NOT_ONE_LOOP_AREA_RATIO = 1.25


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


def _check_options(on: str, history: str, n_points: int | None) -> None:
    if on not in ("averaged", "signal"):
        raise InputError(f"on must be 'averaged' or 'signal', got {on!r}")
    if history not in ("steady", "virgin"):
        raise InputError(f"history must be 'steady' or 'virgin', got {history!r}")
    if on == "averaged" and history == "virgin":
        raise InputError("history='virgin' applies to on='signal'; an averaged loop is steady")
    if n_points is not None and (n_points < 8 or n_points % 2):
        raise InputError(f"n_points must be even and >= 8, got {n_points}")


#: the fit's h0 gives way to the plateau's where they differ by more than this share (and 3
#: standard errors): beyond what an exponential branch's own approach to its asymptote makes
PLATEAU_DISAGREES = 0.03


def apply_regime(
    regime: Regime,
    amp: steps.Amplitude,
    fit: FitResult,
    identifiable: bool,
    evidence: dict[str, Any],
    derived: dict[str, tuple[float, float]],
    max_rel_stderr: float,
) -> None:
    """What the regime identifies: in gross sliding (and stick-slip) ``h0`` from the plateau
    (when the fit does not identify it) and only a lower bound on ``ac``. Updates
    ``evidence`` (per-parameter flags, ``h0_source``, message) and ``derived`` in place."""
    evidence["h0_source"] = "fit"
    pl = regime.plateau
    if not regime.sliding or pl is None:
        return
    derived["h0_plateau"] = (pl.h0, pl.h0_stderr)
    if identifiable:
        # the plateau measures h0 directly; the fit's h0 is its exponential curve's asymptote,
        # which a transition of another shape (a compliant rig, a tribometer's stage) pulls
        # away from the plateau (issue 31: +11 % on a micro-tribometer, +17-30 % on a
        # damper). Where the two agree (an exponential loop: the plateau's mean lies up to
        # ~2 % under the asymptote where the branch is still closing in), the fit stays.
        ph0 = fit.params["h0"]
        se = math.hypot(ph0.stderr or 0.0, pl.h0_stderr)
        gap = abs(ph0.value - pl.h0)
        if not gap > max(3.0 * se, PLATEAU_DISAGREES * pl.h0):
            return
        rel = pl.h0_stderr / pl.h0 if pl.h0 > 0 else math.inf
        evidence["h0"] = bool(rel < max_rel_stderr)
        evidence["h0_source"] = "plateau"
        evidence["message"] += (
            f"; h0 = {pl.h0:.4g} ± {pl.h0_stderr:.2g} N from the plateau ({pl.n_up} + "
            f"{pl.n_down} strokes): the exponential fit's asymptote, {ph0.value:.4g} N, is "
            f"{100 * (ph0.value / pl.h0 - 1):+.1f} % off it (the transition is not exponential)"
        )
        ph0.note = f"Masing-fit value; the plateau gives h0 = {pl.h0:.4g} ± {pl.h0_stderr:.2g} N"
        return
    rel = pl.h0_stderr / pl.h0 if pl.h0 > 0 else math.inf
    evidence["h0"] = bool(rel < max_rel_stderr)
    evidence["ac"] = False
    evidence["h0_source"] = "plateau"
    for k in ("h0_lower_bound", "ac_upper_bound"):  # the small-loop bounds do not apply
        derived.pop(k, None)
    derived["ac_lower_bound"] = (pl.ac_lower_bound, math.nan)
    # The Masing fit's h0·ac and curve are meaningless on a rectangle: the quantities that
    # follow from the plateau are E = 4 h0 A - 8 h0 / ac (ac ≥ its bound: the bound's range
    # enters the error), c_e·ω = E / (π A²), the peak force h0 and k_g = h0 / A; the initial
    # stiffness is only bounded below.
    A, sA = amp.value, amp.stderr if math.isfinite(amp.stderr) else 0.0
    h, sh = pl.h0, pl.h0_stderr
    half_gap = 4.0 * h / pl.ac_lower_bound
    e = 4.0 * h * A - half_gap
    se = math.sqrt((4 * A * sh) ** 2 + (4 * h * sA) ** 2 + half_gap**2)
    derived["energy_per_cycle"] = (e, se)
    derived["equivalent_damping"] = (e / (math.pi * A * A), se / (math.pi * A * A))
    derived["peak_force"] = (h, sh)
    derived["k_global"] = (h / A, math.hypot(sh / A, h * sA / A**2))
    for k in ("h0_ac", "k_local0", "k_local_amplitude"):
        derived.pop(k, None)
    derived["k_local0_lower_bound"] = (h * pl.ac_lower_bound, math.nan)
    evidence["h0_ac"] = False
    evidence["message"] = (
        f"{regime.name}: the loop reaches its plateau, so h0 = {pl.h0:.4g} ± "
        f"{pl.h0_stderr:.2g} N is identified from the plateau ({pl.n_up} + {pl.n_down} "
        f"strokes); ac is NOT identifiable here, only bounded below: ac ≥ "
        f"{pl.ac_lower_bound:.3g} 1/m (each branch covers 95% of its swing within "
        f"{pl.dx95:.3g} m)"
    )
    ph0, pac = fit.params["h0"], fit.params["ac"]
    ph0.identifiable = False
    ph0.note = f"Masing-fit value; the plateau gives h0 = {pl.h0:.4g} ± {pl.h0_stderr:.2g} N"
    pac.identifiable = False
    pac.note = f"not identifiable in {regime.name}: only ac >= {pl.ac_lower_bound:.3g} 1/m"


def collect_warnings(
    pre: list[str],
    raw: FitResult,
    data: steps.FitData,
    amplitude: float,
    identifiable: bool,
    evidence: dict[str, Any],
    regime: Regime,
    weights: np.ndarray | None = None,
    misfit: float | None = None,
) -> list[str]:
    """Everything the user should know about the fit: regime, identifiability, convergence,
    and a misfit beyond the cycle-to-cycle noise (``misfit``: :func:`misfit_ratio` of
    ``raw, data, weights`` when the caller has it already)."""
    # on a plateau the Masing fit is superseded: its numerical notes would only confuse
    plateau = evidence.get("h0_source") == "plateau"
    warns: list[str] = pre + ([] if plateau else list(raw.notes))
    loop = data.loop
    z = evidence["ac_times_amplitude"]
    ratio = regime.area_ratio
    if regime.sliding or (identifiable and z > GROSS_SLIDING_Z) or ratio > GROSS_SLIDING_AREA_RATIO:
        warns.append(
            f"amplitude {amplitude:.3g} m leaves the pre-sliding regime (gross sliding): "
            f"{regime.reason}; the pre-sliding model and its ac describe the loop poorly"
        )
    if ratio > NOT_ONE_LOOP_AREA_RATIO:
        warns.append(
            f"the recorded cycles enclose {100 * ratio:.0f}% of the rectangle 4·A·h_m that "
            "bounds any friction loop of the averaged loop's size: the cycles do not repeat "
            "one loop (an irregular or multi-frequency excitation, or the response of a "
            "structure rather than of a joint?), so the averaged loop and the fitted "
            "parameters do not describe them"
        )
    if not identifiable:
        warns.append(evidence["message"])
    if not raw.success and plateau:
        warns.append(
            "the exponential Masing fit cannot follow this nearly rectangular loop (its ac "
            "runs off towards infinity), which is why h0 comes from the plateau"
        )
    elif not raw.success:
        warns.append(f"the Masing fit did not converge ({raw.message})")
    if loop is not None and data.on == "averaged" and loop.n_cycles > 2:
        ratio_noise = misfit_ratio(raw, data, weights) if misfit is None else misfit
        if ratio_noise > 2.0:
            warns.append(
                f"the residuals are {ratio_noise:.1f}× the cycle-to-cycle noise of force and "
                "displacement: the exponential Masing model misses systematic features of this "
                "loop (look at the loop plot; a lag between the channels, viscous damping or a "
                "changing loop also do this)"
            )
    return warns


@takes_options
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
    force_sign: int | str = "auto",
    initial: dict[str, float] | None = None,
    warn: bool = True,
    delay: float | None = None,
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
    force_sign : {"auto", +1, -1}, default "auto"
        Analyse ``force_sign·F``. ``"auto"`` decides from physics: a passive joint
        dissipates, so the signed loop area ``∮ F dx`` over the complete cycles must be
        positive; when it is within its noise, the sign of the stiffness (F rising with x)
        decides (:func:`contactlab.tangential.orientation.orient`). Reported as
        ``force_sign`` and ``orientation_reason``; an automatic inversion is also a warning.
    invert_force : bool, optional
        Older spelling: True is ``force_sign=-1``, False is ``force_sign=+1``.
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
    delay : float, optional
        A known delay of the force channel behind the displacement (s; negative: the force
        leads), corrected before the analysis: the force is read ``delay`` later
        (:func:`contactlab.tangential.lag.shift_force`; the samples left without force data
        are dropped). Reported as ``delay`` and ``delay_dropped_samples``. Whatever it is,
        the averaged fit estimates the delay that remains (``channel_delay`` ±
        ``channel_delay_stderr``, s) and warns when it matters (:mod:`.lag`).

    Returns
    -------
    TangentialAnalysis

    Examples
    --------
    >>> from contactlab.synthetic.tangential import synthetic_recording
    >>> rec = synthetic_recording(h0=20.0, ac=1e5, amplitude=10e-6, n_cycles=5, seed=0)
    >>> res = analyze_tangential(rec)
    >>> res.identifiable, abs(res.fit.params["h0"].value - 20) < 3 * res.fit.params["h0"].stderr
    (True, True)
    """
    xa, Fa, ta, source, ori, dropped = _prepared(
        recording, t, x, F, on, history, n_points, invert_force, force_sign, delay
    )
    res = _analyze(
        xa,
        Fa,
        ta,
        source,
        ori,
        None,
        on=on,
        history=history,
        fit_offset=fit_offset,
        fit_x0=fit_x0,
        n_points=n_points,
        rel_threshold=rel_threshold,
        min_cycles=min_cycles,
        max_rel_stderr=max_rel_stderr,
        fit_amplitude=fit_amplitude,
        detrend=detrend,
        initial=initial,
        streamed=False,
        delay=delay,
    )
    assert res is not None  # only a streamed window hands its case back
    lag.record(res, delay, dropped)
    _issue(res.warnings, warn)
    return res


def _prepared(
    recording: Recording | None,
    t: Any,
    x: Any,
    F: Any,
    on: str,
    history: str,
    n_points: int | None,
    invert_force: bool | None,
    force_sign: int | str,
    delay: float | None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, str, Orientation, int]:
    """:func:`analyze_tangential`'s inputs checked, the known delay corrected and the force
    oriented: ``(x, F, t, source, orientation, samples dropped by the delay)``."""
    xa, Fa, ta, source = _inputs(recording, t, x, F)
    _check_options(on, history, n_points)
    check_channel("x", xa, "m", "displacement")
    check_channel("F", Fa, "N", "force")
    if invert_force is not None:
        force_sign = -1 if invert_force else 1
    dropped = 0
    if delay is not None:
        ta, xa, Fa, dropped = lag.shift_force(ta, xa, Fa, delay)
    return xa, Fa, ta, source, orient(xa, Fa, ta, force_sign=force_sign), dropped


def _issue(texts: list[str], warn: bool) -> None:
    """Each warning of the result as a :class:`ContactLabWarning` when ``warn``, attributed
    to the caller of :func:`analyze_tangential` (through its options wrapper)."""
    if warn:
        for wtxt in texts:
            warnings.warn(wtxt, ContactLabWarning, stacklevel=4)


def _fast_regime(z_fit: float | None, ratio: float) -> Regime | None:
    """The regime of a window whose ``z = ac·A`` is below gross sliding (pre-sliding or
    transition): what :func:`classify` decides there, without the velocity and stick search
    of the samples (which only gross sliding uses). None from gross sliding on."""
    if z_fit is not None and math.isfinite(z_fit):
        z, src = float(z_fit), "fit"
    else:
        z, src = z_from_area_ratio(ratio), "loop area"
    if not z < REGIME_GROSS_Z:
        return None
    zt = f"ac·A = {z:.3g} (from the {src}; loop area {100 * ratio:.0f}% of the rectangle 4·A·h_m)"
    if z < PRE_SLIDING_Z:
        return Regime("pre-sliding", f"pre-sliding (microslip): {zt}", z, src, ratio)
    return Regime("transition", f"transition towards gross sliding: {zt}", z, src, ratio)


def _unsearched_sticks(rev: Any, n_samples: int) -> dict[str, Any]:
    """``stick_slip`` of a streamed window below gross sliding, where the stick search over
    the samples does not run (it is a gross-sliding verdict, and its velocity estimate costs
    seconds a window): what the window knows, the reversals it has; NaN (null in JSON) for
    what only the search measures. The same keys as the whole-window analysis gives."""
    n_turns = int(rev.peaks.size + rev.valleys.size)
    if n_turns < 2 or n_samples < 20:  # where the search would give none either
        return {}
    unknown = (
        "reversals_with_stick",
        "stick_duration",
        "breakaway_force",
        "breakaway_force_stderr",
        "velocity_threshold",
        "smooth_turn_dwell",
        "reversals_with_dwell",
    )
    return {"stick_slip": {"n_reversals": n_turns, **dict.fromkeys(unknown, math.nan)}}


def _transient_warning(loop: AveragedLoop, amplitude: float, stderr: float) -> list[str]:
    """A start-up or run-out transient averaged in (:mod:`.startup`), when the shift it makes
    in the mean cycle amplitude is at least half the amplitude's standard error."""
    from .startup import transient_cycles

    sc = loop.scatter
    tr = transient_cycles(sc.amplitude, sc.time, sc.period, sc.energy)
    if tr is None:
        return []
    err = stderr if stderr is not None and math.isfinite(stderr) else 0.0
    if abs(tr.shift * amplitude) < 0.5 * err:
        return []
    return [tr.message()]


def _analyze(
    xa: np.ndarray,
    Fa: np.ndarray,
    ta: np.ndarray | None,
    source: str,
    ori: Orientation,
    pre: steps.Detrended | None,
    *,
    on: str,
    history: str,
    fit_offset: bool,
    fit_x0: bool | None,
    n_points: int | None,
    rel_threshold: float,
    min_cycles: int,
    max_rel_stderr: float,
    fit_amplitude: bool,
    detrend: bool,
    initial: dict[str, float] | None,
    streamed: bool,
    delay: float | None = None,
) -> TangentialAnalysis | None:
    """The analysis after the orientation; ``pre``: :func:`steps.detrend` of the oriented
    ``xa, Fa`` with these options, done already. ``streamed``: a window of
    :func:`analyze_window`, which hands back None when its loop reaches gross sliding."""
    steady = history == "steady"
    pre_warns = [f"analysed -F: {ori.reason}"] if (ori.sign < 0 and ori.by != "user") else []
    if ori.sign < 0 and pre is None:  # (a detrended window is negated already: no copy)
        Fa = -Fa
    fit_x0 = True if fit_x0 is None else fit_x0
    det = pre
    if det is None:
        det = steps.detrend(
            xa,
            Fa,
            ta,
            on=on,
            enabled=detrend,
            n_points=n_points,
            rel_threshold=rel_threshold,
            min_cycles=min_cycles,
        )
    f = _fitted(
        det,
        ta,
        on=on,
        steady=steady,
        rel_threshold=rel_threshold,
        min_cycles=min_cycles,
        fit_offset=fit_offset,
        fit_x0=fit_x0,
        fit_amplitude=fit_amplitude,
        initial=initial,
    )
    raw, amp, data = f.raw, f.amp, f.data
    fit = reparametrize(raw)
    identifiable, evidence = identifiability(fit, raw, amp.value, max_rel_stderr)
    h0_lo = evidence.pop("h0_lower_bound")
    ac_up = evidence.pop("ac_upper_bound")
    derived = derived_quantities(raw, amp, det, data.start)
    _refuse_no_loop(evidence, derived["energy_per_cycle_numeric"])
    if not identifiable:
        derived["h0_lower_bound"] = (h0_lo, math.nan)
        derived["ac_upper_bound"] = (ac_up, math.nan)
    ratio = loop_area_ratio(data, amp.value, derived["energy_per_cycle_numeric"][0])
    z_fit = evidence["ac_times_amplitude"] if identifiable else None
    if streamed:
        regime = _fast_regime(z_fit, ratio)
        if regime is None:
            return None
    else:
        regime = classify(
            z_fit=z_fit, ratio=ratio, loop=det.loop, x=det.x, F=det.F, t=ta, rev=data.rev, x_raw=xa
        )
    apply_regime(regime, amp, fit, identifiable, evidence, derived, max_rel_stderr)
    # (the warnings and the delay's both read the misfit of an averaged fit: computed once)
    misfit = misfit_ratio(raw, data, f.res.w) if on == "averaged" else None
    warns = collect_warnings(
        pre_warns, raw, data, amp.value, identifiable, evidence, regime, f.res.w, misfit
    )
    if steady and det.loop is not None:
        warns += _transient_warning(det.loop, amp.value, amp.stderr)
    if on == "averaged":  # the delay between the channels the loop shows (:mod:`.lag`)
        warns += lag.annotate(
            derived,
            fit,
            raw,
            f.res,
            data,
            sliding=regime.sliding,
            misfit=misfit,
            applied=delay,
        )
    regime_d = regime.to_dict()
    if streamed:
        regime_d.update(_unsearched_sticks(data.rev, xa.size))
    return TangentialAnalysis(
        fit=fit,
        model=steps.model_of(raw.values),
        amplitude=float(amp.value),
        amplitude_stderr=amp.stderr,
        loop=det.loop,
        scatter=det.loop.scatter if det.loop is not None else None,
        identifiable=identifiable,
        identifiability=evidence,
        derived=derived,
        regime=regime_d,
        warnings=warns,
        on=on,
        history=history,
        x=np.asarray(data.xd),
        F=np.asarray(data.Fd),
        F_model=f.res.predict(raw.values),
        weights=f.res.w,
        t=data.td,
        source=source,
        meta=_meta(data, f.x_noise, ori, regime),
    )


class _Fitted(NamedTuple):
    """What :func:`_fitted` gives: the fit data, the raw fit and its residuals, the
    displacement noise and the amplitude estimate."""

    data: steps.FitData
    raw: FitResult
    res: steps.Residuals
    x_noise: float
    amp: steps.Amplitude


def _fitted(
    det: steps.Detrended,
    ta: np.ndarray | None,
    *,
    on: str,
    steady: bool,
    rel_threshold: float,
    min_cycles: int,
    fit_offset: bool,
    fit_x0: bool,
    fit_amplitude: bool,
    initial: dict[str, float] | None,
) -> _Fitted:
    """The Masing fit of the detrended samples ``det`` with the covariance of what it takes
    as exact (drifts, turning points, a fixed amplitude) and the amplitude estimate."""
    data = steps.fit_data(det, ta, on=on, steady=steady, rel_threshold=rel_threshold)
    sv = steps.start_values(
        data,
        rel_threshold=rel_threshold,
        fit_offset=fit_offset,
        fit_x0=fit_x0,
        fit_amplitude=fit_amplitude,
        initial=initial,
    )
    raw, res, x_noise = steps.fit(
        steps.Residuals(data, data.w), sv, fit_x0=fit_x0, fit_amplitude=fit_amplitude
    )
    raw = steps.drift_covariance(
        raw, res, det.drift, rel_threshold=rel_threshold, min_cycles=min_cycles
    )
    raw, c_theta_amp = steps.turn_covariance(raw, res)
    raw, g_amp = steps.fixed_amplitude_covariance(raw, res, sv.prior, fit_amplitude)
    amp = steps.amplitude_estimate(
        raw, data, sv.prior, fit_amplitude=fit_amplitude, g_amp=g_amp, c_theta_amp=c_theta_amp
    )
    return _Fitted(data, raw, res, x_noise, amp)


def _meta(data: steps.FitData, x_noise: float, ori: Orientation, regime: Regime) -> dict[str, Any]:
    """The result's ``meta``: where the fit starts, the displacement noise, the orientation
    and, in a sliding regime, the plateau levels' mid-point and branch length (the loop
    plot's levels)."""
    return {
        "fit_start": data.start,
        "invert_force": ori.sign < 0,
        "x_noise": x_noise,
        "force_sign": ori.sign,
        "orientation_reason": ori.reason,
        "orientation_by": ori.by,
        "loop_area_recorded": (ori.loop_area, ori.loop_area_stderr),
        **(
            {"plateau_offset": regime.plateau.offset, "plateau_dx95": regime.plateau.dx95}
            if regime.plateau is not None
            else {}
        ),
    }


# analyze_window moved to contactlab.tangential.window (issue 32): the old name forwards
__getattr__ = forward(__name__, {"analyze_window": "contactlab.tangential.window"})
