"""``force_drift``: the force sensor's zero drifting linearly over the record."""

from __future__ import annotations

import numpy as np

from ..._family import ParamSpec
from .._base import EffectModel, Plausibility, register
from ._common import amplitude

#: the share of the search's ``min_gain`` a slow drift's held-out gain must reach (see
#: :func:`contactlab.diagnose.search.own_gain_floor`): measured on clean records of both
#: generators (tuning seeds), where no drift was named at it
GAIN_FLOOR_SCALE = 0.2
#: the displacement-sensor drift over a record that counts as plausible, as a share of the
#: amplitude (an LVDT or eddy-current probe drifts by a fraction of a micrometre with
#: temperature; the rig simulator draws up to 0.3 %)
X_DRIFT_SHARE = 0.01
#: the bound of a force drift starts this far above the ramp such a displacement drift
#: draws (the fitted F1 scatters about the true one)
PLAUSIBLE_MARGIN = 1.3


@register
class ForceDrift(EffectModel):
    name = "force_drift"
    kind = "tangential"
    params = (ParamSpec("F1", "N", 0.0, -np.inf, np.inf, "F"),)
    description = "force-sensor zero drifting linearly, by F1 over the recording"
    physics = "The load cell's zero drifts (temperature): F = h + F1 (t - t0)/T."
    # A drift D of the displacement sensor is a look-alike where the contact is stiff at the
    # turns: each half cycle runs D/(2N) further one way than the other, and the force at
    # the turning points climbs by the branch's end slope h0·ac·exp(-ac·A) per unit, a ramp
    # of F1 = h0·ac·exp(-ac·A)·D over the record (tests/diagnose/test_slow_power.py::
    # test_a_displacement_drift_draws_a_force_ramp_in_pre_sliding); in gross sliding nothing
    stage = "additive"
    rank = 5
    order = 5
    size_param = "F1"
    #: a straight line in time: no noise of the input feeds its fit (the noise is white in
    #: time), so it need not beat the search's input-noise budget (search._noise_floor)
    input_noise_gain = False
    #: its held-out gain grows over the record (nothing at the start, most at the end): rule
    #: 2 may pass by the proportional t across cycles (search._proportional)
    proportional_gain = True
    #: the share of ``min_gain`` its held-out gain must reach (search.own_gain_floor); the
    #: relative rule (1 % of the remaining error) and the significance rules still apply
    gain_floor_scale = GAIN_FLOOR_SCALE
    #: the stated bound's widening (:func:`contactlab.diagnose.power.power_margin`): hidden
    #: at the linearised bound, a drift was named 6 times in 8 last stop
    #: (``benches/eval_slow_power.py``, seeds 20777000-7) and 3 in 4 on rig tuning seeds
    #: 73001-73005 of ``benches/eval_bound_power.py`` (the miss: t = 2.1 < 3), 4 in 4 at
    #: twice it; the per-cycle t of a ramp scatters more than the linearised draws say
    power_margin = 1.3

    def apply(self, F, p, ctx):
        d = ctx.d
        return F + p["F1"] * ctx.pick(ctx.fixed("t_rel", lambda: d.t - d.t[0])) / d.duration

    def plausible(self, d, p):
        """The shared rules; a ramp larger than what a plausible displacement-sensor drift
        draws (:func:`displacement_ramp`): below it the record cannot tell which sensor
        drifted, and a displacement drift is not an effect (docs/effects.md §3); then the
        data's plateaus must move together by about ``F1`` over the record
        (:func:`.force_offset.drift_verdict`)."""
        from .force_offset import drift_verdict

        base = super().plausible(d, p)
        if not base.ok:
            return base
        ramp = displacement_ramp(d, p)
        if ramp is not None and abs(p["F1"]) <= ramp:
            return Plausibility(
                False,
                f"F1 = {p['F1']:.3g} N is within the {ramp:.3g} N ramp a displacement-sensor "
                f"drift of {100 * X_DRIFT_SHARE:g} % of the amplitude draws where the "
                "contact is stiff at the turns (h0·ac·exp(-ac·A) per metre): the record "
                "cannot tell which sensor drifted",
            )
        ok, why = drift_verdict(d, p)
        if ok is False:
            return Plausibility(False, why)
        return Plausibility(True, f"{base.reason}; {why}") if ok else base

    def smallest_plausible(self, d, p):
        """The smallest ``|F1|`` the diagnosis does not refuse as a displacement drift
        (:meth:`plausible`), with :data:`PLAUSIBLE_MARGIN`, for the stated power; None when
        it refuses none."""
        ramp = displacement_ramp(d, p)
        return None if ramp is None else PLAUSIBLE_MARGIN * ramp

    def argument(self, d, p):
        return (
            f"F1 = {p['F1']:.4g} N over the {d.duration:.3g} s record: both plateaus move "
            "together, cycle after cycle (a sensor's zero drifting)"
        )


def displacement_ramp(d, p) -> float | None:
    """The force ramp (N over the record) that a displacement-sensor drift of
    :data:`X_DRIFT_SHARE` of the amplitude draws: ``h0·ac·exp(-ac·A)·D`` (the element's
    slope at the end of a branch of ``2A``), or None without a base model."""
    h0, ac = float(p.get("h0", np.nan)), float(p.get("ac", np.nan))
    a = amplitude(d)
    if not (np.isfinite(h0) and np.isfinite(ac) and h0 > 0 and ac > 0 and a > 0):
        return None
    return float(h0 * ac * np.exp(-ac * a) * X_DRIFT_SHARE * a)
