"""``parameter_drift``: the friction force drifting over the record (wear, run-in)."""

from __future__ import annotations

import numpy as np

from ..._family import ParamSpec
from .._base import EffectModel, register


@register
class ParameterDrift(EffectModel):
    name = "parameter_drift"
    kind = "tangential"
    params = (ParamSpec("beta", "-", 0.0, -0.95, 5.0, "one"),)
    description = "saturation force drifting over the recording: h0(t) = h0 (1 + beta t/T)"
    physics = (
        "The friction force changes over the record (run-in, wear, heating): h0(t) = "
        "h0 (1 + β t/T). The loops grow or shrink about their centre, unlike a sensor drift."
    )
    stage = "element_force"
    rank = 1
    order = 10
    size_param = "beta"

    def apply(self, h, p, ctx):
        return h * (1.0 + p["beta"] * ctx.t_rel / ctx.d.duration)

    def derived(self, p, se, **more):
        h0, b = p["h0"], p["beta"]
        return {"h0_end": h0 * (1 + b)}, {
            "h0_end": float(np.hypot(se["h0"] * (1 + b), h0 * se["beta"]))
        }

    def argument(self, d, p):
        return (
            f"the friction force goes from {p['h0']:.4g} N to {p['h0'] * (1 + p['beta']):.4g} N "
            f"over the {d.duration:.3g} s record: the loops grow or shrink about their centre"
        )
