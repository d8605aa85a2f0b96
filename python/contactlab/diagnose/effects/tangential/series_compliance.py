"""``series_compliance``: the rig's compliance ``C_s`` in series with the contact."""

from __future__ import annotations

import numpy as np

from ....masing import Masing
from ..._family import ParamSpec
from .._base import EffectModel, register

_SERIES_POINTS = 400

#: the straightness of the turns (:func:`straightness`): the travel to half the force's rise
#: over the travel to 90 % of it. An exponential branch gives ln 2 / ln 10 = 0.30, a tanh
#: one 0.37, a straight ramp to a plateau (a compliance far softer than the contact) 0.56;
#: (the package's clean records at ac·A 1-5: 0.36-0.39; a tanh virgin curve at ac·A 2 with
#: noise: 0.41; the micro-tribometer in ../shared/data, whose README puts its turns on the
#: load cell's and flexure's compliance: 0.59): from STRAIGHT on the turns are the
#: compliance's, unless they hold a dead band (a gap crossed mid-turn also delays the half
#: rise)
STRAIGHT = 0.5


#: below this ``ac·A`` the loops never reach their plateau and no compliance is promised
#: (:meth:`SeriesCompliance.not_separable`; as for a parallel spring)
PLATEAU_ACA = 1.5


def straightness(d) -> tuple[float, int] | None:
    """The median over the record's branches of the travel to half the force's rise over
    the travel to 90 % of it (see :data:`STRAIGHT`), and the branches read; None when too
    few branches reach 90 % of their rise."""
    from .stick_slip import crossing_travels

    rows = crossing_travels(d, (0.5, 0.9))
    if rows is None:
        return None
    return float(np.median(rows[:, 0] / rows[:, 1])), int(rows.shape[0])


def series_backbone(h0: float, ac: float, C_s: float, x_max: float) -> tuple[np.ndarray, ...]:
    """Virgin curve of a Masing element in series with compliance ``C_s``, as points.

    ``x(u) = u + C_s f(u)`` against ``f(u)``, ``u`` from 0 to ``3 x_max`` on a grid that is
    dense where the curve bends.
    """
    s = np.linspace(0.0, 1.0, _SERIES_POINTS)
    u = 3.0 * x_max * s * s
    f = h0 * -np.expm1(-ac * u)
    return u + C_s * f, f


@register
class SeriesCompliance(EffectModel):
    name = "series_compliance"
    kind = "tangential"
    params = (ParamSpec("C_s", "m/N", 0.0, 0.0, np.inf, "C"),)
    description = "measured displacement includes rig compliance C_s·F"
    physics = (
        "The displacement sensor sits behind a compliant part of the rig: x = x_c + C_s h. "
        "A spring in series with a Masing element is a Masing element with the virgin curve "
        "x(u) = u + C_s f(u) against f(u): the loops' turns soften, the plateaus stay."
    )
    stage = "core"
    order = 3
    size_param = "C_s"

    def apply(self, core, p, ctx):
        xmax = float(np.max(np.abs(ctx.xm))) or 1.0
        bx, bf = series_backbone(p["h0"], p["ac"], max(p["C_s"], 0.0), xmax)
        return Masing.from_backbone(bx, bf)

    def base_equivalent(self, p):
        """The loop's initial stiffness is the contact's and the compliance's in series,
        ``1/(1/(h0·ac) + C_s)`` (docs/effects.md): the base alone reads that as its ``h0·ac``
        (the plateau ``h0`` stays). Compared raw, the contact's own ``h0·ac`` behind a
        compliance of a third of its stiffness looked like a base taken over (rig tuning
        seeds 73002, 73005: h0·ac from 1.15e6 to 1.61e6 N/m, the truth 1.6e6, and the
        compliance refused at 2x its stated bound)."""
        k0 = p["h0"] * p["ac"]
        c = max(float(p.get("C_s", 0.0)), 0.0)
        return {"ac": p["ac"] / (1.0 + c * k0)} if k0 > 0 else {}

    def derived(self, p, se, **more):
        if p["C_s"] > 0:
            return {"k_s": 1.0 / p["C_s"]}, {"k_s": se["C_s"] / p["C_s"] ** 2}
        return {}, {}

    def signature(self, d) -> str | None:
        """The data's own evidence for a compliance in series, independent of the fit: the
        turns are straight ramps to the plateau (:func:`straightness` at least
        :data:`STRAIGHT`, and no dead band), which an exponential (0.30) or tanh (0.37)
        element is not. A sentence saying so, or None."""
        from .stick_slip import dead_band

        got = straightness(d)
        if got is None or got[0] < STRAIGHT or dead_band(d) is not None:
            return None
        return (
            f"the turns are straight ramps (over {got[1]} branches the travel to half the "
            f"force's rise is {got[0]:.2f} of the travel to 90 % of it: a straight ramp's "
            "0.56, an exponential branch's 0.30, a tanh one's 0.37): a compliance in series "
            "draws them"
        )

    def not_separable(self, d, p):
        """Why no compliance can be promised where the loops never reach their plateau
        (``ac·A`` below :data:`PLATEAU_ACA`), or None: there a compliance in series is a
        softer contact (a smaller ``ac``, docs/effects.md), which the base absorbs. On the
        rig a compliance at its stated bound and at twice it was named 0 times in 4 at
        ac·A 1.14 and 1.35 (its in-sample gain 0.05 σ² at the bound, 0.009 σ² at twice it;
        position_friction named twice instead: fresh seeds 75220003-4 of
        ``benches/eval_bound_power.py``), and 7 times in 7 at the bound at ac·A 1.98-4.8."""
        ac = float(p.get("ac", np.nan))
        a = 0.5 * float(np.ptp(d.u))
        if not (np.isfinite(ac) and ac > 0 and a > 0):
            return None
        aca = ac * a
        if aca >= PLATEAU_ACA:
            return None
        return (
            "not separable from a softer contact on this record: its loops never reach a "
            f"plateau (ac·A = {aca:.2g} < {PLATEAU_ACA:g}), where a compliance in series is "
            "a smaller ac to the base"
        )

    def argument(self, d, p):
        k0 = p.get("h0", np.nan) * p.get("ac", np.nan)
        return (
            f"a series stiffness 1/C_s = {1 / max(p['C_s'], 1e-300):.4g} N/m against the "
            f"contact's initial stiffness h0·ac = {k0:.4g} N/m: the rig's compliance"
        )
