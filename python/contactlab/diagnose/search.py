"""The moves of the stepwise candidate search: a candidate tried (forward), an effect
checked for removal (backward), a swap, a pair (moved from :mod:`.workflow`)."""

from __future__ import annotations

import dataclasses
import itertools
from dataclasses import dataclass, field
from functools import partial
from typing import Any

import numpy as np

from ..errors import ContactLabError, ConvergenceError, InputError
from ._family import Family, Prepared
from ._parallel import pmap
from .select import MIN_RELATIVE_GAIN, FitOut, Trial, Verdict, evaluate, fit, judge

#: an effect may refine the base model, not replace it: the base parameters that carry the
#: joint's physics (tangential h0, the friction force; normal k, the contact stiffness) may
#: move by at most this fraction from the base fit when an effect is added
MAX_BASE_SHIFT = 0.3
#: ... unless the effect explains most of the base model's misfit: its model leaves at most
#: EXPLAINED_SHARE of the current model's held-out excess error (mean square above the
#: noise's). A base fitted without an effect the data hold is biased by it — a breakaway
#: after each reversal made the base fit h0 = 28.95 N where the rig's contact has 40 N,
#: and its model with the breakaway, h0 = 40.1 N, was refused as "taking over" — so then
#: the base parameters may move by up to MAX_BASE_SHIFT_EXPLAINED
EXPLAINED_SHARE = 0.2
MAX_BASE_SHIFT_EXPLAINED = 0.5
#: ... and by up to MAX_BASE_SHIFT_MOSTLY when it leaves at most MOSTLY_SHARE of it (a
#: breakaway at ac·A = 0.8 biased the base fit to h0 = 24.3 N, 40 N in truth: +67 %)
MOSTLY_SHARE = 0.1
MAX_BASE_SHIFT_MOSTLY = 1.0
_ANCHORS = {"tangential": ("h0",), "normal": ("k",)}
#: the regimes (analyze's decision) whose loops never reach a plateau, so the base reads
#: h0 by extrapolation and the anchor is the initial stiffness h0·ac: pre-sliding, and the
#: transition (a dashpot's loop area, read by the base as the way to gross sliding, moved
#: h0 from 24 to 40 N, the truth, at ac·A 0.53 behind an LVDT's low-pass; the base fit
#: called it transition at ac·A 1.2: rig seed 1000, --chain sensors)
ANCHOR_STIFFNESS_REGIMES = ("pre-sliding", "transition")


def _takes_over(
    family: Family,
    base: dict[str, float],
    p: dict[str, float],
    effects: tuple[str, ...] = (),
    explains: float = 1.0,
    regime: str | None = None,
) -> str | None:
    """Why the model moves a base parameter that carries the joint's physics by more than
    :data:`MAX_BASE_SHIFT` (more when the model leaves only the share ``explains`` of the
    current misfit: :data:`MAX_BASE_SHIFT_EXPLAINED`, :data:`MAX_BASE_SHIFT_MOSTLY`), or
    None. An effect that rescales the base (a branch scale makes
    the loop's height ``λ h0 / 2``) is compared by its equivalent of the base parameter.

    In pre-sliding and transition (``regime``, as analyze decides it:
    :data:`ANCHOR_STIFFNESS_REGIMES`) a tangential loop never reaches its plateau and shows
    its initial stiffness ``h0·ac`` and curvature, not ``h0``: the anchor is then
    ``h0·ac`` (a dashpot's loop area, read by the base as curvature, moved h0 from 27.6 to
    40 N, its true value, at an unchanged stiffness: rig tuning seeds 1402-1408)."""
    from .effects import registry

    reg = registry(family.kind)
    equivalent = dict(p)
    for e in effects:
        if e in reg:
            equivalent.update(reg[e].base_equivalent(p))
    limit = MAX_BASE_SHIFT
    if explains <= EXPLAINED_SHARE:
        limit = MAX_BASE_SHIFT_MOSTLY if explains <= MOSTLY_SHARE else MAX_BASE_SHIFT_EXPLAINED
    # an effect that changes what the base was read from (a channel delay thins the loop whose
    # area decided the regime) may move it by its own ``max_base_shift``
    limit = max([limit] + [float(getattr(reg[e], "max_base_shift", 0.0)) for e in effects
                           if e in reg])  # fmt: skip
    # ... and an effect that only ever adds to what the base was read from (a dashpot adds
    # loop area, which the base fitted without it reads as a stiffer, more curved contact)
    # may lower it by its own ``max_base_lowering``
    lower = max([limit] + [float(getattr(reg[e], "max_base_lowering", 0.0)) for e in effects
                           if e in reg])  # fmt: skip
    anchors = _ANCHORS.get(family.kind, ())
    if regime in ANCHOR_STIFFNESS_REGIMES and family.kind == "tangential" and "ac" in base:
        anchors = ("h0·ac",)
        base = {**base, "h0·ac": base["h0"] * base["ac"]}
        equivalent["h0·ac"] = equivalent["h0"] * equivalent["ac"]
    for name in anchors:
        b, v = base[name], equivalent[name]
        if b > 0 and (v / b - 1.0 > limit or v / b - 1.0 < -lower):
            return (
                f"it takes over the base model ({name} from {b:.4g} to {v:.4g}): the base "
                "is in the wrong regime or the effect is not what the data show"
            )
    return None


def _explains(current: Trial, cand: Trial, sigma: float) -> float:
    """The share of the current model's held-out excess error (mean square above the
    noise's ``sigma²``) the candidate model leaves (1 when there is none to explain)."""
    excess = current.heldout_mse - sigma**2
    if not excess > 0:
        return 1.0
    return float(max(cand.heldout_mse - sigma**2, 0.0) / excess)


def _noise_floor(
    family: Family,
    names: tuple[str, ...],
    budget: float,
    d: Prepared | None = None,
    p: dict[str, float] | None = None,
    effects: tuple[str, ...] | None = None,
) -> float:
    """The input-noise budget a candidate adding ``names`` must beat, or 0 when every one of
    them is blind to the input's noise (an effect's ``input_noise_gain`` False: a factor
    or term in time only, such as a parameter drift, whose fit no input noise can feed —
    the budget kept a drift of the friction force of 6 % over 20 cycles, gain 0.12-0.15 σ²
    at t = 3.7-3.9, below a floor of 0.20 σ² at 2 % input noise). With the record ``d`` and
    the candidate's fitted parameters ``p``, an effect may state its share at those
    parameters (:func:`_noise_share`); with the candidate model's ``effects`` too, an
    effect that cannot filter the input (``input_noise_locked``) beats at most what the
    noise's systematic bias on this record gives its direction (:func:`locked_noise_gain`)."""
    from .effects import registry

    try:
        reg = registry(family.kind)
    except KeyError:
        return budget
    blind = all(not getattr(reg.get(n), "input_noise_gain", True) for n in names)
    if names and blind:
        return 0.0
    # an effect that can take only part of what the input's noise leaves (its
    # ``input_noise_share``, measured on clean records) beats that part of the budget; one
    # that cannot filter the input beats at most what the noise's bias gives it here
    locked = None
    if (
        d is not None
        and p is not None
        and effects is not None
        and any(getattr(reg.get(n), "input_noise_locked", False) for n in names)
    ):
        locked = locked_noise_gain(family, names, effects, d, p)
        if locked is not None:
            locked = NOISE_LOCKED_FACTOR * locked + locked_anchor_margin(budget, d)
    return max((_noise_part(reg.get(n), budget, locked, d, p) for n in names), default=budget)


#: the input-noise floor of an effect that cannot filter the input (its ``input_noise_locked``)
#: is at most NOISE_LOCKED_FACTOR times what the noise's simulated bias gives its direction on
#: the record (:func:`locked_noise_gain`; False: its share of the whole budget, as before
#: stop 51; a bench sets it off for a before/after)
NOISE_LOCKED_RULE = True
#: how many times that gain such an effect must beat (1: all of it)
NOISE_LOCKED_FACTOR = 1.0
#: the realization's own cycle-locked part of the input noise's effect, which the simulated
#: bias (:func:`locked_noise_gain`, fresh draws averaged) cannot see, as a share of the
#: input-noise budget times the record's complete cycles (:func:`locked_anchor_margin`; 0:
#: none, as at stop 51)
LOCKED_ANCHOR_SHARE = 2.5


def locked_anchor_margin(budget: float, d: Prepared | None) -> float:
    """The margin (σ²) the lowered floor of an effect that cannot filter the input adds to
    the simulated bias along its direction: :data:`LOCKED_ANCHOR_SHARE` times the
    input-noise ``budget`` over the record's complete cycles.

    Why (issue 29, stop 52): the Masing memory holds the record's own noisy turning points
    (the first loading's, the largest reversals'), so the input noise leaves a part locked
    to the cycle that is this record's, not the noise's expectation: the simulation, which
    adds fresh draws on top and averages them, does not reproduce it. On clean records of
    the package's generator (1 kHz, 5.9 Hz, 20 cycles, x noise 1.7 % of the range, ac·A
    3.2, ``benches/eval_posfric_clean_lowfs.py``, tuning seed 52200003 and its noise
    repeats) the noise-free force's residual along a track wave of 1.45 half-widths was
    0.23, 0.19, 0.15, 0.11 σ (RMS per sample) where the simulated bias gave 0.12, 0.19,
    0.22, 0.21 σ (sign included), even and odd cycles alike; with 60 cycles the two agreed
    within 0.01-0.05 σ: a one-off of the record, whose share falls as 1/cycles. A wave
    took 0.048-0.065 σ² held out at t 3.6-5.2 on 3 of 10 such records, against floors of
    0.025-0.040 σ² (the budget 0.47 σ²): named position_friction on 2."""
    if d is None or not LOCKED_ANCHOR_SHARE:
        return 0.0
    n = int(getattr(d.cycles, "n_cycles", 0) or 0)
    return float(LOCKED_ANCHOR_SHARE * budget / max(n, 1))


