"""The discrepancy workflow: fit the base model, locate the residual, name the missing
effect from the candidate library, add it, repeat, and show the gap shrink.

Steps (issue 5): (1) fit the base model — Masing with exponential virgin curve for a
tangential joint, linear Kelvin-Voigt for a normal joint (PHYSICS.md §1, §2); (2) describe
where the residual lives (:mod:`.locate`); (3) fit every candidate extension of the current
model, rank by the error on held-out cycles and accept the best only if it passes the rules
of :mod:`.select` against the noise level estimated from the data; (4) after each addition,
refit without each effect named so far and drop one that, added back, would no longer pass
those rules (backward elimination: a wrong effect picked first is not kept once the right
ones are in); repeat until no candidate helps; then, with the set full (``max_effects``) or
two or more named, try replacing each named effect by each candidate not in the model and
keep the swap the held-out rules prefer (a wrong effect picked while the set filled up
would otherwise keep the right one from ever being tried), and go on; when neither an
addition nor a swap passes but a candidate still lowered the held-out error by
:data:`PAIR_GATE` σ², try two candidates at once (:func:`_pair_search`: two effects can each
be weak or misleading alone and plain together), each of which must be needed beside the
other; (5) report held-out RMS, peak error and loop-energy error after each step.
"""

from __future__ import annotations

import copy
import dataclasses
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._options import takes_options
from ..errors import ConvergenceError, InputError
from ._family import Family, Prepared
from ._inputs import arrays as _arrays
from ._inputs import check_channels, check_glitches
from ._parallel import EvaluationCounter, one_blas_thread
from ._prepare import (  # (the names tests and benches import from here, re-exported)
    MAX_SAMPLES,  # noqa: F401
    MIN_SAMPLES_PER_CYCLE,  # noqa: F401
    _declared,
    _prior_weight,
    _same_clock,
    eiv_weight,
    reduce_long,  # noqa: F401
    subsample_long,  # noqa: F401
    subsample_normal,  # noqa: F401
)
from ._signal import noise_rms
from .locate import locate
from .model import ExtendedModel
from .paths import KindPath, RegimeDecision, kind_path, stroke_levels
from .result import DiagnosisReport, Effect, Step, _finite_or_none
from .search import MAX_EVALUATIONS, SearchState, StepwiseSearch, _pair_search  # noqa: F401
from .select import Trial, evaluate, fit, fold_masks

__all__ = ["DiagnosisReport", "Effect", "Step", "diagnose"]


def _family(model: Any) -> tuple[Family, dict[str, float], dict[str, float]]:
    """Model family, starting parameters and context from a name or a model object."""
    from ..masing import Masing

    if isinstance(model, str):
        if model == "tangential":
            from .candidates_tangential import TangentialFamily

            return TangentialFamily(), {}, {}
        if model == "normal":
            from .candidates_normal import NormalFamily

            return NormalFamily(), {}, {}
        raise InputError(
            f"model must be 'tangential' or 'normal' (or a model object), got {model!r}"
        )
    if isinstance(model, Masing):
        from .candidates_tangential import TangentialFamily

        if not model.is_exponential:
            raise InputError("diagnose needs the exponential Masing model (h0, ac)")
        return TangentialFamily(), {"h0": model.h0, "ac": model.ac}, {}
    if isinstance(model, ExtendedModel):
        return model.family, dict(model.params), dict(model.context)
    from .candidates_normal import NormalFamily, start_from_model

    start = start_from_model(model)
    if start is not None:
        if getattr(model, "p0", None) is not None:
            start["p0"] = float(model.p0)
        ctx = {"omega": float(model.omega)} if hasattr(model, "omega") else {}
        return NormalFamily(), start, ctx
    raise InputError(f"cannot diagnose a model of type {type(model).__name__}")


def _frame_constants(
    recording: Any, effects: list[Effect], where: list[str], location: dict[str, Any]
) -> list[Effect]:
    """A force reconstructed from a frame's equation of motion (``meta["frame"]``:
    :meth:`contactlab.tangential.FrameForce.recording`, ``F = K (y - x) + C (y' - x') - M x''``)
    contains the frame's inertia ``- M x''``: an ``inertia`` term ``m x''`` in the diagnosis is
    exactly a different ``M`` (``M + m``), whether ``M`` is off or the two displacement
    channels' filters differ in phase. It is reported as that reading of ``M``
    (``location["frame_constants"]`` and a sentence) and not named as an effect of the joint;
    the final model keeps the term. Other effects stay named: a parallel stiffness or a
    viscous term acts on ``x`` alone, the frame's ``K`` and ``C`` on ``x - y``."""
    meta = getattr(recording, "meta", None)
    frame = meta.get("frame") if isinstance(meta, dict) else None
    if not isinstance(frame, dict) or "M" not in frame:
        return effects
    kept = []
    for e in effects:
        if e.name != "inertia" or "m" not in e.parameters:
            kept.append(e)
            continue
        M0, m = float(frame["M"]), float(e.parameters["m"])
        sm = e.stderr.get("m")
        sm = float(sm) if sm is not None and np.isfinite(sm) else float("nan")
        location["frame_constants"] = {
            "M_given": M0,
            "M_read": M0 + m,
            "M_read_stderr": _finite_or_none(sm),
            "relative": m / M0 if M0 > 0 else None,
            "from_effect": "inertia",
            "units": {"M_given": "kg", "M_read": "kg", "M_read_stderr": "kg"},
        }
        rel = f" ({100.0 * m / M0:+.2f} %)" if M0 > 0 else ""
        where.append(
            f"the frame's mass reads M = {M0 + m:.5g} ± {sm:.2g} kg where {M0:.5g} kg was given"
            f"{rel}: an inertia term m = {m:.3g} kg in a force reconstructed from the frame's "
            "equation of motion is its own M x'' (M off, or the x and y channels filtered with "
            "different phase); reported as a reading of M, not as an effect of the joint"
        )
    return kept


