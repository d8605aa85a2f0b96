"""``asymmetric_branches``: loading and unloading dissipate differently."""

from __future__ import annotations

from ..._family import ParamSpec
from .._base import EffectModel, register


@register
class AsymmetricBranches(EffectModel):
    """Loading and unloading dissipate differently: ``p - p0 = k_s δ + h (1 + a sgn δ') δ'``.

    docs/effects.md §2: plastic flattening of the asperities on loading, elastic recovery on
    unloading. Beyond the symmetric Kelvin-Voigt loss the loading branch (``δ' > 0``) carries
    ``a h |δ'|`` more pressure: an even distortion of the loop's centre curve locked to the
    rate (largest at mid-stroke, nothing at the turning points) that grows with the
    excitation frequency, while the energy per cycle stays that of ``h`` to first order.
    Solved exactly on the linear Kelvin-Voigt joint
    (:func:`contactlab.diagnose.candidates_normal.kelvin_voigt_asymmetric`); not combined
    with a stiffness law or a hysteretic element (each is another account of the loop's
    shape beyond the ellipse).
    """

    name = "asymmetric_branches"
    kind = "normal"
    params = (ParamSpec("a", "-", 0.0, -0.95, 0.95, "one"),)
    description = "loading and unloading branches damped differently, h (1 + a sgn δ') δ'"
    physics = (
        "Asperities flatten plastically on loading and recover elastically on unloading: "
        "the damping differs between the branches, p - p0 = k_s δ + h (1 + a sgn δ') δ' "
        "(a > 0: the loading branch lies farther from the centre curve)."
    )
    stage = "loss"
    rank = 0
    order = 4
    size_param = "a"
    #: the stiffness law's κ1 δ² takes the same 2ω signature (docs/effects.md §2): the
    #: stated bound is what shows beyond it
    rivals = ("stiffness_nonlinearity",)

    def apply(self, delta, p, ctx):
        return ctx.family.asymmetric(delta, p, ctx.d)

    def argument(self, d, p):
        return (
            f"the loading branch is damped {100 * abs(p['a']):.0f} % "
            f"{'more' if p['a'] > 0 else 'less'} and unloading {100 * abs(p['a']):.0f} % "
            f"{'less' if p['a'] > 0 else 'more'} than the Kelvin-Voigt mean (a function of "
            "|δ'|, growing with the frequency, not of δ)"
        )