#: ``d.extra`` key of the effects accepted only by the lowered floor, with the floor of the
#: share of the whole budget they did not reach (the closing checks withdraw them from a
#: record whose misfit test still flags a misfit the final model leaves:
#: ``workflow._withdraw``)
LOCKED_ONLY = "locked_floor_only"
#: ``d.extra`` key of the record's simulated noise bias (:func:`locked_noise_state`)
LOCKED_STATE = "input_noise_locked"


def _noise_part(
    eff: object,
    budget: float,
    locked: float | None,
    d: Prepared | None = None,
    p: dict[str, float] | None = None,
) -> float:
    """The part of the input-noise ``budget`` (σ²) the effect ``eff`` must beat: its share
    (:func:`_noise_share`), and for an effect that cannot filter the input
    (``input_noise_locked``) at most ``locked`` (:func:`_noise_floor`: what the noise's
    bias gives the candidate's direction, or a share of the current misfit), when known."""
    part = budget * _noise_share(eff, d, p)
    if locked is not None and getattr(eff, "input_noise_locked", False):
        part = min(part, float(locked))
    return float(part)


def _note_locked_only(
    family: Family,
    names: tuple[str, ...],
    gain: float,
    floor: float,
    budget: float,
    d: Prepared,
    p: dict[str, float],
) -> None:
    """Keep in ``d.extra[LOCKED_ONLY]`` each of ``names`` accepted with a held-out ``gain``
    below its floor of the share of the whole input-noise budget (``floor``: its own
    ``min_gain`` share), which only the lowered floor of :func:`locked_noise_gain` let
    through; forget it when it reached that floor."""
    store = d.extra.setdefault(LOCKED_ONLY, {})
    old = floor + _noise_floor(family, names, budget, d, p)
    for n in names:
        if gain < old:
            store[n] = float(old)
        else:
            store.pop(n, None)


def locked_noise_state(
    family: Family,
    params: dict[str, float],
    effects: tuple[str, ...],
    d: Prepared,
    sigma: float,
) -> dict[str, Any] | None:
    """The residual structure the input's noise leaves in the model ``(params, effects)``
    on the record ``d``, simulated twice independently
    (:func:`~contactlab.diagnose.eiv.eiv_bias`, simulation-extrapolation, off the model's
    Jacobian), weighted, with the model's weighted Jacobian's orthonormal basis: what
    :func:`locked_noise_gain` projects on a candidate's direction. Kept in
    ``d.extra[LOCKED_STATE]`` (once per record; None when it cannot be simulated).

    Why (issue 29): the input-noise budget (``d.extra["input_noise_budget"]``) is the whole
    variance the input's noise adds to the weighted error per sample. A candidate that
    filters the input (a sub-sample delay, a dashpot reading a smoothed speed) can take a
    fixed share of it on every sample, however long the record: that share stays its
    floor. A candidate that is a function of the measured position or of time (a friction
    wave along the track; a normal load at a harmonic of the drive too, but it keeps the whole
    budget, its ``input_noise_locked`` False) cannot: of the noise's
    effect it can take only what repeats cycle after cycle, the bias a nonlinear model
    driven by a noisy input carries (turning points pushed outward at every reversal, a
    curved branch's mean by ``F''σ²/2``), and of that only the part along its own
    direction. The noise's random part, white in time, it takes only as any fit takes
    noise: a few parameters' worth over the record, a share that falls with the record's
    length and that rule 2 (a gain consistent across held-out cycles) judges. A floor
    fixed as a share of the whole budget asked a track's wave 0.065 σ² per sample on 14 000
    samples, four times the size an ideal test needs (``benches/eval_ideal_bound.py``,
    seed 51100000)."""
    if LOCKED_STATE in d.extra:
        return d.extra[LOCKED_STATE]
    from .eiv import eiv_bias
    from .misfit_null import _jacobian
    from .select import sample_weight

    out: dict[str, Any] | None = None
    try:
        b1 = eiv_bias(family, params, effects, d, seed=0) if sigma > 0 else None
        b2 = eiv_bias(family, params, effects, d, seed=1) if b1 is not None else None
        if b1 is not None and b2 is not None:
            w = np.asarray(sample_weight(d), float)
            use = np.isfinite(b1) & np.isfinite(b2) & (w > 0)
            sw = np.sqrt(w[use])
            J = _jacobian(family, params, effects, d)
            Q = None
            if J is not None and np.all(np.isfinite(J[use])):
                A = J[use] * sw[:, None]
                nrm = np.linalg.norm(A, axis=0)
                nrm[nrm == 0] = 1.0
                Q, _ = np.linalg.qr(A / nrm)
            if use.any():
                out = {"use": use, "sw": sw, "b1": b1[use] * sw, "b2": b2[use] * sw, "Q": Q,
                       "W": float(np.sum(w[use])), "s2": float(sigma) ** 2}  # fmt: skip
    except (ContactLabError, ValueError, ArithmeticError, np.linalg.LinAlgError):
        out = None
    d.extra[LOCKED_STATE] = out
    return out


def locked_noise_gain(
    family: Family,
    names: tuple[str, ...],
    effects: tuple[str, ...],
    d: Prepared,
    p: dict[str, float],
) -> float | None:
    """The held-out gain (σ² per sample) the input noise's systematic bias on this record
    (:func:`locked_noise_state`) gives a candidate model ``(p, effects)`` along the
    directions of the effects ``names`` (their size parameters, those with a null value;
    off the base model's Jacobian): ``b₁ᵀ P b₂ / Σ w`` with ``P`` the weighted projection on
    those directions and ``b₁, b₂`` two independent simulations of the bias (their product
    is free of the simulations' own scatter, which the extrapolation to no noise
    multiplies). The most such a candidate owes to the input's noise (beyond rule 2's
    judgement of its random part). None where the bias was not simulated."""
    state = d.extra.get(LOCKED_STATE)
    if state is None:
        return None
    use, sw = state["use"], state["sw"]
    scales = family.scales(d)
    cols = []
    try:
        for n in names:
            for spec in family.candidates[n].params:
                v = p.get(spec.name)
                if not np.isfinite(spec.null) or v is None or not np.isfinite(v):
                    continue
                h = 1e-4 * max(abs(v), float(scales.get(spec.scale, 1.0)) * 1e-2)
                up, dn = dict(p), dict(p)
                up[spec.name], dn[spec.name] = v + h, v - h
                diff = np.asarray(family.predict(up, effects, d), float) - np.asarray(
                    family.predict(dn, effects, d), float
                )
                cols.append(diff[use] * sw / (2 * h))
    except (ContactLabError, ValueError, ArithmeticError, KeyError):
        return None
    if not cols:
        return None
    A = np.column_stack(cols)
    if not np.all(np.isfinite(A)):
        return None
    Q = state["Q"]
    if Q is not None:
        A = A - Q @ (Q.T @ A)
    u, sv, _ = np.linalg.svd(A, full_matrices=False)
    keep = sv > 1e-8 * max(float(sv[0]) if sv.size else 0.0, 1e-300)
    u = u[:, keep]
    g = float((u.T @ state["b1"]) @ (u.T @ state["b2"])) / state["W"] / state["s2"]
    return max(g, 0.0)


#: a forward step picks among its accepted candidates by the held-out gain beyond the share of
#: the input-noise budget each can take from the noise alone (:func:`net_of_noise`; False:
#: by the held-out gain, as before stop 46). Off by default: on the blind generator's fresh
#: seed bases 60373 and 17491 (stop 46), with it on, force offsets (4 records) and non-Masing
#: scalings (3) were named displacement_offset, an effect with a reduced noise share that the
#: ranking favours (on 60373 before: all 6 named right); switched on only to
#: measure it (``benches/eval_confusions.py``) until a check on other generators holds.
RANK_NET_OF_NOISE = False


def net_of_noise(
    family: Family,
    name: str,
    gain: float,
    budget: float,
    d: Prepared | None = None,
    p: dict[str, float] | None = None,
) -> float:
    """A candidate's held-out ``gain`` (σ²) less the part of the input-noise ``budget`` its
    fit can take from the input's noise alone (:func:`_noise_floor`: all of it for most
    effects, a quarter for a breakaway, a Stribeck term or a track's wave, none for a
    drift in time; with the record ``d`` and the fitted parameters ``p``, the share the
    effect states at those, as its acceptance used: a load off the drive's harmonics).

    The budget is what the input's noise alone gives a candidate's held-out gain on this
    record; the shares were measured on clean records. Two candidates accepted at one step
    both beat their floors; the lead of one that the noise feeds over one it does not is
    evidence only beyond what the noise gives it (docs/effects.md, look-alikes not told
    apart: the same reading for a play over a delay). Ranked by the raw gain, a
    sub-sample delay, which smooths the noisy input, took rig breakaways (1.5 times the
    bound their clean twins state, ac·A 1.9-2.1, x noise 1.8-1.9 % of the range,
    ``benches/eval_confusions.py --cases stick``, tuning seeds 4620000 and 4640000): 1.21
    against 0.88 σ² and 0.98 against 0.66 σ² (budgets 0.55 and 0.58 σ²)."""
    return float(gain) - _noise_floor(family, (name,), budget, d, p)