def infer_model(recording: Any) -> str:
    """The model family of a recording when none is given, as the command line infers it:
    ``"tangential"`` for channels ``x``, ``F``, ``"normal"`` for ``p``, ``delta`` (a
    :class:`~contactlab.io.Recording`'s ``kind``, a dict's keys); a tuple ``(t, x, F)`` is
    tangential. Anything else is an :class:`~contactlab.InputError` asking for ``model=``.

    Examples
    --------
    >>> import numpy as np
    >>> infer_model({"t": np.arange(3.0), "p": np.ones(3), "delta": np.ones(3)})
    'normal'
    """
    kind = getattr(recording, "kind", None)
    if kind in ("tangential", "normal"):
        return str(kind)
    if isinstance(recording, dict):
        # the family whose channels are there (the family's own check then names a missing
        # one: {"x": ..., "force": ...} is a tangential recording without 'F')
        if "x" in recording or "F" in recording:
            return "tangential"
        if "p" in recording or "delta" in recording:
            return "normal"
    if isinstance(recording, tuple):
        return "tangential"
    raise InputError(
        "cannot tell the model of the recording (channels x, F: tangential; p, delta: "
        "normal): give model='tangential' or 'normal'"
    )


def _withdraw_locked(b, d, st, names, z, min_gain, folds, declared_noise, location, checks):
    """An effect named only by the input-noise-locked floor is withdrawn where the misfit test
    flags the final model and still flags it refitted without that effect (a patch over a
    misfit); kept, with the closing checks of the model with it, where the flag goes away
    without it (the flag was the effect's own), or where the data hold its own signature
    beyond any virgin curve (:func:`_signature_at`, stop 52: a rig wave at twice the ideal
    size, t 7.1 over 49 cycles, was withdrawn here since the record was flagged without
    it too: by the wave's own structure)."""
    gone = _locked_on_misfit(st, d, checks)  # flagged by the calibrated null or a patch
    if gone is not None and (shown := _signature_at(b, d, st, gone[0])):
        # the data hold the effect's own signature beyond any virgin curve: no patch
        st.where.append(f"{gone[0]} is kept on a record whose misfit is unexplained: {shown}")
        gone = None
    if gone is not None:
        before = getattr(checks["unexplained"], "absorbing", ())
        args = (names, z, min_gain, folds, declared_noise)
        failed, without = _unexplained_without(b, d, st, gone[0], *args, copy.deepcopy(location))
        own = None if failed else _takes_own_structure(checks["unexplained"], without)
        if own:
            st.where.append(f"{gone[0]} is kept on a record whose misfit is unexplained: {own}")
        if (failed or (without is not None and without.flagged)) and not own:
            checks = _withdraw(b, d, st, *args, location, checks, [gone])
        else:  # kept: the closing checks of the model with it again (the trial rewrote them)
            checks = _assess(b, d, st, *args, location)
        checks = _calibrated(b, d, st, _rivals(b, d, st, checks))
        if before and checks["unexplained"] is not None:
            absorbing = tuple(dict.fromkeys([*before, *checks["unexplained"].absorbing]))
            checks["unexplained"] = dataclasses.replace(checks["unexplained"], absorbing=absorbing)
    return checks


