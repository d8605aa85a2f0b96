"""``channel_delay`` (normal contact): the displacement channel lags the pressure."""

from __future__ import annotations

import numpy as np

from ..._family import MAX_DELAY_FRACTION, ParamSpec, Prepared
from .._base import EffectModel, Plausibility, register

#: excitation frequencies closer than this ratio count as one frequency for the delay test
SINGLE_TONE_SPAN = 1.25


def frequency_span(d: Prepared) -> float:
    """Ratio of the longest to the shortest complete excitation cycle (1 for one tone).

    The first and the last cycle are left out when there are four or more: a maximum found
    at the record's edge closes a cut cycle (a 19-cycle record at 2.93 Hz ended on one of
    494 samples against 663-700, a span of 1.42 on one tone), and the first cycle after a
    start from rest carries the actuator's transient."""
    cyc = d.cycles.cycle
    lengths = np.bincount(cyc[cyc >= 0])
    if lengths.size >= 4:
        lengths = lengths[1:-1]
    lengths = lengths[lengths > 0]
    if lengths.size < 2:
        return 1.0
    return float(np.max(lengths) / np.min(lengths))


@register
class NormalChannelDelay(EffectModel):
    name = "channel_delay"
    kind = "normal"
    params = (ParamSpec("tau", "s", 0.0, -np.inf, np.inf, "tau"),)
    description = "displacement channel lags the pressure channel by tau"
    physics = (
        "The displacement and pressure channels pass different filters or converters: "
        "δ(t) = δ_model(t - τ). At one frequency it cannot be told from the Kelvin-Voigt "
        "damping (the same phase lag); across excitation blocks it can."
    )
    acts_through = "velocity"
    stage = "output"
    order = 3
    size_param = "tau"
    #: not on rule 2's large-gain route (:func:`contactlab.diagnose.search._strong_rule`)
    large_gain_route = False

    def apply(self, delta, p, ctx):
        from ..._signal import shift_cubic

        return shift_cubic(delta, ctx.d.dt, p["tau"])

    def plausible(self, d, p):
        if frequency_span(d) < SINGLE_TONE_SPAN:
            return Plausibility(
                False, "a delay cannot be told from the Kelvin-Voigt damping at one frequency"
            )
        base = super().plausible(d, p)
        if not base.ok:
            return base
        period = d.cycles.period_samples * d.dt
        if abs(p["tau"]) > MAX_DELAY_FRACTION * period:
            return Plausibility(
                False,
                f"a delay of {p['tau']:.3g} s is {100 * abs(p['tau']) / period:.1f} % of the "
                f"excitation period (plausible: below {100 * MAX_DELAY_FRACTION:g} %): the base "
                "model, not the sensors, is off",
            )
        return base

    def argument(self, d, p):
        period = d.cycles.period_samples * d.dt
        return (
            f"τ = {1e3 * p['tau']:.3g} ms = {100 * abs(p['tau']) / period:.2f} % of the "
            f"{period:.3g} s period, told from the damping across the record's frequencies"
        )
