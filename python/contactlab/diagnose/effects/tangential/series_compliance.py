"""``series_compliance``: the rig's compliance ``C_s`` in series with the contact."""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np

from ....masing import Masing
from ..._family import ParamSpec
from .._base import EffectModel, register
from ._common import record_turns

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


#: the branches' approach to the plateau (:func:`plateau_tail`): each steady branch read in
#: the contact's own displacement from TAIL_NEAR/ac past its turning point to TAIL_EDGE of
#: its stroke before the next turn; at least TAIL_BRANCHES branches must reach that far
#: with 12 samples or more for a verdict
TAIL_NEAR, TAIL_EDGE, TAIL_BRANCHES = 0.5, 0.05, 4

#: a named compliance fails the check (:func:`tail_fails`) where the faster tail's share
#: ``g`` (of ``2 h0``) stands TAIL_T standard errors (of the branches' scatter) above zero
#: and above TAIL_G. Tuned on diagnoses of ``benches/eval_spring_shape.py`` seeds 300-307
#: (tanh: misfit chain; series: the rig with a compliance of 0.3-1.0 of the contact's):
#: the 7 tanh records named series_compliance had g 0.067-0.32, t 5.4-10.1; the 7 genuine
#: compliances named g 0.002-0.023, t 0.47-2.63 (a first setting, t ≥ 2 alone, flagged
#: two of them)
TAIL_T, TAIL_G = 3.0, 0.035


def plateau_tail(
    d: Any, ac: float, C_s: float, h0: float, near: float = TAIL_NEAR
) -> dict[str, Any]:
    """The branches' approach to their plateau in the contact's own displacement
    ``v = x - C_s F``.

    A compliance in series keeps the Masing shape in ``v``: along a steady branch from its
    turn the force approaches the plateau as ``exp(-ac |v - v_turn| / 2)``. Per branch
    between two turning points of the filtered input (cycles ≥ 1), the force over the part
    ``ac·|v - v_turn| ≥ near`` up to :data:`TAIL_EDGE` of the stroke before the next turn is
    regressed on ``1``, that tail and the faster ``exp(-ac |v - v_turn|)`` (a tanh virgin
    curve's approach, ``exp(-2 ac_t s)`` against ``exp(-ac_t s)``); ``g`` is the faster
    tail's coefficient in units of ``2 h0`` towards the plateau. Returns ``g`` (the mean
    over the branches), ``t`` (its mean over its standard error from the branches' scatter,
    NaN with fewer than two), ``branches`` and ``reach`` (the steady branches read, the
    largest ``ac`` times the contact's travel from a turn)."""
    x, y = np.asarray(d.u, float), np.asarray(d.y, float)
    out: dict[str, Any] = {"g": float("nan"), "t": float("nan"), "branches": 0, "reach": 0.0}
    if not (np.isfinite(ac) and ac > 0 and np.isfinite(C_s) and np.isfinite(h0) and h0 > 0):
        return out
    v = x - max(C_s, 0.0) * y
    turns = record_turns(x, float(d.extra.get("u_noise", 0.0) or 0.0))
    cyc = np.asarray(d.cycles.cycle)
    gs, reach = [], 0.0
    for a, b in itertools.pairwise(turns):
        if cyc[a] < 1:
            continue
        dist = np.abs(v[a:b] - v[a])
        stroke = abs(float(v[b] - v[a]))
        reach = max(reach, float(ac * (1 - TAIL_EDGE) * stroke))
        keep = (ac * dist >= near) & (dist <= (1 - TAIL_EDGE) * stroke)
        keep &= np.isfinite(y[a:b])
        if np.count_nonzero(keep) < 12:
            continue
        dk = dist[keep]
        sgn = float(np.sign(x[b] - x[a]))
        X = np.column_stack([np.ones(dk.size), np.exp(-0.5 * ac * dk), np.exp(-ac * dk)])
        c, *_ = np.linalg.lstsq(X, y[a:b][keep], rcond=None)
        gs.append(float(-sgn * c[2] / (2 * h0)))
    out["branches"], out["reach"] = len(gs), reach
    if len(gs) < 2:
        return out
    g = np.asarray(gs)
    se = float(g.std(ddof=1) / np.sqrt(g.size))
    out.update(g=float(g.mean()), t=float(g.mean() / se) if se > 0 else float("nan"))
    return out


def tail_fails(s: dict[str, Any]) -> bool | None:
    """Whether a plateau tail ``s`` (:func:`plateau_tail`) contradicts the compliance: the
    faster tail's share :data:`TAIL_T` standard errors above zero and above :data:`TAIL_G`;
    None where fewer than :data:`TAIL_BRANCHES` branches reach the part read (no
    verdict)."""
    if s["branches"] < TAIL_BRANCHES or not np.isfinite(s["t"]):
        return None
    return bool(s["t"] >= TAIL_T and s["g"] >= TAIL_G)


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