@one_blas_thread
@takes_options
def diagnose(
    recording: Any,
    model: Any = None,
    *,
    candidates: Sequence[str] | None = None,
    max_effects: int = 3,
    folds: int = 2,
    z: float = 3.0,
    min_gain: float = 0.05,
    base: Any = None,
    output_filter: Any = None,
    output_noise: float | None = None,
    force_sign: int | str | None = None,
    delay: float | None = None,
) -> Any:
    """Find where a model and a measurement disagree, name the missing effect, add it.

    Parameters
    ----------
    recording : contactlab.io.Recording, dict or tuple
        The measurement: a Recording with channels ``x``, ``F`` (tangential) or ``p``,
        ``delta`` (normal) in SI units, a dict with ``t`` and those keys, or a tuple
        ``(t, x, F)`` / ``(t, p, delta)``. Uniform sampling; several excitation cycles.
    model : {"tangential", "normal"}, model object or None
        Base model family (None, the default: inferred from the recording's channels by
        :func:`infer_model`, as the command line infers it; the report's ``model_inferred``
        says so), or a model whose parameters start the fit
        (:class:`contactlab.Masing`, a normal-contact model, or an :class:`ExtendedModel`
        from an earlier diagnosis, whose effects are kept).
    candidates : sequence of str, optional
        Restrict the candidate library to these names (default: all of the family).
    max_effects : int
        Stop after this many additions.
    folds : int
        Cycles are split into this many interleaved folds for the held-out error.
    z : float
        Significance threshold (t statistic across held-out cycles).
    min_gain : float
        Minimum held-out MSE reduction, in units of the estimated noise variance.
    base : IdentifiedModel or path, optional
        Diagnose a structure instead: an identified structure
        (:func:`contactlab.structure.identify`, or its saved JSON) is the base model and
        ``recording`` is ``(t, u, y)``; the same when ``model`` is an ``IdentifiedModel``.
        Returns a :class:`~contactlab.diagnose.structure.StructureDiagnosis` (see
        :func:`~contactlab.diagnose.structure.diagnose_structure`).
    output_filter : array_like, optional
        Tangential only: the taps (odd count, zero phase) of a smoothing the force channel
        went through, e.g. a force reconstructed from a frame's equation of motion
        (:attr:`contactlab.tangential.FrameForce.force_filter`). Every candidate's predicted
        force passes the same filter, and the half filter at either end of the record
        (where it is not defined) counts for nothing. Default: the recording's
        ``meta["output_filter"]`` (set by :meth:`~contactlab.tangential.FrameForce.recording`).
    output_noise : float, optional
        The output channel's noise RMS when known (a filtered channel's noise is correlated
        and its differences understate it). Default: ``meta["output_noise"]`` of the
        recording, else estimated from the base model's residual.
    force_sign : {"auto", +1, -1}, optional
        Tangential only, as ``analyze`` takes it: diagnose ``force_sign·F``; ``"auto"``: the
        sign that makes the loop dissipate (``∮F dx > 0``). Default (None): the force as
        recorded, and a loop that runs the wrong way is refused with a sentence saying so.
    delay : float, optional
        Tangential only, as ``analyze`` and ``track`` take it: a known delay (s) of the force
        channel behind the displacement; the force is read that much later
        (:func:`contactlab.tangential.lag.delayed_recording`) before the diagnosis, and the
        samples the shift leaves without force data are dropped.

    Returns
    -------
    DiagnosisReport

    Examples
    --------
    >>> import contactlab
    >>> from contactlab.synthetic.diagnosis import hidden_effect_recording
    >>> rec = hidden_effect_recording(["force_offset"], magnitude=0.05, seed=2)
    >>> report = contactlab.diagnose(rec, model="tangential")
    >>> report.effect_names
    ['force_offset']
    """
    # an IdentifiedModel can only exist once contactlab.structure is imported: no need to
    # import it (a fifth of a second) to tell
    structure = sys.modules.get("contactlab.structure")
    if base is not None or (structure is not None and isinstance(model, structure.IdentifiedModel)):
        from .structure import diagnose_structure

        return diagnose_structure(
            recording, model if base is None else base, candidates=candidates,
            max_effects=max_effects, z=z, min_gain=min_gain,
        )  # fmt: skip
    inferred = model is None and base is None
    if inferred:
        model = infer_model(recording)
    family, start, context = _family(model)
    if delay is not None:
        recording = _delayed(recording, family, delay)
    path = kind_path(family)
    t, u, y = _checked_arrays(recording, family, folds, max_effects, z, min_gain)
    y, sign_note = path.orient(t, u, y, force_sign)
    hum_note = None
    hum_kept: list[dict[str, float]] = []
    if family.kind == "tangential":  # (diagvel: mains hum on both channels feeds a delay)
        from ._mains import kept_hum, remove_mains

        hum_kept, hum_kept_note = kept_hum(t, u, y)
        u, y, hum_note = remove_mains(t, u, y)
        if hum_kept_note:
            hum_note = f"{hum_note}; {hum_kept_note}" if hum_note else hum_kept_note
    names = _candidate_names(family, candidates)
    taps, declared_noise = _declared(recording, family, output_filter, output_noise, t.size, y)
    notes = [n for n in (sign_note, hum_note, _same_clock(recording, names, candidates)) if n]
    d, reduced = path.prepare(t, u, y, taps)
    if family.kind == "tangential" and hum_kept:
        d.extra["hum_kept"] = hum_kept
    prior, prior_notes = _ready(family, d, recording, context, taps)
    # a family whose floors are totals over the record (normal contact: gain_scale)
    min_gain = min_gain * float(d.extra.get("gain_scale", 1.0))
    effects: tuple[str, ...] = tuple(model.effects) if isinstance(model, ExtendedModel) else ()
    regime = path.regime(t, u, y)  # the one decision analyze, track and diagnose share
    d.extra["regime_info"] = _regime_info(regime)
    b = _fit_base(family, effects, d, start, folds, declared_noise)
    where, location = _describe_base(b, d, regime, notes, reduced, prior, prior_notes)
    location["samples"] = {"recording": int(t.size), "diagnosed": int(d.t.size)}
    location["noise_declared"] = declared_noise is not None
    st = _search(b, names, d, folds, z, min_gain, max_effects, where)
    checks = _assess(b, d, st, names, z, min_gain, folds, declared_noise, location)
    checks = _withdraw(b, d, st, names, z, min_gain, folds, declared_noise, location, checks)
    checks = _rivals(b, d, st, checks)
    checks = _calibrated(b, d, st, checks)
    checks = _withdraw_locked(b, d, st, names, z, min_gain, folds, declared_noise, location, checks)
    checks = _flag_route(b, d, st, names, z, min_gain, folds, declared_noise, location, checks)
    if checks["unexplained"] is not None and checks["unexplained"].flagged:
        st.where.append(checks["unexplained"].sentence())
    report = _report(b.family, path, recording, regime, d, st, b.sigma, location)
    report.model_inferred = inferred
    report.channel_noise = checks["noise"]
    report.not_detected = checks["not_detected"]
    report.unexplained = checks["unexplained"]
    return report


def _search(
    b: _Base,
    names: list[str],
    d: Prepared,
    folds: int,
    z: float,
    min_gain: float,
    max_effects: int,
    where: list[str],
) -> SearchState:
    """The stepwise candidate search (:class:`.search.StepwiseSearch`) from the base."""
    steps = [Step(None, *StepwiseSearch._errors(b.current))]
    search = StepwiseSearch(
        b.family, names, d, b.scales, folds, b.sigma, z, min_gain, b.budget,
        dict(b.current.full.params), max_effects, Step,
    )  # fmt: skip
    spent = d.extra["evaluations"].total  # by the base; then as a serial run counts them
    return search.run(SearchState(b.current, steps, where, [b.current], used=spent))


def _regime_info(regime: RegimeDecision) -> dict[str, Any]:
    """The regime decision as the candidates read it (``d.extra["regime_info"]``)."""
    return {
        "name": regime.name, "plateau_h0": regime.h0, "plateau_stderr": regime.h0_stderr,
        "breakaway_force": regime.breakaway_force, **regime.extra,
    }  # fmt: skip


def _assess(
    b: _Base,
    d: Prepared,
    st: SearchState,
    names: list[str],
    z: float,
    min_gain: float,
    folds: int,
    declared_noise: float | None,
    location: dict[str, Any],
) -> dict[str, Any]:
    """Issue 29 items 1-3 on the finished search: both channels' noise, what each candidate
    not named would have needed to be seen, and structure the final model leaves
    (:mod:`.assessment`); the detection settings go into ``location``, a flagged misfit's
    sentence into the search's ``where``."""
    from .assessment import assess

    checks = assess(
        b.family, d, st.current, b.sigma, z=z, gain_floor=min_gain + b.budget, folds=folds,
        candidates=names, declared_output=declared_noise,
    )  # fmt: skip
    location["detection"] = {k: checks[k] for k in ("z", "gain_floor", "folds", "candidates")}
    return checks


#: the key of ``d.extra`` under which the closing checks keep the effects they withdrew,
#: with why (read by the stated power: :func:`contactlab.diagnose.power.detectable_above`)
WITHDRAWN = "withdrawn"
#: what the report says of an effect withdrawn because the misfit test found it absorbing
#: structure it does not model (:data:`contactlab.diagnose.misfit.SHAPE_ABSORBERS`)
ABSORBED = (
    "it reshaped the virgin curve and took up part of a systematic misfit it does not "
    "model (its own signature test failed)"
)