def _noise_share(
    eff: object, d: Prepared | None = None, p: dict[str, float] | None = None
) -> float:
    """The share of the input-noise budget an effect's fit can take from the noise alone: 0
    when it is blind to the input (``input_noise_gain`` False), else its
    ``input_noise_share_at(d, p)`` at the fitted parameters when it has one and they are
    given (a normal load off the drive's harmonics cannot take what the noise leaves
    locked to the cycle), else its ``input_noise_share`` (default 1: all of it)."""
    if not getattr(eff, "input_noise_gain", True):
        return 0.0
    hook = getattr(eff, "input_noise_share_at", None)
    if hook is not None and d is not None and p is not None:
        share = hook(d, p)
        if share is not None:
            return float(share)
    return float(getattr(eff, "input_noise_share", 1.0))


def own_gain_floor(
    family: Family,
    names: tuple[str, ...],
    min_gain: float,
    d: Prepared | None = None,
    p: dict[str, float] | None = None,
) -> float:
    """The held-out (and in-sample) gain, σ², a candidate adding ``names`` must reach beside
    the input-noise budget: ``min_gain`` times the largest of their ``gain_floor_scale``
    (an effect's own, default 1).

    ``min_gain`` is a floor on the effect's size per sample, whatever the record's length:
    on a long record it asks far more than significance does (an effect of 0.05 σ² per sample
    over 20 000 samples has a noncentrality of 1 000). An effect with a structure no noise
    and no misfit of the base model along the phase of the cycle takes — a straight line in
    time — has its floor scaled down (``gain_floor_scale``, measured on clean records), the
    significance rules across cycles, the BIC and the share of the remaining error
    (:data:`~contactlab.diagnose.select.MIN_RELATIVE_GAIN`) still apply in full. With the
    record ``d`` and the candidate's parameters ``p`` (its fit to all data), an effect may
    state its scale at those parameters (``gain_floor_scale_at(d, p)``: a normal load off
    the drive's harmonics, which no cycle-locked misfit feeds)."""
    from .effects import registry

    try:
        reg = registry(family.kind)
    except KeyError:
        return min_gain

    def scale_of(eff: object) -> float:
        hook = getattr(eff, "gain_floor_scale_at", None)
        if hook is not None and d is not None and p is not None:
            at = hook(d, p)
            if at is not None:
                return float(at)
        return float(getattr(eff, "gain_floor_scale", 1.0))

    scale = max((scale_of(reg.get(n)) for n in names), default=1.0)
    return min_gain * scale


def relative_gain_scale(family: Family, names: tuple[str, ...]) -> float:
    """The share of rule 4's :data:`~contactlab.diagnose.select.MIN_RELATIVE_GAIN` a
    candidate adding ``names`` must reach: the largest of their ``relative_gain_scale`` (an
    effect's own, default 1).

    Rule 4 keeps a misspecified base's systematic residual from being shaved by any
    candidate. A residual that repeats cycle after cycle (a virgin curve of another shape,
    a sensor chain's filters) is orthogonal to a factor that is a straight line in time
    centred on the record's middle (a parameter drift: Σ (t - t_m) g(phase) r(phase) = 0
    over whole cycles), so such an effect can be held to a smaller share of it."""
    from .effects import registry

    try:
        reg = registry(family.kind)
    except KeyError:
        return 1.0
    return max((float(getattr(reg.get(n), "relative_gain_scale", 1.0)) for n in names), default=1.0)


def _proportional(family: Family, names: tuple[str, ...]) -> bool:
    """Whether rule 2 may pass by :func:`~contactlab.diagnose.select.proportional_t` for a
    candidate adding ``names``: the family's ``proportional_gain``, or every one of them an
    effect whose held-out gain is by its nature uneven across cycles (its own
    ``proportional_gain``: a drift gains nothing in the record's middle and most at its
    ends, so the per-cycle log ratios scatter by the drift's own shape, not by the noise)."""
    if getattr(family, "proportional_gain", False):
        return True
    from .effects import registry

    try:
        reg = registry(family.kind)
    except KeyError:
        return False
    return bool(names) and all(getattr(reg.get(n), "proportional_gain", False) for n in names)


def _not_fitted(name: str, exc: Exception) -> Verdict:
    """The verdict on a candidate whose fit failed: not named, and the reason kept."""
    return Verdict(name, np.nan, np.nan, np.nan, np.nan, False, f"could not be fitted: {exc}")


def _start_new(
    family: Family, current: Trial, new: tuple[str, ...], d: Prepared
) -> dict[str, float]:
    """Starting parameters of the current model with the effects ``new`` added."""
    start = dict(current.full.params)
    if hasattr(family, "start_effect"):
        for e in new:
            start.update(family.start_effect(e, start, d, -current.full_residual(d)))
    return start


def _try_candidate(
    name: str,
    family: Family,
    current: Trial,
    effects: tuple[str, ...],
    d: Prepared,
    scales: dict[str, float],
    folds: int,
    sigma: float,
    z: float,
    min_gain: float,
    budget: float,
    base_fit: dict[str, float],
    all_samples: np.ndarray,
    also: tuple[str, ...] = (),
    full: FitOut | None = None,
) -> tuple[Verdict, Trial | None]:
    """The verdict on adding ``name`` to the current model (and its trial when it was
    cross-validated); ``also``: effects added together with it (the pair move); ``full``:
    the candidate model's fit to all data when it is at hand (:func:`_pair_search`)."""
    trial_effects = (*effects, *also, name)
    start_c = _start_new(family, current, (*also, name), d)
    # screening: a candidate whose fit to all data lowers the error by less than
    # min_gain σ² cannot do better on held-out cycles; no cross-validation for it
    if full is None:
        try:
            full = fit(family, trial_effects, d, all_samples, start_c, scales)
        # e.g. a trial stiffness with no equilibrium; a trial fit stepping out of the model's
        # domain (ac to 0: "ac must be finite and > 0", a rig record with a channel delay)
        except (ConvergenceError, InputError) as exc:
            return _not_fitted(name, exc), None
    in_gain = (current.full.mse - full.mse) / sigma**2
    floor = own_gain_floor(family, (*also, name), min_gain, d, full.params)
    # a mass on one drive frequency with no plateau: its size against the record's own
    # simulated null stands in for the floors, the significance and the start-up rule
    beyond = (
        _beyond_null(family, name, d, current, full.params, sigma)
        if not also and in_gain > 0
        else None
    )
    if in_gain < floor and beyond is None:
        reason = f"in-sample gain {in_gain:.3g} σ² below {floor:g} σ²"
        return Verdict(name, np.nan, float(in_gain), np.nan, np.nan, False, reason), None
    try:
        cand = evaluate(family, trial_effects, d, start_c, scales, folds, full)
    except (ConvergenceError, InputError) as exc:
        return _not_fitted(name, exc), None
    p = cand.full.params
    # errors in variables: every candidate must beat what the input's noise alone does to
    # the weighted error (the budget). A sub-sample delay wins by smoothing the input; a
    # track-dependent friction by the turning points noisy x pushes outward (at 1 % x noise
    # position_friction gained 0.08 σ² on clean records against a budget of 0.70 σ²)
    extra = _noise_floor(family, (*also, name), budget, d, p, trial_effects)
    prop = d if _proportional(family, (*also, name)) else None
    rs = relative_gain_scale(family, (*also, name))
    v = judge(name, current, cand, sigma, z, floor + extra, prop, rel_scale=rs,
              strong=_strong_rule(family, z, (*also, name)))  # fmt: skip
    if beyond is not None and not v.accepted and v.gain > 0:
        v = dataclasses.replace(v, accepted=True, reason="accepted")
    if v.accepted and beyond is None:
        _note_locked_only(family, (*also, name), v.gain, floor, budget, d, p)
    # every effect of the candidate model, not only the new one: a refit can push an
    # effect added before to the edge of its physical range
    why = next(
        (w for e in trial_effects if (w := family.implausible(e, p, d))), None
    ) or _takes_over(
        family, base_fit, p, trial_effects, _explains(current, cand, sigma),
        regime=(d.extra.get("regime_info") or {}).get("name"),
    )  # fmt: skip
    if v.accepted and why:
        v = dataclasses.replace(v, accepted=False, reason=f"implausible: {why}")
    if v.accepted:
        # an effect whose held-out gain counts as its evidence only where it lies (a mass on
        # a single-frequency drive with no plateau: in the start-up, not the steady cycles)
        unsep = None
        if beyond is None:
            unsep = next((w for e in (*also, name) if (w := _gain_not_its_own(family, e, d,
                          current, cand))), None)  # fmt: skip
        if unsep:
            v = dataclasses.replace(v, accepted=False, reason=unsep)
    if v.accepted and hasattr(family, "identified"):
        # each new effect's size must stand out of its own error (issue 29: a held-out gain
        # the effect shares with a base parameter it trades off with is not its own); one
        # whose size stood beyond its simulated null (:func:`_beyond_null`) has been judged
        # against the trade-off itself
        se = cand.full.stderr
        unid = None
        if beyond is None:
            unid = next((w for e in (*also, name) if (w := family.identified(e, p, se, d=d))),
                        None)  # fmt: skip
        if unid:
            v = dataclasses.replace(v, accepted=False, reason=unid)
    return v, cand


