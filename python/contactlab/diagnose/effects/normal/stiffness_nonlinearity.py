"""``stiffness_nonlinearity``: symmetric hardening of the contact stiffness (eq. 17)."""

from __future__ import annotations

from ..._family import ParamSpec
from .._base import EffectModel, register


@register
class StiffnessNonlinearity(EffectModel):
    name = "stiffness_nonlinearity"
    kind = "normal"
    params = (ParamSpec("kappa", "-", 0.0, -0.15, 10.0, "one"),)
    description = "stiffness growing with displacement, k_s(δ) = k (1 + κ (δ/δ_r)²) (eq. 17)"
    physics = (
        "The real contact area of rough surfaces grows with the load: the stiffness "
        "hardens symmetrically, k_s(δ) = k (1 + κ (δ/δ_r)²) (the paper's eq. 17)."
    )
    stage = "law"
    rank = 1
    order = 0
    size_param = "kappa"

    def apply(self, coeffs, p, ctx):
        k, a2, a3 = coeffs
        return (k, a2, a3 + p["k"] * p["kappa"] / ctx.d.extra["delta_r"] ** 2)

    def argument(self, d, p):
        return (
            f"the stiffness changes by {100 * p['kappa']:.1f} % at the displacement's RMS "
            f"δ_r = {d.extra.get('delta_r', float('nan')):.3g} m, alike in compression and relief"
        )
