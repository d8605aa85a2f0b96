"""``rate_dependent_presliding``: micro-damping of the pre-sliding bristles (Dahl / LuGre)."""

from __future__ import annotations

import numpy as np

from ..._family import ParamSpec
from .._base import EffectModel, register
from ._common import peak_speed


@register
class RateDependentPresliding(EffectModel):
    name = "rate_dependent_presliding"
    kind = "tangential"
    params = (ParamSpec("sigma1", "N s/m", 0.0, 0.0, np.inf, "c"),)
    description = (
        "LuGre micro-damping σ1·ż of the pre-sliding deflection: F = h + σ1 ẋ k(x)/k0, "
        "k(x)/k0 the share of the initial stiffness left on the branch"
    )
    physics = (
        "Rate-dependent pre-sliding (Dahl / LuGre): the asperities ('bristles') deflect "
        "elastically before the contact slides, and their deflection rate ż is damped, "
        "F = σ0 z + σ1 ż. With the Masing element as σ0 z, ż = ẋ k(x)/k0: a damping force "
        "right after each turning point that vanishes in gross sliding (a viscous term "
        "persists there). For the exponential element k/k0 = 1 - |h - h_r|/(2 h0)."
    )
    acts_through = "velocity"
    stage = "factor"
    rank = 3
    order = 17
    size_param = "sigma1"

    def apply(self, h, p, ctx):
        from .stick_slip import reversal_anchors

        full = ctx.scratch["element"]  # the element's force over the history
        d = ctx.d
        if ctx.sp is None:
            rev = d.cycles.reversals
            n = full.size
            has, r = ctx.fixed("anchors", lambda: reversal_anchors(rev, n))
            hr = np.where(has, full[r], 0.0)
            he, hr = ctx.pick(full), ctx.pick(hr)
        else:
            sp = ctx.sp
            if sp.anchors is None:
                sp.anchors = reversal_anchors(sp.reversals, sp.size)
            has, r = sp.anchors
            hr = np.where(has, full[r], 0.0)[sp.rows]
            he = full[sp.rows]
        share = np.clip(1.0 - np.abs(he - hr) / (2.0 * p["h0"]), 0.0, 1.0)
        return h + p["sigma1"] * ctx.pick(d.ud) * share

    def argument(self, d, p):
        v = peak_speed(d)
        return (
            f"σ1 = {p['sigma1']:.3g} N s/m: up to {p['sigma1'] * v:.3g} N at the peak speed "
            f"{v:.3g} m/s right after each turning point ({100 * p['sigma1'] * v / p['h0']:.0f} "
            "% of h0), gone once the contact slides: damped pre-sliding deflection"
        )
