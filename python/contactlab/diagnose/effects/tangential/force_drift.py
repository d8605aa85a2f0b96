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
#: the displacement-sensor drift over a record that counts as plausible (share of the
#: amplitude): an LVDT or eddy-current probe drifts by a fraction of a micrometre with
#: temperature, a few per cent of a pre-sliding amplitude
X_DRIFT_SHARE = 0.02
#: the share of a force ramp's signature (weighted squares) a displacement drift must draw
#: for the two to count as one reading of the record
X_DRIFT_ALIKE = 0.5


@register
class ForceDrift(EffectModel):
    name = "force_drift"
    kind = "tangential"
    params = (ParamSpec("F1", "N", 0.0, -np.inf, np.inf, "F"),)
    description = "force-sensor zero drifting linearly, by F1 over the recording"
    physics = "The load cell's zero drifts (temperature): F = h + F1 (t - t0)/T."
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

    def apply(self, F, p, ctx):
        d = ctx.d
        return F + p["F1"] * ctx.pick(ctx.fixed("t_rel", lambda: d.t - d.t[0])) / d.duration

    def plausible(self, d, p):
        """The shared rules, and a force drift told from a displacement-sensor drift.

        A drift ``D`` of the displacement sensor moves the force by ``-k D (t - t0)/T``
        wherever the contact is stiff (``k`` its local slope ``dF/dx``): in pre-sliding,
        where ``k`` hardly changes along the loop, exactly a force drift. The fitted ramp is
        refused when a displacement drift of at most :data:`X_DRIFT_SHARE` of the amplitude
        draws at least :data:`X_DRIFT_ALIKE` of its signature (:func:`displacement_alike`):
        the record cannot say which sensor drifted, and a displacement drift is not an
        effect (docs/effects.md §3)."""
        base = super().plausible(d, p)
        if not base.ok:
            return base
        alike = displacement_alike(d, p)
        if alike is not None:
            D, share = alike
            a = amplitude(d)
            return Plausibility(
                False,
                f"a displacement-sensor drift of {D:.3g} m ({100 * abs(D) / a:.2g} % of the "
                f"amplitude) draws {100 * share:.0f} % of this force ramp (F1 = {p['F1']:.3g} "
                "N): the contact's stiffness turns the one into the other, and the record "
                "cannot tell which sensor drifted",
            )
        return base

    def smallest_plausible(self, d, p):
        """The smallest ``|F1|`` this record does not refuse as a displacement-sensor drift
        (:func:`displacement_alike`), for the stated power; None when no size is refused."""
        probe = dict(p, F1=1.0)
        ramp = _ramps(d, probe)
        if ramp is None:
            return None
        share, per_D = ramp
        if share < X_DRIFT_ALIKE:
            return None
        return 1.001 * X_DRIFT_SHARE * amplitude(d) * per_D

    def argument(self, d, p):
        return (
            f"F1 = {p['F1']:.4g} N over the {d.duration:.3g} s record: both plateaus move "
            "together, cycle after cycle (a sensor's zero drifting)"
        )


def _ramps(d, p) -> tuple[float, float] | None:
    """``(share, k̄)``: the weighted squared correlation of a force ramp with the force a
    displacement drift draws (``k (t - t0)/T``, ``k`` the base Masing element's local slope
    ``dF/dx``, ``h0·ac`` where the measured displacement does not move), and the force
    ramp per metre of displacement drift that draws it best; None when not computable."""
    from ....masing import Masing

    h0, ac = float(p.get("h0", np.nan)), float(p.get("ac", np.nan))
    if not (np.isfinite(h0) and np.isfinite(ac) and h0 > 0 and ac > 0):
        return None
    u = d.u
    if u.size < 8 or not d.duration > 0:
        return None
    m = Masing(h0, ac).force(u)
    du, dm = np.gradient(u), np.gradient(m)
    kmax = h0 * ac
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.where(np.abs(du) > 0, dm / du, kmax)
    k = np.clip(np.nan_to_num(k, nan=kmax, posinf=kmax, neginf=0.0), 0.0, kmax)
    w = d.extra.get("weight")
    w = np.ones(u.size) if w is None or np.shape(w) != u.shape else np.asarray(w, float)
    ramp = (d.t - d.t[0]) / d.duration
    jx = k * ramp
    sff, sxx, sfx = (float(np.sum(w * a * b)) for a, b in ((ramp, ramp), (jx, jx), (ramp, jx)))
    if not (sff > 0 and sxx > 0 and sfx > 0):
        return None
    return sfx * sfx / (sff * sxx), sxx / sfx


def displacement_alike(d, p) -> tuple[float, float] | None:
    """``(D, share)`` when a displacement drift ``D`` (m over the record) of at most
    :data:`X_DRIFT_SHARE` of the amplitude draws the share ``share >= X_DRIFT_ALIKE`` of the
    fitted force ramp ``F1 (t - t0)/T``, else None (:func:`_ramps`: the weighted squared
    correlation of the two ramps with the diagnosis's sample weights)."""
    F1 = float(p["F1"])
    ramps = _ramps(d, p)
    if ramps is None or F1 == 0.0:
        return None
    share, per_D = ramps
    D = F1 / per_D  # the displacement drift whose force best draws F1·ramp
    if share >= X_DRIFT_ALIKE and abs(D) <= X_DRIFT_SHARE * amplitude(d):
        return -D, share  # (F - M(x_meas) = -k D: the sensor reads the contact D too far)
    return None
