"""``parallel_stiffness``: a linear spring ``k_p x`` in parallel with the contact."""

from __future__ import annotations

import numpy as np

from ..._family import ParamSpec
from .._base import EffectModel, register
from ._common import amplitude


@register
class ParallelStiffness(EffectModel):
    name = "parallel_stiffness"
    kind = "tangential"
    params = (ParamSpec("k_p", "N/m", 0.0, 0.0, np.inf, "k"),)
    description = "linear spring k_p·x in parallel (rig flexures, guides)"
    physics = (
        "Flexures, guides or cables carry part of the load beside the contact: F = h + k_p x. "
        "The loop tilts (its plateaus slope by k_p) and its area is unchanged."
    )
    stage = "additive"
    rank = 1
    order = 2
    size_param = "k_p"

    def apply(self, F, p, ctx):
        return F + p["k_p"] * ctx.pick(ctx.x)

    def argument(self, d, p):
        a = amplitude(d)
        h0 = p.get("h0", np.nan)
        return (
            f"k_p = {p['k_p']:.4g} N/m tilts the plateaus by {p['k_p'] * a:.3g} N at the "
            f"stroke's end ({100 * p['k_p'] * a / h0:.0f} % of h0 = {h0:.4g} N): a spring "
            "beside the contact"
        )