def _locked_on_misfit(
    st: SearchState, d: Prepared, checks: dict[str, Any]
) -> tuple[str, str] | None:
    """An effect named only by the lowered input-noise floor of an effect that cannot
    filter the input (``search.locked_noise_gain``: below the share of the whole budget it
    beat before) on a record whose final model still leaves a misfit the misfit test flags,
    and why; else None. The lowered floor answers the input's noise; against a misspecified
    base, whose systematic residual any candidate shaves a sliver off, the share of the
    budget stays its floor (a tanh virgin curve behind the sensor chain,
    ``benches/eval_misfit_flag.py`` tuning seed 51125004: a track's wave took 0.048 σ² at
    t = 6.5 beside a series compliance, below the 0.050 σ² of that floor)."""
    u = checks.get("unexplained")
    if u is None or not u.flagged:
        return None
    from .search import LOCKED_ONLY

    only = d.extra.get(LOCKED_ONLY) or {}
    e = next((e for e in st.added if e in only), None)
    if e is None:
        return None
    return e, (
        f"accepted below {only[e]:.3g} σ², the input-noise share's floor, by the floor of "
        "the noise's own bias, on a record whose misfit is unexplained"
    )


#: an effect named by the locked floor stays on a flagged record where the structure the
#: phase bins flag without it is its own (:func:`_takes_own_structure`; False: withdrawn
#: whenever the record is flagged with and without it, as at stop 52)
LOCKED_OWN_STRUCTURE = True
#: the structure tests of the misfit flag (the flag's other sources, ``rivals``, ``patches``
#: and ``absorbing``, judge the named effects, not the residual)
STRUCTURE_TESTS = ("phase_bins", "backbone")


def _takes_own_structure(with_it: Any, without: Any) -> str | None:
    """Why an effect named only by the locked floor is no patch over a misfit although the
    record is flagged with and without it, else None: without it only the phase bins flag
    (the free-form virgin curve does not: no virgin curve of another shape draws that
    structure), and with it no structure test flags (phase bins and free-form virgin curve
    both quiet): what is left flagged is the shape checks' caveat on the named effect
    itself (``rivals``, ``patches``), which the report keeps.

    Why (issue 29, stop 53): a rig track wave of 1.5 times the ideal test's size (2 kHz,
    10.7 Hz, 35 cycles, x noise 3 % of the amplitude, ac·A 1.57; ``benches/eval_ideal_bound.py``
    condition posfric_d, tuning seed 53200000) was accepted by the locked floor (held-out
    gain 0.036 σ²) and withdrawn: with it the record was flagged by the rivals and patch
    checks only (phase bins T = 74, hand statistic 8 against 31), without it by the phase
    bins (T = 221 against 60 of the simulated null, hand statistic 75 against 31), the
    free-form virgin curve quiet (t = 3.5 against 4.8): the wave was the structure the
    phase bins saw."""
    from .flag_route import _flag_sources

    if not LOCKED_OWN_STRUCTURE or with_it is None or without is None or not without.flagged:
        return None
    if any(s in STRUCTURE_TESTS for s in _flag_sources(with_it)):
        return None
    if _flag_sources(without) != ["phase_bins"]:
        return None
    return (
        "without it the phase bins flag the structure it takes (no virgin curve of another "
        "shape draws it: the free-form virgin curve does not flag), with it neither structure "
        "test flags; what stays flagged is the shape checks' caveat on the named effect"
    )


def _flagged_without(
    b: _Base,
    d: Prepared,
    st: SearchState,
    name: str,
    names: list[str],
    z: float,
    min_gain: float,
    folds: int,
    declared_noise: float | None,
    location: dict[str, Any],
) -> bool:
    """Whether the misfit test still flags the final model refitted without ``name`` (the
    closing checks on a copy of the search's state): a misfit of the base that the effect
    did not explain (guard of :func:`_locked_on_misfit`); where the flag goes with it, the
    flag was the effect's own (a named set a free-form virgin curve explains as well) and
    the effect stays."""
    failed, u = _unexplained_without(
        b, d, st, name, names, z, min_gain, folds, declared_noise, location
    )
    return bool(failed or (u is not None and u.flagged))


def _unexplained_without(
    b: _Base,
    d: Prepared,
    st: SearchState,
    name: str,
    names: list[str],
    z: float,
    min_gain: float,
    folds: int,
    declared_noise: float | None,
    location: dict[str, Any],
) -> tuple[bool, Any]:
    """Whether the refit of the final model without ``name`` failed, and the misfit test's
    answer (``unexplained``, calibrated; None: nothing to test) on it
    (:func:`_flagged_without`)."""
    rest = tuple(e for e in st.current.effects if e != name)
    try:
        refit = evaluate(b.family, rest, d, st.current.full.params, b.scales, folds)
    except (ConvergenceError, InputError):
        return True, None
    trial = dataclasses.replace(
        st, current=refit, steps=list(st.steps), where=list(st.where),
        trials=[*st.trials, refit], added=[e for e in st.added if e != name],
        visited=set(st.visited), seen=dict(st.seen), untested=list(st.untested),
    )  # fmt: skip
    checks = _assess(b, d, trial, names, z, min_gain, folds, declared_noise, location)
    checks = _calibrated(b, d, trial, _rivals(b, d, trial, checks))
    return False, checks["unexplained"]


