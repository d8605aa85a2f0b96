"""``backlash``: lost motion between the displacement sensor's point and the contact."""

from __future__ import annotations

import itertools
from typing import ClassVar

import numpy as np

from ..._family import ParamSpec
from .._base import EffectModel, Plausibility, register
from ._common import actual_turns, amplitude, smoothed_velocity

#: the samples away from the turns (:meth:`Backlash.yields_to_tried`): the speed at least
#: this share of the record's peak speed (the middle two thirds of each stroke in time on a
#: sine, |x| within 0.87 A), where a play's dead band has closed and the noise's wiggles at
#: the turning points are not
FAST_SHARE = 0.5
#: a play no wider than this many input-noise RMS (``d.extra["u_noise"]``, the raw input's)
#: is within the outward push the noise gives the turning points
#: (:meth:`Backlash.within_noise`): a delay of 0.90 ms (1.5x its stated bound, ac·A 2.5,
#: x noise 1.6 % of the range) was named a play of b = 1.15 σ_u at a paired t of 6.1 over
#: the delay (3.3 at speeds above half the peak), its own fit stuck at τ = 0.40 ms
#: (``benches/eval_confusions.py --cases delay``, fresh seed 95000)
NOISE_WIDTH = 2.0
#: a play no wider than this many input-noise RMS must lead a channel delay tried at the
#: same step beyond the noise to be named (:meth:`Backlash.noise_sized_lead`): delays of
#: 0.32-0.89 ms at x noise 1.5-2 % of the range were fitted plays of 0.40-0.96 noise RMS,
#: a clean record's play 0.33; a genuine play of 1.58 noise RMS (b = 4 % of A), whose lead
#: over the delay read t = 0.2, was lost at :data:`NOISE_WIDTH` (rig, tuning seeds
#: 8100000-8100003 and fresh 8200000-8200005, 8300002 of ``benches/eval_velocity_conf.py``)
NOISE_LEAD_WIDTH = 1.0
#: the paired t (across held-out cycles) such a play must reach over the delay, after its
#: lead is discounted by the input-noise budget and read away from the turns too (the
#: search's default ``z``)
NOISE_LEAD_Z = 3.0


def _cycle_gains(d, current, cand, where=None) -> dict[int, float]:
    """The held-out gain of ``cand`` over ``current`` per cycle (weighted as the held-out
    error is; on the samples ``where`` only when given), as
    :func:`contactlab.diagnose.search.gain_by_cycle` reads it."""
    from ...select import sample_weight

    r = d.y - current.prediction
    delta = cand.prediction - current.prediction
    held = current.heldout & cand.heldout
    if where is not None:
        held = held & where
    g = sample_weight(d) * (2.0 * r * delta - delta * delta)
    cyc = np.asarray(d.cycles.cycle)
    return {int(c): float(np.sum(g[held & (cyc == c)])) for c in np.unique(cyc[held])}


def paired_t(d, current, a, b, where=None) -> float:
    """The t statistic of ``a``'s lead over ``b`` across held-out cycles (the mean of the
    per-cycle differences of their held-out gains over its standard error; nan with fewer
    than two cycles, ±inf when every cycle gives the same lead)."""
    ga, gb = _cycle_gains(d, current, a, where), _cycle_gains(d, current, b, where)
    diff = np.array([ga[c] - gb[c] for c in ga if c in gb])
    if diff.size < 2:
        return float("nan")
    sd, m = float(np.std(diff, ddof=1)), float(np.mean(diff))
    if not sd > 0:
        return float("inf") if m > 0 else float("-inf") if m < 0 else 0.0
    return m / (sd / np.sqrt(diff.size))


