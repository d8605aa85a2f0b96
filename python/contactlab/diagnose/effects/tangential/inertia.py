"""``inertia``: the inertial force ``m ẍ`` of a mass between force sensor and contact."""

from __future__ import annotations

import numpy as np

from ..._family import ParamSpec
from .._base import EffectModel, Plausibility, register
from ._common import peak_acceleration


@register
class Inertia(EffectModel):
    name = "inertia"
    kind = "tangential"
    params = (ParamSpec("m", "kg", 0.0, 0.0, np.inf, "m"),)
    description = "inertial force m·ẍ of the mass between force sensor and contact"
    physics = (
        "The force sensor also accelerates the mass m between it and the contact: F = h + "
        "m ẍ. The inertial force is in phase with the acceleration (against the "
        "displacement); it grows with ω² and does no work over a cycle."
    )
    acts_through = "velocity"
    stage = "additive"
    rank = 3
    order = 1
    size_param = "m"
    #: an inertial force beyond this share of the friction force means the sensor weighs the
    #: moving part more than it measures the contact: a misfit of the base model instead
    MAX_FORCE_SHARE = 1.0
    #: ... and no fixture between a load cell and a contact weighs a tonne (docs/effects.md:
    #: "kg for a tribometer, tonnes never"); a fit beyond it reads a misfit as a mass
    MAX_MASS = 1000.0

    def apply(self, F, p, ctx):
        return F + p["m"] * ctx.pick(ctx.d.udd)

    def plausible(self, d, p):
        base = super().plausible(d, p)
        if not base.ok:
            return base
        if p["m"] > self.MAX_MASS:
            return Plausibility(
                False,
                f"a mass of {p['m']:.3g} kg between sensor and contact (plausible: below "
                f"{self.MAX_MASS:g} kg, a fixture): the base model's misfit in phase with the "
                "acceleration is read as one",
            )
        a = peak_acceleration(d)
        h0 = p.get("h0", np.nan)
        f = p["m"] * a
        if np.isfinite(h0) and h0 > 0 and f > self.MAX_FORCE_SHARE * h0:
            return Plausibility(
                False,
                f"a mass of {p['m']:.3g} kg between sensor and contact would put "
                f"{f:.3g} N of inertia on the sensor at the peak acceleration {a:.3g} m/s², "
                f"more than the friction force h0 = {h0:.4g} N itself: not a mass on the "
                "sensor but a misfit of the base model",
            )
        return base

    def argument(self, d, p):
        a = peak_acceleration(d)
        h0 = p.get("h0", np.nan)
        return (
            f"m = {p['m']:.3g} kg: {p['m'] * a:.3g} N at the peak acceleration {a:.3g} m/s² "
            f"({100 * p['m'] * a / h0:.0f} % of h0 = {h0:.4g} N), a mass between sensor "
            "and contact"
        )
