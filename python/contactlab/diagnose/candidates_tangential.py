"""Tangential contact: the Masing base model and its library of candidate extensions.

Base model (PHYSICS.md §1): Masing hysteresis with the exponential virgin curve
``f(u) = h0 (1 - exp(-ac u))`` and branch scale 2, force ``h = M(x)`` for the measured
displacement history ``x``. The candidate effects are objects, one file each under
``diagnose/effects/tangential/`` (:func:`contactlab.diagnose.effects.registry`), defined
physically in ``docs/effects.md``: each has its parameters (name, unit, bounds, the value
meaning "absent"), what it does at its stage of the composition
(:meth:`~contactlab.diagnose.effects.EffectModel.apply`), whether a fitted value is
physical on a record and why (:meth:`~contactlab.diagnose.effects.EffectModel.plausible`)
and the smallest size a record reveals
(:meth:`~contactlab.diagnose.effects.EffectModel.detectable`). A new effect is one new file.

=============================  =========================================================== =========
name                           measured force ``F`` (or measured ``x``)                    params
=============================  =========================================================== =========
``viscous_damping``            ``F = h + c ẋ``                                             c [N s/m]
``inertia``                    ``F = h + m ẍ`` (mass between sensor and contact)           m [kg]
``parallel_stiffness``         ``F = h + k_p x`` (rig flexures in parallel)                k_p [N/m]
``series_compliance``          ``x = x_c + C_s h`` (rig compliance in series)              C_s [m/N]
``force_offset``               ``F = h + F0`` (sensor bias)                                F0 [N]
``force_drift``                ``F = h + F1 (t - t0)/T`` (load-cell zero drifting)         F1 [N]
``displacement_offset``        ``h = M(x - x0)`` (displacement sensor zero off the origin) x0 [m]
``channel_delay``              ``F(t) = h(t - τ)`` (force channel lags displacement)       tau [s]
``asymmetry``                  ``F = h + α |h|``: saturation ``h0(1 ± α)`` per direction   alpha [-]
``non_masing_scaling``         branches ``h_r + λ f((x - x_r)/λ)`` from rest at the turns  lam [-]
``parameter_drift``            ``F = h (1 + β (t - t_m)/T)``, ``t_m`` mid-record           beta [-]
``stribeck``                   ``F = h (1 + s exp(-(ẋ/v_s)²))``                            s, v_s
``position_friction``          ``F = h (1 + a1 cos φ + b1 sin φ)``, ``φ = 2π(x-x_mid)/L``  a1, b1, L
``stick_slip``                 ``F = h + s_b h0 sgn(ẋ) (s/ell) e^(1 - s/ell)``, s: travel  s_b, ell
``normal_load``                ``F = h (1 + ε_c cos 2π f_n t + ε_s sin 2π f_n t)``         eps, f_n
``power_law_microslip``        Segalman's Iwan element (F_S = h0, K_T = h0 ac)             chi, beta
``backlash``                   ``F = M(u)``, ``u`` the play operator of ``x`` (width 2b)   b [m]
``rate_dependent_presliding``  ``F = h + σ1 ẋ k(x)/k0`` (LuGre micro-damping)              sigma1
=============================  =========================================================== =========

Notes on exactness. The exponential Masing force is linear in ``h0`` at fixed ``ac`` along a
history, so the drift factor is exact. A linear spring in series with a Masing element is
again a Masing element whose virgin curve is ``x(u) = u + C_s f(u)`` against ``f(u)``, so
the series compliance is solved exactly by reparametrising the virgin curve
(:meth:`contactlab.Masing.from_backbone`); Segalman's element likewise (an Iwan model obeys
Masing's rules). The branch scale and the play operator run on the actual turning points of
the filtered input (a hysteresis of a few input-noise standard deviations). ``ẋ`` and ``ẍ``
are Savitzky-Golay derivatives of the measured displacement; the delay is a
fractional-sample shift by linear interpolation. When several effects are active they
compose by stage (:data:`contactlab.diagnose.effects.TANGENTIAL_STAGES`): the displacement
the contact sees; the element; terms on its force; the breakaway; factors on the friction;
the additive terms; the delay on the total measured force.
"""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np

from .. import _core
from ..errors import InputError
from ..masing import Masing, loop_area
from ._family import Candidate, ParamSpec, Prepared
from ._filters import savgol_coeffs, savgol_filter
from ._kept import delayed, span
from ._signal import Knots, minimize_bounded
from .effects import ForceContext, ordered, registry
from .effects.tangential import memo, turn_clipped_input
from .effects.tangential import normal_load as _normal_load
from .effects.tangential.series_compliance import series_backbone
from .effects.tangential.stick_slip import breakaway, breakaway_force, reversal_anchors

__all__ = [
    "CANDIDATES",
    "EFFECTS",
    "TangentialFamily",
    "breakaway",
    "breakaway_force",
    "reversal_anchors",
    "series_backbone",
]

_INF = np.inf

