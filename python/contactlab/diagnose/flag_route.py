"""The flag route (issue 29): name the one candidate that explains a flagged misfit.

The stepwise search names a candidate only when its held-out gain beats the per-sample
floors (``min_gain`` and the input-noise budget), is consistent across held-out cycles at
``t > z``, lowers the BIC and is not a sliver of the remaining error
(:func:`contactlab.diagnose.select.judge`). Those rules guard a record on which nothing
says that any structure is left. Once the closing checks flag the final model
(:mod:`.misfit`, :mod:`.misfit_null`: the residual holds structure locked to the cycle
beyond the record's own simulated null, at the false-alarm rate
:data:`~.detection.MISFIT_FALSE_ALARM`), the question is another one: is that structure
one candidate's, or a misfit no candidate draws (a virgin curve of another shape, a
non-Masing branch)?

:func:`flag_route` asks it of the final model, flagged by the structure tests alone (the
phase bins or the free-form virgin curve against the simulated null, not by a named set
that a free-form curve explains as well, ``rivals``/``patches``, nor where a shape effect
was withdrawn as absorbing it, ``absorbing``: there the flag already says the structure is
a shape misfit):

1. every candidate not in the final model (and not withdrawn by the closing checks) is
   added and cross-validated as the search does (:func:`.search._try_candidate`), with the
   per-sample floor ``min_gain`` dropped (the flag has established that structure is there)
   but the held-out gain beyond the input-noise budget's share the candidate can take from
   the input's noise alone (:func:`.search.net_of_noise`: a bias, not a significance
   floor; a sub-sample delay smoothing the noisy input took a 2f load's flag without it,
   tuning seeds 51300003, 51300200-201), the per-cycle
   ``t`` above :data:`ROUTE_Z` (conditional on the flag: the structure is established, the
   test only has to say which direction of it the candidate takes), the BIC and rule 4's
   relative floor as they are, and every plausibility, identification and take-over rule
   of the search;
   and a candidate a virgin curve of another shape can stand in for
   (:data:`.shape.PATCHABLE`) must not be drawn by the free-form virgin curve's columns:
   the share of its own signal (its model's fit minus the final model's) they draw stays
   below :data:`.shape.RIVAL_SHARE` (:func:`_signal_share`; the closing checks' rivals
   test, a share of the *gain*, exceeds 1 for a genuine effect where the residual holds
   other structure too: genuine position frictions on the shaker rig, tuning seeds
   51300003-7, gain shares 0.96-1.59, signal shares 0.55-0.96; misfits absorbed by a
   compliance, a spring, a 2f load, a backlash or a stick-slip on ``benches/eval_misfit_flag.py``
   seeds 51315005 and 51315012: signal shares 0.82-1.0), so it replaces the rivals test for
   the candidate itself;
2. the :data:`ROUTE_TRIES` of those with the largest held-out gains beyond their
   input-noise floor (:func:`.search.net_of_noise`) are added to the final
   model one at a time and the closing checks re-run on it (the record's null simulated
   again for that model, the free-form and alternative virgin curves, the patch, slope and
   tail checks): a candidate *explains* the flagged structure when the flag clears;
3. the one that explains it is named, with ``location["flag_route"]`` saying so, when no
   other candidate that passed the held-out rules of step 1 (a shape lookalike refused by
   its signal's share included) fits the held-out cycles comparably (its lead's paired ``t``
   across held-out cycles, :func:`.search.paired_lead`, above the search's ``z``, as the
   search tells look-alikes apart); otherwise
   none is named and the candidates not told apart are reported (the flag stays).

A misfit no candidate draws (tanh, rational, gamma virgin curves, a non-Masing branch)
keeps the flag after any single candidate: the closing checks built for shape absorbers
(:func:`.misfit.absorbed_backbone`, :func:`.misfit.alternative_virgin`,
:func:`.shape.patch_check`) run on the augmented model too.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import numpy as np

from ..errors import ContactLabError
from ._family import Prepared
from .shape import RIVAL_SHARE, RIVAL_SHARE_OWN

__all__ = ["ROUTE_TRIES", "ROUTE_Z", "flag_route"]

#: the per-cycle t a candidate's held-out gain must exceed on a flagged record (one-sided
#: 2.3 % of a normal: the structure is established at the flag's false-alarm rate; the
#: flag clearing is the candidate's main test)
ROUTE_Z = 2.0
#: a candidate must gain beyond its share of the input-noise budget (False: a positive
#: held-out gain suffices). On the shaker rig at issue 29's conditions (seeds 51300100-105
#: and 51300200-201, 11 records where the route ran): with it 1 named right (position
#: friction), 0 wrong; without it 5 right (position friction), 1 wrong (a delay for a 2f
#: load at 1 kHz, 3.9 Hz, 0.7x the blind miss's size): a miss is preferred to a wrong name
NET_OF_NOISE = True
#: candidates (largest held-out gain first) for which the closing checks are re-run
ROUTE_TRIES = 3
#: the flag sources that read the structure as a misfit of the branches' shape: where any
#: of them flagged, the route does not run (a bench may empty it to measure the route's own
#: guards on such records)
SHAPE_FLAGS = ("rivals", "patches", "absorbing")


def _flag_sources(u: Any) -> list[str]:
    """The tests that flagged the final model (``unexplained``): ``calibrated.by``, else
    the hand thresholds', and ``rivals``, ``patches`` and ``absorbing`` where non-empty."""
    cal = getattr(u, "calibrated", None)
    src = list((cal or {}).get("by") or []) if cal is not None else []
    if cal is None:
        if u.statistic > u.threshold:
            src.append("phase_bins")
        if (u.backbone or {}).get("flagged"):
            src.append("backbone")
    for key in ("rivals", "patches", "absorbing"):
        if getattr(u, key, ()):
            src.append(key)
    return src