def _gain_not_its_own(
    family: Family, name: str, d: Prepared, current: Trial, cand: Trial
) -> str | None:
    """Why the held-out gain of the candidate model (``name`` added to ``current``) is not
    the effect's own evidence on this record, or None: the effect's
    ``gain_not_its_own(d, p, cycle_gain)`` given the fitted parameters and the held-out
    gain of each cycle (weighted as the held-out error is, :func:`gain_by_cycle`)."""
    from .effects import registry

    try:
        eff = registry(family.kind).get(name)
    except KeyError:
        return None
    hook = getattr(eff, "gain_not_its_own", None)
    if hook is None:
        return None
    return hook(d, cand.full.params, gain_by_cycle(d, current, cand))


def _beyond_null(
    family: Family, name: str, d: Prepared, current: Trial, p: dict[str, float], sigma: float
) -> Any:
    """The effect ``name``'s test against the record's own simulated null where it applies
    and its size stands beyond it (a :class:`~contactlab.diagnose.mass_null.LinearNull`),
    else None. It applies where the effect's ``steady_null(d, p)`` says so (``p``: the
    candidate model fitted to all data; a mass on one drive frequency with no plateau):
    its size, linearised on the base model ``current``, is compared with its sizes on
    copies of the record simulated from that base model with the record's own noise on
    both channels (:func:`~contactlab.diagnose.mass_null.linear_term_null`). Where it
    stands beyond them, it takes the place of the candidate's gain floors, the
    significance of its held-out gain, its ``gain_not_its_own`` and ``identified`` rules
    (the base model's trade-off with a linear term, and the input noise's bias, are what
    the copies simulate); the plausibility stays, and the held-out gain must be positive.
    The names that stood beyond are kept in ``d.extra["beyond_null"]`` (the effect's
    ``identified_apart`` reads it in the closing checks)."""
    from .effects import registry

    try:
        eff = registry(family.kind).get(name)
    except KeyError:
        return None
    hook = getattr(eff, "steady_null", None)
    size_param = getattr(eff, "size_param", None)
    if hook is None or not size_param or not hook(d, p):
        return None
    from .mass_null import MASS_NULL_ALPHA, linear_term_null

    alpha = float(getattr(eff, "null_alpha", MASS_NULL_ALPHA))
    res = linear_term_null(
        family, current.full.params, current.effects, name, size_param, d, sigma, alpha=alpha
    )
    if res is None or not res.beyond:
        return None
    # the closing checks ask the effect's ``identified_apart`` again (workflow._unfounded)
    d.extra.setdefault("beyond_null", set()).add(name)
    return res


def gain_by_cycle(
    d: Prepared, current: Trial, cand: Trial, where: np.ndarray | None = None
) -> dict[int, float]:
    """The held-out gain of ``cand`` over ``current`` on each cycle of ``d`` (index as
    ``d.cycles.cycle``; -1 before the first): ``Σ w (r² - (r - Δ)²)`` over its held-out
    samples (and, given ``where``, those of them in it), ``r`` the current model's held-out
    residual, ``Δ`` the candidate's held-out prediction minus the current one, ``w`` the
    likelihood weights (:func:`~contactlab.diagnose.select.sample_weight`)."""
    from .select import sample_weight

    r = d.y - current.prediction
    delta = cand.prediction - current.prediction
    held = current.heldout & cand.heldout
    if where is not None:
        held = held & where
    g = sample_weight(d) * (2.0 * r * delta - delta * delta)
    cyc = np.asarray(d.cycles.cycle)
    out: dict[int, float] = {}
    for c in np.unique(cyc[held]):
        out[int(c)] = float(np.sum(g[held & (cyc == c)]))
    return out


def _fit_cost(family: Family, name: str) -> int:
    """Expected work of trying candidate ``name``, for the order the candidates of a step
    start in on threads (:func:`~contactlab.diagnose._parallel.pmap`; the results do not
    depend on it): its parameter count (the Jacobian's columns; the candidates with a
    nonlinear frequency, slip distance or speed carry two or more)."""
    return len(family.candidates[name].params)


#: rounds of the stepwise search (each adds one effect, then drops redundant ones) at most,
#: per effect the model may hold: room for every addition and as many swaps
ROUNDS_PER_EFFECT = 2


def _drop_check(
    name: str,
    family: Family,
    current: Trial,
    d: Prepared,
    scales: dict[str, float],
    folds: int,
    sigma: float,
    z: float,
    min_gain: float,
    budget: float,
) -> tuple[Verdict, Trial | None]:
    """The verdict on keeping ``name`` in the current model (backward elimination).

    The model without ``name`` is refitted (from the current fit) and cross-validated; then
    ``name`` is judged as a candidate added back to it by the rules of a forward step
    (:func:`contactlab.diagnose.select.judge`, with the input-noise budget). Not
    accepted means the other effects explain what it did: it is dropped. Returns the verdict
    and the reduced model's trial (None when that could not be fitted: then it is kept).
    """
    rest = tuple(e for e in current.effects if e != name)
    try:
        reduced = evaluate(family, rest, d, current.full.params, scales, folds)
    except (ConvergenceError, InputError) as exc:
        # as in a forward trial (_try_candidate): a refit that steps out of the model's
        # domain (a zero-slope virgin curve drove ac to its bound 0 in a difference step:
        # "ac must be finite and > 0") cannot judge the effect, which is then kept
        return _not_fitted(name, exc), None
    # the forward rule's (_try_candidate), at the kept fit's parameters
    extra = _noise_floor(family, (name,), budget, d, current.full.params, current.effects)
    prop = d if _proportional(family, (name,)) else None
    floor = own_gain_floor(family, (name,), min_gain, d, current.full.params)
    rs = relative_gain_scale(family, (name,))
    verdict = judge(name, reduced, current, sigma, z, floor + extra, prop, rel_scale=rs,
                    strong=_strong_rule(family, z, (name,)))  # fmt: skip
    return verdict, reduced


def _strong_rule(
    family: Family, z: float, names: tuple[str, ...] = ()
) -> tuple[float, float] | None:
    """Rule 2's large-gain route of the family (its ``strong_gain``: ``(factor, z_strong)``,
    :func:`contactlab.diagnose.select._strong_pass`) for a candidate adding ``names``, or
    None: when the family has none, or one of them opts out (an effect's
    ``large_gain_route`` False: a normal channel delay or hysteretic loss, which on clean
    single-tone chains reached 2-14 floors at t 1.9-2.5 by the input noise or a sensor
    drift, refused there only because one tone cannot identify them). ``z_strong`` never
    above ``z`` (a search run at a lower threshold keeps its own)."""
    rule = getattr(family, "strong_gain", None)
    if rule is None:
        return None
    from .effects import registry

    try:
        reg = registry(family.kind)
    except KeyError:
        reg = {}
    if any(not getattr(reg.get(n), "large_gain_route", True) for n in names):
        return None
    factor, z_strong = rule
    return float(factor), float(min(z_strong, z))


#: the swap move's threshold on the t statistic of the per-cycle gain (see _swap_search)
SWAP_Z = 0.0


def _swap_search(
    family: Family,
    names: list[str],
    current: Trial,
    named: tuple[str, ...],
    visited: set[frozenset[str]],
    d: Prepared,
    scales: dict[str, float],
    folds: int,
    sigma: float,
    min_gain: float,
    budget: float,
    base_fit: dict[str, float],
    all_samples: np.ndarray,
) -> tuple[tuple[str, Verdict, Trial] | None, list[Verdict], int]:
    """The swap move: every effect ``named`` by this diagnosis replaced by every candidate
    not in the model.

    Each swapped model is judged against the current one by the rules of a forward step
    (:func:`_try_candidate` with the effect taken out: the in-sample screening, the held-out
    gain of at least ``min_gain`` σ² and :data:`~contactlab.diagnose.select.MIN_RELATIVE_GAIN`
    of the current error, the BIC, plausibility), except that the gain across held-out
    cycles need only be positive on average (``t > SWAP_Z``), not significant: a swap does
    not make the model larger, it picks the better of two of the same size. Returns the
    best accepted swap ``(effect out, verdict on the one in, its trial)`` or None, every
    verdict (named ``"out ⇄ in"``), and the model evaluations spent.
    """
    spent = d.extra["evaluations"]
    effects = current.effects
    pairs = [
        (out, name)
        for out in named
        for name in names
        if name not in effects
        and family.check(rest := (*(e for e in effects if e != out), name))
        and frozenset(rest) not in visited
    ]

    def one(pair: tuple[str, str]) -> tuple[Verdict, Trial | None]:
        out, name = pair
        rest = tuple(e for e in effects if e != out)
        return _try_candidate(
            name, family, current, rest, d, scales, folds, sigma, SWAP_Z, min_gain, budget,
            base_fit, all_samples,
        )  # fmt: skip

    before = spent.total
    results = pmap(one, pairs, cost=lambda pair: _fit_cost(family, pair[1]))
    verdicts, best = [], None
    for (out, _), (v, cand) in zip(pairs, results, strict=True):
        verdicts.append(dataclasses.replace(v, name=f"{out} ⇄ {v.name}"))
        if cand is not None and v.accepted and (best is None or v.gain > best[1].gain):
            best = (out, v, cand)
    return best, verdicts, spent.total - before


