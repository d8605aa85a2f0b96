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
#: the start's grid (:meth:`ChannelDelay.start`): this many delays either side of 0 up to the
#: largest plausible one
START_GRID = 40


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
    #: the base parameter that carries the joint's physics may move by up to this fraction
    #: when a delay is added (search._takes_over; 0.3 for most effects): a lag of the force
    #: is a negative damping that thins the loop, so the regime analyze reads from the loop's
    #: area and the base fitted without the delay are both biased by it. A 1.5 ms delay at
    #: 33 Hz (ac·A 2.7, ``benches/chain_inertia_delay.py`` seed 105) made the loop read as
    #: pre-sliding at ac·A 0.96; the delay's fit moved h0·ac from 8.3e6 to 1.48e7 N/m (the
    #: truth 1.49e7) and was refused as taking over the base
    max_base_shift = 1.0

    def start(self, p, d, residual, family=None):
        """The delay on a grid (:data:`START_GRID` either side of 0, up to the largest
        plausible one) that best brings the current model's prediction, shifted by it, onto
        the data (the likelihood's weights). From ``tau = 0`` the solver stays near a base
        fitted to the delayed loop: a 1.5 ms delay at 27 Hz (ac·A 1.0) made the force's lag
        a negative loop area, the base collapsed to a straight line (h0 = 2.7e5 N, ac·A
        2.5e-4), and from 0 the delay's fit reached half the held-out gain it reached from
        the truth (``benches/chain_inertia_delay.py`` seed 104: 2.8 against 5.6 σ²)."""
        r = np.asarray(residual, float)
        if d.t.size < 8 or not np.all(np.isfinite(r)):
            return {}
        per = period(d)
        top = min(max(MAX_DELAY_FRACTION * per, MAX_SKEW_SECONDS), MAX_DELAY_SECONDS)
        if not top > d.dt:
            return {}
        pred = d.y - r
        w = d.extra.get("weight")
        w = np.ones_like(r) if w is None or np.shape(w) != r.shape else np.asarray(w, float)
        best, out = float(np.sum(w * r * r)), {}
        grid = [float(v) for v in np.linspace(-top, top, 2 * START_GRID + 1) if v != 0.0]
        for tau in grid:
            e = d.y - shift(pred, d.t, tau)
            v = float(np.sum(w * e * e))
            if v < best:
                best, out = v, {"tau": tau}
        base = getattr(family, "initial_base", None)
        if base is None or not set(p) <= {"h0", "ac", "tau"}:
            return out
        # the base alone (no effect named yet): its grid refitted to the force with each
        # delay taken back, as a base fitted to the delayed loop may have collapsed
        import dataclasses

        from ....errors import InputError

        for tau in grid[1::4]:
            extra = {k: v for k, v in d.extra.items() if k not in ("fixed", "evaluations")}
            dd = dataclasses.replace(d, y=shift(d.y, d.t, -tau), extra=extra)
            try:
                q = base(dd)
                e = d.y - shift(family.predict(q, (), dd), d.t, tau)
            except InputError:
                continue
            v = float(np.sum(w * e * e))
            if v < best:
                best, out = v, {"tau": tau, "h0": float(q["h0"]), "ac": float(q["ac"])}
        return out

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