#: the library: one :class:`~contactlab.diagnose.effects.EffectModel` per file under
#: ``diagnose/effects/tangential/`` (parameters, bounds, what it does, its plausibility)
EFFECTS = registry("tangential")
CANDIDATES: dict[str, Candidate] = {name: e.candidate for name, e in EFFECTS.items()}

BASE_PARAMS = (
    ParamSpec("h0", "N", _INF, 0.0, _INF, "F"),
    ParamSpec("ac", "1/m", _INF, 0.0, _INF, "ac"),
)

#: a normal-load fluctuation must make this many periods in the record; slower, it is a drift
MIN_LOAD_PERIODS = _normal_load.MIN_LOAD_PERIODS


def _grid(x: np.ndarray, F: np.ndarray, offset: bool = False) -> tuple[float, float, float]:
    """Best ``(rss, h0, ac)`` over ``ac·max|x|`` from pre-sliding to gross sliding; with
    ``offset``, each curve is fitted with a constant force beside it (its rss then)."""
    xmax = float(np.max(np.abs(x)))
    best = (np.inf, 1.0, 1.0)
    if offset:
        F = F - np.mean(F)
    for q in np.geomspace(0.2, 5000.0, 23):
        ac = q / xmax
        g = Masing(1.0, ac).force(x)
        if offset:
            g = g - np.mean(g)
        gg = float(g @ g)
        if gg == 0.0:
            continue
        h0 = max(float(g @ F) / gg, 1e-12)
        r = float(np.sum((h0 * g - F) ** 2))
        if r < best[0]:
            best = (r, h0, ac)
    return best


#: ac·A from which the base loop is near-rectangular (gross sliding, as regime() says)
GROSS_SLIDING_ZA = 10.0
#: a gross-sliding base whose h0 is this many combined standard errors from the plateau
#: force is re-anchored to it (TangentialFamily.anchor); h0 is then held within
#: ANCHOR_BAND plateau errors of the plateau
ANCHOR_SIGMAS = 3.0
ANCHOR_BAND = 2.0
#: ... or within this share of the plateau force, the larger (the final model keeps h0
#: within 5 % of the plateau analyze reads: issue 29)
H0_HOLD = 0.025


def _sg_dot(window: int, deriv: int, dt: float) -> np.ndarray:
    """Cubic Savitzky-Golay weights of the ``deriv``-th derivative, dot orientation (as
    :func:`contactlab.tangential.frame.savgol_coefficients`, in numpy)."""
    return savgol_coeffs(window, 3, deriv, dt)[::-1]


#: unit Masing forces kept per recording (one per ac, x0 tried); 64 of 24 000 samples: 12 MB
_MASING_KEEP = 64


def _masing_force(
    d: Prepared, h0: float, ac: float, x0: float | None, x: np.ndarray, token: int = 0
) -> np.ndarray:
    """``Masing(h0, ac).force(x)`` as ``h0`` times the force of the unit element (h0 = 1),
    which is kept per ``(ac, x0)`` and history (``token``: a span of a kept record): along a
    given history the exponential Masing force is linear in h0 (to rounding, 1e-15 h0), and
    the fits step h0 and the effects' parameters at a fixed ac thousands of times (their
    Jacobian columns)."""
    if not (np.isfinite(h0) and h0 > 0):
        return Masing(h0, ac).force(x)  # the model's own refusal
    cache = d.extra.setdefault("masing", {})
    key = (ac, x0, x.size, token)
    g = cache.get(key)
    if g is None:
        g = Masing(1.0, ac).force(x)
        g.flags.writeable = False
        if len(cache) >= _MASING_KEEP:
            cache.clear()
        cache[key] = g
    return h0 * g