#: the pair move (families with ``pair_move``: tangential; a normal joint's fits integrate
#: an ODE, and its library combines few effects) tries pairs among this many candidates not
#: in the model, those with the largest gains seen at any step of the search (_pair_search)
PAIR_POOL = 6
#: ... when a single candidate at the current step lowered the error by at least this many
#: σ² (held out, or in its fit to all data) but was not accepted; below it, nothing is left
#: that two effects could share. Far from the noise (a real loop the library cannot
#: follow, 66 σ after the search) the bar is MIN_RELATIVE_GAIN of the current error
#: instead: a few σ² there are a sliver of a larger misfit, as for a single effect
PAIR_GATE = 1.0
#: ... and cross-validates this many of the pair models, those whose fits to all data
#: lower the error most
PAIR_TRIALS = 4


def _pair_search(
    family: Family,
    pool: list[str],
    current: Trial,
    named: tuple[str, ...],
    max_effects: int,
    visited: set[frozenset[str]],
    d: Prepared,
    scales: dict[str, float],
    folds: int,
    sigma: float,
    z: float,
    min_gain: float,
    budget: float,
    base_fit: dict[str, float],
    all_samples: np.ndarray,
) -> tuple[tuple[str | None, tuple[str, str], Verdict, Trial] | None, list[Verdict], int]:
    """The pair move: two candidates added at once, to the current model or in place of
    one effect ``named`` by this diagnosis.

    Greedy steps add the one candidate that helps most alone. Two effects can each be weak
    or misleading alone and plain together: a force offset and a force drift (a ramp that
    starts at 0 needs the offset to centre it), or a channel delay and a breakaway after
    each reversal (each alone is mimicked by a branch scale, which a greedy step then
    names). Every pair ``{a, b}`` of ``pool`` (the candidates with the largest gains seen
    so far) gives the models ``current + a + b`` and ``current - out + a + b``; each is
    fitted to all data, and the :data:`PAIR_TRIALS` that lower the error most are judged
    against the current model by the rules of a forward step (:func:`_try_candidate`:
    significance ``t > z``, the gain thresholds, the BIC, plausibility of every effect).
    Since a pair is two claims, each of ``a`` and ``b`` must also pass those rules added
    back to the pair model without it (:func:`_drop_check`): each is needed beside the
    other. Returns the best accepted move ``(effect out or None, (a, b), verdict, trial)``
    or None, the verdicts on the pair models judged (named ``"a + b"`` or
    ``"out ⇄ a + b"``), and the model evaluations spent.
    """
    spent = d.extra["evaluations"]
    effects = current.effects
    moves: list[tuple[str | None, tuple[str, str]]] = []
    # added to the model while there is room (an effect the pair makes redundant is then
    # dropped by the backward step), else in place of one named effect
    outs = [None] if len(named) + 2 <= max_effects else list(named)
    for out in outs:
        rest = tuple(e for e in effects if e != out)
        for a, b in itertools.combinations(pool, 2):
            if family.check((*rest, a, b)) and frozenset((*rest, a, b)) not in visited:
                moves.append((out, (a, b)))

    def rest_of(move: tuple[str | None, tuple[str, str]]) -> tuple[str, ...]:
        return tuple(e for e in effects if e != move[0])

    def full_fit(move: tuple[str | None, tuple[str, str]]) -> FitOut | None:
        start = _start_new(family, current, move[1], d)
        try:
            return fit(family, (*rest_of(move), *move[1]), d, all_samples, start, scales)
        except ConvergenceError:
            return None

    def judged(
        item: tuple[tuple[str | None, tuple[str, str]], FitOut],
    ) -> tuple[Verdict, Trial | None]:
        move, full = item
        (a, b), rest = move[1], rest_of(move)
        v, cand = _try_candidate(
            b, family, current, rest, d, scales, folds, sigma, z, min_gain, budget,
            base_fit, all_samples, also=(a,), full=full,
        )  # fmt: skip
        if cand is None or not v.accepted:
            return v, cand
        for e in (a, b):  # each is needed beside the other
            w, _ = _drop_check(e, family, cand, d, scales, folds, sigma, z, min_gain, budget)
            if not w.accepted:
                why = f"{e} not needed beside the other: {w.reason}"
                return dataclasses.replace(v, accepted=False, reason=why), cand
        return v, cand

    before = spent.total
    fits = pmap(full_fit, moves)
    ranked = sorted(
        ((m, f) for m, f in zip(moves, fits, strict=True) if f is not None),
        key=lambda mf: mf[1].mse,
    )[:PAIR_TRIALS]
    results = pmap(judged, ranked)
    verdicts, best = [], None
    for ((out, pair), _), (v, cand) in zip(ranked, results, strict=True):
        label = " + ".join(pair) if out is None else f"{out} ⇄ {' + '.join(pair)}"
        verdicts.append(dataclasses.replace(v, name=label))
        if cand is not None and v.accepted and (best is None or v.gain > best[2].gain):
            best = (out, pair, v, cand)
    return best, verdicts, spent.total - before


#: Model evaluations (residual calls of every fit, numerical Jacobians included) a diagnosis
#: may spend. Typical runs use 1 000-8 000; the slowest of 657 random fuzz inputs 7 237 (a
#: minute on a loaded machine); without a bound the search (candidates x rounds x folds fits
#: of up to 400 iterations each) could take hours. Once spent, the candidates not yet tried
#: are reported as untested, with a sentence saying so.
MAX_EVALUATIONS = 40_000


def _max_evaluations() -> int:
    return MAX_EVALUATIONS


@dataclass
class SearchState:
    """Where the stepwise search stands: the current model's trial, the effects named by this
    diagnosis (``added``), the effect sets reached, the steps and sentences so far, the
    candidates' largest gains (the pair move's pool) and the evaluations spent."""

    current: Trial
    steps: list[Any]
    where: list[str]
    trials: list[Trial]
    added: list[str] = field(default_factory=list)
    visited: set[frozenset[str]] = field(default_factory=set)
    seen: dict[str, float] = field(default_factory=dict)
    untested: list[str] = field(default_factory=list)
    used: int = 0

    @property
    def effects(self) -> tuple[str, ...]:
        return self.current.effects


