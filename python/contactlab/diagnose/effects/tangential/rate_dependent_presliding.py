"""``rate_dependent_presliding``: micro-damping of the pre-sliding bristles (Dahl / LuGre)."""

from __future__ import annotations

import numpy as np

from ..._family import ParamSpec
from .._base import EffectModel, Plausibility, register
from ._common import peak_speed


def presliding_force(d, p) -> np.ndarray:
    """``σ1 ẋ k(x)/k0`` along the record for the exponential element of ``h0``, ``ac``
    (the term this effect adds), from the record's reversals."""
    from ....masing import Masing
    from .stick_slip import reversal_anchors

    h = Masing(p["h0"], p["ac"]).force(d.u)
    has, r = reversal_anchors(d.cycles.reversals, h.size)
    hr = np.where(has, h[r], 0.0)
    share = np.clip(1.0 - np.abs(h - hr) / (2.0 * p["h0"]), 0.0, 1.0)
    return p["sigma1"] * d.ud * share


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

    #: the pre-sliding damping force may reach this share of the friction force at most:
    #: beyond, the "bristles" would carry more than the contact transmits when it slides
    MAX_FORCE_SHARE = 0.5

    def plausible(self, d, p):
        """The shared rules; then the turns must be the contact's own pre-sliding: where
        the data's turns hold a dead band (:func:`.stick_slip.dead_band`: the displacement
        crossing a gap with no force change), what follows a turning point is the gap and
        the impact that closes it, not damped asperities; and the damping force must stay
        below :attr:`MAX_FORCE_SHARE` of ``h0``."""
        from .stick_slip import dead_band

        base = super().plausible(d, p)
        if not base.ok or not (p.get("h0", 0) > 0 and p.get("ac", 0) > 0):
            return base
        gap = dead_band(d)
        if gap is not None:
            return Plausibility(
                False,
                f"{gap}; right after the turns the force is set by crossing that gap and the "
                "impact closing it (its overshoot grows with the speed), not by damped "
                "asperities deflecting (LuGre's σ1 ż)",
            )
        peak = float(np.max(np.abs(presliding_force(d, p))))
        if peak > self.MAX_FORCE_SHARE * p["h0"]:
            return Plausibility(
                False,
                f"a pre-sliding damping force of up to {peak:.3g} N is "
                f"{100 * peak / p['h0']:.0f} % of the friction force h0 = {p['h0']:.4g} N "
                f"(plausible: up to {100 * self.MAX_FORCE_SHARE:g} %): the asperities cannot "
                "carry more than the sliding contact; a misfit after the turns is read as one",
            )
        return base

    def argument(self, d, p):
        peak = float(np.max(np.abs(presliding_force(d, p))))
        v = peak_speed(d)
        return (
            f"σ1 = {p['sigma1']:.3g} N s/m: up to {peak:.3g} N ({100 * peak / p['h0']:.0f} % "
            f"of h0) right after each turning point (peak speed {v:.3g} m/s), gone once the "
            "contact slides: damped pre-sliding deflection (LuGre's σ1 ż)"
        )
