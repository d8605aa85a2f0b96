"""``force_drift``: the force sensor's zero drifting linearly over the record."""

from __future__ import annotations

import numpy as np

from ..._family import ParamSpec
from .._base import EffectModel, Plausibility, register


@register
class ForceDrift(EffectModel):
    name = "force_drift"
    kind = "tangential"
    params = (ParamSpec("F1", "N", 0.0, -np.inf, np.inf, "F"),)
    description = "force-sensor zero drifting linearly, by F1 over the recording"
    physics = "The load cell's zero drifts (temperature): F = h + F1 (t - t0)/T."
    stage = "additive"
    rank = 5
    order = 5
    size_param = "F1"

    def apply(self, F, p, ctx):
        d = ctx.d
        return F + p["F1"] * ctx.pick(ctx.fixed("t_rel", lambda: d.t - d.t[0])) / d.duration

    def plausible(self, d, p):
        """The shared rules, then the data's plateaus must move together by about ``F1``
        over the record (:func:`.force_offset.drift_verdict`)."""
        from .force_offset import drift_verdict

        base = super().plausible(d, p)
        if not base.ok:
            return base
        ok, why = drift_verdict(d, p)
        if ok is False:
            return Plausibility(False, why)
        return Plausibility(True, f"{base.reason}; {why}") if ok else base

    def argument(self, d, p):
        return (
            f"F1 = {p['F1']:.4g} N over the {d.duration:.3g} s record: both plateaus move "
            "together, cycle after cycle (a sensor's zero drifting)"
        )
