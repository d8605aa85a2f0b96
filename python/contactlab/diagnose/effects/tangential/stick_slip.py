"""``stick_slip``: a breakaway after each reversal (static above kinetic friction)."""

from __future__ import annotations

import numpy as np

from ..._family import ParamSpec
from .._base import EffectModel, register


def reversal_anchors(reversals: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """For each of ``n`` samples: whether a reversal precedes it (or is it), and the index of
    the last such reversal (0 where none)."""
    idx = np.searchsorted(reversals, np.arange(n), side="right") - 1
    has = idx >= 0
    r = reversals[np.where(has, idx, 0)] if reversals.size else np.zeros(n, int)
    return has, r


def breakaway(
    h: np.ndarray,
    x: np.ndarray,
    reversals: np.ndarray,
    s_b: float,
    ell: float,
    anchors: tuple[np.ndarray, np.ndarray] | None = None,
    at: np.ndarray | None = None,
) -> np.ndarray:
    """Branches with a breakaway peak: after each reversal ``r`` the rise ``h - h_r`` is
    scaled by ``1 + s_b exp(-|x - x_r| / ell)`` — equal to Masing's at the reversal (no
    jump) and far from it, above it in between (static friction above kinetic). Before the
    first reversal the virgin curve from the origin is treated the same way. ``anchors``:
    :func:`reversal_anchors` of ``reversals``, when computed already; ``at``: sample indices,
    the result at those samples only."""
    if s_b == 0.0:
        return h if at is None else h[at]
    has, r = anchors if anchors is not None else reversal_anchors(reversals, h.size)
    if at is not None:  # the anchors (reversals) from the whole history, the rest at ``at``
        has, r = has[at], r[at]
    xr = np.where(has, x[r], 0.0)
    hr = np.where(has, h[r], 0.0)
    if at is not None:
        h, x = h[at], x[at]
    return hr + (h - hr) * (1.0 + s_b * np.exp(-np.abs(x - xr) / max(ell, 1e-300)))


def breakaway_force(h0: float, ac: float, s_b: float, ell: float) -> float:
    """Peak force of a full branch from ``-h0`` with the breakaway of :func:`breakaway`
    (the static friction force; ``h0`` without breakaway)."""
    u = np.linspace(0.0, 20.0 / ac + 20.0 * ell, 4001)
    rise = 2.0 * h0 * -np.expm1(-ac * u / 2.0)
    return float(np.max(-h0 + rise * (1.0 + s_b * np.exp(-u / max(ell, 1e-300)))))


@register
class StickSlip(EffectModel):
    name = "stick_slip"
    kind = "tangential"
    params = (
        ParamSpec("s_b", "-", 0.0, 0.0, 0.5, "one"),
        ParamSpec("ell", "m", np.nan, 0.0, np.inf, "x"),
    )
    description = (
        "breakaway after each reversal: the branch rises s_b above Masing's and falls back "
        "over a slip distance ell (static friction above kinetic)"
    )
    physics = (
        "Static friction above kinetic: after each reversal the branch overshoots the "
        "plateau by up to s_b h0 and falls back to it over a slip distance ell (a function "
        "of the distance slid, not of the speed — Stribeck's is of the speed)."
    )
    stage = "branch"
    order = 13
    size_param = "s_b"

    def start(self, p, d, residual, family=None):
        return {"ell": 1.0 / p["ac"]}

    def apply(self, h, p, ctx):
        d = ctx.d
        if ctx.sp is None:
            rev = d.cycles.reversals
            n = ctx.x.size
            anchors = ctx.fixed("anchors", lambda: reversal_anchors(rev, n))
            return breakaway(h, ctx.x, rev, p["s_b"], p["ell"], anchors, ctx.rows)
        sp = ctx.sp
        if sp.anchors is None:
            sp.anchors = reversal_anchors(sp.reversals, sp.size)
        return breakaway(h, ctx.xm, sp.reversals, p["s_b"], p["ell"], sp.anchors, sp.rows)

    def derived(self, p, se, *, effects=None, d=None, family=None, **more):
        """``breakaway_force``: with the model's ``effects``, the data ``d`` and the
        ``family``, the model's breakaway as the sticks of the data measure it
        (:meth:`~contactlab.diagnose.candidates_tangential.TangentialFamily.model_breakaway`);
        without them, the peak of a full branch of the term alone (:func:`breakaway_force`)."""
        if effects is not None and d is not None and family is not None:
            val = family.model_breakaway(p, effects, d)
            var = 0.0
            for k, s in se.items():
                if not (np.isfinite(s) and s > 0):
                    continue
                step = 1e-3 * s
                q = dict(p)
                q[k] += step
                var += ((family.model_breakaway(q, effects, d) - val) / step * s) ** 2
            return {"breakaway_force": val}, {"breakaway_force": float(np.sqrt(var))}
        keys = ("h0", "ac", "s_b", "ell")
        val = breakaway_force(*(p[k] for k in keys))
        var = 0.0
        for i, k in enumerate(keys):
            step = 1e-4 * abs(p[k]) or 1e-12
            q = [p[j] for j in keys]
            q[i] += step
            var += ((breakaway_force(*q) - val) / step * se.get(k, np.inf)) ** 2
        return {"breakaway_force": val}, {"breakaway_force": float(np.sqrt(var))}

    def argument(self, d, p):
        return (
            f"the force overshoots the plateau by up to {100 * p['s_b']:.0f} % after each "
            f"reversal and falls back within ell = {p['ell']:.3g} m of sliding: static "
            "friction above kinetic"
        )
