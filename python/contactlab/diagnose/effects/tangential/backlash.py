"""``backlash``: a dead band (gap) in series with the joint."""

from __future__ import annotations

import numpy as np

from ..._family import ParamSpec
from .._base import EffectModel, Plausibility, register
from ._common import amplitude


def gap_force(h0: float, ac: float, b: float, x: np.ndarray, rev: np.ndarray) -> np.ndarray:
    """Force of an exponential Masing element (``h0``, ``ac``) behind a gap of half-width
    ``b``: the contact pushes the element only from one side of the gap at a time.

    From rest in the middle of the gap, the element is reached once ``|x| > b``. After
    each turning point the element unloads along its Masing branch
    ``h_r + 2 s f(s (u - u_r)/2)`` (``s`` the new direction) until its force reaches zero;
    the gap then opens and the force stays zero while ``x`` crosses the gap (``2 b``); the
    element is then pushed from the other side and its branch goes on. A dead band of zero
    force in the middle of every stroke, of width ``2 b``; ``b = 0`` is the plain element
    (its branches from the turning points)."""
    f = lambda v: h0 * -np.expm1(-ac * v)  # noqa: E731  (odd: used on |v| with a sign)

    def branch(hr: float, ur: float, s: float, u: np.ndarray) -> np.ndarray:
        return hr + s * 2.0 * f(np.maximum(s * (u - ur), 0.0) / 2.0)

    n = x.size
    u = np.sign(x) * np.maximum(np.abs(x) - b, 0.0)  # from rest, mid-gap
    h = np.sign(u) * f(np.abs(u))
    if rev.size == 0:
        return h
    r0 = int(rev[0])
    hr, ur = float(h[r0]), float(u[r0])
    gr = float(x[r0] - ur)  # the gap's state at the turning point
    for k in range(rev.size):
        a = int(rev[k])
        e = int(rev[k + 1]) if k + 1 < rev.size else n - 1
        xs = x[a : e + 1]  # the next turning point included: the next branch starts there
        s = float(np.sign(x[e] - x[a])) or 1.0
        uc = xs - gr
        if s * hr < 0.0 and abs(hr) / 2.0 < h0:
            # contact on the old side while the force keeps its old sign, until it is zero
            ustar = ur + s * 2.0 * (-np.log1p(-abs(hr) / 2.0 / h0) / ac)
            before = s * (uc - ustar) < 0.0
            pushed = xs - s * b  # the element pushed from the new side of the gap
            crossed = s * (pushed - ustar) >= 0.0
            ue = np.where(before, uc, np.where(crossed, pushed, ustar))
        else:  # pushed from the new side already: no gap to cross
            ue = uc
        he = branch(hr, ur, s, ue)
        u[a : e + 1], h[a : e + 1] = ue, he
        hr, ur = float(he[-1]), float(ue[-1])
        gr = float(xs[-1] - ur)
    return h


@register
class Backlash(EffectModel):
    name = "backlash"
    kind = "tangential"
    params = (ParamSpec("b", "m", 0.0, 0.0, np.inf, "x"),)
    description = "dead band of half-width b in series with the joint (zero force in the gap)"
    physics = (
        "Play in the load path (a clevis, a keyway, a drum's band): after each turning "
        "point the joint unloads, the gap of width 2b opens and the force stays at zero "
        "until the far side is reached, then the joint loads the other way. A flat "
        "stretch of zero force in the middle of each stroke, of width 2b."
    )
    stage = "element"
    order = 16
    size_param = "b"

    def start(self, p, d, residual):
        return {"b": 0.02 * amplitude(d)}

    def apply(self, core, p, ctx):
        if not (p["h0"] > 0 and p["ac"] > 0 and np.isfinite(p["h0"] * p["ac"])):
            from ....masing import Masing

            return Masing(p["h0"], p["ac"]).force(ctx.xm)  # (the element's own refusal)
        rev = ctx.d.cycles.reversals if ctx.sp is None else ctx.sp.reversals
        return gap_force(p["h0"], p["ac"], max(p["b"], 0.0), ctx.xm, rev)

    def plausible(self, d, p):
        base = super().plausible(d, p)
        if base.ok and p["b"] > 0.5 * amplitude(d):
            return Plausibility(
                False, f"a gap of ±{p['b']:.3g} m is over half the amplitude: no contact left"
            )
        return base

    def argument(self, d, p):
        a = amplitude(d)
        return (
            f"a dead band of 2b = {2 * p['b']:.3g} m ({100 * p['b'] / a:.1f} % of the "
            f"amplitude {a:.3g} m per side) with zero force in the middle of each stroke: "
            "play in the load path"
        )