def _unfounded(family: Family, st: SearchState, d: Prepared) -> tuple[str, str] | None:
    """The first effect named by this diagnosis that its final fit does not support, and
    why: its size within :attr:`~contactlab.diagnose.effects.EffectModel.IDENTIFIED_SIGMAS`
    standard errors of "absent", at "absent" itself, or with no computable error (the least
    significant first), else implausible on the
    record with the final parameters (a refit after later additions can move an effect
    accepted early into a value the record contradicts). None when every one stands."""
    p, se = st.current.full.params, st.current.full.stderr
    weakest: tuple[float, str, str] | None = None
    if hasattr(family, "identified"):
        from .effects import registry

        reg = registry(family.kind)
        for e in st.added:
            if e not in reg:
                continue
            why = family.identified(e, p, se, d=d)
            v, s = reg[e].size(p, se)
            if not why and (v == 0 or (not np.isfinite(s) and _at_null(reg[e], p))):
                # at its null value (its error not computable there): nothing says it is there
                err = "cannot be computed" if not np.isfinite(s) else f"is {s:.2g}"
                why = (
                    f"not identifiable: its size is {v:.3g}, at the value meaning no effect, "
                    f"and its standard error {err}"
                )
            if why:
                ratio = v / s if np.isfinite(s) and s > 0 else 0.0
                if weakest is None or ratio < weakest[0]:
                    weakest = (ratio, e, why)
    if weakest is not None:
        return weakest[1], weakest[2]
    if hasattr(family, "implausible"):
        for e in st.added:
            why = family.implausible(e, p, d)
            if why:
                return e, f"implausible: {why}"
    return None


def _at_null(effect: Any, p: dict[str, float]) -> bool:
    """Whether the effect's size parameter lies within 1e-3 of its bounds' span from the
    value meaning "absent" (as :meth:`~contactlab.diagnose.effects.EffectModel.plausible`
    judges a value at a limit; False for a parameter without finite bounds)."""
    spec = next((q for q in effect.params if q.name == effect.size_param), effect.params[0])
    span = spec.upper - spec.lower
    null = spec.null if np.isfinite(spec.null) else 0.0
    return bool(np.isfinite(span) and abs(p[spec.name] - null) <= 1e-3 * span)


def _withdraw(
    b: _Base,
    d: Prepared,
    st: SearchState,
    names: list[str],
    z: float,
    min_gain: float,
    folds: int,
    declared_noise: float | None,
    location: dict[str, Any],
    checks: dict[str, Any],
    force: list[tuple[str, str]] | None = None,
) -> dict[str, Any]:
    """The final model without the effects it cannot name (issue 29 item 5), refitted.

    An effect named by the search is withdrawn when the closing checks find it absorbing a
    misfit it does not model (the misfit test's ``absorbing``; kept, with a sentence, when
    the data show its own signature independently of the fit: :func:`_signature`), when
    its final size is not significantly different from "absent" (within two standard
    errors, after the other effects: the search judged it against the model of its step),
    or when its final
    parameters are implausible on the record. One at a time: the model is refitted and
    cross-validated without it (a step ``- name`` in the gap-shrink table, so that the
    parameters, the held-out gap and the h0 check are the reported model's) and checked
    again. ``location["withdrawn"]`` lists them, ``location["withdrawn_why"]`` says why.
    ``force``: ``(name, why)`` withdrawn too, when nothing above withdraws one
    (:func:`_locked_on_misfit`). Returns the closing checks of the final model."""
    force = list(force or ())
    withdrawn: dict[str, str] = {}
    absorbed: list[str] = []
    kept: set[str] = set()
    for _ in range(len(st.added)):
        absorbing = getattr(checks["unexplained"], "absorbing", ())
        for e in absorbing:
            shown = _signature(b.family, e, d) if e in st.added and e not in kept else None
            if not shown and e in st.added and e not in kept:
                shown = _signature_at(b, d, st, e)
            if shown:
                kept.add(e)
                st.where.append(
                    f"{e} leaves a systematic misfit but is kept: {shown} (the misfit left is "
                    "reported as unexplained)"
                )
        gone = next(((e, ABSORBED) for e in absorbing if e in st.added and e not in kept), None)
        gone = gone or _unfounded(b.family, st, d) or (force.pop() if force else None)
        if gone is None:
            break
        name, why = gone
        rest = tuple(e for e in st.current.effects if e != name)
        try:
            refit = evaluate(b.family, rest, d, st.current.full.params, b.scales, folds)
        except (ConvergenceError, InputError) as exc:
            st.where.append(f"{name} could not be withdrawn ({why}): the refit failed: {exc}")
            break
        st.current = refit
        st.added.remove(name)
        st.trials.append(refit)
        st.steps.append(Step(None, *StepwiseSearch._errors(refit), removed=name))
        st.where.append(
            f"withdrawn: {name} ({why}); the final model is refitted without it, and its "
            "parameters, held-out error and h0 are those of the refit"
        )
        withdrawn[name] = why
        # the stated power promises no size of an effect seen and withdrawn (power.py)
        d.extra.setdefault(WITHDRAWN, {})[name] = why
        if why is ABSORBED:
            absorbed.append(name)
        checks = _assess(b, d, st, names, z, min_gain, folds, declared_noise, location)
    if withdrawn:  # (a second pass, after the calibrated flag, adds to the first's)
        location["withdrawn"] = [*location.get("withdrawn", []), *withdrawn]
        location["withdrawn_why"] = {**location.get("withdrawn_why", {}), **withdrawn}
    if checks["unexplained"] is not None:  # the absorbers withdrawn (not those kept)
        checks["unexplained"] = dataclasses.replace(
            checks["unexplained"], absorbing=tuple(absorbed)
        )
    return checks


def _rivals(b: _Base, d: Prepared, st: SearchState, checks: dict[str, Any]) -> dict[str, Any]:
    """A named effect that a free-form virgin curve explains as well (issue 29 item 3).

    A virgin curve of another shape is taken up by named effects that are no shape of the
    branches (a tanh virgin curve named normal_load or stribeck): after them the residual
    looks white and the misfit tests stay silent. For each named effect of
    :data:`.shape.SHAPE_RIVALS` the final model is refitted without it, and a Masing
    element with a free-form virgin curve is fitted to that refit's residual
    (:func:`.shape.rival_share`): where it reaches :data:`.shape.RIVAL_SHARE` of the
    effect's gain, the effect's evidence is equally a misfit of the branch shape, and the
    misfit is flagged (``unexplained.rivals``; the effect stays named, with that caveat).
    Returns the closing checks, updated."""
    from .select import specs_for
    from .shape import RIVAL_SHARE, RIVAL_SHARE_OWN, SHAPE_RIVALS, rival_share

    u = checks["unexplained"]
    p = dict(st.current.full.params)
    effects = tuple(st.current.effects)
    if u is None or b.family.kind != "tangential" or "ac" not in p:
        return checks
    r1 = -st.current.full_residual(d)
    found: list[dict[str, Any]] = []
    for e in effects:
        if e not in SHAPE_RIVALS:
            continue
        rest = tuple(x for x in effects if x != e)
        try:
            f = fit(b.family, rest, d, np.ones(d.y.size, bool), p, b.scales)
            r0 = d.y - b.family.predict(f.params, rest, d)
        except (ConvergenceError, InputError):
            continue
        n_par = len(specs_for(b.family, effects)) - len(specs_for(b.family, rest))
        got = rival_share(d, r1, r0, float(p["ac"]), b.sigma, n_par)
        if got is not None and got["share"] >= RIVAL_SHARE_OWN.get(e, RIVAL_SHARE):
            found.append({"effect": e, **got})
    if not found:
        return checks
    checks["unexplained"] = dataclasses.replace(u, flagged=True, rivals=found)
    return checks


