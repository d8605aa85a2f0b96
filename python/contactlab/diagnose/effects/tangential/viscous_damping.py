"""``viscous_damping``: a viscous force ``c ẋ`` in parallel with the contact."""

from __future__ import annotations

import numpy as np

from ..._family import ParamSpec
from .._base import EffectModel, register
from ._common import peak_speed, smoothed_velocity


@register
class ViscousDamping(EffectModel):
    name = "viscous_damping"
    kind = "tangential"
    params = (ParamSpec("c", "N s/m", 0.0, 0.0, np.inf, "c"),)
    description = "viscous force c·ẋ in parallel with the contact"
    physics = (
        "A dashpot in parallel with the contact (lubricant film, the rig's guides, air): "
        "F = h + c ẋ, ẋ the sliding velocity. Dissipates π c ω A² per cycle, growing with "
        "frequency; acts through the velocity like a delay, Stribeck friction and inertia."
    )
    acts_through = "velocity"
    stage = "additive"
    rank = 2
    order = 0
    size_param = "c"
    #: the effect reads ẋ of the measured input (the stated bound takes its direction with
    #: the differentiated noise smoothed away: :func:`contactlab.diagnose.power.signal_input`)
    reads_input_derivatives = True
    #: candidates that take the same signature: in pre-sliding a delay shifts the force by
    #: ``-τ k ẋ`` (``k`` the local stiffness), a dashpot's ``c ẋ`` for ``τ = -c/k``
    rivals = ("channel_delay",)

    def apply(self, F, p, ctx):
        # ẋ smoothed over 15 % of a period: differentiated over 8 %, the input noise left
        # 16 % of the drive's ẋ in d.ud (rig, x noise 1.7 % at 86 samples a period), and a
        # delay, which shifts the model's force of the filtered input, fitted the dashpot
        # better than the dashpot did (held-out gain 2.2 against 1.35 σ², tune seed 1407)
        return F + p["c"] * ctx.pick(smoothed_velocity(ctx.d))

    def argument(self, d, p):
        v = peak_speed(d)
        h0 = p.get("h0", np.nan)
        return (
            f"c = {p['c']:.3g} N s/m gives {p['c'] * v:.3g} N at the peak speed {v:.3g} m/s "
            f"({100 * p['c'] * v / h0:.0f} % of h0 = {h0:.4g} N): a force in phase with the "
            "velocity beside the friction"
        )
