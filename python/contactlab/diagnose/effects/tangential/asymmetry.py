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
