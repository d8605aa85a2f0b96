"""Tangential contact: the Masing base model and its library of candidate extensions.

Base model (PHYSICS.md §1): Masing hysteresis with the exponential virgin curve
``f(u) = h0 (1 - exp(-ac u))`` and branch scale 2, force ``h = M(x)`` for the measured
displacement history ``x``. Candidate effects, each with its own fitted parameters:

=======================  ===========================================================  =========
name                     measured force ``F`` (or measured ``x``)                     params
=======================  ===========================================================  =========
``viscous_damping``      ``F = h + c ẋ``                                              c [N s/m]
``inertia``              ``F = h + m ẍ`` (mass between sensor and contact)            m [kg]
``parallel_stiffness``   ``F = h + k_p x`` (rig flexures in parallel)                 k_p [N/m]
``series_compliance``    ``x = x_c + C_s h`` (rig compliance in series)               C_s [m/N]
``force_offset``         ``F = h + F0`` (sensor bias)                                 F0 [N]
``force_drift``          ``F = h + F1 (t - t0)/T`` (load-cell zero drifting)          F1 [N]
``displacement_offset``  ``h = M(x - x0)`` (displacement sensor zero off the origin)  x0 [m]
``channel_delay``        ``F(t) = h(t - τ)`` (force channel lags displacement)        tau [s]
``asymmetry``            ``F = h + α |h|``: saturation ``h0(1 ± α)`` per direction    alpha [-]
``non_masing_scaling``   branch scale ``λ`` instead of 2, loops kept closed           lam [-]
``parameter_drift``      ``h0(t) = h0 (1 + β t/T)``, i.e. ``F = h (1 + β t/T)``       beta [-]
=======================  ===========================================================  =========

Notes on exactness. The exponential Masing force is linear in ``h0`` at fixed ``ac`` along a
history, so the drift factor is exact. A linear spring in series with a Masing element is
again a Masing element whose virgin curve is ``x(u) = u + C_s f(u)`` against ``f(u)`` (the
branch rule ``x - x_r = λ g⁻¹((F - F_r)/λ)`` holds for the sum because both parts obey it),
so the series compliance is solved exactly by reparametrising the virgin curve and using
:meth:`contactlab.Masing.from_backbone`. The branch scale uses
:mod:`contactlab.diagnose.scaled_masing` (λ-scaled branch shape anchored at both ends),
because ``Masing(..., scale=λ)`` jumps where the memory rules end a branch and so cannot
be fitted to noisy data. ``ẋ`` and ``ẍ`` are Savitzky-Golay derivatives of the
measured displacement; the delay is a fractional-sample shift by linear interpolation.
Beyond the issue's list, ``force_drift`` and ``displacement_offset`` cover two common sensor
faults that no other candidate can stand in for. When several effects are active they
compose in this order: displacement offset on the input; series compliance and branch
scale inside the Masing element; asymmetry and drift on its force; the additive terms
(parallel stiffness, viscous, inertia, offset, force drift); the delay on the total
measured force.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from typing import Any

import numpy as np

from .. import _core
from ..errors import InputError
from ..masing import Masing, loop_area
from ._family import Candidate, ParamSpec, Prepared, implausible_common
from ._filters import savgol_coeffs, savgol_filter
from ._kept import delayed, span
from ._signal import Knots, minimize_bounded, modulation_gains, shift
from .scaled_masing import memory, scaled_force

_INF = np.inf

# Physical ranges of the real-friction effects (a fit at their edge is refused as
# implausible): static over kinetic friction of dry metal pairs is at most about 2 (a full
# branch peaks near h0 (1 + 2 s_b) when the slip distance is long against 1/ac: s_b <= 0.5);
# Stribeck's low-speed excess within -0.5..1 of the sliding force; friction along a track
# varies by tens of per cent, not by its own size (each Fourier coefficient within ±0.3);
# the friction force of the two directions differs by less than a factor 3 (|alpha| <= 0.5).
CANDIDATES: dict[str, Candidate] = {
    c.name: c
    for c in (
        Candidate(
            "viscous_damping",
            (ParamSpec("c", "N s/m", 0.0, 0.0, _INF, "c"),),
            "viscous force c·ẋ in parallel with the contact",
        ),
        Candidate(
            "inertia",
            (ParamSpec("m", "kg", 0.0, 0.0, _INF, "m"),),
            "inertial force m·ẍ of the mass between force sensor and contact",
        ),
        Candidate(
            "parallel_stiffness",
            (ParamSpec("k_p", "N/m", 0.0, 0.0, _INF, "k"),),
            "linear spring k_p·x in parallel (rig flexures, guides)",
        ),
        Candidate(
            "series_compliance",
            (ParamSpec("C_s", "m/N", 0.0, 0.0, _INF, "C"),),
            "measured displacement includes rig compliance C_s·F",
        ),
        Candidate(
            "force_offset",
            (ParamSpec("F0", "N", 0.0, -_INF, _INF, "F"),),
            "constant force-sensor bias F0",
        ),
        Candidate(
            "force_drift",
            (ParamSpec("F1", "N", 0.0, -_INF, _INF, "F"),),
            "force-sensor zero drifting linearly, by F1 over the recording",
        ),
        Candidate(
            "displacement_offset",
            (ParamSpec("x0", "m", 0.0, -_INF, _INF, "x"),),
            "displacement-sensor zero: the contact sees x - x0",
        ),
        Candidate(
            "channel_delay",
            (ParamSpec("tau", "s", 0.0, -_INF, _INF, "tau"),),
            "force channel lags the displacement channel by tau",
        ),
        Candidate(
            "asymmetry",
            (ParamSpec("alpha", "-", 0.0, -0.5, 0.5, "one"),),
            "saturation force h0(1+alpha) in the positive, h0(1-alpha) in the negative direction",
        ),
        Candidate(
            "non_masing_scaling",
            (ParamSpec("lam", "-", 2.0, 0.2, 20.0, "one"),),
            "branch scale lam instead of Masing's 2 (generalised Masing rule)",
        ),
        Candidate(
            "parameter_drift",
            (ParamSpec("beta", "-", 0.0, -0.95, 5.0, "one"),),
            "saturation force drifting over the recording: h0(t) = h0 (1 + beta t/T)",
        ),
        Candidate(
            "stribeck",
            (
                ParamSpec("s", "-", 0.0, -0.5, 1.0, "one"),
                ParamSpec("v_s", "m/s", np.nan, 0.0, _INF, "v"),
            ),
            "velocity-dependent friction: F = h (1 + s exp(-|ẋ|/v_s)) (Stribeck, s > 0: "
            "friction weakening with sliding speed)",
        ),
        Candidate(
            "position_friction",
            tuple(ParamSpec(n, "-", 0.0, -0.3, 0.3, "one") for n in ("a1", "b1", "a2", "b2")),
            "friction varying along the track (wavy plateaus): F = h (1 + Σ a_k cos(kπ ξ) + "
            "b_k sin(kπ ξ)), ξ the position scaled to -1..1 over the stroke, k = 1, 2",
        ),
        Candidate(
            "stick_slip",
            (
                ParamSpec("s_b", "-", 0.0, 0.0, 0.5, "one"),
                ParamSpec("ell", "m", np.nan, 0.0, _INF, "x"),
            ),
            "breakaway after each reversal: the branch rises s_b above Masing's and falls back "
            "over a slip distance ell (static friction above kinetic)",
        ),
        Candidate(
            "normal_load",
            (
                ParamSpec("eps_c", "-", 0.0, -0.5, 0.5, "one"),
                ParamSpec("eps_s", "-", 0.0, -0.5, 0.5, "one"),
                ParamSpec("f_n", "Hz", np.nan, 0.0, _INF, "fq"),
            ),
            "normal load fluctuating at its own frequency f_n: F = h (1 + eps_c cos 2π f_n t "
            "+ eps_s sin 2π f_n t)",
        ),
    )
}

BASE_PARAMS = (
    ParamSpec("h0", "N", _INF, 0.0, _INF, "F"),
    ParamSpec("ac", "1/m", _INF, 0.0, _INF, "ac"),
)

_SERIES_POINTS = 400
#: a normal-load fluctuation must make this many periods in the record; slower, it is a drift
MIN_LOAD_PERIODS = 2.0


def series_backbone(h0: float, ac: float, C_s: float, x_max: float) -> tuple[np.ndarray, ...]:
    """Virgin curve of a Masing element in series with compliance ``C_s``, as points.

    ``x(u) = u + C_s f(u)`` against ``f(u)``, ``u`` from 0 to ``3 x_max`` on a grid that is
    dense where the curve bends.
    """
    s = np.linspace(0.0, 1.0, _SERIES_POINTS)
    u = 3.0 * x_max * s * s
    f = h0 * -np.expm1(-ac * u)
    return u + C_s * f, f


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


def _grid(x: np.ndarray, F: np.ndarray) -> tuple[float, float, float]:
    """Best ``(rss, h0, ac)`` over ``ac·max|x|`` from pre-sliding to gross sliding."""
    xmax = float(np.max(np.abs(x)))
    best = (np.inf, 1.0, 1.0)
    for q in np.geomspace(0.2, 5000.0, 23):
        ac = q / xmax
        g = Masing(1.0, ac).force(x)
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


def _sg_dot(window: int, deriv: int, dt: float) -> np.ndarray:
    """Cubic Savitzky-Golay weights of the ``deriv``-th derivative, dot orientation (as
    :func:`contactlab.tangential.frame.savgol_coefficients`, in numpy)."""
    return savgol_coeffs(window, 3, deriv, dt)[::-1]


def _fixed(d: Prepared, key: str, make: Callable[[], Any]) -> Any:
    """An array of the model evaluation that depends on the recording only (not on the
    fitted parameters): computed on the first evaluation, then reused by every fit on ``d``
    (the fits evaluate the model thousands of times)."""
    cache = d.extra.setdefault("fixed", {})
    k = (key, d.t.size)
    if k not in cache:
        cache[k] = make()
    return cache[k]


#: entries of the small per-recording memos below (index sets, load-fluctuation terms)
_MEMO_KEEP = 64


def _memo(d: Prepared, name: str) -> dict[Any, Any]:
    cache = d.extra.setdefault(name, {})
    if len(cache) >= _MEMO_KEEP:
        cache.clear()
    return cache


def _delay_support(d: Prepared, at: np.ndarray, tau: float) -> np.ndarray:
    """The samples a delayed prediction at the samples ``at`` needs: for each shifted time
    ``t[at] - tau`` the two samples that bracket it as :func:`numpy.interp` finds them
    (``t[j] <= t < t[j+1]``, the first or last sample off the ends); ``at`` itself when
    ``tau`` is 0. Kept per ``(tau, at)``: a fit's Jacobian steps every other parameter at
    the same delay."""
    if tau == 0.0:
        return at
    memo = _memo(d, "delay_rows")
    key = (tau, id(at))
    hit = memo.get(key)
    if hit is not None and hit[0] is at:  # (the array is held: its id is not reused)
        return hit[1]
    n = d.t.size
    j = np.searchsorted(d.t, d.t[at] - tau, side="right") - 1
    need = np.zeros(n, bool)
    need[np.clip(j, 0, n - 1)] = True
    need[np.clip(j + 1, 0, n - 1)] = True
    rows = np.flatnonzero(need)
    memo[key] = (at, rows)
    return rows


def _load_terms(d: Prepared, f_n: float, rows: np.ndarray | None) -> tuple[np.ndarray, ...]:
    """``cos 2π f_n t``, ``sin 2π f_n t`` of ``normal_load`` (``t`` from the record's start) at
    the samples ``rows`` (all when None), kept per ``(f_n, rows)``: only a step of ``f_n``
    changes them."""
    memo = _memo(d, "load_terms")
    key = (f_n, None if rows is None else id(rows))
    hit = memo.get(key)
    if hit is not None and hit[0] is rows:
        return hit[1], hit[2]
    t_rel = _fixed(d, "t_rel", lambda: d.t - d.t[0])
    ph = 2.0 * np.pi * f_n * (t_rel if rows is None else t_rel[rows])
    out = (np.cos(ph), np.sin(ph))
    memo[key] = (rows, *out)
    return out


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


def _track_harmonics(x: np.ndarray, d: Prepared) -> tuple[np.ndarray, ...]:
    """``cos ξ, sin ξ, cos 2ξ, sin 2ξ`` of ``position_friction``, ``ξ = π (x - x_mid)/x_half``."""
    xi = np.pi * (x - d.extra["x_mid"]) / d.extra["x_half"]
    return np.cos(xi), np.sin(xi), np.cos(2 * xi), np.sin(2 * xi)


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
        """Fix the base first when it is in the wrong regime: in gross sliding (``ac·A`` of
        the base fit at least :data:`GROSS_SLIDING_ZA`) the plateau measures ``h0``
        directly and ``ac`` is only bounded from below
        (:func:`contactlab.tangential.regime.plateau`, on the measured displacement, as
        ``analyze`` reads it). When the base's ``h0`` lies more than
        :data:`ANCHOR_SIGMAS` combined standard errors from the plateau (the least-squares
        fit trades ``h0`` against what the Masing element cannot follow: the sticks, the
        friction varying along the track), ``h0`` is held within
        :data:`ANCHOR_BAND` plateau errors of it and ``ac`` above the bound from then on
        (the base and every candidate), so no effect is credited with moving ``h0`` back;
        the band stays with the family (a refit of the final model keeps it). Returns a
        sentence saying so, or None (nothing changed)."""
        from ..tangential.preprocess import average_loop
        from ..tangential.regime import plateau, velocity

        amp = 0.5 * float(np.ptp(d.u))
        if self.h0_band is not None or p["ac"] * amp < GROSS_SLIDING_ZA:
            return None
        x = d.extra.get("u_raw", d.u)
        try:
            loop = average_loop(x, d.y, d.t)
            v, thr, _ = velocity(d.t, x)
            pl = plateau(loop, x, d.y, v, thr)
        except (InputError, ValueError):  # no loop to average: no plateau to anchor to
            return None
        if pl is None or not (np.isfinite(pl.h0_stderr) and pl.h0_stderr > 0):
            return None
        err = float(np.hypot(se["h0"] if np.isfinite(se["h0"]) else 0.0, pl.h0_stderr))
        off = abs(p["h0"] - pl.h0) / err
        if off <= ANCHOR_SIGMAS:
            return None
        band = ANCHOR_BAND * pl.h0_stderr
        self.h0_band = (pl.h0 - band, pl.h0 + band)
        self.ac_floor = min(pl.ac_lower_bound, p["ac"])
        return (
            f"base re-anchored to the plateau: in gross sliding h0 is the plateau force "
            f"{pl.h0:.4g} ± {pl.h0_stderr:.2g} N, but the least-squares base put it at "
            f"{p['h0']:.4g} N ({off:.1f} σ away); h0 is held within ±{band:.2g} N of the "
            f"plateau and ac ≥ {self.ac_floor:.3g} 1/m (only a lower bound is identified)"
        )

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
        ``position_friction``; kept when given by a fitted model's context."""
        if "x_mid" not in d.extra:
            lo, hi = float(np.min(d.u)), float(np.max(d.u))
            d.extra["x_mid"], d.extra["x_half"] = 0.5 * (lo + hi), 0.5 * (hi - lo) or 1.0

    def context(self, d: Prepared) -> dict[str, float]:
        """The stroke scaling of ``position_friction`` (the rest are parameters)."""
        return {"x_mid": d.extra["x_mid"], "x_half": d.extra["x_half"]}

    def start_effect(
        self, name: str, p: dict[str, float], d: Prepared, residual: np.ndarray
    ) -> dict[str, float]:
        """Starting values of an effect's nonlinear parameters from the current residual.

        ``normal_load``: the frequency whose ``h cos, h sin`` pair explains most of the
        residual (measured minus model), scanned from 0.05 excitation frequencies (at least
        two periods in the record) to 3, at a quarter of the record's frequency resolution;
        ``stick_slip``: a slip distance of ``1/ac``; ``stribeck``: ``v_s`` of the RMS speed.
        """
        if name == "stick_slip":
            return {"ell": 1.0 / p["ac"]}
        if name == "stribeck":
            return {"v_s": float(np.sqrt(np.mean(d.ud**2)))}
        if name != "normal_load":
            return {}
        h = self.predict(p, (), d)
        f_exc = 1.0 / (d.cycles.period_samples * d.dt)
        f_lo = max(0.05 * f_exc, MIN_LOAD_PERIODS / d.duration)
        step = 0.25 / d.duration
        freqs = np.arange(f_lo, 3.0 * f_exc, step)
        # a fluctuation locked to the drive is position_friction's: skip the harmonics
        k = np.round(freqs / f_exc)
        freqs = freqs[(k < 1) | (np.abs(freqs - k * f_exc) >= 1.0 / d.duration)]
        if not freqs.size:
            return {"f_n": f_exc}
        # the least-squares gain of the pair (h cos, h sin) at every frequency, by FFT
        j = np.rint((freqs - f_lo) / step).astype(int)
        gains = modulation_gains(h, residual, d.duration, f_lo, step, int(j[-1]) + 1)[j]
        return {"f_n": float(freqs[int(np.argmax(gains))])}

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
            CANDIDATES["normal_load"].params[0].lower,
            CANDIDATES["normal_load"].params[0].upper,
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
        """All tangential effects combine (in the order of the module docstring)."""
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
            if _grid(d.u, -d.y)[0] < 0.5 * var:
                raise InputError(
                    f"the loop runs the wrong way: ∮F dx = {loop_area(d.u, d.y):.3g} J over the "
                    "recording, but a passive joint dissipates (∮F dx > 0); the force channel "
                    "is recorded with the opposite sign — negate F"
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
        """The joint's force at the sensor, before any declared measurement filter."""
        if "channel_delay" in effects and "raw_input" in d.extra and p["tau"] != 0.0:
            # a kept record (workflow.subsample_long): the model at the shifted raw positions
            rest = tuple(e for e in effects if e != "channel_delay")
            return self._force(p, rest, delayed(d, p["tau"]), at)
        x = d.u
        if "displacement_offset" in effects:
            x = x - p["x0"]
        # a record kept every q-th sample (workflow.subsample_long): the element and the
        # terms up to the breakaway run over the kept samples with the turning points
        # between them merged in (xm), which gives the full-rate values at the kept samples;
        # with ``at``, over the samples asked for and the turning points only (``sp``)
        kn: Knots | None = d.extra.get("knots")
        x0 = p["x0"] if x is not d.u else None
        sp = None if kn is None else span(d, kn, at)
        if kn is None or sp is None:
            xm = x
        else:  # merged once per displacement (x0) and kept: the fits step x0 rarely
            memo = _memo(d, "merged")
            xm = memo.get(x0)
            if xm is None:
                xm = memo[x0] = kn.merge(x, x0 or 0.0)
            if sp.index is not None:  # the span of it a fit's samples need, kept likewise:
                # gathered for every evaluation before (11 000 of 30 000 samples of a
                # 1e6-sample record), though a kept unit force mostly makes it unneeded
                memo = _memo(d, "merged_span")
                key = (x0, sp.token)
                part = memo.get(key)
                if part is None:
                    part = memo[key] = xm[sp.index]
                xm = part
        if "series_compliance" in effects:
            xmax = float(np.max(np.abs(xm))) or 1.0
            bx, bf = series_backbone(p["h0"], p["ac"], max(p["C_s"], 0.0), xmax)
            core = Masing.from_backbone(bx, bf)
        elif "non_masing_scaling" in effects:
            core = Masing(p["h0"], p["ac"])
        if "non_masing_scaling" in effects:
            # the reversal bookkeeping depends on x (through x0 too: the start at the origin
            # and the mirrored targets on the virgin curve), so a cached one is reused only
            # for the very same displacement (issue 13)
            mem = d.extra.get("memory")
            if mem is None or not np.array_equal(mem.x, xm):
                mem = d.extra["memory"] = memory(xm)
            h = scaled_force(core.virgin, p["lam"], mem)
        elif "series_compliance" in effects:
            h = core.force(xm)
        else:
            h = _masing_force(d, p["h0"], p["ac"], x0, xm, 0 if sp is None else sp.token)
        if "asymmetry" in effects:
            h = h + p["alpha"] * np.abs(h)
        if "parameter_drift" in effects:
            t_rel = _fixed(d, "t_rel", lambda: d.t - d.t[0]) if sp is None else sp.t - d.t[0]
            h = h * (1.0 + p["beta"] * t_rel / d.duration)
        # from here on sample by sample: with ``at``, only at the samples asked for — or, with
        # a delay (which interpolates between samples), at the two around each shifted time
        delay = "channel_delay" in effects
        rows = _delay_support(d, at, p["tau"]) if at is not None and delay else at
        pick: Callable[[np.ndarray], np.ndarray] = (
            (lambda a: a) if rows is None else (lambda a: a[rows])
        )
        if "stick_slip" in effects:
            if sp is None:
                rev = d.cycles.reversals
                anchors = _fixed(d, "anchors", lambda: reversal_anchors(rev, x.size))
                h = breakaway(h, x, rev, p["s_b"], p["ell"], anchors, rows)
            else:
                if sp.anchors is None:
                    sp.anchors = reversal_anchors(sp.reversals, sp.size)
                h = breakaway(h, xm, sp.reversals, p["s_b"], p["ell"], sp.anchors, sp.rows)
        else:
            h = pick(h) if sp is None else h[sp.rows]
        if "stribeck" in effects:
            speed = pick(_fixed(d, "speed", lambda: np.abs(d.ud)))
            h = h * (1.0 + p["s"] * np.exp(-speed / max(p["v_s"], 1e-300)))
        if "position_friction" in effects:
            # the harmonics along the track are fixed unless x itself moves (x0)
            c1, s1, c2, s2 = (
                _track_harmonics(pick(x), d)
                if "displacement_offset" in effects
                else map(pick, _fixed(d, "track", lambda: _track_harmonics(x, d)))
            )
            h = h * (1.0 + p["a1"] * c1 + p["b1"] * s1 + p["a2"] * c2 + p["b2"] * s2)
        if "normal_load" in effects:
            cos, sin = _load_terms(d, p["f_n"], rows)
            h = h * (1.0 + p["eps_c"] * cos + p["eps_s"] * sin)
        F = h
        if "parallel_stiffness" in effects:
            F = F + p["k_p"] * pick(x)  # (picked where needed: a gather per evaluation)
        if "viscous_damping" in effects:
            F = F + p["c"] * pick(d.ud)
        if "inertia" in effects:
            F = F + p["m"] * pick(d.udd)
        if "force_offset" in effects:
            F = F + p["F0"]
        if "force_drift" in effects:
            F = F + p["F1"] * pick(_fixed(d, "t_rel", lambda: d.t - d.t[0])) / d.duration
        if delay:
            if at is None:
                F = shift(F, d.t, p["tau"])
            elif p["tau"] != 0.0:  # (tau = 0: rows is at, F is there already)
                # F is known at ``rows`` only, which hold both neighbours of every shifted
                # time: np.interp brackets each by the same two samples as on the full grid
                F = np.interp(d.t[at] - p["tau"], d.t[rows], F)
        return F if F.flags.writeable else F.copy()

    #: :meth:`derived` takes the model's effects and the data (keywords ``effects``, ``d``)
    derived_from_data = True

    def model_breakaway(self, p: dict[str, float], effects: tuple[str, ...], d: Prepared) -> float:
        """The breakaway force of the fitted model as the sticks of the data measure it: the
        mean over the strokes between reversals of the largest force within ``20/ac + 3 ell``
        of the reversal, about the model's own zero (the force offset and drift taken off).

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
        """Extra reported quantities of an effect (with delta-method standard errors).

        ``stick_slip``'s ``breakaway_force``: with the model's ``effects`` and the data
        ``d``, :meth:`model_breakaway` (comparable with ``analyze``'s breakaway force of the
        sticks); without them, the peak of a full branch of the breakaway term
        (:func:`breakaway_force`), which ignores the other effects.
        """
        if effect == "stick_slip" and effects is not None and d is not None:
            val = self.model_breakaway(p, effects, d)
            var = 0.0
            for k, s in se.items():
                if not (np.isfinite(s) and s > 0):
                    continue
                step = 1e-3 * s
                q = dict(p)
                q[k] += step
                var += ((self.model_breakaway(q, effects, d) - val) / step * s) ** 2
            return {"breakaway_force": val}, {"breakaway_force": float(np.sqrt(var))}
        if effect == "series_compliance" and p["C_s"] > 0:
            return {"k_s": 1.0 / p["C_s"]}, {"k_s": se["C_s"] / p["C_s"] ** 2}
        if effect == "asymmetry":
            h0, a = p["h0"], p["alpha"]
            s = float(np.hypot(se["h0"] * (1 + a), h0 * se["alpha"]))
            s2 = float(np.hypot(se["h0"] * (1 - a), h0 * se["alpha"]))
            return {"h0_plus": h0 * (1 + a), "h0_minus": h0 * (1 - a)}, {
                "h0_plus": s,
                "h0_minus": s2,
            }
        if effect == "stick_slip":
            keys = ("h0", "ac", "s_b", "ell")
            val = breakaway_force(*(p[k] for k in keys))
            var = 0.0
            for i, k in enumerate(keys):
                step = 1e-4 * abs(p[k]) or 1e-12
                q = [p[j] for j in keys]
                q[i] += step
                var += ((breakaway_force(*q) - val) / step * se.get(k, np.inf)) ** 2
            return {"breakaway_force": val}, {"breakaway_force": float(np.sqrt(var))}
        if effect == "parameter_drift":
            h0, b = p["h0"], p["beta"]
            return {"h0_end": h0 * (1 + b)}, {
                "h0_end": float(np.hypot(se["h0"] * (1 + b), h0 * se["beta"]))
            }
        return {}, {}

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
        """Why a fitted effect cannot be physical on this rig, or None."""
        why = implausible_common(self.candidates[name], p, d)
        if why:
            return why
        if name == "non_masing_scaling" and not 0.5 <= p["lam"] <= 8.0:
            return f"branch scale lam = {p['lam']:.3g} is outside 0.5..8 (no known joint)"
        if name == "normal_load":
            if p["f_n"] < MIN_LOAD_PERIODS / d.duration:
                return (
                    f"a load fluctuation of {p['f_n']:.3g} Hz makes fewer than "
                    f"{MIN_LOAD_PERIODS:g} periods in the record: a drift (parameter_drift)"
                )
            f_exc = 1.0 / (d.cycles.period_samples * d.dt)
            k = round(p["f_n"] / f_exc)
            if k >= 1 and abs(p["f_n"] - k * f_exc) < 1.0 / d.duration:
                return (
                    f"a load fluctuation at {p['f_n']:.4g} Hz, harmonic {k} of the excitation, "
                    "cannot be told from friction that varies along the track "
                    "(position_friction)"
                )
        if name == "displacement_offset":
            amp = 0.5 * float(np.ptp(d.u))
            if abs(p["x0"]) > 0.5 * amp:
                return f"a displacement offset of {p['x0']:.3g} m is over half the amplitude"
        if name == "asymmetry" and p["ac"] * 0.5 * float(np.ptp(d.u)) >= GROSS_SLIDING_ZA:
            # on a near-rectangular loop h + α|h| moves both plateaus by α h0, as an offset
            # does: only the short turns differ, so the two cannot be told apart; the offset
            # (a sensor's zero, the reconstruction's K (y - x)) is the one tried
            return (
                f"in gross sliding (ac·A ≥ {GROSS_SLIDING_ZA:g}) an asymmetry shifts both "
                f"plateaus alike (α h0 = {p['alpha'] * p['h0']:.3g} N), as a force offset "
                "does: the two cannot be told apart, and force_offset stands for both"
            )
        return None

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
