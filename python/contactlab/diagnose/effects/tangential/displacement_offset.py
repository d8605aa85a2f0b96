"""``displacement_offset``: the displacement sensor's zero off the contact's origin."""

from __future__ import annotations

import numpy as np

from ..._family import ParamSpec
from .._base import EffectModel, Plausibility, register
from ._common import amplitude

#: the share of the input-noise budget it must beat (``search._noise_floor``): the input's
#: noise is symmetric about the true x and cannot move the contact's origin. On 18 clean
#: records of both generators (seeds 45000-45017 of ``benches/eval_clean_gains.py --open``,
#: every floor off, x noise 0.4-1.8 %) its largest held-out gain was 0.018 σ² at t <= 2.5,
#: at most 0.17 of the budget on records with a budget above 0.1 σ² (asymmetry, whose share
#: is 0.25 on the same evidence: 0.017 σ², 0.15). The whole budget hid offsets of 4-6 % of
#: A at x noise 1.6-1.9 % of the range (held-out gains 0.18-0.38 σ² against floors of
#: 0.45-0.58 σ²), and an asymmetry or a force drift of a lower floor took their gain
#: (``benches/eval_lookalike.py`` tuning seeds 41002, 42001-42002). Its own gain floor
#: stays the search's ``min_gain``.
INPUT_NOISE_SHARE = 0.25
#: the share of the search's ``min_gain`` (0.05 σ² per sample) its held-out and in-sample
#: gain must reach (``search.own_gain_floor``), as asymmetry's, Stribeck's and position
#: friction's: the whole ``min_gain`` asked far more than significance on long records
#: (issue 29: rig at the issue's conditions, ``benches/eval_ideal_bound.py`` seeds
#: 41000000-2, the stated bound 4.4-5.3 times what an ideal test needs, 1.7-4.3 times with
#: the floors off; an offset at twice the ideal size missed on the floor, held-out gain
#: 0.035 σ² against 0.104 σ²). Clean records' largest held-out gain with every floor off
#: stayed 0.018 σ² at t <= 2.5 (above): the per-cycle t rule, not the floor, keeps them quiet
GAIN_FLOOR_SCALE = 0.2


@register
class DisplacementOffset(EffectModel):
    name = "displacement_offset"
    kind = "tangential"
    params = (ParamSpec("x0", "m", 0.0, -np.inf, np.inf, "x"),)
    description = "displacement-sensor zero: the contact sees x - x0"
    physics = (
        "The displacement sensor's zero is not where the contact started: h = M(x - x0). "
        "Seen on the virgin curve (a record from rest) and on the first turn."
    )
    stage = "input"
    order = 6
    size_param = "x0"
    #: a steady Masing loop is the same loop shifted along x (docs/effects.md): what tells
    #: an offset is the first loading from rest (the virgin curve from x0, not from 0) and,
    #: where the loops do not saturate, a vertical shift ``f(x0 + A) - f(A)`` of every
    #: cycle. Its held-out gain sits in the first cycles by its nature, so the per-cycle
    #: t scatters by that shape, not by the noise: rule 2 may pass by the proportional t
    #: across cycles (search._proportional). On the rig with its whole sensor chain (tuning
    #: seed 610008 of ``benches/eval_offsets.py``: x0 = 0.14 A at ac·A 4.1, x noise 1.9 %)
    #: an offset gained 7.3 σ² (held-out RMS 1.06 -> 0.48 N) at a per-cycle t of 2.95 and
    #: was not named
    proportional_gain = True
    input_noise_share = INPUT_NOISE_SHARE
    #: the share of the search's ``min_gain`` its gain must reach (search.own_gain_floor)
    gain_floor_scale = GAIN_FLOOR_SCALE

    def apply(self, x, p, ctx):
        return x - p["x0"]

    def plausible(self, d, p):
        base = super().plausible(d, p)
        if base.ok and abs(p["x0"]) > 0.5 * amplitude(d):
            return Plausibility(
                False, f"a displacement offset of {p['x0']:.3g} m is over half the amplitude"
            )
        if base.ok:  # a record from rest: the contact rests where the record starts
            from .force_offset import rest_start

            rest = rest_start(d)
            if rest is not None and p.get("h0", 0) > 0 and p.get("ac", 0) > 0:
                n, _, fr, spread = rest

                def at_rest(x0: float) -> float:  # the model's force at rest
                    u = float(np.median(d.u[:n])) - x0
                    f = float(np.sign(u) * p["h0"] * -np.expm1(-p["ac"] * abs(u)))
                    return f + p.get("alpha", 0.0) * abs(f) + p.get("F0", 0.0)

                # wrong by more than the rest's noise and 5 % of h0, and twice as wrong as
                # the same model without the offset
                f, off = at_rest(p["x0"]), abs(at_rest(0.0) - fr)
                if abs(f - fr) > max(4.0 * spread, 0.05 * p["h0"], 2.0 * off):
                    return Plausibility(
                        False,
                        f"the record starts at rest with the force at {fr:.4g} N; an offset "
                        f"x0 = {p['x0']:.3g} m would have the contact loaded to {f:.4g} N "
                        "there (its virgin curve at x - x0): the contact rests where the "
                        "record starts",
                    )
        return base

    def argument(self, d, p):
        a = amplitude(d)
        return (
            f"x0 = {p['x0']:.3g} m ({100 * p['x0'] / a:.1f} % of the amplitude {a:.3g} m): "
            "the virgin curve starts off the sensor's zero"
        )
