"""``hysteretic_damping``: a rate-independent loss factor besides the viscous one."""

from __future__ import annotations

from ..._family import ParamSpec
from .._base import EffectModel, register


@register
class HystereticDamping(EffectModel):
    name = "hysteretic_damping"
    kind = "normal"
    params = (ParamSpec("eta", "-", 0.0, 0.0, 2.0, "psi"),)
    description = "rate-independent loss factor η (energy per cycle independent of frequency)"
    physics = (
        "Microslip at the asperities dissipates an energy per cycle that does not depend on "
        "the frequency: δ̂ = p̂ / (k + i ω h + i η k sgn ω)."
    )
    stage = "element"
    order = 1
    size_param = "eta"

    def apply(self, pd, p, ctx):
        return ctx.family.hysteretic(pd, p, ctx.d)

    def argument(self, d, p):
        return (
            f"a loss factor η = {p['eta']:.3g} beside ψ = {p['psi']:.3g}: the same energy per "
            "cycle at every frequency of the record"
        )