def play(x: np.ndarray, b: float, rev: np.ndarray) -> np.ndarray:
    """The play (backlash) operator of half-width ``b``: ``u`` stands still until
    ``|x - u| = b``, then follows ``x`` at distance ``b``; from rest at ``u = 0`` in the
    middle of the gap.

    Exact for a history that is monotone between the turning points ``rev`` up to wiggles
    smaller than the gap (the filtered input between its reversals): on a rising stretch
    ``u = max(u_r, running max of x - b)``, on a falling one ``min(u_r, running min of
    x + b)``."""
    if b <= 0.0:
        return x.copy()
    u = np.empty_like(x)
    # each stretch ends at its turning point (included): the next one starts after it
    bounds = np.r_[0, rev + 1, x.size] if rev.size else np.array([0, x.size])
    ur = 0.0
    for a, e in itertools.pairwise(bounds.tolist()):
        if e <= a:
            continue
        seg = x[a:e]
        rising = seg[-1] >= seg[0] if e - a > 1 else x[min(e, x.size - 1)] >= seg[0]
        if rising:
            u[a:e] = np.maximum(ur, np.maximum.accumulate(seg - b))
        else:
            u[a:e] = np.minimum(ur, np.minimum.accumulate(seg + b))
        ur = float(u[e - 1])
    return u


