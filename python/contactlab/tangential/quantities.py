"""Quantities an analysis of a tangential loop derives from its fit: identifiability of
``h0`` and ``ac``, energy per cycle, equivalent damping and stiffness with their errors, the
loop-area ratio and the misfit of an averaged fit against its cycle-to-cycle noise.

Split from :mod:`contactlab.tangential.analysis`, which names them as before."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import InputError
from ..fitting import FitResult
from ..masing import loop_area
from . import steps
from .uncertainty import correl, numeric_energy


def _percent(rel: float) -> str:
    """A relative standard error as a percentage for a message: beyond 1000 % the figure
    says nothing more than that the parameter is not determined ("1175301844650%" read as
    noise), so it is given as such."""
    if not math.isfinite(rel) or rel >= 10.0:
        return "over 1000% (undetermined)"
    return f"{100 * rel:.0f}%"


def identifiability(
    fit: FitResult, raw: FitResult, amplitude: float, max_rel_stderr: float
) -> tuple[bool, dict[str, Any]]:
    """Are ``h0`` and ``ac`` separately determined? Marks the parameters of ``fit`` that are
    not and returns ``(identifiable, evidence)``."""
    ph0, pac = fit.params["h0"], fit.params["ac"]
    rel_h0 = ph0.rel_stderr if ph0.stderr is not None else math.inf
    rel_ac = pac.rel_stderr if pac.stderr is not None else math.inf
    k0 = raw.params["k0"]
    rel_k0 = k0.rel_stderr if k0.stderr is not None else math.inf
    corr = correl(fit, "h0", "ac")
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
            f"relative errors h0 {_percent(rel_h0)}, ac {_percent(rel_ac)}, correlation "
            f"{corr:+.3f}. Identified: h0·ac = {k0.value:.6g} ± {k0.stderr or math.nan:.3g} N/m"
            f" ({100 * rel_k0:.2f}%); ac < {ac_up:.3g} 1/m and h0 > {h0_lo:.3g} N (2σ)."
        )
        if not rel_k0 < max_rel_stderr:
            msg += (
                " Not even h0·ac is determined: the force hardly follows the displacement "
                "(a noise-only or disconnected force channel?)."
            )
        for p in (ph0, pac):
            p.identifiable = False
            p.note = "not separately identifiable: only h0·ac is (see identifiability)"
    evidence = {
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
        "h0_lower_bound": float(h0_lo),
        "ac_upper_bound": float(ac_up),
    }
    return identifiable, evidence


def _refuse_no_loop(evidence: dict[str, Any], energy: tuple[float, float]) -> None:
    """Refuse a recording without a loop: neither the loop's initial stiffness h0·ac is
    determined nor its area (the energy per cycle from the samples) distinguishable from
    zero at 3 standard errors. Pure noise, a disconnected force channel or unrelated
    channels would otherwise give a result of undetermined numbers ("± nan", "ac < inf")."""
    if evidence["h0_ac"]:
        return
    e, e_err = energy
    if math.isfinite(e_err) and e_err > 0 and abs(e) > 3 * e_err:
        return
    area = f"{e:.3g} ± {e_err:.2g} J" if math.isfinite(e_err) else f"{e:.3g} J"
    raise InputError(
        "no friction loop in this recording: the force does not follow the displacement "
        f"(the loop's initial stiffness h0·ac is undetermined, relative error "
        f"{_percent(evidence['rel_stderr_h0_ac'])}, and the loop area {area} per cycle is "
        "not distinguishable from zero): a noise-only or disconnected force channel, or "
        "unrelated channels?"
    )


#: the model's quantities at the amplitude (:func:`_model_quantities`), in its order
_MODEL_QUANTITIES = (
    "energy_per_cycle",
    "equivalent_damping",
    "k_local_amplitude",
    "k_global",
    "peak_force",
)


def _model_quantities(v: dict[str, float], A: float) -> np.ndarray:
    """Energy per cycle, c_e·ω = E / (π A²) (eq. 17), local stiffness at the amplitude
    (eq. 18), global stiffness (eq. 19) and peak force of the model ``v`` at amplitude ``A``:
    one model for the five (their errors from one set of perturbed parameter values)."""
    m = steps.model_of(v)
    e = float(m.loop_energy(A))  # (refuses a non-finite A first, as before)
    f = float(m.virgin(A))
    # f(A) / A is what global_stiffness divides (its backbone value, the same call) away
    # from A = 0, where it takes the slope instead
    kg = f / A if A != 0.0 else float(m.global_stiffness(A))
    return np.array([e, e / (math.pi * A * A), float(m.local_stiffness(A)), kg, f])


def derived_quantities(
    raw: FitResult, amp: steps.Amplitude, det: steps.Detrended, start: int
) -> dict[str, tuple[float, float]]:
    """Energy per cycle (analytic and loop area), c_e·ω (eq. 17), stiffness (eqs. 18-19),
    peak force and drifts, each ``(value, stderr)``."""

    k0 = raw.params["k0"]
    derived: dict[str, tuple[float, float]] = {}
    derived["h0_ac"] = (float(k0.value), float(k0.stderr) if k0.stderr is not None else math.nan)
    derived.update(steps.propagate_many(raw, amp, _MODEL_QUANTITIES, _model_quantities))
    derived["k_local0"] = derived["h0_ac"]
    loop, xa, Fa = det.loop, det.x, det.F
    drift = det.force_drift
    if loop is not None:
        e_num, e_sem = numeric_energy(loop, xa, Fa)
        if drift[1] > 0:
            # a drift error δs opens every cycle's polygon by δs·T·A
            period = float(np.mean(loop.scatter.period))
            e_sem = math.hypot(e_sem, drift[1] * period * amp.value)
    else:
        e_num = loop_area(xa[start:], Fa[start:])
        e_sem = math.nan
    derived["energy_per_cycle_numeric"] = (float(e_num), e_sem)
    a2 = math.pi * amp.value**2
    derived["equivalent_damping_numeric"] = (float(e_num / a2), e_sem / a2)
    derived["force_drift"] = drift
    derived["displacement_drift"] = det.displacement_drift
    return derived


def loop_area_ratio(data: steps.FitData, amplitude: float, e_num: float) -> float:
    """``E / (4 A h_m)``: 0 for a line, 1 for the Coulomb rectangle (h_m from the data)."""
    hm = 0.5 * float(np.ptp(data.loop.F if data.loop is not None else data.F))
    return e_num / (4 * amplitude * hm) if hm > 0 and amplitude > 0 else 0.0


def misfit_ratio(raw: FitResult, data: steps.FitData, weights: np.ndarray | None) -> float:
    """RMS of an averaged fit's residuals over what the cycle-to-cycle noise explains (1 for
    a model that fits to the noise; NaN when there is no spread to compare with).

    A bin's mean force errs by its force noise and its mean displacement by the displacement
    noise, which the model turns into a force error ``k σx`` (``k``: the branch's local
    stiffness, ``h0·ac`` at the turns, :func:`steps.branch_slope`): the expected squared
    residual of bin ``i`` is ``(σF,i² + k_i² σx,i²) / count_i`` (per-sample variances from
    the cycle-to-cycle spread), weighted as the fit weights it. Force noise alone is not
    enough: with a noisy displacement channel and a clean force the residuals were 2.0-3.0×
    the force's spread, a warning about a model that fits."""
    loop = data.loop
    if loop is None or loop.n_cycles < 2:
        return math.nan
    vF, vx = steps.loop_noise(loop)
    k = steps.branch_slope(raw.values, data.xpath)
    expected = vF + k * k * np.nan_to_num(vx, nan=0.0)
    ok = np.isfinite(expected)
    if not ok.any():  # no bin with a spread (numpy would warn on an empty mean)
        return math.nan
    w2 = (weights[: loop.count.size] ** 2 if weights is not None else loop.count) / loop.count
    noise = float(np.mean((w2 * expected)[ok]))
    if not noise > 0:
        return math.nan
    return math.sqrt(raw.redchi / noise)