def flag_route(
    b: Any,
    d: Prepared,
    st: Any,
    names: list[str],
    checks: dict[str, Any],
    recheck: Callable[[Any, dict[str, Any]], dict[str, Any]],
    folds: int,
    z: float,
    location: dict[str, Any],
) -> dict[str, Any]:
    """The flag route on the finished diagnosis (module docstring); ``b`` the workflow's
    base (family, scales, sigma), ``st`` the search's state (updated in place when a
    candidate is named), ``recheck(state, location)`` the workflow's closing checks on a
    state. Returns the closing checks of the final model; ``location["flag_route"]`` says
    what was tried and decided."""
    from .search import StepwiseSearch, _try_candidate, net_of_noise, paired_lead

    u = checks.get("unexplained")
    if u is None or not u.flagged:
        return checks
    src = _flag_sources(u)
    info: dict[str, Any] = {
        "ran": False, "route": "flag", "z": ROUTE_Z, "z_told_apart": float(z),
        "before": {"named": list(st.added), "flagged_by": src},
        "tried": [], "named": None, "not_told_apart": [],
        "input_noise_budget": float(b.budget),
    }  # fmt: skip
    location["flag_route"] = info
    shape = [s for s in src if s in SHAPE_FLAGS]
    if shape or not src:
        info["why_not"] = (
            f"flagged by {', '.join(shape)}: the structure reads as a misfit of the branches' shape"
            if shape
            else "no structure test flagged"
        )
        return checks
    info["ran"] = True
    family, current = b.family, st.current
    effects = tuple(current.effects)
    withdrawn = set((d.extra.get("withdrawn") or {}).keys())
    pool = [n for n in names if n not in effects and n not in withdrawn]
    all_samples = np.ones(d.y.size, bool)
    base_fit = dict(st.trials[0].full.params) if st.trials else dict(current.full.params)
    passed: list[tuple[Any, Any, float]] = []
    rivals: list[tuple[Any, Any]] = []
    for name in pool:
        try:
            v, cand = _try_candidate(
                name, family, current, effects, d, b.scales, folds, b.sigma, ROUTE_Z, 0.0,
                0.0, base_fit, all_samples,
            )  # fmt: skip
        except ContactLabError:
            continue
        if cand is None or not (np.isfinite(v.gain) and v.gain > 0):
            continue
        net = net_of_noise(family, name, v.gain, b.budget, d, cand.full.params)
        entry = {
            "name": name, "gain": float(v.gain), "gain_net_of_noise": float(net),
            "t": float(v.t_stat), "accepted": bool(v.accepted), "reason": v.reason,
        }  # fmt: skip
        info["tried"].append(entry)
        if v.accepted:
            # every candidate that passed the held-out rules is a rival of the one named,
            # a shape lookalike included (a 2f load drawn by a virgin curve still fits the
            # held-out cycles as a delay does: shaker rig, fresh seeds 51300200-1)
            rivals.append((v, cand))
            if NET_OF_NOISE and not net > 0:
                # within what the input's noise alone gives it (the search's budget share):
                # a delay smoothing the noisy input cleared a 2f load's flag at a gain
                # 0.07-0.23 σ² below its floor (shaker rig, seeds 51300200-201)
                entry["accepted"] = False
                entry["reason"] = (
                    f"held-out gain {v.gain:.3g} σ² within its input-noise floor "
                    f"({v.gain - net:.3g} σ²)"
                )
                continue
            share = _virgin_share(family, name, effects, current, cand, d, b.sigma)
            sig = _signal_share(name, current, cand, d)
            if sig is not None:
                entry["signal_share"] = sig
            if share is not None:
                entry["virgin_share"] = share
            # (the signal's share: one threshold for every candidate; stick-slip's own 1.0
            # was set for the gain's share, which exceeds 1 where a misfit adds to it)
            limit = RIVAL_SHARE if SHARE_BY == "signal" else RIVAL_SHARE_OWN.get(name, RIVAL_SHARE)
            share = sig if SHARE_BY == "signal" else share
            if share is not None:
                if share >= limit:
                    entry["accepted"] = False
                    entry["reason"] = (
                        f"a free-form virgin curve draws {share:.2f} of it: it may be a "
                        "shape misfit's patch"
                    )
                    continue
            passed.append((v, cand, net))
    passed.sort(key=lambda vc: -vc[2])
    explains: list[tuple[Any, Any, dict[str, Any], Any]] = []
    for v, cand, _ in passed[:ROUTE_TRIES]:
        trial_st = dataclasses.replace(
            st, current=cand, added=[*st.added, v.name], where=[], steps=list(st.steps),
            trials=list(st.trials),
        )  # fmt: skip
        scratch: dict[str, Any] = {}
        try:
            ck = recheck(trial_st, scratch)
        except ContactLabError:
            continue
        uu = ck.get("unexplained")
        if SHARE_BY == "signal" and uu is not None and uu.flagged:
            # the rivals' check on the candidate itself: replaced by its signal's share
            # (checked above), where nothing else flags
            own = all(r.get("effect") == v.name for r in uu.rivals)
            if uu.rivals and own and _flag_sources(uu) == ["rivals"]:
                uu = dataclasses.replace(uu, flagged=False, rivals=())
                ck = {**ck, "unexplained": uu}
        cleared = uu is None or not uu.flagged
        for e in info["tried"]:
            if e["name"] == v.name:
                e["clears_flag"] = bool(cleared)
                e["flagged_by_after"] = [] if uu is None else _flag_sources(uu)
        if cleared:
            explains.append((v, cand, ck, trial_st))
    if not explains:
        info["why_not"] = "no candidate that passed clears the flag"
        return checks
    v, cand, ck, trial_st = explains[0]  # (the largest net gain of those that clear it)
    ties = []
    for w, other in rivals:
        if w.name == v.name:
            continue
        t = paired_lead(d, current, cand, other)
        info.setdefault("paired", {})[w.name] = float(t)
        if not (np.isfinite(t) and t > z):
            ties.append({"name": w.name, "gain": float(w.gain), "t": float(t)})
    if ties:
        info["not_told_apart"] = [{"name": v.name, "gain": float(v.gain)}, *ties]
        info["why_not"] = "not told apart"
        alts = ", ".join(f"{x['name']} ({x['gain']:.3g} σ², paired t = {x['t']:.2f})" for x in ties)
        st.where.append(
            f"flag route: {v.name} (held-out gain {v.gain:.3g} σ², t = {v.t_stat:.2f}) would "
            f"explain the flagged structure but is not told apart from {alts} (paired t of its "
            f"lead across held-out cycles at most {z:g}): none is named"
        )
        return checks
    # named: the final model is the candidate's
    st.current = cand
    st.added.append(v.name)
    st.trials.append(cand)
    st.steps.append(_step_of(st, v, cand, StepwiseSearch))
    st.where.extend(trial_st.where)
    st.where.append(
        f"named by the flag route: {v.name} explains the structure the final model left "
        f"(held-out gain {v.gain:.3g} σ², t = {v.t_stat:.2f} > {ROUTE_Z:g} across held-out "
        "cycles, below the search's floors; with it the misfit is no longer flagged, and no "
        "other candidate fits the held-out cycles comparably)"
    )
    info["named"] = v.name
    info["gain"] = float(v.gain)
    info["t"] = float(v.t_stat)
    return ck