@register
class Backlash(EffectModel):
    name = "backlash"
    kind = "tangential"
    params = (ParamSpec("b", "m", 0.0, 0.0, np.inf, "x"),)
    description = "lost motion of width 2b between the displacement sensor and the contact"
    physics = (
        "Lost motion of width 2b between the displacement sensor's point and the contact "
        "(clearance in a clamp, a loose probe; docs/effects.md): u is the play operator of x "
        "(u stands still until |x - u| = b, then follows at distance b) and F = M[u]. A "
        "horizontal segment of width 2b at each turning point (F constant while x moves) — "
        "the dual of sticking's vertical one."
    )
    stage = "element_input"
    order = 16
    size_param = "b"

    #: the look-alike a play yields to (:meth:`yields_to`)
    LOOKALIKES = ("channel_delay",)
    #: the share of the input-noise budget a play's lead over a rival may owe to the noise
    #: alone (:func:`contactlab.diagnose.search._mark_not_told_apart`): at each turn a play
    #: passes over the noise's wiggles, which a delay cannot, and so leads it cycle after
    #: cycle, a lead a paired t reads as significant. On the rig through the whole sensor
    #: chain at 1.5-2 % x noise, delays of 0.46 and 0.96 ms were named backlash with leads
    #: of 0.81 and 0.57 σ² against budgets of 0.65 and 0.60 σ², nearly all of it within a
    #: fifth of the stroke's speed of the turns (``benches/eval_lookalike.py`` tuning seeds
    #: 52001, 52005, plain chain): the delay's bound said it would have been seen
    noise_fed_lead: ClassVar[dict[str, float]] = {"channel_delay": 1.0}

    def within_noise(self, d, p):
        """Why the play cannot be told from the turning points the input's noise pushes
        outward (its half-width at most :data:`NOISE_WIDTH` times the input noise's RMS),
        or None (:func:`contactlab.diagnose.search._mark_not_told_apart`). A noisy ``x``
        peaks beyond its true turning point, so the base turns late by about the noise's
        RMS and its next branch runs shifted as a play of that width shifts it; a delay
        takes that shift in part. The play stays named; a delay's bound is not promised."""
        noise = float(d.extra.get("u_noise", 0.0) or 0.0)
        b = float(p.get("b", 0.0))
        if not (noise > 0 and 0 < b <= NOISE_WIDTH * noise):
            return None
        return (
            f"the play's half-width b = {b:.3g} m is {b / noise:.2f} times the input noise's "
            f"RMS ({noise:.3g} m), within the {NOISE_WIDTH:g} the noise pushes the turning "
            "points outward by"
        )

    def unfed_samples(self, d):
        """The samples where the input's noise does not feed a play's lead over a delay
        (:func:`contactlab.diagnose.search._mark_not_told_apart`): away from the turns, the
        speed at least :data:`FAST_SHARE` of its peak, where a play is a fixed shift of the
        branch and a delay one proportional to the speed."""
        speed = np.abs(smoothed_velocity(d))
        return speed >= FAST_SHARE * float(np.percentile(speed, 99.0))

    def yields_to(self, p, gains, own, d=None):
        """Why a play is not named beside a channel delay accepted at the same step whose
        held-out gain falls short of its own by less than the input-noise budget
        (``d.extra["input_noise_budget"]``, σ²: what the input's noise alone can give a
        candidate), or None.

        Right after a turn a delayed force stays on its plateau while ``x`` returns by
        ``A (1 - cos ωτ)``, a dead band as a play draws; a play also passes over the noise's
        wiggles at each turning point, which no delay can, so on a noisy input the play
        wins by what the noise gives it. Delays of 1.5 ms through a realistic chain (x noise
        0.9-1.3 %) were named backlash with held-out gains 5.57 and 5.98 σ² against the
        delay's 5.45 and 5.63 (budgets 0.25 and 0.70 σ²); at 0.05 % x noise the delay won
        (5.79 against 5.25: ``benches/chain_inertia_delay.py`` seeds 104 and 105)."""
        if d is None:
            return None
        budget = float(d.extra.get("input_noise_budget", 0.0) or 0.0)
        rival = max(
            (n for n in self.LOOKALIKES if n in gains and np.isfinite(gains[n])),
            key=lambda n: gains[n],
            default=None,
        )
        if rival is None or not budget > 0 or not own - gains[rival] < budget:
            return None
        return (
            f"b = {p['b']:.3g} m (a dead band at each turn) beats {rival} by "
            f"{own - gains[rival]:.3g} σ² of held-out gain, less than the {budget:.3g} σ² the "
            "input's noise alone can give a play that passes over its wiggles at the turns: "
            f"{rival} draws the same dead band"
        )

    def yields_to_tried(self, p, v, cand, tried, current, d):
        """Why a play is not named when a channel delay tried at the same step (accepted or
        not) falls short of its held-out gain by less than the input-noise budget
        (``d.extra["input_noise_budget"]``) and, away from the turns (speed at least
        :data:`FAST_SHARE` of the peak), predicts the held-out cycles at least as well as
        the play; or None.

        The two differ in where they act (docs/effects.md): a play is a dead band of fixed
        width at each reversal, after which the branch runs shifted by the constant ``b``;
        a delay shifts both branches in time by ``τ``, in ``x`` by ``ẋτ``, largest where
        the speed is. At the turns both thin the loop alike, and there a play also passes
        over the input noise's wiggles, which gives it up to the budget on a noisy ``x``:
        so the delay, which the noise does not feed, may miss the budget where the play
        passes it (rig through the whole sensor chain, x noise 1.6-2 % of the range,
        τ 0.57-0.73 ms at 22-39 Hz: play 0.64-0.74 σ², delay 0.18-0.56 σ², floors
        0.55-0.62 σ²; ``benches/eval_lookalike.py`` tuning seeds 41000-42005). Away from
        the turns the noise gives neither anything; where the delay's speed-proportional
        shift fits there as well as the play's constant one, the play's lead is the
        noise's."""
        rival = tried.get("channel_delay")
        if rival is None:
            return None
        rv, rc = rival
        budget = float(d.extra.get("input_noise_budget", 0.0) or 0.0)
        if (rv.reason or "").startswith(("implausible", "could not be fitted")):
            return None
        if budget > 0 and np.isfinite(rv.gain):
            noise_sized = self.noise_sized_lead(p, v, cand, rv, rc, current, d)
            if noise_sized:
                return noise_sized
        if not (budget > 0 and np.isfinite(rv.gain) and rv.gain > 0):
            return None
        if not v.gain - rv.gain < budget:
            return None
        from ...select import gain_where

        speed = np.abs(smoothed_velocity(d))
        fast = speed >= FAST_SHARE * float(np.percentile(speed, 99.0))
        own, other = gain_where(d, current, cand, fast), gain_where(d, current, rc, fast)
        if not (other > 0 and other >= own):
            return None
        return (
            f"b = {p['b']:.3g} m beats channel_delay by {v.gain - rv.gain:.3g} σ² of held-out "
            f"gain, less than the {budget:.3g} σ² the input's noise can give a play at the "
            "turns; away from them (speed above half its peak), where a play is a fixed "
            "shift and a delay one proportional to the speed, the delay predicts the held-out "
            f"cycles at least as well ({other / own if own > 0 else np.inf:.2f}× the play's "
            "gain there): the dead band is not the data's"
        )

    def noise_sized_lead(self, p, v, cand, rv, rc, current, d):
        """Why a play no wider than :data:`NOISE_LEAD_WIDTH` input-noise RMS (what the noise
        alone draws at the turns) is not named beside a channel delay tried at the same step
        (``rv``, ``rc``: its verdict and trial), or None: the play's lead over the delay,
        beyond the input-noise budget the noise alone gives a play (the paired t across
        held-out cycles scaled by the share of the lead left beyond it) and away from the
        turns (the paired t on :meth:`unfed_samples`), the smaller of the two, is not
        significant (at most :data:`NOISE_LEAD_Z`).

        Such a play is what the input's noise draws at every turn, on a clean record as
        behind a delay: the search had named it and only withheld the delay's bound
        (``_mark_not_told_apart``). On the rig's plain chain (tuning seeds 8100000-8100003
        of ``benches/eval_velocity_conf.py --kinds delay``: τ 0.38-0.74 ms, ac·A 1.5-1.8,
        x noise 1.5-1.9 % of the range) three delays were named plays of 0.45-0.96 input
        noise RMS whose lead over the delay read t = -4.6, 2.6 and -2.9 that way."""
        noise = float(d.extra.get("u_noise", 0.0) or 0.0)
        b = float(p.get("b", 0.0))
        budget = float(d.extra.get("input_noise_budget", 0.0) or 0.0)
        if not (noise > 0 and 0 < b <= NOISE_LEAD_WIDTH * noise and budget > 0):
            return None
        why = (
            f"the play's half-width b = {b:.3g} m is {b / noise:.2f} times the input noise's "
            f"RMS ({noise:.3g} m), within the {NOISE_LEAD_WIDTH:g} the noise draws at each turn"
        )
        lead = float(v.gain - rv.gain)
        t = paired_t(d, current, cand, rc)
        if lead > 0 and np.isfinite(t):
            t *= 1.0 - budget / lead
        t_unfed = paired_t(d, current, cand, rc, self.unfed_samples(d))
        if np.isfinite(t_unfed):
            t = min(t, t_unfed) if np.isfinite(t) else t_unfed
        if not (np.isfinite(t) and t <= NOISE_LEAD_Z):
            return None
        return (
            f"{why}; its lead over channel_delay ({lead:.3g} σ² of held-out gain, beyond the "
            f"{budget:.3g} σ² the input's noise alone can give a play and away from the "
            f"turns) is not significant across held-out cycles (t = {t:.2f} <= "
            f"{NOISE_LEAD_Z:g}): the dead band is the noise's"
        )

    def not_separable(self, d, p):
        """Why no size of a play is promised (always): its linearised bound is not
        calibrated. At ``b = 0`` a play's first-order effect is a step at every turn (the
        branch shifted by ``2b`` where the contact is stiffest), which the input's noise
        blurs and a channel delay takes in part (:meth:`yields_to`), so the fits see far
        less than the linearisation promises. Hidden on the rig simulator at 1, 2, 3, 4, 6,
        10 and 16 times the linearised bound its clean twin stated, a play was named in
        3/6, 7/14, 8/14, 8/14, 9/14, 10/14 and 11/14 records (tuning seeds 73000-73013 of
        ``benches/eval_bound_power.py --effects backlash``; the misses: held-out gains
        below the floor, the play yielding to a delay, one fit that never left b = 0 at x
        noise 1.8 %), never the 95 % a stated bound promises; no multiple of it would be
        honest on every record."""
        return (
            "no size of a play can be promised: its linearised bound is not calibrated (on "
            "the rig a play 16 times that bound was named in 11 of 14 records; the input's "
            "noise at the turns and a channel delay take the dead band's signature)"
        )

    def apply(self, xm, p, ctx):
        return play(xm, max(p["b"], 0.0), actual_turns(ctx))

    def plausible(self, d, p):
        base = super().plausible(d, p)
        if base.ok and p["b"] > 0.5 * amplitude(d):
            return Plausibility(
                False, f"a play of ±{p['b']:.3g} m is over half the amplitude: no contact left"
            )
        return base

    def argument(self, d, p):
        a = amplitude(d)
        return (
            f"lost motion 2b = {2 * p['b']:.3g} m ({100 * p['b'] / a:.1f} % of the amplitude "
            f"{a:.3g} m per side): the force holds while the displacement crosses the gap at "
            "each turning point, which a series spring (a sloped segment) cannot do"
        )
