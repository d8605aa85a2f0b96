"""``channel_delay``: the force channel lags the displacement channel by ``tau``."""

from __future__ import annotations

import numpy as np

from ..._family import MAX_DELAY_FRACTION, ParamSpec
from ..._signal import shift
from .._base import EffectModel, Plausibility, register
from ._common import delay_support, period, reconstructed

#: (MAX_DELAY_FRACTION, the largest plausible delay as a fraction of the excitation period,
#: is shared with the normal family's delay: :data:`contactlab.diagnose._family`)
#: the largest plausible delay in absolute terms: no sensor chain skews two channels by
#: tens of milliseconds (an 8-pole anti-alias filter at 0.4 fs delays by about a sample; a
#: converter's decimation filter by a few tens of its output samples, alike on both
#: channels of one converter)
MAX_DELAY_SECONDS = 0.010
#: a skew this short is plausible whatever the drive's frequency, even above
#: MAX_DELAY_FRACTION of its period: a conditioning amplifier's low-pass on one channel
#: (second order at 200 Hz: 1.1 ms of group delay) or a load cell's own filter skews the
#: channels by up to a millisecond or two at any drive frequency (refused above 2 % of the
#: period, a 1.5 ms delay at 18-50 Hz was named backlash or normal_load instead: the
#: independent generator, stop 37)
MAX_SKEW_SECONDS = 0.002


@register
class ChannelDelay(EffectModel):
    name = "channel_delay"
    kind = "tangential"
    params = (ParamSpec("tau", "s", 0.0, -np.inf, np.inf, "tau"),)
    description = "force channel lags the displacement channel by tau"
    physics = (
        "The force and displacement channels pass different anti-alias filters or "
        "converters: F(t) = h(t - τ), τ < 0 when the displacement's filter is the slower. "
        "A skew of a few samples; it shifts the loop's corners along the velocity (a thin "
        "loop looks damped) and acts through the velocity like a viscous term, Stribeck "
        "friction and inertia."
    )
    acts_through = "velocity"
    stage = "output"
    order = 7
    size_param = "tau"

    def rows_needed(self, d, at, p):
        """The samples a delayed prediction at ``at`` needs (both neighbours of each shifted
        time)."""
        return delay_support(d, at, p["tau"])

    def apply(self, F, p, ctx):
        d = ctx.d
        if ctx.at is None:
            return shift(F, d.t, p["tau"])
        if p["tau"] != 0.0:  # (tau = 0: rows is at, F is there already)
            # F is known at ``rows`` only, which hold both neighbours of every shifted time:
            # np.interp brackets each by the same two samples as on the full grid
            return np.interp(d.t[ctx.at] - p["tau"], d.t[ctx.rows], F)
        return F

    def plausible(self, d, p):
        base = super().plausible(d, p)
        if not base.ok:
            return base
        why = reconstructed(d)
        if why:
            return Plausibility(
                False, f"{why}: the two channels share one clock, so the force cannot lag"
            )
        per = period(d)
        tau = p["tau"]
        # (a negative delay, the force leading, is kept: docs/effects.md §3 calls a
        # leading force a damping look-alike, but unequal anti-alias filters make one when
        # the displacement channel's is the slower — the difference of group delays)
        if abs(tau) > max(MAX_DELAY_FRACTION * per, MAX_SKEW_SECONDS):
            return Plausibility(
                False,
                f"a delay of {tau:.3g} s is {100 * abs(tau) / per:.1f} % of the excitation "
                f"period (plausible: below {100 * MAX_DELAY_FRACTION:g} % or "
                f"{1e3 * MAX_SKEW_SECONDS:g} ms): the base model, not the sensors, is off",
            )
        if abs(tau) > MAX_DELAY_SECONDS:
            return Plausibility(
                False,
                f"a delay of {1e3 * tau:.3g} ms ({abs(tau) / d.dt:.1f} samples) is more than "
                f"{1e3 * MAX_DELAY_SECONDS:g} ms: no sensor chain skews two channels by tens "
                "of milliseconds; a misfit of the base model near the reversals is read as one",
            )
        return base

    def argument(self, d, p):
        per = period(d)
        tau = p["tau"]
        return (
            f"τ = {1e3 * tau:.3g} ms = {100 * abs(tau) / per:.2f} % of the {per:.3g} s period "
            f"({abs(tau) / d.dt:.2f} samples): a skew of the channels' filters or converters "
            f"(plausible: below {100 * MAX_DELAY_FRACTION:g} % of a period or "
            f"{1e3 * MAX_SKEW_SECONDS:g} ms, and never above {1e3 * MAX_DELAY_SECONDS:g} ms), "
            "the force and displacement from separate sensors"
        )