def _absorbed(b: _Base, d: Prepared, st: SearchState, flagged: bool) -> list[dict[str, Any]]:
    """The named shape effects that a free-form virgin curve with none of them predicts as
    well on held-out cycles (:func:`.misfit.absorbed_backbone`), or a virgin curve of
    another shape in place of the base and those effects that predicts them better
    (:func:`.misfit.alternative_virgin`): a patch entry where either flags, else empty (not
    run where the misfit is already flagged: each costs up to four fits)."""
    from .misfit import absorbed_backbone, alternative_virgin

    if flagged:
        return []
    p = dict(st.current.full.params)
    got = absorbed_backbone(b.family, tuple(st.current.effects), d, p, b.scales, b.sigma)
    if got is not None and got["flagged"]:
        return [got]
    # a virgin curve of another shape in place of the base and the named shape effects
    alt = alternative_virgin(b.family, tuple(st.current.effects), d, p, b.scales, b.sigma)
    return [alt] if alt is not None and alt["flagged"] else []


def _calibrated(b: _Base, d: Prepared, st: SearchState, checks: dict[str, Any]) -> dict[str, Any]:
    """The misfit flag against the record's own simulated null (issue 29 items 1 and 3).

    The phase bins' ``T`` and the free-form virgin curve's held-out ``t`` on the final
    residual are compared with their distribution over copies of the record simulated
    under the null with its own noise on both channels
    (:func:`.misfit_null.simulated_null`, :func:`.misfit_null.calibrated_flag`), not with
    hand thresholds; and a named set that a free-form virgin curve with fewer parameters
    explains as well is a patch over a shape misfit (:func:`.shape.patch_check`). Either
    flags the misfit, as do the rivals (:func:`_rivals`). Tangential records only; where
    the null cannot be simulated (a record kept at a lower rate) the earlier flag stands.
    Returns the closing checks, updated."""
    from .misfit import unexplained_structure
    from .misfit_null import calibrated_flag, simulated_null
    from .shape import patch_check, slope_check, tail_check

    u = checks["unexplained"]
    p = dict(st.current.full.params)
    if b.family.kind != "tangential" or "ac" not in p:
        return checks
    effects = tuple(st.current.effects)
    r1 = -st.current.full_residual(d)
    if u is None:  # every bin left out for its input noise: the calibrated null needs none
        u = unexplained_structure(d, r1, b.sigma, unit=b.family.output_unit, min_weight=0.0)
        if u is None:
            return checks
        u = dataclasses.replace(u, flagged=False)
    nd = simulated_null(b.family, p, effects, d, r1, float(checks["noise"].output), b.sigma)
    patches = patch_check(b.family, effects, d, p, b.scales, r1, b.sigma)
    slope, unchecked = slope_check(effects, d, p)
    tail, untailed = tail_check(effects, d, p)
    patches = [*patches, *slope, *tail]
    for note in (unchecked, untailed):
        if note:
            st.where.append(note)
    if nd is None:
        patches = patches or _absorbed(b, d, st, bool(u.rivals))
        if patches:
            checks["unexplained"] = dataclasses.replace(u, flagged=True, patches=patches)
        return checks
    # the phase bins flag where both their hand threshold (with the interval null of the
    # input noise's reach) and the simulated null say so: the chain's own imprint (a load
    # cell's ringing after each reversal, a skew between the anti-alias filters) is
    # structure at a few per cent of the noise that the simulation does not carry
    cal = calibrated_flag(nd, hand_bins=bool(u.statistic > u.threshold))
    if not patches:
        patches = _absorbed(b, d, st, bool(cal["flagged"] or u.rivals))
    flagged = cal["flagged"] or bool(u.rivals) or bool(patches)
    checks["unexplained"] = dataclasses.replace(u, flagged=flagged, calibrated=cal, patches=patches)
    return checks


#: the flag route runs on flagged final models (:mod:`.flag_route`; False: off, to measure)
FLAG_ROUTE = True


def _flag_route(
    b: _Base,
    d: Prepared,
    st: SearchState,
    names: list[str],
    z: float,
    min_gain: float,
    folds: int,
    declared_noise: float | None,
    location: dict[str, Any],
    checks: dict[str, Any],
) -> dict[str, Any]:
    """A flagged final model: the one candidate that explains the flagged structure, named
    by :func:`.flag_route.flag_route` with the closing checks (:func:`_assess`,
    :func:`_rivals`, :func:`_calibrated`) re-run on the model with it; not run once the
    search has spent its evaluation budget. Returns the closing checks of the final model."""
    u = checks["unexplained"]
    if not FLAG_ROUTE or u is None or not u.flagged:
        return checks
    from .search import _max_evaluations

    # the search's evaluation budget binds the route too: once spent, no candidate is fitted
    if st.untested or st.used >= _max_evaluations():
        return checks
    from .flag_route import flag_route

    def recheck(state: SearchState, where: dict[str, Any]) -> dict[str, Any]:
        ck = _assess(b, d, state, names, z, min_gain, folds, declared_noise, where)
        return _calibrated(b, d, state, _rivals(b, d, state, ck))

    return flag_route(b, d, st, names, checks, recheck, folds, z, location)


def _signature(family: Family, name: str, d: Prepared) -> str | None:
    """The data's own evidence for the effect ``name``, independent of any fit (the
    effect's ``signature(d)``: series compliance's straight turns), or None."""
    from .effects import registry

    eff = registry(family.kind).get(name) if family.kind in ("tangential", "normal") else None
    sig = getattr(eff, "signature", None)
    return sig(d) if sig is not None else None