@dataclass
class StepwiseSearch:
    """The stepwise search of :func:`contactlab.diagnose.diagnose` (see its module
    docstring): forward steps, swaps, pairs and backward elimination, until no move passes;
    then the parsimony rule for effects acting through one signal (:meth:`parsimony`)."""

    family: Family
    names: list[str]
    d: Prepared
    scales: dict[str, float]
    folds: int
    sigma: float
    z: float
    min_gain: float
    budget: float
    base_fit: dict[str, float]
    max_effects: int
    make_step: Any  # workflow.Step

    def __post_init__(self) -> None:
        self.all_samples = np.ones(self.d.y.size, bool)
        self.spent = self.d.extra["evaluations"]
        # the search's two floors, for the stated power's per-effect floor (own_gain_floor),
        # and the noise they are in units of (an effect's start weighing its floors)
        self.d.extra["gain_rules"] = {
            "min_gain": self.min_gain, "budget": self.budget, "sigma": self.sigma,
        }  # fmt: skip

    def _locked_budget(self, st: SearchState) -> None:
        """The record's simulated noise bias (:func:`locked_noise_state`) at the base model
        the search starts from, once, where the input carries noise and a candidate cannot
        filter it."""
        from .effects import registry

        try:
            reg = registry(self.family.kind)
        except KeyError:
            return
        if not (NOISE_LOCKED_RULE and self.budget > 0) or not any(
            getattr(reg.get(n), "input_noise_locked", False) for n in self.names
        ):
            return
        locked_noise_state(self.family, dict(st.current.full.params), st.effects, self.d,
                           self.sigma)  # fmt: skip

    def _rules(self) -> dict[str, Any]:
        return {
            "d": self.d, "scales": self.scales, "folds": self.folds, "sigma": self.sigma,
            "min_gain": self.min_gain, "budget": self.budget,
        }  # fmt: skip

    def run(self, st: SearchState) -> SearchState:
        st.visited.add(frozenset(st.effects))
        self._locked_budget(st)
        for _round in range(ROUNDS_PER_EFFECT * self.max_effects + 1):
            verdicts, best = self.forward(st)
            moved = False
            if best is None:
                moved = self.swap(st)
            if best is None and not moved:
                if not self.pair(st, verdicts):
                    break
            if best is not None:
                v, st.current = best
                st.added.append(v.name)
                st.trials.append(st.current)
                st.steps.append(self.make_step(v.name, *self._errors(st.current)))
                st.visited.add(frozenset(st.effects))
            self.backward(st)
        if st.untested:
            st.where.append(
                f"the candidate search stopped after {st.used} model evaluations (its budget "
                f"is {_max_evaluations()}); not tested: {', '.join(dict.fromkeys(st.untested))}"
            )
        self.parsimony(st)
        return st

    def _rank(self, vc: tuple[Verdict, Trial]) -> float:
        """The order of the accepted candidates a forward step picks from: the held-out
        gain, on tangential records beyond the share of the input-noise budget the
        candidate's fit can take from the noise alone (:func:`net_of_noise`)."""
        if not (RANK_NET_OF_NOISE and getattr(self.family, "kind", "") == "tangential"):
            return vc[0].gain
        params = getattr(getattr(vc[1], "full", None), "params", None)
        d = getattr(self, "d", None)
        return net_of_noise(self.family, vc[0].name, vc[0].gain, self.budget, d, params)

    @staticmethod
    def _errors(tr: Trial) -> tuple[float, float, float]:
        return tr.heldout_rms, tr.heldout_peak, tr.energy_error

    def forward(self, st: SearchState) -> tuple[list[Verdict], tuple[Verdict, Trial] | None]:
        """Every candidate not in the model tried (in parallel), each verdict in the
        library's order as a serial run gives it, within the evaluation budget."""
        limit = _max_evaluations()
        effects = st.effects
        tried = [
            n
            for n in self.names
            if len(st.added) < self.max_effects
            and n not in effects
            and self.family.check((*effects, n))
            and frozenset((*effects, n)) not in st.visited
        ]
        try_one = partial(
            _try_candidate, family=self.family, current=st.current, effects=effects, z=self.z,
            base_fit=self.base_fit, all_samples=self.all_samples, **self._rules(),
        )  # fmt: skip
        spent = self.spent

        def counted(name: str) -> tuple[Verdict, Trial | None, int]:
            before = spent.mine()  # a task runs on one thread: these are its evaluations
            v, cand = try_one(name)
            return v, cand, spent.mine() - before

        def unless_spent(name: str) -> tuple[Verdict, Trial | None, int] | None:
            return None if spent.total >= limit else counted(name)

        # the budget as a serial run spends it: a candidate is tried only while the base and
        # the candidates before it in the library's order are within it; one a thread found
        # the budget spent for is run here after all if the serial count says it would be
        verdicts: list[Verdict] = []
        best = None
        accepted: list[tuple[Verdict, Trial]] = []
        seen_trials: dict[str, tuple[Verdict, Trial]] = {}
        outs = pmap(unless_spent, tried, cost=partial(_fit_cost, self.family))
        for name, out in zip(tried, outs, strict=True):
            if st.used >= limit:
                st.untested.append(name)
                why = f"not tested: the budget of {limit} model evaluations is spent"
                verdicts.append(Verdict(name, np.nan, np.nan, np.nan, np.nan, False, why))
                continue
            v, cand, n = out if out is not None else counted(name)
            st.used += n
            verdicts.append(v)
            if cand is not None and v.accepted and (best is None or v.gain > best[0].gain):
                best = (v, cand)
            if cand is not None and v.accepted:
                accepted.append((v, cand))
            if cand is not None and np.isfinite(v.gain):
                seen_trials[name] = (v, cand)
        accepted, verdicts = _yield_to_lookalikes(self.family, accepted, verdicts, self.d)
        accepted, verdicts = _yield_to_tried(
            self.family, accepted, verdicts, seen_trials, st.current, self.d
        )
        best = max(accepted, key=self._rank) if accepted else None
        best = _parsimonious(best, accepted)
        # tangential only: the normal family's look-alikes are judged by their own rules
        if best is not None and getattr(self.family, "kind", "") == "tangential":
            _mark_not_told_apart(best, seen_trials, st, self.d, self.z, self.family.kind)
        if verdicts:
            st.steps[-1] = dataclasses.replace(
                st.steps[-1], candidates=tuple(sorted(verdicts, key=lambda v: v.heldout_rms))
            )
        for v in verdicts:  # the pair move's pool: the largest gains seen at any step
            if np.isfinite(v.gain):
                st.seen[v.name] = max(st.seen.get(v.name, -np.inf), v.gain)
        return verdicts, best

    def swap(self, st: SearchState) -> bool:
        """No effect can be added: an effect named early may stand in for one never tried
        because the set filled up. True when a swap was made."""
        if not (st.added and st.used < _max_evaluations()):
            return False
        if len(st.added) < min(2, self.max_effects):
            return False
        swap, verdicts, n = _swap_search(
            self.family, self.names, st.current, tuple(st.added), st.visited, self.d,
            self.scales, self.folds, self.sigma, self.min_gain, self.budget, self.base_fit,
            self.all_samples,
        )  # fmt: skip
        st.used += n
        if verdicts:
            st.steps[-1] = dataclasses.replace(
                st.steps[-1], candidates=st.steps[-1].candidates + tuple(verdicts)
            )
        if swap is None:
            return False
        out, v, new = swap
        if getattr(self.family, "kind", "") == "tangential":
            _mark_swapped_out(out, v, st.current, new, st, self.d, self.z, self.family.kind)
        st.current = new
        self._seen_and_dropped(out, f"named, then swapped out for {v.name}")
        st.added[st.added.index(out)] = v.name
        st.trials.append(st.current)
        st.visited.add(frozenset(st.effects))
        st.steps.append(self.make_step(v.name, *self._errors(st.current), removed=out, removal=v))
        st.where.append(
            f"swap: {out} replaced by {v.name} (the model with {v.name} instead predicts the "
            f"held-out cycles better: gain {v.gain:.3g} σ², t = {v.t_stat:.2f})"
        )
        return True

    def pair(self, st: SearchState, verdicts: list[Verdict]) -> bool:
        """No single effect can be added or swapped in, yet one lowered the error by a
        sizeable amount without significance: two together may. True when a pair was
        added."""
        pool = [n for n in sorted(st.seen, key=lambda n: -st.seen[n]) if n not in st.effects]
        gains = [v.gain for v in verdicts if np.isfinite(v.gain)]
        gate = max(PAIR_GATE, MIN_RELATIVE_GAIN * st.current.heldout_mse / self.sigma**2)
        if not (
            getattr(self.family, "pair_move", False)
            and max(gains, default=0.0) >= gate
            and st.used < _max_evaluations()
            and len(pool) > 1
        ):
            return False
        pair, pair_verdicts, n_pair = _pair_search(
            self.family, pool[:PAIR_POOL], st.current, tuple(st.added), self.max_effects,
            st.visited, self.d, self.scales, self.folds, self.sigma, self.z, self.min_gain,
            self.budget, self.base_fit, self.all_samples,
        )  # fmt: skip
        st.used += n_pair
        if pair_verdicts:
            st.steps[-1] = dataclasses.replace(
                st.steps[-1], candidates=st.steps[-1].candidates + tuple(pair_verdicts)
            )
        if pair is None:
            return False
        gone, (a, b), v, st.current = pair
        if gone is not None:
            st.added.remove(gone)
        st.added += [a, b]
        st.trials.append(st.current)
        st.visited.add(frozenset(st.effects))
        st.steps.append(
            self.make_step(f"{a} + {b}", *self._errors(st.current), removed=gone,
                           removal=v if gone else None)
        )  # fmt: skip
        st.where.append(
            f"pair: {a} and {b} added together{f' in place of {gone}' if gone else ''} "
            f"(neither was accepted alone; together they predict the held-out cycles better: "
            f"gain {v.gain:.3g} σ², t = {v.t_stat:.2f}, and each is needed beside the other)"
        )
        return True

    def backward(self, st: SearchState) -> None:
        """Backward elimination (after an addition or a swap): an effect named early may be
        redundant once later ones are in."""
        while len(st.added) >= 2 and st.used < _max_evaluations():
            back = partial(
                _drop_check, family=self.family, current=st.current, z=self.z, **self._rules()
            )
            before = self.spent.total
            checks = pmap(back, list(st.added))
            st.used += self.spent.total - before
            drop = [(v, r) for v, r in checks if r is not None and not v.accepted]
            if not drop:
                break
            v, st.current = min(drop, key=lambda vr: vr[0].gain)
            self._drop(st, v, "backward step", "refitted without it, the other effects leave it "
                       f"nothing to add: {v.reason}")  # fmt: skip

    def _seen_and_dropped(self, name: str, why: str) -> None:
        """Note in ``d.extra["withdrawn"]`` (tangential records) an effect the search named
        at a step and then dropped or swapped out: the record showed it, so no size of it
        is promised (:func:`contactlab.diagnose.power._withdrawn`) unless the final model
        holds it. A delay of 1.9 ms, 4x its stated bound, named at the first step and then
        displaced by a play kept its bound of 0.41 ms (``benches/eval_confusions.py --cases
        delay``, fresh seed 95001)."""
        if getattr(self.family, "kind", "") == "tangential":
            self.d.extra.setdefault("withdrawn", {}).setdefault(name, why)

    def _drop(self, st: SearchState, v: Verdict, what: str, why: str) -> None:
        self._seen_and_dropped(v.name, f"named, then dropped by the search's {what}: {why}")
        st.added.remove(v.name)
        st.trials.append(st.current)
        st.visited.add(frozenset(st.effects))
        st.steps.append(self.make_step(None, *self._errors(st.current), removed=v.name, removal=v))
        st.where.append(f"{what}: {v.name} dropped ({why})")

    def parsimony(self, st: SearchState) -> None:
        """Effects that act through the same signal (``acts_through``, one name or several: the
        velocity for a delay, viscous damping, Stribeck friction, inertia, pre-sliding damping;
        the friction along the branch for Stribeck, position friction and stick-slip) are named
        together only when each is separately significant after the others at
        :data:`PARSIMONY_Z` times the search's threshold (each one's gain, refitted without
        it, must stand on its own, not on a misfit the others share). The weakest is
        dropped until that holds; a sentence says which and why."""
        from .effects import registry

        reg = registry(self.family.kind)
        settled: set[tuple[str, ...]] = set()  # groups whose members all stood on their own
        while st.used < _max_evaluations():
            groups: dict[str, list[str]] = {}
            for e in st.added:
                g = reg[e].acts_through if e in reg else None
                for one in (g,) if isinstance(g, str) else g or ():
                    groups.setdefault(one, []).append(e)
            shared = [
                (g, es) for g, es in groups.items() if len(es) >= 2 and (g, *es) not in settled
            ]
            if not shared:
                return
            group, members = shared[0]
            back = partial(
                _drop_check, family=self.family, current=st.current, z=PARSIMONY_Z * self.z,
                **self._rules(),
            )  # fmt: skip
            before = self.spent.total
            checks = pmap(back, members)
            st.used += self.spent.total - before
            weak = [(v, r) for v, r in checks if r is not None and not v.accepted]
            if not weak:
                st.where.append(
                    f"{' and '.join(members)} all act through the {group}; each is "
                    f"significant after the other{'s' if len(members) > 2 else ''} "
                    f"(t = {', '.join(f'{v.t_stat:.1f}' for v, _ in checks)}, threshold "
                    f"{PARSIMONY_Z * self.z:g}): named together"
                )
                settled.add((group, *members))
                continue
            v, st.current = min(weak, key=lambda vr: vr[0].gain)
            others = ", ".join(m for m in members if m != v.name)
            self._drop(st, v, "parsimony", f"it acts through the {group} as {others} does, and "
                       f"is not separately significant after it: {v.reason}")  # fmt: skip