#: how the route asks whether a virgin curve of another shape stands in for a candidate:
#: ``"gain"`` (:func:`.shape.rival_share`, the closing checks' rivals test) or ``"signal"``
#: (:func:`_signal_share`)
SHARE_BY = "signal"


def _signal_share(name: str, current: Any, cand: Any, d: Prepared) -> float | None:
    """For a candidate of :data:`.shape.PATCHABLE`, the share of its own signal (the
    candidate model's fit to all data minus the final model's, the base's refit included)
    that the free-form virgin curve's columns (:func:`.shape._basis`) draw, weighted as the
    fit weights the samples: near 1 where a virgin curve of another shape draws what the
    candidate adds; None for another candidate or where not computable."""
    from .select import sample_weight
    from .shape import PATCHABLE, _basis

    ac = float(current.full.params.get("ac", np.nan))
    if name not in PATCHABLE or not (np.isfinite(ac) and ac > 0):
        return None
    delta = np.asarray(cand.fitted, float) - np.asarray(current.fitted, float)
    w = sample_weight(d)
    use = np.isfinite(delta) & (w > 0)
    if np.count_nonzero(use) < 100:
        return None
    sw = np.sqrt(w[use])
    B = _basis(d, ac)[use] * sw[:, None]
    nrm = np.linalg.norm(B, axis=0)
    nrm[nrm == 0] = 1.0
    y = delta[use] * sw
    tot = float(y @ y)
    if not tot > 0:
        return None
    coef, *_ = np.linalg.lstsq(B / nrm, y, rcond=1e-10)
    fit = (B / nrm) @ coef
    return float(fit @ fit) / tot


def _virgin_share(
    family: Any,
    name: str,
    effects: tuple[str, ...],
    current: Any,
    cand: Any,
    d: Prepared,
    sigma: float,
) -> float | None:
    """For a candidate a virgin curve of another shape can stand in for
    (:data:`.shape.PATCHABLE`), the share of its gain over the final model that a free-form
    virgin curve reaches on the final model's residual (:func:`.shape.rival_share`, as the
    closing checks ask of a named rival); None for another candidate or where not
    computable."""
    from .select import specs_for
    from .shape import PATCHABLE, rival_share

    ac = float(current.full.params.get("ac", np.nan))
    if name not in PATCHABLE or not np.isfinite(ac):
        return None
    n_par = len(specs_for(family, (*effects, name))) - len(specs_for(family, effects))
    got = rival_share(d, -cand.full_residual(d), -current.full_residual(d), ac, sigma, n_par)
    return None if got is None else float(got["share"])


def _step_of(st: Any, v: Any, cand: Any, search: Any) -> Any:
    """The gap-shrink table's step for an effect the route named (the step class of the
    search's first step)."""
    step_cls = type(st.steps[0])
    return step_cls(v.name, *search._errors(cand), candidates=(v,))