def _signature_at(b: _Base, d: Prepared, st: SearchState, name: str) -> str | None:
    """The evidence for the named effect ``name`` that its fitted parameters show beyond
    any virgin curve (:func:`signature_beyond_virgin` at the final model), or None."""
    try:
        return signature_beyond_virgin(
            b.family, name, d, dict(st.current.full.params), tuple(st.current.effects)
        )
    except (ConvergenceError, InputError, ValueError, ArithmeticError, np.linalg.LinAlgError):
        return None


def signature_beyond_virgin(
    family: Family,
    name: str,
    d: Prepared,
    params: dict[str, float],
    effects: tuple[str, ...],
    z: float | None = None,
) -> str | None:
    """Why the effect ``name`` of the model ``(params, effects)`` is no patch over a virgin
    curve of another shape, or None: the effect's ``signature_parts`` (the residual without
    it, its direction) tested by :func:`.misfit.beyond_virgin`, its held-out gain beyond a
    free-form virgin curve across cycles at t > ``z`` (:data:`SIGNATURE_Z`). None for an
    effect without ``signature_parts`` (issue 29, stop 52: a track's wave)."""
    from .effects import registry
    from .misfit import beyond_virgin

    z = SIGNATURE_Z if z is None else z
    eff = registry(family.kind).get(name) if family.kind == "tangential" else None
    hook = getattr(eff, "signature_parts", None)
    if hook is None or "ac" not in params or not np.isfinite(z):
        return None
    parts = hook(d, params, effects, family)
    if parts is None:
        return None
    res = beyond_virgin(d, parts[0], parts[1], float(params["ac"]))
    if res is None or not (res["t"] > z and res["gain"] > 0):
        return None
    return (
        f"a free-form virgin curve does not draw it: its part odd about the stroke's "
        f"middle gains across held-out cycles beyond one (t = {res['t']:.1f} over "
        f"{res['cycles']} cycles)"
    )


#: the held-out t across cycles an effect's evidence beyond the shapes it is withdrawn for
#: must reach to keep it (:func:`_signature_at`; the search's own z; inf: never, as before
#: stop 52)
SIGNATURE_Z = 3.0


def _ready(
    family: Family, d: Prepared, recording: Any, context: dict[str, float], taps: Any
) -> tuple[dict[str, Any] | None, list[str]]:
    """The prepared record made ready for the search: the model's context and the
    recording's meta in ``d.extra``, the prior weight of the data (returned, with its
    sentences), the evaluation counter, and the family's own preparation."""
    d.extra.update(context)
    d.extra["meta"] = _meta(recording)
    prior, prior_notes = _prior_weight(family, d, taps)
    d.extra["evaluations"] = EvaluationCounter()  # counted by select.fit
    family.prepare(d)
    return prior, prior_notes