#: the key of ``d.extra`` under which the search keeps, per candidate not named, the named
#: effect it was not told apart from (:func:`_mark_not_told_apart`; read by the stated
#: power: :func:`contactlab.diagnose.power.detectable_above`)
NOT_TOLD_APART = "not_told_apart"


def paired_lead(
    d: Prepared, current: Trial, best: Trial, other: Trial, where: np.ndarray | None = None
) -> float:
    """The t statistic of ``best``'s lead over ``other`` across held-out cycles: the mean of
    the per-cycle differences of their held-out gains over ``current``
    (:func:`gain_by_cycle`, on the samples ``where`` only when given) over its standard
    error (``±inf`` when every cycle gives the same lead, ``nan`` with fewer than two
    cycles in common)."""
    a, b = gain_by_cycle(d, current, best, where), gain_by_cycle(d, current, other, where)
    diff = np.array([a[c] - b[c] for c in a if c in b])
    if diff.size < 2:
        return float("nan")
    sd = float(np.std(diff, ddof=1))
    m = float(np.mean(diff))
    if not sd > 0:
        return float("inf") if m > 0 else float("-inf") if m < 0 else 0.0
    return m / (sd / np.sqrt(diff.size))


def _mark_not_told_apart(
    best: tuple[Verdict, Trial],
    tried: dict[str, tuple[Verdict, Trial]],
    st: SearchState,
    d: Prepared,
    z: float,
    kind: str = "tangential",
) -> None:
    """Note in ``d.extra[NOT_TOLD_APART]`` every candidate tried at this step (accepted or
    not, neither implausible nor unfitted, a positive held-out gain) whose held-out gain
    the effect added (``best``) does not beat significantly cycle by cycle (the paired t
    of :func:`paired_lead` at most the search's ``z``), and say so in ``st.where``. The
    lead counted is beyond what the input's noise alone gives the effect over that rival
    (its ``noise_fed_lead[rival]`` times the input-noise budget
    ``d.extra["input_noise_budget"]``, σ²: a play passes over the noise's wiggles at each
    turn, which a delay cannot): the t is scaled by the share of the held-out lead left
    beyond it, the per-cycle scatter unchanged; and where the effect says on which samples
    the noise does not feed it (its ``unfed_samples(d)``: a play away from the turns), the
    paired t there counts too, the smaller of the two deciding (delays of 0.25-1.8 ms at
    x noise 1.6 % of the range and ac·A 2.5-2.7 were named backlash with a paired t of
    4.1-4.5 over the delay, 3.5-4.4 after the discount, and 1.8-2.6 at speeds above half
    the peak; ``benches/eval_confusions.py --cases delay``, tuning seeds 90000-90001); and
    where its fitted size is within what the noise itself draws (its ``within_noise(d,
    p)``: a play no wider than twice the input noise), it is not told apart at all.

    Look-alikes draw nearly the same force on one amplitude (docs/effects.md: a 2f load, a
    dashpot, a Stribeck term and a delay in gross sliding; a spring and a 2f load's
    quadrature part): where the held-out error ranks them by chance, naming one is a
    choice the data do not make. The effect stays named (it passed every rule); the
    rival's stated bound says it was not told apart from it instead of promising a size
    (rig through the whole sensor chain, 2f loads of 3-6 % of h0: named viscous_damping at
    2.452 σ² against the load's 2.429, stribeck at 3.175 against 3.228, channel_delay at
    1.188 against 1.139; ``benches/eval_lookalike.py`` tuning seeds 52001, 52005,
    52006)."""
    from .effects import registry

    v, cand = best
    store = d.extra.setdefault(NOT_TOLD_APART, {})
    try:
        fed = dict(getattr(registry(kind).get(v.name), "noise_fed_lead", {}) or {})
    except KeyError:
        fed = {}
    budget = float(d.extra.get("input_noise_budget", 0.0) or 0.0)
    where_unfed = getattr(registry(kind).get(v.name), "unfed_samples", None) if fed else None
    unfed = where_unfed(d) if where_unfed is not None and budget > 0 else None
    within = getattr(registry(kind).get(v.name), "within_noise", None) if fed else None
    ties, better = [], []
    for name, (w, other) in tried.items():
        if name == v.name or name in st.effects or not (np.isfinite(w.gain) and w.gain > 0):
            continue
        why = w.reason or ""
        if why.startswith(("implausible", "could not be fitted")):
            continue
        t = paired_lead(d, st.current, cand, other)
        lead, owed = v.gain - w.gain, fed.get(name, 0.0) * budget
        if owed > 0 and lead > 0 and np.isfinite(t):
            # the lead beyond what the noise gives, at the same scatter across cycles
            t *= 1.0 - owed / lead
        noise_sized = ""
        params = getattr(getattr(cand, "full", None), "params", None)
        if name in fed and within is not None and params is not None:
            noise_sized = within(d, params) or ""
        if name in fed and unfed is not None:
            # and where the noise does not feed it: the lead there must be significant too
            t_unfed = paired_lead(d, st.current, cand, other, unfed)
            if np.isfinite(t_unfed):
                t = min(t, t_unfed) if np.isfinite(t) else t_unfed
        if (np.isfinite(t) and t <= z) or noise_sized:
            store[name] = {"named": v.name, "gain_named": float(v.gain),
                           "gain": float(w.gain), "t": float(t),
                           "refused": "" if w.accepted else why, "z": float(z)}  # fmt: skip
            if noise_sized:
                store[name]["noise_sized"] = noise_sized
            entry = f"{name} ({w.gain:.3g} σ², t = {t:.2f}" + (
                f"; {noise_sized}" if noise_sized else ""
            )
            if np.isfinite(t) and t <= -z:
                # told apart, the other way: the rival fitted significantly better and was
                # kept out by its refusal (or the search's order), not by the data
                better.append(f"{entry}; {why[:120] if why else 'accepted, ranked below'})")
            else:
                ties.append(f"{entry})")
    if ties:
        st.where.append(
            f"{v.name} (held-out gain {v.gain:.3g} σ²) is not told apart from "
            f"{', '.join(ties)}: its lead over each across held-out cycles is not significant "
            f"(paired t between -{z:g} and {z:g}); on this record the data do not say which of "
            "them it is"
        )
    if better:
        st.where.append(
            f"{v.name} (held-out gain {v.gain:.3g} σ²) was added although "
            f"{', '.join(better)} fitted the held-out cycles significantly better (paired t of "
            f"its lead at most -{z:g}): each was refused for the reason given, not told apart "
            "from it by the data"
        )


