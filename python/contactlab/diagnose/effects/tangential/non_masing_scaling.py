"""``non_masing_scaling``: branches scaled by λ instead of Masing's 2, from rest, at the
actual turning points."""

from __future__ import annotations

import numpy as np

from ..._family import ParamSpec
from .._base import EffectModel, Plausibility, register
from ._common import actual_turns, record_turns, turning_points  # noqa: F401  (re-exported)
from ._first_loading import start_tells, unexplained_start

#: the branch scales :meth:`NonMasingScaling.start` tries (λ = 2 is Masing)
START_GRID = (0.6, 0.8, 1.0, 1.2, 1.35, 1.5, 1.65, 1.8, 2.0, 2.3, 2.7, 3.2, 4.0, 5.0, 6.5)


def turning_point_force(virgin, lam: float, x: np.ndarray, rev: np.ndarray) -> np.ndarray:
    """Force of the λ-scaled element started from rest: the virgin curve ``f(x)`` up to the
    first turning point, then from each turning point ``(x_r, h_r)`` the branch
    ``h_r + λ f((x - x_r)/λ)`` (``f`` odd), ``h_r`` where the previous branch arrived.

    ``rev``: the indices of the actual turning points (the record's reversals, which noise
    does not split). With λ = 2 and loops of one amplitude this is Masing's element; with
    λ ≠ 2 the closed loop it settles to spans ``λ f(A·2/λ)`` and is shifted off the origin
    by ``f(A) - λ f(2A/λ)/2`` — the first loading from rest, not the loop, tells it from a
    force offset."""
    if rev.size == 0:
        return virgin(x)
    xr = x[rev]
    hr = np.empty(rev.size)
    hr[0] = float(virgin(xr[:1])[0])
    if rev.size > 1:
        hr[1:] = hr[0] + np.cumsum(lam * virgin(np.diff(xr) / lam))
    k = np.searchsorted(rev, np.arange(x.size), side="right") - 1
    on = k >= 0
    kk = np.where(on, k, 0)
    return np.where(on, hr[kk] + lam * virgin((x - xr[kk]) / lam), virgin(x))


def loop_shift(p: dict[str, float], d) -> float:
    """The constant force by which the fitted λ-scaled element's closed loops sit off the
    Masing loops of ``(λ h0 / 2, 2 ac / λ)`` after the first turning point (the median over
    the record; one amplitude: exactly ``f(A) - λ f(2A/λ)/2``, docs/effects.md), N."""
    from ....masing import Masing

    x = d.u - p.get("x0", 0.0)
    turns = record_turns(d.u, d.extra.get("u_noise", 0.0))
    if turns.size == 0:
        return float("nan")
    lam, h0, ac = p["lam"], p["h0"], p["ac"]
    g = turning_point_force(Masing(h0, ac).virgin, lam, x, turns)
    gm = Masing(h0 * lam / 2.0, 2.0 * ac / lam).force(x)
    k = int(turns[0])
    return float(np.median(g[k:] - gm[k:]))


@register
class NonMasingScaling(EffectModel):
    name = "non_masing_scaling"
    kind = "tangential"
    params = (ParamSpec("lam", "-", 2.0, 0.2, 20.0, "one"),)
    description = "branch scale lam instead of Masing's 2, from rest at the turning points"
    physics = (
        "Generalised Masing rule: after each turning point (x_r, h_r) the branch is "
        "h_r + λ f((x - x_r)/λ), λ instead of 2, started from rest on the virgin curve. "
        "With λ < 2 the closed loop is a Masing-like loop of height λ f(2A/λ) shifted by a "
        "constant force: a force offset moves the virgin curve too, this does not."
    )
    stage = "element"
    order = 9
    size_param = "lam"

    def start(self, p, d, residual, family=None):
        """λ and the base parameters that keep the steady loop the current one.

        A λ-scaled element of ``(2 h0 / λ, λ ac / 2)`` runs, after the first half cycle, the
        same loop as the Masing element of ``(h0, ac)``, shifted by the constant ``F_c(λ)``
        (docs/effects.md): what tells λ is that shift together with the first loading from
        rest. Started at λ = 2 the solver sees the offset and the first loading pull λ in
        opposite directions and can run to the edge of its range (λ = 0.2 on a record of
        λ = 1.47 whose force offset then took the gain); each λ of :data:`START_GRID` is
        scored against the data with the rest of the current model kept, and the fit starts
        at the best."""
        from ....masing import Masing

        h0, ac = float(p.get("h0", np.nan)), float(p.get("ac", np.nan))
        if not (np.isfinite(h0) and np.isfinite(ac) and h0 > 0 and ac > 0) or d.u.size < 3:
            return {}
        x = d.u
        turns = record_turns(x, d.extra.get("u_noise", 0.0))
        masing = Masing(h0, ac).force(x)
        rest = (d.y - residual) - masing  # the current model's terms beside its element
        best, best_sse = None, np.inf
        for lam in START_GRID:
            h_l, a_l = 2.0 * h0 / lam, lam * ac / 2.0
            pred = rest + turning_point_force(Masing(h_l, a_l).virgin, lam, x, turns)
            sse = float(np.sum((pred - d.y) ** 2))
            if np.isfinite(sse) and sse < best_sse:
                best, best_sse = lam, sse
        if best is None or best == 2.0:
            return {}
        return {"lam": best, "h0": 2.0 * h0 / best, "ac": best * ac / 2.0}

    def apply(self, core, p, ctx):
        from ....masing import Masing

        core = core if core is not None else Masing(p["h0"], p["ac"])
        return turning_point_force(core.virgin, p["lam"], ctx.xm, actual_turns(ctx))

    def base_equivalent(self, p):
        """The steady loop is a Masing loop of ``(λ h0 / 2, 2 ac / λ)`` (docs/effects.md)."""
        return {"h0": p["h0"] * p["lam"] / 2.0, "ac": 2.0 * p["ac"] / p["lam"]}

    def plausible(self, d, p):
        """The shared rules, λ within 0.5..8, and the first loading from rest explained
        (:func:`~._first_loading.unexplained_start`): the loop shift a branch scale draws
        appears with the motion, so a record whose force is already off by it at rest (a
        force offset) or whose contact rests off the sensor's zero (a displacement offset:
        the model's virgin curve then starts with a jump) is refused with that reason; and
        told from a force offset by that start (:func:`~._first_loading.start_tells`: a
        start too noisy to tell leaves the simpler reading, a sensor's zero). Beside a
        force offset (``F0`` in the model) the start is the offset's to explain."""
        base = super().plausible(d, p)
        if base.ok and not 0.5 <= p["lam"] <= 8.0:
            return Plausibility(
                False, f"branch scale lam = {p['lam']:.3g} is outside 0.5..8 (no known joint)"
            )
        if base.ok and "F0" not in p:
            shift, what = loop_shift(p, d), f"λ = {p['lam']:.3g}"
            why = unexplained_start(p, d, shift, what) or start_tells(
                p, d, shift, what, "a force offset", self.IDENTIFIED_SIGMAS
            )
            if why:
                return Plausibility(False, why)
        return base

    def argument(self, d, p):
        lam = p["lam"]
        return (
            f"branch scale λ = {lam:.3g} instead of 2: each branch from a turning point is "
            f"{'flatter' if lam > 2 else 'steeper'} than Masing's; from rest the loop settles "
            f"{(1 - lam / 2) * p['h0']:.3g} N off the origin in gross sliding while the "
            "virgin curve starts at zero, which a force offset cannot do"
        )
