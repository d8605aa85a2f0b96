"""``stick_slip``: a breakaway after each reversal (static above kinetic friction)."""

from __future__ import annotations

import itertools

import numpy as np

from ..._family import ParamSpec
from .._base import EffectModel, Plausibility, register
from ._common import amplitude
from .backlash import paired_t


def reversal_anchors(reversals: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """For each of ``n`` samples: whether a reversal precedes it (or is it), and the index of
    the last such reversal (0 where none)."""
    idx = np.searchsorted(reversals, np.arange(n), side="right") - 1
    has = idx >= 0
    r = reversals[np.where(has, idx, 0)] if reversals.size else np.zeros(n, int)
    return has, r


def breakaway_term(
    h: np.ndarray,
    x: np.ndarray,
    reversals: np.ndarray,
    s_b: float,
    ell: float,
    h0: float,
    anchors: tuple[np.ndarray, np.ndarray] | None = None,
    at: np.ndarray | None = None,
) -> np.ndarray:
    """The branches with the breakaway of docs/effects.md added: after each reversal
    ``r``, ``h + s_b h0 sgn(ẋ) (s/ell) e^(1 - s/ell)`` with ``s = |x - x_r|`` the travel
    since it (``sgn(ẋ) s = x - x_r``): zero at the reversal (no jump), peak ``s_b h0`` at
    ``s = ell``, gone far from it; before the first reversal (the first loading from rest)
    the travel is counted from the origin, where the virgin curve starts. ``anchors``:
    :func:`reversal_anchors` of ``reversals``, when computed already; ``at``: sample
    indices, the result at those samples only."""
    if s_b == 0.0:
        return h if at is None else h[at]
    has, r = anchors if anchors is not None else reversal_anchors(reversals, h.size)
    xx = x
    if at is not None:  # the anchors (reversals) from the whole history, the rest at ``at``
        has, r, h, xx = has[at], r[at], h[at], x[at]
    e = max(ell, 1e-300)
    # the first loading from rest breaks away from the origin, where the virgin curve starts
    # (static friction holds at rest as after a turn; a record cut mid-loop is far from it)
    dx = np.where(has, xx - x[r], xx)
    return h + s_b * h0 * (dx / e) * np.exp(1.0 - np.abs(dx) / e)


def breakaway(
    h: np.ndarray,
    x: np.ndarray,
    reversals: np.ndarray,
    s_b: float,
    ell: float,
    anchors: tuple[np.ndarray, np.ndarray] | None = None,
    at: np.ndarray | None = None,
) -> np.ndarray:
    """Branches with a breakaway peak of the package's generator
    (:func:`contactlab.synthetic.diagnosis.hidden_effect_recording` makes its stick-slip
    with it; the candidate follows docs/effects.md, :func:`breakaway_term`): after each
    reversal ``r`` the rise ``h - h_r`` is scaled by ``1 + s_b exp(-|x - x_r| / ell)`` —
    equal to Masing's at the reversal (no jump) and far from it, above it in between. Before
    the first reversal the virgin curve from the origin is treated the same way. ``anchors``:
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
    """Peak force of a full branch from ``-h0`` with the breakaway of :func:`breakaway_term`
    (the static friction force; ``h0`` without breakaway)."""
    u = np.linspace(0.0, 20.0 / ac + 20.0 * ell, 4001)
    rise = 2.0 * h0 * -np.expm1(-ac * u / 2.0)
    e = max(ell, 1e-300)
    return float(np.max(-h0 + rise + s_b * h0 * (u / e) * np.exp(1.0 - u / e)))


#: the dead-band test (:func:`turn_shape`): the force window, as a share of a branch's rise
#: (half-width), the window centres it tries (shares of the rise), the share of the rise the
#: travel is measured to, and the share of that travel a dead band spends in one window
#: (an exponential Masing branch spends at most 12.5 % of its travel to 90 % of the rise in
#: a window of 10 % of the rise centred within 35-65 %, a straight one 11 %, about 15 %
#: sampled at 45 samples per turn; a breakaway or a stick does not flatten it (17 % for a
#: breakaway of 0.4 h0 in the test); a dead band, where the displacement moves with no force
#: change, spends the gap there)
WINDOW_HALF, WINDOW_CENTRES, TRAVEL_TO = 0.05, tuple(np.linspace(0.35, 0.65, 7)), 0.9
DEAD_BAND_SHARE = 0.25
#: branches the test needs, and samples each must hold
MIN_BRANCHES, MIN_BRANCH_SAMPLES = 3, 40


def _first_crossing(s: np.ndarray, q: np.ndarray, level: float) -> float:
    above = np.flatnonzero(q >= level)
    return float(s[above[0]]) if above.size else np.nan


def turn_branches(
    d, y: np.ndarray | None = None
) -> list[tuple[np.ndarray, np.ndarray, float, float]]:
    """The record's branches from one reversal to the next as the turn-shape tests read
    them: ``(s, q, start force, rise)`` with ``s`` the travel since the reversal and ``q``
    the force's rise from it (oriented with the motion, smoothed over 1 % of the branch's
    samples) over the whole rise to the branch's end (the median over its last 5 % of
    travel). Branches with fewer than :data:`MIN_BRANCH_SAMPLES` samples or no rise are
    left out. ``y``: a force to read instead of the record's (a model's, at the record's
    displacement)."""
    rev = np.asarray(d.cycles.reversals, int)
    u, y = d.u, (d.y if y is None else y)
    out: list[tuple[np.ndarray, np.ndarray, float, float]] = []
    if y is None or rev.size < 2:
        return out
    for a, b in itertools.pairwise(rev):
        if b - a < MIN_BRANCH_SAMPLES:
            continue
        uu, yy = u[a : b + 1], y[a : b + 1]
        sign = 1.0 if uu[-1] >= uu[0] else -1.0
        s = sign * (uu - uu[0])
        g = sign * (yy - yy[0])
        k = max(1, (b - a) // 100)
        if k > 1:
            g = np.convolve(g, np.ones(k) / k, mode="same")
        rise = float(np.median(g[s >= 0.95 * float(np.max(s))]))
        if rise > 0:
            out.append((s, g / rise, float(yy[0]), sign * rise))
    return out


def crossing_travels(d, levels: tuple[float, ...]) -> np.ndarray | None:
    """Per branch (:func:`turn_branches`), the travel since the reversal at which the force
    first covers each share ``levels`` of its rise (rows: branches), or None when fewer than
    :data:`MIN_BRANCHES` branches reach every level."""
    rows = []
    for s, q, _, _ in turn_branches(d):
        row = [_first_crossing(s, q, lv) for lv in levels]
        if all(np.isfinite(row)) and row[-1] > 0:
            rows.append(row)
    return np.asarray(rows) if len(rows) >= MIN_BRANCHES else None


def turn_shape(d, y: np.ndarray | None = None) -> dict | None:
    """How the force turns over at the reversals of the record ``d`` (the data, or the
    force ``y`` at its displacement): per branch (:func:`turn_branches`), ``share``: the
    largest travel spent with the rise ``q`` in a window of ±:data:`WINDOW_HALF` centred
    at :data:`WINDOW_CENTRES`, over the travel to :data:`TRAVEL_TO` of the rise (the median
    over the branches); ``level``: the force at the centre of that window (the median of
    its magnitude over the branches), ``travel``: that travel (m).

    A stick holds the displacement while the force turns (``share`` near 0), a breakaway
    leaves the middle of the turn about as steep as an exponential branch's (0.125), a dead
    band (backlash: the displacement crosses a gap with no force change) makes it flat
    there (above :data:`DEAD_BAND_SHARE`). None when fewer than :data:`MIN_BRANCHES`
    branches can be read."""
    shares, levels, travels = [], [], []
    for s, q, f0, rise in turn_branches(d, y):
        s90 = _first_crossing(s, q, TRAVEL_TO)
        if not (np.isfinite(s90) and s90 > 0):
            continue
        best, at = -1.0, np.nan
        for c in WINDOW_CENTRES:
            w = _first_crossing(s, q, c + WINDOW_HALF) - _first_crossing(s, q, c - WINDOW_HALF)
            if np.isfinite(w) and w > best:
                best, at = w, float(c)
        if best < 0:
            continue
        shares.append(best / s90)
        travels.append(best)
        levels.append(f0 + at * rise)
    if len(shares) < MIN_BRANCHES:
        return None
    return {
        "share": float(np.median(shares)),
        "level": float(np.median(np.abs(levels))),
        "travel": float(np.median(travels)),
        "branches": len(shares),
    }


def dead_band(d) -> str | None:
    """The sentence saying the record's turns hold a dead band (:func:`turn_shape`'s
    ``share`` at least :data:`DEAD_BAND_SHARE`), or None."""
    shape = turn_shape(d)
    if shape is None or shape["share"] < DEAD_BAND_SHARE:
        return None
    return (
        f"the data show a dead band at the turns, not a breakaway: over {shape['branches']} "
        f"branches the displacement travels {shape['travel']:.3g} m "
        f"({100 * shape['share']:.0f} % of the travel to {100 * TRAVEL_TO:.0f} % of the "
        f"force's rise) while the force changes by only {200 * WINDOW_HALF:.0f} % of its rise "
        f"(near |F| = {shape['level']:.3g} N), where an exponential branch spends at most "
        "12.5 %, a breakaway or a stick no more (backlash: the displacement crosses a gap with "
        "no force change)"
    )


def drawn_by_breakaway(d, p) -> bool:
    """Whether the fitted breakaway itself draws the flat stretch :func:`dead_band` reads in
    the data's turns: the turn shape of Masing's branches with the breakaway term
    (:func:`breakaway_term`, parameters ``p``) at the record's displacement reaches
    :data:`DEAD_BAND_SHARE` too.

    In pre-sliding a branch rises by only ``2 h0 (1 - e^(-ac A))``; a breakaway of
    ``s_b h0`` is then a large share of it, and the fall back to the kinetic branch after
    the peak cancels the branch's own rise: the force stays level while the displacement
    moves on, as across a gap (a breakaway of 0.2 h0 at ac·A 0.35: share 0.42-0.44, the
    friction damper's dead band 0.40-0.48). A gap is what the breakaway cannot draw; where
    it draws the flat stretch, the flat stretch is the breakaway's."""
    h0, ac = float(p.get("h0", np.nan)), float(p.get("ac", np.nan))
    if not (np.isfinite(h0) and h0 > 0 and np.isfinite(ac) and ac > 0 and p.get("s_b", 0) > 0):
        return False
    from ....masing import Masing

    base = Masing(h0, ac).force(d.u)
    model = breakaway_term(base, d.u, np.asarray(d.cycles.reversals, int), p["s_b"], p["ell"], h0)
    shape = turn_shape(d, model)
    return shape is not None and shape["share"] >= DEAD_BAND_SHARE


#: the share of the search's ``min_gain`` its held-out gain must reach, and the share of the
#: input-noise budget it must beat (:func:`contactlab.diagnose.search.own_gain_floor`,
#: ``search._noise_floor``), as for ``stribeck`` and ``position_friction``: on 24 clean
#: records (tuning seeds 950000-950029 of ``benches/eval_loadslip_gains.py``, 12 of
#: ``benches/chain_loadslip.py`` and 12 of the rig, x noise 0-1.9 %, its own floors off) its
#: largest held-out gain was 0.0008 σ² at t <= 1.22, at most 0.001 of the budget (a
#: breakaway is one-signed, s_b >= 0, and anchored at the reversals: the input's noise
#: cannot feed it). The whole budget had hidden a breakaway of 8 % of h0 at ac·A 3.2 and
#: 1.6 % x noise (held-out gain 0.118 σ², t = 6.8, against a floor of 0.276 σ²)
GAIN_FLOOR_SCALE = 0.2
INPUT_NOISE_SHARE = 0.25


#: the rivals a breakaway named on its reduced floors yields to when they draw the held-out
#: cycles significantly better (:meth:`StickSlip.yields_to_tried`): on one amplitude of a
#: periodic drive a dashpot's force ``c ẋ``, a spring's ``k_p x`` and a channel delay's
#: ``τ H'(x) ẋ`` (the stiffness of the branch times the speed: a skew between the channels
#: makes a hook at each turn) are, like the breakaway, the motion's sign times a function of
#: the travel since the last turn (``sgn(ẋ) c A ω √(s (2A - s)) / A``, ``sgn(ẋ) k_p (s -
#: A)``); the breakaway's peak after the turn falls back to the kinetic branch, the delay's
#: term follows the speed up to mid-stroke
YIELD_RIVALS = ("viscous_damping", "parallel_stiffness", "channel_delay")

#: a rival's lead over the breakaway across held-out cycles (the paired t of
#: :func:`~contactlab.diagnose.search.paired_lead`) that makes the breakaway yield: the
#: search's ``z`` for "told apart"
YIELD_Z = 3.0


#: slip distances :meth:`StickSlip.start` tries, as shares of the displacement amplitude
START_SHARES = (0.03, 0.06, 0.1, 0.15, 0.25, 0.4, 0.6)


@register
class StickSlip(EffectModel):
    name = "stick_slip"
    kind = "tangential"
    params = (
        ParamSpec("s_b", "-", 0.0, 0.0, 1.0, "one"),
        ParamSpec("ell", "m", np.nan, 0.0, np.inf, "x"),
    )
    description = (
        "breakaway after each reversal: s_b h0 sgn(v) (s/ell) e^(1 - s/ell) added, s the "
        "travel since the reversal (static friction above kinetic)"
    )
    physics = (
        "Static friction above kinetic: after each reversal the force rises above Masing's "
        "branch by up to s_b h0 at a travel ell and falls back to it (a function of the "
        "distance slid since the reversal, not of the speed — Stribeck's is of the speed): "
        "F = M[x] + s_b h0 sgn(ẋ) (s/ell) e^(1 - s/ell) (docs/effects.md)."
    )
    acts_through = "friction along the branch"
    stage = "branch"
    order = 13
    size_param = "s_b"
    #: per-effect floors (see GAIN_FLOOR_SCALE, INPUT_NOISE_SHARE above)
    gain_floor_scale = GAIN_FLOOR_SCALE
    input_noise_share = INPUT_NOISE_SHARE

    def start(self, p, d, residual, family=None):
        """The slip distance (of :data:`START_SHARES` of the amplitude) and size whose term
        lowers the current residual most (the term is linear in ``s_b`` at a given
        ``ell``); ``ell = 1/ac`` when none does."""
        h0 = float(p.get("h0", np.nan))
        A = amplitude(d)
        rev = d.cycles.reversals
        best: dict[str, float] = {"ell": 1.0 / p["ac"]}
        if not (np.isfinite(h0) and h0 > 0 and A > 0 and rev.size):
            return best
        has, r = reversal_anchors(rev, d.u.size)
        dx = np.where(has, d.u - d.u[r], 0.0)
        top = 0.0
        for share in START_SHARES:
            e = share * A
            term = h0 * (dx / e) * np.exp(1.0 - np.abs(dx) / e)
            tt, rt = float(term @ term), float(residual @ term)
            if tt > 0 and rt > 0 and rt * rt / tt > top:
                top = rt * rt / tt
                best = {"ell": e, "s_b": min(rt / tt, 0.9)}
        return best

    def apply(self, h, p, ctx):
        d = ctx.d
        if ctx.sp is None:
            rev = d.cycles.reversals
            n = ctx.x.size
            anchors = ctx.fixed("anchors", lambda: reversal_anchors(rev, n))
            return breakaway_term(h, ctx.x, rev, p["s_b"], p["ell"], p["h0"], anchors, ctx.rows)
        sp = ctx.sp
        if sp.anchors is None:
            sp.anchors = reversal_anchors(sp.reversals, sp.size)
        return breakaway_term(
            h, ctx.xm, sp.reversals, p["s_b"], p["ell"], p["h0"], sp.anchors, sp.rows
        )

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

    #: (:data:`YIELD_RIVALS`; a bench sets it empty for a before/after on one tree)
    yield_rivals = YIELD_RIVALS

    def yields_to_tried(self, p, v, cand, tried, current, d):
        """Why a breakaway that stands only on its reduced floors (its held-out gain below
        the input-noise budget, ``d.extra["input_noise_budget"]``, plus the search's gain
        floor, ``d.extra["gain_rules"]["min_gain"]``: the floors a rival must reach, a
        breakaway only :data:`INPUT_NOISE_SHARE` and :data:`GAIN_FLOOR_SCALE` of them) is
        not named beside a dashpot, a parallel spring or a channel delay tried at the same
        step (:data:`YIELD_RIVALS`) that drew the held-out cycles significantly better: its
        lead over the breakaway across held-out cycles (the paired t of
        :func:`~contactlab.diagnose.search.paired_lead`) at least :data:`YIELD_Z`; or None.

        The reduced floors rest on the input's noise not feeding a breakaway; they do not
        make the residual a breakaway's. On one amplitude of a periodic drive a dashpot
        (``c ẋ``: the speed rises as √s from each turn, peaks at mid-stroke), a spring
        (``k_p x``: a straight rise from each turn) and a delay (``τ H'(x) ẋ``) are the
        motion's sign times a function of the travel ``s`` since the turn, the breakaway's
        own form, and a breakaway with the base's curvature moved takes a share of either
        (rig, a dashpot at half its stated bound in pre-sliding: the breakaway, ell 0.1-0.15
        A, gained 0.27 and 0.16 of the dashpot's held-out gain, the dashpot below the full
        budget). Where the rival, which must beat the whole budget, draws the held-out
        cycles significantly better beyond what the input's noise gives it over a breakaway
        (its lead less ``(1 - INPUT_NOISE_SHARE)`` of the budget, the paired t scaled by the
        share of the lead left, as :func:`~contactlab.diagnose.search._mark_not_told_apart`
        discounts a play's lead), the shape is the rival's held back by the input's noise:
        the record does not show a peak after the turn falling back to the kinetic branch,
        and nothing is named in its place. A rival
        ahead by chance (paired t below :data:`YIELD_Z`) does not make it yield (a blind
        breakaway of ac·A 1.15 at 1.9 % x noise was lost so, issue 29), nor does a delay's
        lead that the noise feeds: rig breakaways at their stated bound (tuning seed 5310002
        of ``benches/eval_confusions.py --cases stick``, ac·A 1.92, x noise 1.84 % of the
        range) read a delay 0.146 σ² ahead at t = 7.5 against a budget of 0.54 σ²)."""
        budget = float(d.extra.get("input_noise_budget", 0.0) or 0.0)
        # the floors a rival (a gain floor scale and an input-noise share of 1) must reach
        floor = budget + float((d.extra.get("gain_rules") or {}).get("min_gain", 0.0) or 0.0)
        if not (budget > 0 and np.isfinite(v.gain) and v.gain < floor):
            return None
        best = None
        for name in self.yield_rivals:
            rival = tried.get(name)
            if rival is None:
                continue
            rv, rc = rival
            if (rv.reason or "").startswith(("implausible", "could not be fitted", "look-alike")):
                continue
            if not (np.isfinite(rv.gain) and rv.gain > v.gain):
                continue
            # the rival's lead counts beyond what the input's noise alone gives it over a
            # breakaway (the rest of the budget: the rival takes all of it, a breakaway
            # INPUT_NOISE_SHARE), at the same scatter across cycles
            lead, owed = float(rv.gain - v.gain), (1.0 - self.input_noise_share) * budget
            if not lead > owed:
                continue
            t = paired_t(d, current, rc, cand)  # search.paired_lead's statistic
            t *= 1.0 - owed / lead
            if np.isfinite(t) and t >= YIELD_Z and (best is None or rv.gain > best[0].gain):
                best = (rv, t)
        if best is None:
            return None
        rv, t = best
        return (
            f"a breakaway of {100 * p['s_b']:.2g} % of h0 (ell = {p['ell']:.3g} m) gained "
            f"{v.gain:.3g} σ² held-out, below the {floor:.3g} σ² floors (input-noise budget "
            f"{budget:.3g} σ² and the search's gain floor) it need not reach, and {rv.name} "
            "tried at the same step drew the held-out cycles significantly better "
            f"({rv.gain:.3g} σ², paired t of its lead beyond the noise's share {t:.2f} >= "
            f"{YIELD_Z:g}): on one amplitude both are the motion's sign times a function of "
            f"the travel since the turn, and the breakaway takes a share of the {rv.name}'s "
            "shape, held back by the input's noise"
        )

    def plausible(self, d, p):
        """The shared rules, then the data's own turns: a dead band (the displacement
        moving with no force change in the middle of the turn, :func:`dead_band`) is the
        opposite of a breakaway, and the breakaway term fitted there only bends the branch
        towards it."""
        base = super().plausible(d, p)
        if not base.ok:
            return base
        why = dead_band(d)
        if why is not None and not drawn_by_breakaway(d, p):
            return Plausibility(False, why)
        return base

    def argument(self, d, p):
        shape = turn_shape(d)
        seen = (
            f"; in the middle of the turns the displacement travels {100 * shape['share']:.0f} "
            f"% of the way to {100 * TRAVEL_TO:.0f} % of the rise per {200 * WINDOW_HALF:.0f} % "
            "of force change (no dead band: an exponential branch's is at most 12.5 %)"
            if shape is not None
            else ""
        )
        return (
            f"the force rises {100 * p['s_b']:.0f} % of h0 above the branch at a travel "
            f"ell = {p['ell']:.3g} m after each reversal and falls back: static friction "
            f"above kinetic{seen}"
        )
