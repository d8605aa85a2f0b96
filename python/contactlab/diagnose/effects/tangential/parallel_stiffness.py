"""``parallel_stiffness``: a linear spring ``k_p x`` in parallel with the contact."""

from __future__ import annotations

import numpy as np

from ..._family import ParamSpec
from .._base import EffectModel, register
from ._common import amplitude, single_frequency


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
        text = (
            f"k_p = {p['k_p']:.4g} N/m tilts the plateaus by {p['k_p'] * a:.3g} N at the "
            f"stroke's end ({100 * p['k_p'] * a / h0:.0f} % of h0 = {h0:.4g} N): a spring "
            "beside the contact"
        )
        one = single_frequency(d)
        if one is not None:
            w2 = one[0]
            text += (
                f"; on this single-frequency drive (ω = {np.sqrt(w2):.4g} rad/s) a mass m "
                "would act as the stiffness -mω² and the two are not separable: the record "
                f"sets k_p - mω² = {p['k_p']:.4g} N/m; a positive value cannot be a mass"
            )
        return text

    def power_note(self, d, p):
        """What a single-frequency drive means for the stated bound (empty otherwise)."""
        one = single_frequency(d)
        if one is None:
            return ""
        return (
            "parallel stiffness and inertia are not separable on this single-frequency drive "
            f"(ω = {np.sqrt(one[0]):.4g} rad/s): the record sets k_p - mω² only"
        )
