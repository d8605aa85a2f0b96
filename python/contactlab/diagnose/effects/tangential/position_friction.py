"""``position_friction``: friction varying along the track."""

from __future__ import annotations

import numpy as np

from ..._family import ParamSpec
from .._base import EffectModel, register


def track_harmonics(x: np.ndarray, d) -> tuple[np.ndarray, ...]:
    """``cos ξ, sin ξ, cos 2ξ, sin 2ξ`` and ``ξ/π``, ``ξ = π (x - x_mid)/x_half``."""
    r = (x - d.extra["x_mid"]) / d.extra["x_half"]
    xi = np.pi * r
    return np.cos(xi), np.sin(xi), np.cos(2 * xi), np.sin(2 * xi), r


#: the terms of the friction along the track: two harmonics of the stroke and a gradient
TRACK_TERMS = ("a1", "b1", "a2", "b2", "g1")


@register
class PositionFriction(EffectModel):
    name = "position_friction"
    kind = "tangential"
    params = tuple(ParamSpec(n, "-", 0.0, -0.3, 0.3, "one") for n in TRACK_TERMS)
    description = (
        "friction varying along the track (wavy plateaus): F = h (1 + Σ a_k cos(kπ ξ) + "
        "b_k sin(kπ ξ) + g1 ξ), ξ the position scaled to -1..1 over the stroke, k = 1, 2"
    )
    physics = (
        "The friction coefficient varies along the track (waviness, wear scar, debris): the "
        "plateaus bend with position, the same on every stroke, up and down alike as a "
        "function of x. A normal load fluctuating at the drive's harmonics depends on time "
        "(the same along up and down strokes only for even harmonics in phase)."
    )
    stage = "factor"
    rank = 1
    order = 12
    size_param = "a1"

    def size(self, p, se):
        """The amplitude over (a1, b1, a2, b2, g1), with its delta-method error."""
        names = TRACK_TERMS
        v = float(np.sqrt(sum(p.get(n, 0.0) ** 2 for n in names)))
        if v == 0:
            return 0.0, float(np.inf)
        e2 = sum((p.get(n, 0.0) / v * se.get(n, np.inf)) ** 2 for n in names)
        return v, float(np.sqrt(e2))

    def apply(self, h, p, ctx):
        d = ctx.d
        if "displacement_offset" in ctx.effects:
            c1, s1, c2, s2, r = track_harmonics(ctx.pick(ctx.x), d)
        else:
            x = ctx.x
            c1, s1, c2, s2, r = map(ctx.pick, ctx.fixed("track", lambda: track_harmonics(x, d)))
        g = (
            p["a1"] * c1 + p["b1"] * s1 + p["a2"] * c2 + p["b2"] * s2 + p.get("g1", 0.0) * r
        )  # (a model saved before g1: none)
        return h * (1.0 + g)

    def argument(self, d, p):
        amp = float(np.sqrt(sum(p.get(n, 0.0) ** 2 for n in TRACK_TERMS)))
        return (
            f"the friction varies by {100 * amp:.0f} % along the track, the same on every "
            "stroke (a function of position, not of time)"
        )
