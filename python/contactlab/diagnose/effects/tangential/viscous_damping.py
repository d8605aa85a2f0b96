"""``viscous_damping``: a viscous force ``c ẋ`` in parallel with the contact."""

from __future__ import annotations

import numpy as np

from ..._family import ParamSpec
from .._base import EffectModel, register
from ._common import fastest_period, fixed, peak_speed

#: the window of the dashpot's velocity, as a fraction of the fastest cycles' period, and its
#: polynomial degree: a local quintic over half a period passes the drive (1 - 4e-4) and a
#: block at 1.7 times its frequency (1 - 0.009), and leaves of the differentiated input noise
#: 1/37 of the variance a cubic over 15 % left. A regressor carrying noise shrinks its
#: coefficient by var(ẋ) / (var(ẋ) + var(noise)) (errors in variables): with the 15 % cubic
#: the rig's c came out at 0.89-0.99 of the truth at 2 % x noise (tune seeds 1000-1007)
VELOCITY_FRACTION, VELOCITY_DEGREE = 0.5, 5


def dashpot_velocity(d) -> np.ndarray:
    """``ẋ`` the dashpot term reads: ``d.ud`` smoothed by a local quintic over
    :data:`VELOCITY_FRACTION` of the fastest cycles' period when the input carries noise
    (``d.extra["u_noise"] > 0``; ``d.ud`` itself otherwise), kept per record."""

    def make() -> np.ndarray:
        if not float(d.extra.get("u_noise", 0.0) or 0.0) > 0.0:
            return d.ud
        from ...._filters import savgol_filter
        from ..._signal import smooth_window

        w = smooth_window(fastest_period(d), VELOCITY_FRACTION, 9)
        w = min(w, d.t.size - (1 - d.t.size % 2))
        if w <= VELOCITY_DEGREE + 2:
            return d.ud
        return savgol_filter(d.ud, w, VELOCITY_DEGREE, mode="interp")

    return fixed(d, "dashpot_velocity", make)


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
    #: ... and a normal load locked to the drive at 2f, whose in-phase part is in gross
    #: sliding the friction's sign times a bump at mid-stroke, as c ẋ (docs/effects.md)
    rivals = ("channel_delay", "normal_load")
    #: the base parameter that carries the joint's physics may be lowered by up to this
    #: fraction when a dashpot is added (search._takes_over; raised, or lowered by other
    #: effects, by 0.3 at most): a dashpot adds π c ω A² to the loop's area, from which
    #: analyze read the regime and which the base fitted without it reads as a stiffer,
    #: more curved contact (never a softer one). A dashpot making 40 % of the force's RMS at
    #: ac·A 0.66 (rig, 38.5 Hz, x noise 1.1 % of the range: ``benches/eval_velocity_noise.py``
    #: tuning seed 7100001) made the loop read as transition at ac·A 2.4 with h0 = 24 N; its
    #: fit lowered h0·ac from 3.38e6 to 1.68e6 N/m (the truth 1.6e6: by 50 %) and was
    #: refused as taking over the base, and a load at 2f was named instead
    max_base_lowering = 0.75

    def apply(self, F, p, ctx):
        # ẋ smoothed by a quintic over half a period (dashpot_velocity): differentiated over
        # 8 %, the input noise left 16 % of the drive's ẋ in d.ud (rig, x noise 1.7 % at 86
        # samples a period), and a regressor carrying noise shrinks c (errors in variables)
        return F + p["c"] * ctx.pick(dashpot_velocity(ctx.d))

    def argument(self, d, p):
        v = peak_speed(d)
        h0 = p.get("h0", np.nan)
        return (
            f"c = {p['c']:.3g} N s/m gives {p['c'] * v:.3g} N at the peak speed {v:.3g} m/s "
            f"({100 * p['c'] * v / h0:.0f} % of h0 = {h0:.4g} N): a force in phase with the "
            "velocity beside the friction"
        )