def _mark_swapped_out(
    out: str,
    v: Verdict,
    old: Trial,
    new: Trial,
    st: SearchState,
    d: Prepared,
    z: float,
    kind: str = "tangential",
) -> None:
    """Note in ``d.extra[NOT_TOLD_APART]`` an effect ``out`` a swap replaced by ``v.name``
    when the data do not tell the two apart: the swapped model's lead over the old one is
    not significant cycle by cycle (:func:`paired_lead` at most ``z``), or the incoming
    effect says its fitted size is what the input's noise draws for that rival (its
    ``within_noise(d, p)``, where ``noise_fed_lead`` names the rival). As
    :func:`_mark_not_told_apart` does for a step's rivals; a swap is a step too (a delay of
    1.9 ms at 4x its stated bound, named first, was swapped for a play, and its bound of
    0.41 ms stood: ``benches/eval_confusions.py --cases delay``, fresh seed 95001)."""
    from .effects import registry

    try:
        eff = registry(kind).get(v.name)
    except KeyError:
        eff = None
    t = paired_lead(d, old, new, old)
    noise_sized = ""
    within = getattr(eff, "within_noise", None)
    if out in dict(getattr(eff, "noise_fed_lead", {}) or {}) and within is not None:
        noise_sized = within(d, new.full.params) or ""
    if not ((np.isfinite(t) and t <= z) or noise_sized):
        return
    entry = {"named": v.name, "gain_named": float(v.gain), "gain": 0.0, "t": float(t),
             "refused": f"swapped out: the model with {v.name} instead gained {v.gain:.3g} "
                        "σ² held-out over it"}  # fmt: skip
    if noise_sized:
        entry["noise_sized"] = noise_sized
    d.extra.setdefault(NOT_TOLD_APART, {})[out] = entry
    st.where.append(
        f"{v.name} replaced {out} without telling them apart (paired t of its lead "
        f"{t:.2f}" + (f"; {noise_sized}" if noise_sized else "") + ")"
    )


def _yield_to_lookalikes(
    family: Family,
    accepted: list[tuple[Verdict, Trial]],
    verdicts: list[Verdict],
    d: Prepared | None = None,
) -> tuple[list[tuple[Verdict, Trial]], list[Verdict]]:
    """``accepted`` and ``verdicts`` with the candidates that yield to a look-alike accepted
    at the same step refused: an effect's ``yields_to(p, gains, own, d)`` (the fitted
    parameters, the accepted candidates' held-out gains, its own, the record) says why its
    fit is another effect's signature (a speed-strengthening Stribeck term beside a mass or
    a series compliance; a 2f load in phase with the stroke beside a Stribeck term), or
    None."""
    from .effects import registry

    try:
        reg = registry(family.kind)
    except KeyError:
        return accepted, verdicts

    def yielding(gains: dict[str, float]) -> dict[str, str]:
        out = {}
        for v, cand in accepted:
            hook = getattr(reg.get(v.name), "yields_to", None)
            why = None if hook is None else hook(cand.full.params, gains, v.gain, d)
            if why:
                out[v.name] = why
        return out

    # (the accepted candidates' fitted parameters, for a hook that asks what its rival
    # shows: a 2f load yields to a Stribeck term only where that term has a low-speed
    # excess of its own, ``NormalLoad.yields_to``)
    if d is not None:
        d.extra["step_accepted_params"] = {v.name: dict(c.full.params) for v, c in accepted}
    # an effect yields only to a rival that stands: those that yield are judged again
    # against the others (a 2f load yields to a Stribeck term, which may itself yield to a
    # series compliance: the load then stands)
    first = yielding({v.name: v.gain for v, _ in accepted})
    why_of = yielding({v.name: v.gain for v, _ in accepted if v.name not in first}) if first else {}
    keep, refused = [], {}
    for v, cand in accepted:
        if v.name in first and v.name in why_of:
            reason = f"look-alike: {why_of[v.name]}"
            refused[v.name] = dataclasses.replace(v, accepted=False, reason=reason)
        else:
            keep.append((v, cand))
    if not refused:
        return accepted, verdicts
    # ... and only to a rival that is named at this step: when a third candidate outgains
    # every rival, the look-alike's reading ("the speed function is named") does not hold,
    # and the yielding effect is judged against that candidate alone (rig, tuning seed
    # 610017 of benches/eval_offsets.py: a 2f load in phase with the stroke, ±15 % at ac·A
    # 4, gained 87.8 σ²; it yielded to a Stribeck term of 73.3 σ², and a parallel spring of
    # 85.8 σ², which draws the rise of each branch's second half, was named)
    top = max(keep, key=lambda vc: vc[0].gain) if keep else None
    if top is not None:
        for v, cand in accepted:
            if v.name not in refused or not v.gain > top[0].gain:
                continue
            hook = getattr(reg.get(v.name), "yields_to", None)
            if hook is None or not hook(cand.full.params, {top[0].name: top[0].gain}, v.gain, d):
                del refused[v.name]
                keep.append((v, cand))
    return keep, [refused.get(v.name, v) if v.accepted else v for v in verdicts]


def _yield_to_tried(
    family: Family,
    accepted: list[tuple[Verdict, Trial]],
    verdicts: list[Verdict],
    tried: dict[str, tuple[Verdict, Trial]],
    current: Trial,
    d: Prepared,
) -> tuple[list[tuple[Verdict, Trial]], list[Verdict]]:
    """``accepted`` and ``verdicts`` with the candidates refused whose lead over a look-alike
    *tried* at the same step (cross-validated, accepted or not: ``tried``) is not their own
    physics: an effect's ``yields_to_tried(p, v, cand, tried, current, d)`` says why, or
    None.

    :func:`_yield_to_lookalikes` judges an effect against rivals accepted at the same step.
    A look-alike whose fit feeds on the input's noise (a play passes over the noise's
    wiggles at each turning point) can pass the input-noise budget where the effect it
    mimics, which no such noise feeds, falls just short of it: then the rival is not
    accepted, and the comparison must read where the two differ physically (a play against
    a delay: away from the turns, a fixed shift against one proportional to the speed)."""
    from .effects import registry

    try:
        reg = registry(family.kind)
    except KeyError:
        return accepted, verdicts
    keep, refused = [], {}
    for v, cand in accepted:
        hook = getattr(reg.get(v.name), "yields_to_tried", None)
        why = None if hook is None else hook(cand.full.params, v, cand, tried, current, d)
        if why:
            refused[v.name] = dataclasses.replace(v, accepted=False, reason=f"look-alike: {why}")
        else:
            keep.append((v, cand))
    if not refused:
        return accepted, verdicts
    return keep, [refused.get(v.name, v) if v.accepted else v for v in verdicts]


#: accepted candidates whose held-out gains lie within this share of the best one's are a
#: tie the held-out error cannot break: the one with the lowest BIC (fewest parameters for
#: the same fit) is added (:func:`_parsimonious`)
TIE_SHARE = 0.02


def _parameter_count(name: str) -> int | None:
    """The number of parameters of the effect ``name`` in the library (None: not an effect
    of it)."""
    from .effects import registry

    for kind in ("tangential", "normal"):
        try:
            eff = registry(kind).get(name)
        except KeyError:
            continue
        if eff is not None:
            return len(eff.params)
    return None


def _parsimonious(
    best: tuple[Verdict, Trial] | None, accepted: list[tuple[Verdict, Trial]]
) -> tuple[Verdict, Trial] | None:
    """Of the accepted candidates whose held-out gain is within :data:`TIE_SHARE` of the
    best's (either side), the one with the fewest parameters, among as many the lowest
    ``delta_bic`` (``best`` when alone, or when no tied candidate has fewer parameters than it).

    A viscous term and a normal-load fluctuation at twice the drive frequency draw nearly
    the same force in gross sliding (both the friction's sign times a bump at mid-stroke,
    docs/effects.md): the held-out gains tie to 0.2 % (rig, tuning seed 1044) and the
    three-parameter fluctuation won by chance; with equal fits the one-parameter effect is
    the simpler reading. Between candidates of as many parameters the BIC is the in-sample
    fit alone, which the held-out error already judged better: the best by held-out gain
    stays (rig, tuning seed 107: a mass 0.811 σ² and a series compliance 0.795 σ², one
    parameter each; the compliance's lower in-sample error won the tie, was withdrawn by the
    closing checks as absorbing a misfit it does not model, and nothing was named)."""
    if best is None or len(accepted) < 2:
        return best
    floor, top = best[0].gain * (1.0 - TIE_SHARE), best[0].gain * (1.0 + TIE_SHARE)
    # (``top``: a candidate whose raw gain is higher but that ranked below ``best`` beyond
    # the input noise's share, :func:`net_of_noise`, is not tied with it)
    tied = [vc for vc in accepted if floor <= vc[0].gain <= top and np.isfinite(vc[0].delta_bic)]
    if len(tied) < 2:
        return best
    n_best = _parameter_count(best[0].name)
    fewer = [vc for vc in tied if (n := _parameter_count(vc[0].name)) is None
             or n_best is None or n < n_best]  # fmt: skip
    if not fewer:
        return best
    # the fewest parameters first: the BIC's in-sample edge of a candidate with more of
    # them is the fit the held-out tie says it does not carry (rig, tuning seed 8100000 of
    # benches/eval_velocity_conf.py: a 0.38 ms delay gained 0.967 σ² held-out, a 2f load
    # 0.984 σ², and the load's lower BIC named it)
    return min([best, *fewer], key=lambda vc: (_parameter_count(vc[0].name) or 0, vc[0].delta_bic))


#: the parsimony rule's threshold on the t statistic, in units of the search's ``z``
PARSIMONY_Z = 1.5
