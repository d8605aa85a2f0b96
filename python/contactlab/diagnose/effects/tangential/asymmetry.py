"""``asymmetry``: a friction force that differs between the two sliding directions."""

from __future__ import annotations

import numpy as np

from ..._family import ParamSpec
from .._base import EffectModel, Plausibility, register
from ._common import amplitude

#: ac·A from which the base loop is near-rectangular (gross sliding)
GROSS_SLIDING_ZA = 10.0


#: the share of the search's ``min_gain`` its held-out gain must reach, and the share of the
#: input-noise budget it must beat (:func:`contactlab.diagnose.search.own_gain_floor`,
#: ``search._noise_floor``): on 36 clean records of both generators (tuning seeds 1000-1035
#: of ``benches/eval_clean_gains.py --open``, every floor off) its largest held-out gain was
#: 0.018 σ² at t <= 2.10 (at most 0.07 of the budget on records with a budget above 0.1 σ²)
GAIN_FLOOR_SCALE = 0.2
INPUT_NOISE_SHARE = 0.25


#: the samples near the force's zero crossings (:meth:`Asymmetry.yields_to_tried`): the
#: current model's force within this share of its largest (99th percentile)
NEAR_ZERO = 0.3


@register
class Asymmetry(EffectModel):
    name = "asymmetry"
    kind = "tangential"
    params = (ParamSpec("alpha", "-", 0.0, -0.5, 0.5, "one"),)
    description = (
        "saturation force h0(1+alpha) in the positive, h0(1-alpha) in the negative direction"
    )
    physics = (
        "The friction force differs between the two sliding directions (a self-energising "
        "band, a tilted contact): F = h + α |h|, saturating at h0 (1 ± α)."
    )
    stage = "element_force"
    rank = 0
    order = 8
    size_param = "alpha"
    #: per-effect floors (see GAIN_FLOOR_SCALE, INPUT_NOISE_SHARE above)
    gain_floor_scale = GAIN_FLOOR_SCALE
    input_noise_share = INPUT_NOISE_SHARE

    def yields_to_tried(self, p, v, cand, tried, current, d):
        """Why an asymmetry is not named when a displacement offset tried at the same step
        (accepted or not, not implausible) gains at least as much held-out, and more than the
        asymmetry where the force is near zero (:data:`NEAR_ZERO` of the largest force), or
        None.

        Both draw a shift of the steady loop's midline (docs/effects.md): an offset ``x0`` of
        the contact's origin shifts every steady loop of the model by ``f(x0 + A) - f(A)``,
        and ``h + α|h|`` shifts both plateaus by ``α h0``, while a record from rest lets
        neither be a force offset. They differ where the force crosses zero: an asymmetry
        scales each sign's force and adds nothing at ``F = 0`` (its zero crossings stay),
        the offset's shift runs through them. An asymmetry that explains less than the
        offset overall and less near ``F = 0`` is the offset's shift read as a gain
        (rig through the whole sensor chain, x0 = 3.7-5.7 % of A at ac·A 2.4-3.3, x noise
        1.6-1.9 % of the range: asymmetry α = -0.007 named at 0.15-0.30 σ², the offset
        0.18-0.38 σ² below its floor of 0.45-0.58 σ²; ``benches/eval_lookalike.py`` tuning
        seeds 41002, 42001-42002)."""
        rival = tried.get("displacement_offset")
        if rival is None:
            return None
        rv, rc = rival
        if not (np.isfinite(rv.gain) and rv.gain >= v.gain and rv.gain > 0):
            return None
        if (rv.reason or "").startswith("implausible"):
            return None
        from ...select import gain_where

        h = np.abs(current.fitted)
        near = h <= NEAR_ZERO * float(np.percentile(h, 99.0))
        own, other = gain_where(d, current, cand, near), gain_where(d, current, rc, near)
        if not (other > 0 and other > own):
            return None
        return (
            f"α = {p['alpha']:.3g} shifts the plateaus by α h0 = {p['alpha'] * p['h0']:.3g} N "
            f"with {v.gain:.3g} σ² of held-out gain, a displacement offset "
            f"{rc.full.params.get('x0', np.nan):.3g} m shifts the loop with {rv.gain:.3g} σ², "
            f"and near F = 0, where an asymmetry adds nothing, the offset gains more "
            f"({other / own if own > 0 else np.inf:.2f}× the asymmetry's there): the shift is "
            "the offset's"
        )

    def apply(self, h, p, ctx):
        return h + p["alpha"] * np.abs(h)

    def derived(self, p, se, **more):
        h0, a = p["h0"], p["alpha"]
        s = float(np.hypot(se["h0"] * (1 + a), h0 * se["alpha"]))
        s2 = float(np.hypot(se["h0"] * (1 - a), h0 * se["alpha"]))
        return {"h0_plus": h0 * (1 + a), "h0_minus": h0 * (1 - a)}, {
            "h0_plus": s,
            "h0_minus": s2,
        }

    def plausible(self, d, p):
        from .force_offset import rest_verdict

        base = super().plausible(d, p)
        if not base.ok:
            return base
        # a record from rest tells the two apart: a sensor's zero reads its offset at rest,
        # a friction differing between the directions reads nothing before the motion
        ok, rest = rest_verdict(d, p["alpha"] * p["h0"])
        if ok is False:
            return Plausibility(
                True, f"{base.reason}; an offset of the plateaus' midline α h0 = "
                f"{p['alpha'] * p['h0']:.4g} N is not the sensor's: {rest}",
            )  # fmt: skip
        if p["ac"] * amplitude(d) >= GROSS_SLIDING_ZA:
            # on a near-rectangular loop h + α|h| moves both plateaus by α h0, as an offset
            # does: only the short turns differ, so the two cannot be told apart
            return Plausibility(
                False,
                f"in gross sliding (ac·A ≥ {GROSS_SLIDING_ZA:g}) an asymmetry shifts both "
                f"plateaus alike (α h0 = {p['alpha'] * p['h0']:.3g} N), as a force offset "
                "does: the two cannot be told apart, and force_offset stands for both",
            )
        return base

    def argument(self, d, p):
        h0, a = p["h0"], p["alpha"]
        return (
            f"the friction force is {h0 * (1 + a):.4g} N one way and {h0 * (1 - a):.4g} N the "
            f"other (α = {a:.3g}): the turns, not only the plateaus, differ between the "
            "directions, which a force offset cannot follow"
        )