def _checked_arrays(
    recording: Any, family: Family, folds: int, max_effects: int, z: float, min_gain: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The recording's arrays, checked (channels, glitches) with the search's settings."""
    t, u, y = _arrays(recording, family)
    named = {family.input_name: (u, family.input_unit), family.output_name: (y, family.output_unit)}
    check_channels(t, named)
    check_glitches(t, named)
    if folds < 2:
        raise InputError(f"folds must be >= 2, got {folds}")
    if max_effects < 0:
        raise InputError(f"max_effects must be >= 0, got {max_effects}")
    if not (z > 0 and min_gain >= 0):
        raise InputError(f"z must be > 0 and min_gain >= 0, got z={z}, min_gain={min_gain}")
    return t, u, y


def _candidate_names(family: Family, candidates: Sequence[str] | None) -> list[str]:
    names = list(family.candidates) if candidates is None else list(candidates)
    for n in names:
        if n not in family.candidates:
            raise InputError(
                f"unknown {family.kind} candidate {n!r}; choose from {', '.join(family.candidates)}"
            )
    return names


def _delayed(recording: Any, family: Family, delay: float) -> Any:
    """``diagnose(..., delay=)``: the tangential recording with its force read later."""
    if family.kind != "tangential":
        raise InputError("delay= is for tangential recordings (force against displacement)")
    from ..tangential.lag import delayed_recording

    return delayed_recording(recording, delay)


def _meta(recording: Any) -> dict[str, Any]:
    """The recording's meta (a reconstructed force, a frame), for the effects' plausibility."""
    meta = getattr(recording, "meta", None)
    return dict(meta) if isinstance(meta, dict) else {}


def _output_noise(
    family: Family, params: dict[str, float], d: Prepared, residual: np.ndarray
) -> float:
    """The output noise RMS the detection judges gains in: the white estimate from the
    residual's third differences, or, for a tangential record whose residual's spectrum
    shows the noise coloured (an anti-alias filter on the force), the spectral one
    (:func:`.detection.output_noise_rms`, kept in ``d.extra["y_noise_spectral"]`` for the
    closing checks)."""
    white = noise_rms(residual)
    d.extra.pop("y_noise_spectral", None)
    if family.kind != "tangential":
        return white
    from .detection import model_slope, output_noise_rms

    slope = model_slope(family, params, d) if float(d.extra.get("u_noise", 0.0) or 0.0) else None
    coloured = output_noise_rms(d, residual, slope, white)
    if coloured is None:
        return white
    d.extra["y_noise_spectral"] = coloured
    return coloured


@dataclass
class _Base:
    """The base model as the search starts from it."""

    family: Family
    current: Trial
    sigma: float
    budget: float
    scales: dict[str, float]
    weighted: bool
    anchored: str | None
    unanchored: dict[str, Any]


def _fit_base(
    family: Family,
    effects: tuple[str, ...],
    d: Prepared,
    start: dict[str, float],
    folds: int,
    declared_noise: float | None,
) -> _Base:
    """The base fitted to all data (the noise level and the errors-in-variables weights),
    cross-validated once with the weights it ends up with; then, for a family that can, the
    base anchored to its regime (on a copy: a model passed in keeps its own family)."""
    scales = family.scales(d)
    if not start:
        start = family.initial_base(d)
    fold_masks(d, folds)  # too few cycles to hold any out: said before fitting
    base_all = fit(family, effects, d, np.ones(d.y.size, bool), start, scales)
    sigma = declared_noise or _output_noise(
        family, base_all.params, d, family.predict(base_all.params, effects, d) - d.y
    )
    if sigma <= 0:
        raise InputError("the output channel has no noise at all; cannot judge significance")
    budget = 0.0
    w = eiv_weight(family, base_all.params, d, sigma)
    if w is not None:  # errors in variables: refit the base with the likelihood's weights
        d.extra["weight"], budget = w
        d.extra["input_noise_budget"] = budget  # (for an effect's yields_to)
        current = evaluate(family, effects, d, base_all.params, scales, folds, parallel=True)
        sigma = declared_noise or _output_noise(
            family, current.full.params, d, current.full_residual(d)
        )
    else:
        current = evaluate(family, effects, d, start, scales, folds, base_all, parallel=True)
    anchored, unanchored = None, {}
    if hasattr(family, "anchor"):
        family = copy.copy(family)
        anchored = family.anchor(current.full.params, current.full.stderr, d)
    if anchored:  # the base was in the wrong regime: fixed before any effect is tried
        unanchored = {
            "heldout_rms": current.heldout_rms,
            "h0": current.full.params["h0"],
            "h0_stderr": _finite_or_none(current.full.stderr["h0"]),
        }
        current = evaluate(family, effects, d, current.full.params, scales, folds, parallel=True)
    return _Base(family, current, sigma, budget, scales, w is not None, anchored, unanchored)


def _describe_base(
    b: _Base,
    d: Prepared,
    regime: RegimeDecision,
    notes: list[str],
    reduced: str,
    prior: dict[str, Any] | None,
    prior_notes: list[str],
) -> tuple[list[str], dict[str, Any]]:
    """Where the base residual lives, in sentences (the regime first, then how the record
    was read and reduced, then the locations) and the report's ``location`` entries."""
    where, location = locate(d, b.current.full_residual(d), b.family)
    if b.anchored:
        location["base_unanchored"] = b.unanchored
        where.insert(0, b.anchored)
    head = [_regime_sentence(b.family, regime, b.current.full.params, d), *notes]
    head += [reduced] if reduced else []
    if prior is not None:
        location.update(prior)
        head += prior_notes
    where[0:0] = head
    location["regime"] = regime.to_dict()
    if b.weighted:
        low = float(np.mean(d.extra["weight"] < 0.5))
        location["low_weight_fraction"] = low
        if low > 0.01:
            where.append(
                f"{100 * low:.0f} % of the samples count less than half (input noise "
                f"{d.extra['u_noise']:.3g} seen through a steep local slope, e.g. sticking "
                "phases after reversals): what the model does there is barely tested"
            )
    return where, location


def _regime_sentence(
    family: Family, regime: RegimeDecision, p: dict[str, float], d: Prepared
) -> str:
    """The regime (analyze's decision where there is one) and the base model's numbers."""
    own = family.regime(p, d)
    if regime.source != "analyze":
        err = regime.extra.get("analyze_error")
        return own if not err else f"{own} (analyze could not read the record: {err})"
    tail = own.rsplit("; ", 1)[1] if own and "; " in own else ""
    return f"{regime.reason}; base model: {tail}" if tail else regime.reason


def _refused(st: SearchState, effects: tuple[str, ...]) -> dict[str, str]:
    """The candidates that passed the held-out rules at some step but were refused as
    physically implausible on the record (the last reason given for each), not in the final
    model: the report says why each is not named (issue 29 item 5)."""
    out: dict[str, str] = {}
    for step in st.steps:
        for v in step.candidates:
            if v.reason.startswith("implausible: ") and " ⇄ " not in v.name and "+" not in v.name:
                out[v.name] = v.reason.removeprefix("implausible: ")
    return {k: v for k, v in out.items() if k not in effects}


def _report(
    family: Family,
    path: KindPath,
    recording: Any,
    regime: RegimeDecision,
    d: Prepared,
    st: SearchState,
    sigma: float,
    location: dict[str, Any],
) -> DiagnosisReport:
    """The report of a finished search: each effect with its parameters, derived values and
    plausibility argument; the final model checked against ``analyze``'s parameters."""
    current, where = st.current, st.where
    p, se, effects = current.full.params, current.full.stderr, current.effects
    out_effects = []
    for name in st.added:
        ps = {s.name: p[s.name] for s in family.candidates[name].params}
        ss = {s.name: se[s.name] for s in family.candidates[name].params}
        more = {"effects": effects, "d": d} if getattr(family, "derived_from_data", False) else {}
        dp, ds = family.derived(p, se, name, **more)
        why = ""
        if hasattr(family, "plausibility"):
            why = family.plausibility(name, p, d)[1]
        out_effects.append(Effect(name, {**ps, **dp}, {**ss, **ds}, why))
    final = ExtendedModel(family, effects, p, se, family.context(d))
    out_effects = _frame_constants(recording, out_effects, where, location)
    model_force = strokes = None
    if regime.h0 is not None:  # the final model's force, read as analyze read the data
        fitted = family.predict(p, effects, d)
        model_force = (d.t, d.extra.get("u_raw", d.u), fitted)
        levels = [stroke_levels(d.u, f, d.cycles.reversals) for f in (d.y, fitted)]
        strokes = (levels[0], levels[1]) if None not in levels else None
    check, moved = path.check_final(regime, p, effects, model_force, strokes)
    if check is not None:
        location["h0_check"] = check
    if moved:
        where.append(moved)
    refused = _refused(st, effects)
    if refused:
        location["refused"] = refused
        where.extend(
            f"not named: {name} would have lowered the held-out error significantly, but is "
            f"refused as {why}"
            for name, why in refused.items()
        )
    gap = current.heldout_rms / sigma
    if gap > 1.5:
        where.append(
            f"after {'the additions' if st.added else 'the base fit'} the held-out RMS is "
            f"still {gap:.1f}× the noise level: the remaining discrepancy is not explained by "
            "any candidate of the library"
        )
    return DiagnosisReport(
        family.kind, out_effects, st.steps, where, sigma, final, location, d, st.trials
    )
