"""``force_offset``: a constant force-sensor bias."""

from __future__ import annotations

import numpy as np

from ..._family import ParamSpec
from .._base import EffectModel, register


@register
class ForceOffset(EffectModel):
    name = "force_offset"
    kind = "tangential"
    params = (ParamSpec("F0", "N", 0.0, -np.inf, np.inf, "F"),)
    description = "constant force-sensor bias F0"
    physics = "The load cell's zero is off: F = h + F0. Both plateaus move by F0."
    stage = "additive"
    rank = 4
    order = 4
    size_param = "F0"

    def apply(self, F, p, ctx):
        return F + p["F0"]

    def argument(self, d, p):
        h0 = p.get("h0", np.nan)
        return (
            f"F0 = {p['F0']:.4g} N ({100 * p['F0'] / h0:.1f} % of h0 = {h0:.4g} N): both "
            "plateaus shifted alike, a sensor's zero (the virgin curve starts from F0, not 0)"
        )
