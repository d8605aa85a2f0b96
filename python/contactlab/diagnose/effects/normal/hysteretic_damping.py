"""``hysteretic_damping``: a rate-independent loss factor besides the viscous one."""

from __future__ import annotations

from ..._family import ParamSpec
from .._base import EffectModel, Plausibility, register
from .channel_delay import SINGLE_TONE_SPAN, frequency_span


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
    #: not on rule 2's large-gain route (:func:`contactlab.diagnose.search._strong_rule`)
    large_gain_route = False

    def apply(self, pd, p, ctx):
        return ctx.family.hysteretic(pd, p, ctx.d)

    def plausible(self, d, p):
        """Not identifiable on a record excited at one frequency (docs/effects.md §2).

        At one frequency a loss factor and the Kelvin-Voigt viscosity are one number
        (``c ω = η k``); what the frequency-domain solve adds beyond it there is the ideal
        element's non-causal start-up, a slow trend of δ that a drifting displacement
        sensor draws too (chain of ``benches/eval_normal_fit.py``: a straight drift of
        1-2 % of δ's range on a record that starts from rest was named
        ``hysteretic_damping`` on 3 of 4 seeds of ``benches/chain_normal.py``'s recipe).
        """
        if frequency_span(d) < SINGLE_TONE_SPAN:
            return Plausibility(
                False,
                "a loss factor cannot be told from the Kelvin-Voigt damping at one "
                "frequency (c ω = η k): excite at several frequencies to tell them apart",
            )
        return super().plausible(d, p)

    def argument(self, d, p):
        return (
            f"a loss factor η = {p['eta']:.3g} beside ψ = {p['psi']:.3g}: the same energy per "
            "cycle at every frequency of the record"
        )
