"""``backlash``: lost motion between the displacement sensor's point and the contact."""

from __future__ import annotations

import itertools

import numpy as np

from ..._family import ParamSpec
from .._base import EffectModel, Plausibility, register
from ._common import actual_turns, amplitude


def play(x: np.ndarray, b: float, rev: np.ndarray) -> np.ndarray:
    """The play (backlash) operator of half-width ``b``: ``u`` stands still until
    ``|x - u| = b``, then follows ``x`` at distance ``b``; from rest at ``u = 0`` in the
    middle of the gap.

    Exact for a history that is monotone between the turning points ``rev`` up to wiggles
    smaller than the gap (the filtered input between its reversals): on a rising stretch
    ``u = max(u_r, running max of x - b)``, on a falling one ``min(u_r, running min of
    x + b)``."""
    if b <= 0.0:
        return x.copy()
    u = np.empty_like(x)
    # each stretch ends at its turning point (included): the next one starts after it
    bounds = np.r_[0, rev + 1, x.size] if rev.size else np.array([0, x.size])
    ur = 0.0
    for a, e in itertools.pairwise(bounds.tolist()):
        if e <= a:
            continue
        seg = x[a:e]
        rising = seg[-1] >= seg[0] if e - a > 1 else x[min(e, x.size - 1)] >= seg[0]
        if rising:
            u[a:e] = np.maximum(ur, np.maximum.accumulate(seg - b))
        else:
            u[a:e] = np.minimum(ur, np.minimum.accumulate(seg + b))
        ur = float(u[e - 1])
    return u


@register
class Backlash(EffectModel):
    name = "backlash"
    kind = "tangential"
    params = (ParamSpec("b", "m", 0.0, 0.0, np.inf, "x"),)
    description = "lost motion of width 2b between the displacement sensor and the contact"
    physics = (
        "Lost motion of width 2b between the displacement sensor's point and the contact "
        "(clearance in a clamp, a loose probe; docs/effects.md): u is the play operator of x "
        "(u stands still until |x - u| = b, then follows at distance b) and F = M[u]. A "
        "horizontal segment of width 2b at each turning point (F constant while x moves) — "
        "the dual of sticking's vertical one."
    )
    stage = "element_input"
    order = 16
    size_param = "b"

    def apply(self, xm, p, ctx):
        return play(xm, max(p["b"], 0.0), actual_turns(ctx))

    def plausible(self, d, p):
        base = super().plausible(d, p)
        if base.ok and p["b"] > 0.5 * amplitude(d):
            return Plausibility(
                False, f"a play of ±{p['b']:.3g} m is over half the amplitude: no contact left"
            )
        return base

    def argument(self, d, p):
        a = amplitude(d)
        return (
            f"lost motion 2b = {2 * p['b']:.3g} m ({100 * p['b'] / a:.1f} % of the amplitude "
            f"{a:.3g} m per side): the force holds while the displacement crosses the gap at "
            "each turning point, which a series spring (a sloped segment) cannot do"
        )
