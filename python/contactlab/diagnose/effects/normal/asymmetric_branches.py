"""``asymmetric_branches``: a different stiffness on the compression and relief sides."""

from __future__ import annotations

from ..._family import ParamSpec
from .._base import EffectModel, register


@register
class AsymmetricBranches(EffectModel):
    name = "asymmetric_branches"
    kind = "normal"
    params = (ParamSpec("a", "-", 0.0, -0.4, 0.4, "one"),)
    description = "different stiffness on the compression and relief sides, k (1 + a δ/δ_r)"
    physics = (
        "Compression closes the gap between asperities, relief opens it: the stiffness "
        "depends on the sign of the displacement, k_s(δ) = k (1 + a δ/δ_r)."
    )
    stage = "law"
    rank = 0
    order = 4
    size_param = "a"

    def apply(self, coeffs, p, ctx):
        k, a2, a3 = coeffs
        return (k, a2 + p["k"] * p["a"] / ctx.d.extra["delta_r"], a3)

    def argument(self, d, p):
        return (
            f"the stiffness is {100 * abs(p['a']):.1f} % {'higher' if p['a'] > 0 else 'lower'} "
            "in compression than in relief at the displacement's RMS"
        )