class TangentialFamily:
    """Masing base model with the tangential candidate library (see module docstring)."""

    kind = "tangential"
    candidates = CANDIDATES
    #: the search tries two candidates at once when no single one passes
    #: (:func:`contactlab.diagnose.workflow._pair_search`)
    pair_move = True
    #: the solver's tolerances relative 1e-6 and the Gauss-Newton polish after it stopped at
    #: steps below 0.01 standard errors (:data:`~contactlab.diagnose.select.QUICK_TOL`,
    #: :data:`~contactlab.diagnose.select.POLISH_STOP`), as for the normal contact: every
    #: error moves by far less than the noise. At 1e-8 a candidate with an unidentified
    #: direction crawled along it (stribeck with ``v_s`` far above the record's speeds,
    #: where ``h0`` and ``s`` trade off: 1 327 model evaluations of one fit of a 1e6-sample
    #: record, 193 now, both ending not converged), and a fit with ``normal_load`` zigzagged
    #: about its minimum in ``f_n`` through all 30 polish steps, each below 0.01 standard
    #: errors (370 of the 486 evaluations of one fold fit)
    quick_polish = True
    #: the base's h0 held to this band and ac to at least ``ac_floor`` (:meth:`anchor`)
    h0_band: tuple[float, float] | None = None
    ac_floor: float = 0.0

    @property
    def base_params(self) -> tuple[ParamSpec, ...]:
        """``h0`` and ``ac``; within the plateau's band once :meth:`anchor` has set one."""
        if self.h0_band is None:
            return BASE_PARAMS
        lo, hi = self.h0_band
        return (
            ParamSpec("h0", "N", _INF, lo, hi, "F"),
            ParamSpec("ac", "1/m", _INF, self.ac_floor, _INF, "ac"),
        )

    def anchor(self, p: dict[str, float], se: dict[str, float], d: Prepared) -> str | None:
        """Hold ``h0`` at the plateau in the sliding regimes: there the plateau measures
        ``h0`` directly and ``ac`` is only bounded from below.

        The plateau is the one ``analyze`` reads (``d.extra["regime_info"]``, set by the
        workflow from :func:`contactlab.tangential.analyze_tangential`: the same regime
        decision and the same plateau); without it, :func:`contactlab.tangential.regime.
        plateau` on this record when the base fit is in gross sliding (``ac·A`` at least
        :data:`GROSS_SLIDING_ZA`). ``h0`` is then held within ``max(ANCHOR_BAND plateau
        errors, H0_HOLD h0)`` of the plateau and ``ac`` above the plateau's bound from then
        on (the base and every candidate), so that no effect trades ``h0`` against a misfit
        and the final model keeps the friction force ``analyze`` found; the band stays with
        the family (a refit of the final model keeps it). Returns a sentence when the base
        had to be moved into the band (its least-squares ``h0`` more than
        :data:`ANCHOR_SIGMAS` combined standard errors from the plateau, or outside the
        band), None otherwise."""
        if self.h0_band is not None:
            return None
        if p["ac"] * 0.5 * float(np.ptp(d.u)) < GROSS_SLIDING_ZA:
            # not rectangular: the plateau is read where the loop still bends, and effects
            # that act along the stroke (a viscous term, Stribeck, a parallel spring) move
            # it; h0 stays the fit's (the final check reports how it compares)
            return None
        info = d.extra.get("regime_info") or {}
        if info.get("h0_source") == "plateau" and info.get("plateau_h0"):
            h0_pl = float(info["plateau_h0"])
            se_pl = float(info.get("plateau_stderr") or np.nan)
            ac_lb = info.get("ac_lower_bound")
            what = "the plateau analyze reads"
        else:
            pl = self._own_plateau(p, d)
            if pl is None:
                return None
            h0_pl, se_pl, ac_lb = pl.h0, pl.h0_stderr, pl.ac_lower_bound
            what = "the plateau"
        if not (np.isfinite(se_pl) and se_pl > 0):
            return None
        band = max(ANCHOR_BAND * se_pl, H0_HOLD * h0_pl)
        self.h0_band = (h0_pl - band, h0_pl + band)
        if ac_lb is not None and np.isfinite(ac_lb):
            self.ac_floor = min(float(ac_lb), p["ac"])
        err = float(np.hypot(se["h0"] if np.isfinite(se["h0"]) else 0.0, se_pl))
        off = abs(p["h0"] - h0_pl) / err
        if off <= ANCHOR_SIGMAS and abs(p["h0"] - h0_pl) <= band:
            return None
        floor = f" and ac ≥ {self.ac_floor:.3g} 1/m (only a lower bound is identified)"
        return (
            f"base re-anchored to the plateau: in the sliding regime h0 is {what}, "
            f"{h0_pl:.4g} ± {se_pl:.2g} N, but the least-squares base put it at "
            f"{p['h0']:.4g} N ({off:.1f} σ away); h0 is held within ±{band:.2g} N of the "
            f"plateau{floor if self.ac_floor > 0 else ''}"
        )

    def _own_plateau(self, p: dict[str, float], d: Prepared) -> Any:
        """The plateau of this record (:func:`contactlab.tangential.regime.plateau`) when
        the base fit is in gross sliding, else None."""
        from ..tangential.preprocess import average_loop
        from ..tangential.regime import plateau, velocity

        amp = 0.5 * float(np.ptp(d.u))
        if p["ac"] * amp < GROSS_SLIDING_ZA:
            return None
        x = d.extra.get("u_raw", d.u)
        try:
            loop = average_loop(x, d.y, d.t)
            v, thr, _ = velocity(d.t, x)
            return plateau(loop, x, d.y, v, thr)
        except (InputError, ValueError):  # no loop to average: no plateau to anchor to
            return None

    #: a stick changes the force by at least this share of its range (1st to 99th
    #: percentile) while the displacement stands still (:meth:`sticking`)
    STICK_FORCE_SHARE = 0.25

    def sticking(self, d: Prepared) -> np.ndarray:
        """The samples where the contact sticks: the displacement stands still within its
        noise (``|v| < 3 σv``, the Savitzky-Golay velocity of
        :func:`contactlab.tangential.regime.velocity`) for at least
        :data:`~contactlab.tangential.regime.STICK_DWELL_FACTOR` times as long as a smooth
        turn of that stroke's amplitude would, within a quarter period of a reversal, while
        the force changes by at least :attr:`STICK_FORCE_SHARE` of its range — the sticks
        ``analyze`` reports (:func:`contactlab.tangential.regime.stick_slip`) — widened by
        half the velocity filter's window either side (the filter spreads the start of the
        motion over that: on Coulomb frames the samples it missed, 1.5 % of the record,
        carried all of a spurious delay's gain).

        While stuck, the force is whatever holds the body still (a frame's drive ramping
        from the sliding force through zero to the breakaway force), not a function of the
        displacement, which does not move: a model driven by the displacement cannot
        predict it, and the one candidate that lowers the error there is a negative
        channel delay, which reads the force's change off the displacement after the stick
        (measured on Coulomb frames: all of the delay's held-out gain comes from the stuck
        samples, on the true force as on the reconstructed one). A displacement-driven rig
        never dwells that long at a turn: the mask is empty there, as it is when the velocity
        filter spans more than a quarter period (too few samples a cycle to tell a stick).
        """
        from ..tangential.frame import difference_noise, lepski_window
        from ..tangential.regime import STICK_DWELL_FACTOR, VELOCITY_SIGMAS, long_runs

        x = d.extra.get("u_raw", d.u)
        mask = np.zeros(x.size, bool)
        rev = d.cycles.reversals
        amp = 0.5 * float(np.ptp(x))
        if rev.size < 2 or x.size < 20 or not amp > 0:
            return mask
        # regime.velocity (the sticks analyze reports) with numpy's Savitzky-Golay filters:
        # the same values to rounding, without importing scipy.signal (0.3 s a diagnosis)
        sx = difference_noise(x)
        window = min(lepski_window(x, d.dt, sx, coefficients=_sg_dot), (x.size // 2) * 2 - 1)
        window = max(window, 5)
        v = savgol_filter(x, window, 3, deriv=1, delta=d.dt, mode="interp")
        thr = VELOCITY_SIGMAS * sx * float(np.linalg.norm(_sg_dot(window, 1, d.dt)))
        if not thr > 0:
            thr = 1e-9 * float(np.max(np.abs(v)))
        if window > 0.25 * d.cycles.period_samples:  # too few samples a cycle to tell
            return mask
        period = d.cycles.period_samples * d.dt
        omega = 2.0 * np.pi / period
        # the smooth dwell of a turn of the stroke's own amplitude (the larger half swing
        # either side of the reversal): a record starting from rest ramps its amplitude
        # up, and its first small turns dwell long without sticking
        swing = np.abs(np.diff(x[rev]))
        local = 0.5 * np.maximum(np.r_[swing, swing[-1]], np.r_[swing[0], swing])
        smooth = 2.0 * thr / (np.maximum(local, 1e-300) * omega**2)
        quarter = 0.25 * d.cycles.period_samples
        lo, hi = np.percentile(d.y, [1.0, 99.0])
        swing_f = self.STICK_FORCE_SHARE * float(hi - lo)
        shortest = max(4, int(np.ceil(STICK_DWELL_FACTOR * float(np.min(smooth)) / d.dt)))
        spans: dict[int, list[int]] = {}  # reversal -> [first stuck sample, end]
        for a, b in long_runs((v < thr) & (v > -thr), shortest):
            mid = 0.5 * (a + b - 1)
            k = int(np.argmin(np.abs(rev - mid)))
            need = max(4, int(np.ceil(STICK_DWELL_FACTOR * float(smooth[k]) / d.dt)))
            if b - a >= need and abs(rev[k] - mid) <= quarter + 0.5 * (b - a):
                sp = spans.setdefault(k, [a, b])  # noise splits a stick into runs
                sp[0], sp[1] = min(sp[0], a), max(sp[1], b)
        for a, b in spans.values():
            # a stick holds a turn, not a whole stroke (at most half a period), and the
            # force changes while it holds
            if b - a <= 2 * quarter and float(np.ptp(d.y[a:b])) >= swing_f:
                # the velocity filter spreads the departure from rest over half its window:
                # that close to a detected stick a sample may still be stuck
                mask[max(a - window // 2, 0) : b + window // 2] = True
        return mask

    input_name = "x"
    output_name = "F"
    input_unit = "m"
    output_unit = "N"

    def prepare(self, d: Prepared) -> None:
        """The stroke (centre and half-range of x) that scales the position of
        ``position_friction``; kept when given by a fitted model's context. The start-up
        (before the input's first maximum) is a held-out unit of the folds
        (:func:`contactlab.diagnose.select.heldout_unit`, issue 29)."""
        d.extra.setdefault("heldout_startup", True)
        if "x_mid" not in d.extra:
            lo, hi = float(np.min(d.u)), float(np.max(d.u))
            d.extra["x_mid"], d.extra["x_half"] = 0.5 * (lo + hi), 0.5 * (hi - lo) or 1.0

    def context(self, d: Prepared) -> dict[str, float]:
        """The stroke scaling of ``position_friction`` (the rest are parameters)."""
        return {"x_mid": d.extra["x_mid"], "x_half": d.extra["x_half"]}

    def start_effect(
        self, name: str, p: dict[str, float], d: Prepared, residual: np.ndarray
    ) -> dict[str, float]:
        """Starting values of an effect's nonlinear parameters from the current residual
        (the effect's own :meth:`~contactlab.diagnose.effects.EffectModel.start`)."""
        return EFFECTS[name].start(p, d, residual, family=self)

    #: the load-frequency search (:meth:`search_start`): a grid of ``LOAD_GRID`` points either
    #: side of the start, ``LOAD_GRID_STEP`` of the record's frequency resolution ``1/T``
    #: apart (within the lobe of the start: its half-width is ``1/T``), then Brent's method
    #: within one grid step of the best point, to ``LOAD_XTOL / T``
    LOAD_GRID = 4
    LOAD_GRID_STEP = 0.125
    LOAD_XTOL = 1e-4

    def search_start(
        self,
        effects: tuple[str, ...],
        d: Prepared,
        at: np.ndarray,
        y: np.ndarray,
        w: np.ndarray,
        p: dict[str, float],
    ) -> tuple[dict[str, float], int]:
        """A start for a fit of ``effects`` on the samples ``at`` (measured ``y``, residual
        weights ``w``) from the start ``p``: with ``normal_load``, its frequency ``f_n`` and
        amplitudes ``eps_c, eps_s`` searched with every other parameter held at ``p``.
        Returns the start and the model evaluations spent.

        The force is affine in ``(eps_c, eps_s)`` whatever the other effects (they multiply
        the element's force; what follows is added, delayed or filtered linearly), so at a
        given ``f_n`` the two are solved by linear least squares from three evaluations
        (variable projection), and ``f_n`` is searched in one dimension on the projected
        residual: a grid about the start, then Brent's method. The solver alone crawls
        there (870 to 1700 model evaluations a fit on a 1e6-sample record): the
        fluctuation's phase drifts by ``2π δf t`` over the record, so ``f_n`` and the
        amplitudes move together along a curved valley, and where the model misses other
        structure (the residual far above the noise) the Gauss-Newton curvature of ``f_n``
        is wrong and each trust-region step advances a fraction of a standard error."""
        if "normal_load" not in effects:
            return p, 0
        q = dict(p, eps_c=0.0, eps_s=0.0)
        a = self.predict(q, effects, d, at)
        r0 = (y - a) * w
        rr = float(r0 @ r0)
        spent = 1
        lo_e, hi_e = (
            EFFECTS["normal_load"].params[0].lower,
            EFFECTS["normal_load"].params[0].upper,
        )
        seen: dict[float, tuple[float, float, float]] = {}

        def projected(f: float) -> float:
            nonlocal spent
            hit = seen.get(f)
            if hit is not None:
                return hit[0]
            cols = []
            for ec, es in ((1.0, 0.0), (0.0, 1.0)):
                cols.append(
                    (self.predict(dict(q, f_n=f, eps_c=ec, eps_s=es), effects, d, at) - a) * w
                )
            spent += 2
            m = np.column_stack(cols)
            g = m.T @ m
            b = m.T @ r0
            # (minimum-norm where the two columns are parallel: eps = 0, or f_n near 0)
            e = np.linalg.lstsq(m, r0, rcond=1e-10)[0]
            e = np.clip(e, lo_e, hi_e)
            cost = rr - 2.0 * float(e @ b) + float(e @ g @ e)
            if not np.isfinite(cost):
                cost = np.inf
            seen[f] = (cost, float(e[0]), float(e[1]))
            return cost

        lobe = 1.0 / d.duration
        step = self.LOAD_GRID_STEP * lobe
        f0 = p["f_n"]
        grid = [f0 + k * step for k in range(-self.LOAD_GRID, self.LOAD_GRID + 1)]
        grid = [f for f in grid if f > 0.5 * step]
        if not grid:
            return p, spent
        best = min(grid, key=projected)
        f, _, _ = minimize_bounded(
            projected, max(best - step, 0.5 * step), best + step, self.LOAD_XTOL * lobe
        )
        f = min(seen, key=lambda k: seen[k][0])  # (Brent's end, or a grid point below it)
        _, ec, es = seen[f]
        return dict(p, f_n=float(f), eps_c=ec, eps_s=es), spent

    def check(self, effects: tuple[str, ...]) -> bool:
        """Effects combine in the order of their stages, with at most one element law
        (``stage == "element"``: the branch scale, the power-law microslip, the backlash
        replace the exponential element; each may sit behind a series compliance), and no
        element law other than the branch scale behind a series compliance."""
        stages = [EFFECTS[e].stage for e in effects]
        if stages.count("element") > 1:
            return False
        if "element" in stages and "core" in stages and "non_masing_scaling" not in effects:
            return False
        return True

    def scales(self, d: Prepared) -> dict[str, float]:
        rms = lambda a: float(np.sqrt(np.mean(a * a))) or 1.0  # noqa: E731
        Fs, xs = rms(d.y - np.mean(d.y)), rms(d.u - np.mean(d.u))
        return {
            "F": Fs,
            "ac": 1.0 / xs,
            "c": Fs / rms(d.ud),
            "m": Fs / rms(d.udd),
            "k": Fs / xs,
            "C": xs / Fs,
            "x": 0.05 * xs,
            "tau": d.cycles.period_samples * d.dt / 100.0,
            "one": 1.0,
            "v": rms(d.ud),
            "fq": 1.0 / d.duration,
        }

    def initial_base(self, d: Prepared) -> dict[str, float]:
        """Grid over ``ac·max|x|`` with ``h0`` by linear least squares (F is linear in h0).

        Refuses, with a sentence about the data, a force that no Masing curve follows and a
        loop that runs the wrong way (∮F dx < 0: the force recorded with the opposite sign).
        """
        rss, h0, ac = _grid(d.u, d.y)
        var = float(np.sum((d.y - d.y.mean()) ** 2))
        if not rss < 0.9 * var:
            # a constant force beside the loop (a sensor's zero, force_offset) larger than the
            # loop itself: the curve through the origin cannot follow it, one beside a constant
            # can (a pre-sliding loop of +-1.6 N offset by -1.5 N was refused as "no friction
            # loop"); the base starts from that curve and the candidates take the constant
            rss_c, h0_c, ac_c = _grid(d.u, d.y, offset=True)
            if rss_c < 0.5 * var:
                return {"h0": h0_c, "ac": ac_c}
            if _grid(d.u, -d.y)[0] < 0.5 * var:
                raise InputError(
                    f"the loop runs the wrong way: ∮F dx = {loop_area(d.u, d.y):.3g} J over the "
                    "recording, but a passive joint dissipates (∮F dx > 0); the force channel "
                    "is recorded with the opposite sign — negate F (force_sign=-1, --force-sign -1)"
                )
            raise InputError(
                f"the force does not follow the displacement: the best Masing curve explains "
                f"{100 * max(0.0, 1 - rss / var):.0f} % of the force variance — no friction "
                "loop in this recording (unrelated or swapped channels?)"
            )
        return {"h0": h0, "ac": ac}

    #: :meth:`predict` takes ``at`` (the fits evaluate the model at their samples only)
    predicts_at = True

    def predict(
        self,
        p: dict[str, float],
        effects: tuple[str, ...],
        d: Prepared,
        at: np.ndarray | None = None,
    ) -> np.ndarray:
        """Measured force predicted for the measured displacement ``d.u`` (at the sample
        indices ``at`` only, when given: the Masing element still runs over the whole
        history, the terms sample by sample only where asked — the same values).

        A force channel with a declared measurement filter (``d.extra["output_filter"]``:
        the taps of a zero-phase smoothing, e.g. a force reconstructed from a frame's
        equation of motion, :attr:`contactlab.tangential.FrameForce.force_filter`) is
        predicted through that same filter, whatever the effects: the model's force is
        smoothed as the measurement was, so no candidate can win by imitating the
        smoothing (the record's ends, where the filter is not defined, are weighted out by
        :func:`contactlab.diagnose.diagnose`)."""
        taps = d.extra.get("output_filter")
        if taps is None:
            return self._force(p, effects, d, at)
        F = np.convolve(self._force(p, effects, d), taps, mode="same")
        return F if at is None else F[at]

    def _force(
        self,
        p: dict[str, float],
        effects: tuple[str, ...],
        d: Prepared,
        at: np.ndarray | None = None,
    ) -> np.ndarray:
        """The joint's force at the sensor, before any declared measurement filter: the
        effects composed in the order of their stage
        (:data:`~contactlab.diagnose.effects.TANGENTIAL_STAGES`), each by its own
        :meth:`~contactlab.diagnose.effects.EffectModel.apply`."""
        if "channel_delay" in effects and "raw_input" in d.extra and p["tau"] != 0.0:
            # a kept record (workflow.subsample_long): the model at the shifted raw positions
            rest = tuple(e for e in effects if e != "channel_delay")
            return self._force(p, rest, delayed(d, p["tau"]), at)
        chain = ordered("tangential", effects)
        staged = lambda name: [e for e in chain if e.stage == name]  # noqa: E731
        ctx = ForceContext(d, effects, d.u, d.u, None, at=at, rows=at)
        for e in staged("input"):
            ctx.x = e.apply(ctx.x, p, ctx)
        x = ctx.x
        ctx.x0 = p["x0"] if x is not d.u else None
        self._merge(ctx)
        if ctx.sp is None:  # the element turns where the denoised input turns
            clipped = turn_clipped_input(d)
            if clipped is not d.u:
                ctx.xm = clipped if ctx.xm is d.u else ctx.xm + (clipped - d.u)
        reshaped = staged("element_input")
        for e in reshaped:
            ctx.xm = e.apply(ctx.xm, p, ctx)
        for e in staged("core"):
            ctx.core = e.apply(ctx.core, p, ctx)
        elements = staged("element")
        if elements:
            h = elements[0].apply(ctx.core, p, ctx)
        elif ctx.core is not None:
            h = ctx.core.force(ctx.xm)
        elif reshaped:  # (the kept unit forces are of the displacement itself)
            h = Masing(p["h0"], p["ac"]).force(ctx.xm)
        else:
            token = 0 if ctx.sp is None else ctx.sp.token
            h = _masing_force(d, p["h0"], p["ac"], ctx.x0, ctx.xm, token)
        ctx.scratch["element"] = h
        for e in staged("element_force"):
            h = e.apply(h, p, ctx)
        # from here on sample by sample: with ``at``, only at the samples asked for — or, with
        # a delay (which interpolates between samples), at the samples around each shift
        if at is not None:
            for e in chain:
                need = getattr(e, "rows_needed", None)
                if need is not None:
                    ctx.rows = need(d, at, p)
        branch = staged("branch")
        if branch:
            h = branch[0].apply(h, p, ctx)
        else:
            h = ctx.pick(h) if ctx.sp is None else h[ctx.sp.rows]
        for e in staged("factor"):
            h = e.apply(h, p, ctx)
        F = h
        for e in staged("additive"):
            F = e.apply(F, p, ctx)
        for e in staged("output"):
            F = e.apply(F, p, ctx)
        return F if F.flags.writeable else F.copy()

    @staticmethod
    def _merge(ctx: ForceContext) -> None:
        """The displacement the element runs over (``ctx.xm``) and the span (``ctx.sp``).

        A record kept every q-th sample (workflow.subsample_long): the element and the terms
        up to the breakaway run over the kept samples with the turning points between them
        merged in, which gives the full-rate values at the kept samples; with ``at``, over
        the samples asked for and the turning points only (the span)."""
        d, x, x0 = ctx.d, ctx.x, ctx.x0
        kn: Knots | None = d.extra.get("knots")
        sp = None if kn is None else span(d, kn, ctx.at)
        ctx.sp = sp
        if kn is None or sp is None:
            ctx.xm = x
            return
        merged = memo(d, "merged")  # merged once per displacement (x0) and kept
        xm = merged.get(x0)
        if xm is None:
            xm = merged[x0] = kn.merge(x, x0 or 0.0)
        if sp.index is not None:  # the span of it a fit's samples need, kept likewise
            parts = memo(d, "merged_span")
            key = (x0, sp.token)
            part = parts.get(key)
            if part is None:
                part = parts[key] = xm[sp.index]
            xm = part
        ctx.xm = xm

    #: :meth:`derived` takes the model's effects and the data (keywords ``effects``, ``d``)
    derived_from_data = True

    def model_breakaway(self, p: dict[str, float], effects: tuple[str, ...], d: Prepared) -> float:
        """The breakaway force of the fitted model as the sticks of the data measure it: the
        mean over the strokes between reversals of the largest force within ``20/ac + 3 ell``
        of the reversal (plus ``2 h0 C_s (1 + s_b)`` with a series spring, whose stretch the
        swing needs too: without it a friction damper's breakaway read 1.0 kN for h0 = 17
        kN), about the model's own zero (the force offset and drift taken off).

        This is the quantity :func:`contactlab.tangential.regime.stick_slip` reads off the
        measured sticks (the largest ``|F - offset|`` while stuck and up to the onset of
        sliding). It is read off the whole model, not off the breakaway term alone: on the
        measured frame the friction along the track (``position_friction``) is 18 % lower
        at the stroke's ends, where the breakaway happens, than its mean ``h0``; a full
        branch of the term alone from ``-h0`` (:func:`breakaway_force`) put the breakaway
        1.2x too high there.
        """
        F = self.predict(p, effects, d)
        if "force_offset" in effects:
            F = F - p["F0"]
        if "force_drift" in effects:
            F = F - p["F1"] * (d.t - d.t[0]) / d.duration
        rev = d.cycles.reversals
        # the peak lies within a few slip distances (ell) of the reversal, once the branch
        # has covered its swing (20/ac: to within 2e^-10): beyond, the term has decayed
        reach = 20.0 / p["ac"] + (3.0 * p["ell"] if "stick_slip" in effects else 0.0)
        if "series_compliance" in effects:  # a series spring stretches the swing by 2 h0 C_s
            reach += 2.0 * p["h0"] * p["C_s"] * (1.0 + p.get("s_b", 0.0))
        peaks = []
        for a, b in itertools.pairwise(rev):
            s = 1.0 if d.u[b] > d.u[a] else -1.0
            near = s * (d.u[a:b] - d.u[a]) <= reach
            if np.any(near):
                peaks.append(float(np.max(s * F[a:b][near])))
        return float(np.mean(peaks)) if peaks else np.nan

    def derived(
        self,
        p: dict[str, float],
        se: dict[str, float],
        effect: str,
        *,
        effects: tuple[str, ...] | None = None,
        d: Prepared | None = None,
    ) -> tuple[dict[str, float], dict[str, float]]:
        """Extra reported quantities of an effect (with delta-method standard errors), from
        the effect's own :meth:`~contactlab.diagnose.effects.EffectModel.derived`.

        ``stick_slip``'s ``breakaway_force``: with the model's ``effects`` and the data
        ``d``, :meth:`model_breakaway` (comparable with ``analyze``'s breakaway force of the
        sticks); without them, the peak of a full branch of the breakaway term
        (:func:`breakaway_force`), which ignores the other effects.
        """
        more = {} if effects is None or d is None else {"effects": effects, "d": d, "family": self}
        return EFFECTS[effect].derived(p, se, **more)

    def base_model(self, p: dict[str, float], context: dict[str, float]) -> Any:
        return Masing(p["h0"], p["ac"])

    def slope(self, p: dict[str, float], d: Prepared) -> np.ndarray:
        """Local slope ``|dF/dx|`` where the input noise turns into force error: the larger of
        the base Masing element's slope along the (filtered) displacement and the measured
        path's (``|dF/dt| / |dx/dt|``, Savitzky-Golay derivatives), within ``[0, h0·ac]`` —
        the steepest slope of the exponential element, at a reversal. The measured path is
        what marks a sticking phase (the force changes while the displacement does not),
        which a steep element crosses in a fraction of a micrometre."""
        kn: Knots | None = d.extra.get("knots")
        h = Masing(p["h0"], p["ac"]).force(d.u if kn is None else kn.merge(d.u))
        h = h if kn is None else h[kn.grid]
        kmax = p["h0"] * p["ac"]
        w = min(d.window, d.y.size - (1 - d.y.size % 2))
        yd = savgol_filter(d.y, w, 3, deriv=1, mode="interp")
        ud = savgol_filter(d.u, w, 3, deriv=1, mode="interp")
        with np.errstate(divide="ignore", invalid="ignore"):
            km = np.abs(np.gradient(h) / np.gradient(d.u))
            kd = np.abs(yd / ud)
        k = np.fmax(np.where(np.isfinite(km), km, kmax), np.where(np.isfinite(kd), kd, kmax))
        return np.clip(k, 0.0, kmax)

    def implausible(self, name: str, p: dict[str, float], d: Prepared) -> str | None:
        """Why a fitted effect cannot be physical on this rig, or None (the effect's own
        :meth:`~contactlab.diagnose.effects.EffectModel.plausible`)."""
        ok, why = EFFECTS[name].plausible(d, p)
        return None if ok else why

    def identified(
        self, name: str, p: dict[str, float], se: dict[str, float], d: Prepared | None = None
    ) -> str | None:
        """Why a fitted effect's size is not identified (within its error of "absent"), or
        None; with the record ``d``, an effect whose own signature in the data stands out
        of the noise apart from the fit's error (its ``identified_apart(d, p)``: a mass's
        plateau tilt on one drive frequency) is identified."""
        why = EFFECTS[name].identified(p, se)
        apart = getattr(EFFECTS[name], "identified_apart", None)
        if why and d is not None and apart is not None and apart(d, p):
            return None
        return why

    def plausibility(self, name: str, p: dict[str, float], d: Prepared) -> tuple[bool, str]:
        """The effect's plausibility verdict and its argument in numbers."""
        return tuple(EFFECTS[name].plausible(d, p))  # type: ignore[return-value]

    def regime(self, p: dict[str, float], d: Prepared) -> str:
        """Pre-sliding, transition or gross sliding, from ``ac·A`` of the base fit."""
        amp = 0.5 * float(np.ptp(d.u))
        q = p["ac"] * amp
        if q < 1.0:
            kind = "pre-sliding (ac·A < 1: only h0·ac, the initial stiffness, is well fixed)"
        elif q < GROSS_SLIDING_ZA:
            kind = "transition from pre-sliding to sliding (h0 and ac both fixed)"
        else:
            kind = (
                "gross sliding (ac·A > 10: near-rectangular loops; h0 is the plateau force, "
                "ac only bounded from below)"
            )
        return f"base model regime: {kind}; h0 = {p['h0']:.4g} N, ac·A = {q:.3g}"

    @staticmethod
    def loop_energy(u: np.ndarray, y: np.ndarray) -> float:
        """Energy dissipated around one cycle, ``∮ F dx``."""
        return loop_area(u, y)

    @staticmethod
    def loop_energies(u: np.ndarray, y: np.ndarray, bounds: list[int]) -> np.ndarray:
        """:meth:`loop_energy` of each run ``bounds[k]:bounds[k+1]`` of at least 3 samples
        (NaN below) in one call (``u``, ``y``: contiguous float64, finite)."""
        return _core.loop_areas(u, y, bounds)
