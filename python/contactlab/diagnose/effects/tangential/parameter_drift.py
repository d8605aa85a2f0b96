"""``parameter_drift``: the friction force drifting over the record (wear, run-in)."""

from __future__ import annotations

import numpy as np

from ..._family import ParamSpec
from .._base import EffectModel, register

#: the share of the search's ``min_gain`` a parameter drift's held-out (and in-sample) gain
#: must reach (search.own_gain_floor). 0.05 (0.0025 σ² at the default ``min_gain``) is of
#: the order of the floor the BIC rule sets by the record itself (a one-parameter effect
#: must lower the error of the at most 5000 fitted samples by ln n / n = 0.0017 of it): the
#: fixed floor of the sensor's drift (0.2, 0.01 σ²) was what missed drifts the record's
#: noise shows (rig, ``benches/eval_slow_power.py``: at the size an oracle with the true
#: shape needs, in-sample gains 0.003-0.008 σ² fell below it on 6 of 8 records)
GAIN_FLOOR_SCALE = 0.05
#: the share of rule 4 (1 % of the remaining held-out error) it must reach
#: (search.relative_gain_scale): a residual that repeats every cycle cannot feed a factor
#: that is a straight line in time centred on the record's middle
RELATIVE_GAIN_SCALE = 0.25
#: see :attr:`ParameterDrift.power_margin`
POWER_MARGIN = 1.7


@register
class ParameterDrift(EffectModel):
    name = "parameter_drift"
    kind = "tangential"
    params = (ParamSpec("beta", "-", 0.0, -1.9, 1.9, "one"),)
    description = (
        "saturation force drifting over the recording: h0(t) = h0 (1 + beta (t - t_m)/T), "
        "h0 the value at mid-record t_m"
    )
    physics = (
        "The friction force changes over the record (run-in, wear, heating): h0(t) = "
        "h0 (1 + β (t - t_m)/T), t_m the record's middle (docs/effects.md), so h0 stays the "
        "record's mean friction force, the plateau analyze reads. The loops grow or shrink "
        "about their centre, unlike a sensor drift."
    )
    stage = "element_force"
    rank = 1
    order = 10
    size_param = "beta"
    #: a slow factor in time on the element's force: no noise of the input feeds its fit
    #: (the noise is white in time, the factor a straight line over the record), so it
    #: need not beat the input-noise budget of the search (search._noise_floor); the
    #: held-out rules across cycles (t > z, BIC, the gain floor) still apply
    input_noise_gain = False
    #: its held-out gain is nothing in the record's middle and largest at both ends: rule 2
    #: may pass by the proportional t across cycles (search._proportional)
    proportional_gain = True
    #: the share of ``min_gain`` its held-out gain must reach (search.own_gain_floor)
    gain_floor_scale = GAIN_FLOOR_SCALE
    #: the share of rule 4's relative floor it must reach (search.relative_gain_scale)
    relative_gain_scale = RELATIVE_GAIN_SCALE
    #: the stated bound's widening (:func:`contactlab.diagnose.power.power_margin`): with
    #: the floors above, hidden at the linearised bound a drift was named 3 times in 6 on the
    #: rig (tuning seeds 29500000-29500005 of ``benches/eval_slow_power.py``); the misses
    #: were named at 1.55 and 1.67 times it (the third, 6 cycles, not at it); widened, it was
    #: named 8 of 8 at it on fresh seeds 29800000-29800007 (``benches/eval_bound_power.py``)
    power_margin = POWER_MARGIN

    def apply(self, h, p, ctx):
        return h * (1.0 + p["beta"] * (ctx.t_rel / ctx.d.duration - 0.5))

    def derived(self, p, se, **more):
        h0, b = p["h0"], p["beta"]
        vals, errs = {}, {}
        for key, k in (("h0_start", -0.5), ("h0_end", 0.5)):
            vals[key] = h0 * (1 + k * b)
            errs[key] = float(np.hypot(se["h0"] * (1 + k * b), h0 * k * se["beta"]))
        return vals, errs

    def argument(self, d, p):
        h0, b = p["h0"], p["beta"]
        return (
            f"the friction force goes from {h0 * (1 - b / 2):.4g} N to {h0 * (1 + b / 2):.4g} N "
            f"over the {d.duration:.3g} s record (mean {h0:.4g} N): the loops grow or shrink "
            "about their centre"
        )
