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

    #: the look-alike a play yields to (:meth:`yields_to`)
    LOOKALIKES = ("channel_delay",)

    def yields_to(self, p, gains, own, d=None):
        """Why a play is not named beside a channel delay accepted at the same step whose
        held-out gain falls short of its own by less than the input-noise budget
        (``d.extra["input_noise_budget"]``, σ²: what the input's noise alone can give a
        candidate), or None.

        Right after a turn a delayed force stays on its plateau while ``x`` returns by
        ``A (1 - cos ωτ)``, a dead band as a play draws; a play also passes over the noise's
        wiggles at each turning point, which no delay can, so on a noisy input the play
        wins by what the noise gives it. Delays of 1.5 ms through a realistic chain (x noise
        0.9-1.3 %) were named backlash with held-out gains 5.57 and 5.98 σ² against the
        delay's 5.45 and 5.63 (budgets 0.25 and 0.70 σ²); at 0.05 % x noise the delay won
        (5.79 against 5.25: ``benches/chain_inertia_delay.py`` seeds 104 and 105)."""
        if d is None:
            return None
        budget = float(d.extra.get("input_noise_budget", 0.0) or 0.0)
        rival = max(
            (n for n in self.LOOKALIKES if n in gains and np.isfinite(gains[n])),
            key=lambda n: gains[n],
            default=None,
        )
        if rival is None or not budget > 0 or not own - gains[rival] < budget:
            return None
        return (
            f"b = {p['b']:.3g} m (a dead band at each turn) beats {rival} by "
            f"{own - gains[rival]:.3g} σ² of held-out gain, less than the {budget:.3g} σ² the "
            "input's noise alone can give a play that passes over its wiggles at the turns: "
            f"{rival} draws the same dead band"
        )

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
