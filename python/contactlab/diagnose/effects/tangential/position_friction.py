"""``position_friction``: friction varying along the track."""

from __future__ import annotations

import numpy as np

from ..._family import ParamSpec
from .._base import EffectModel, Plausibility, register

#: wavelengths :meth:`PositionFriction.start` tries, as multiples of the stroke's half-width
#: (the long waves; :func:`start_wavelengths` adds the short ones the record resolves)
START_WAVELENGTHS = np.geomspace(0.6, 8.0, 28)
#: the short waves' grid (:func:`start_wavelengths`): uniform in the wavenumber, a step that
#: turns the wave's phase over the whole stroke (two half-widths) by at most π/START_PHASE_STEP
#: (a geometric grid of 10 % steps turned a wave of 0.17 half-widths by 7 rad over the
#: stroke between two of its points, and missed it: rig, L = 40 µm at A = 240 µm, tuning seed
#: 49400000 of ``benches/eval_posfric.py``); down to the shortest wave that keeps
#: SHORT_WAVE_SAMPLES samples per wave at mid-stroke (where the speed is π/2 of its mean)
#: and SHORT_WAVE_NOISE input-noise standard deviations per wave, and no shorter than
#: SHORTEST_WAVE half-widths
START_PHASE_STEP, SHORT_WAVE_SAMPLES, SHORT_WAVE_NOISE, SHORTEST_WAVE = 4.0, 5.0, 10.0, 0.05
#: whether :func:`start_wavelengths` adds the short waves (a bench sets it off for a
#: before/after on one tree)
SHORT_WAVES = True
#: the wavelength the stated power is given at, in half-widths of the stroke (a wave between
#: one and two of them: the track's features that a stroke shows as a wave)
POWER_WAVELENGTH = 1.5
#: a wave longer than this many half-widths of the stroke is a level or a gradient of the
#: friction over the stroke (h0, parameter drift, asymmetry), not a feature of the track
LONGEST_WAVE = 12.0


def start_wavelengths(d, half: float) -> np.ndarray:
    """The wavelengths (m) :meth:`PositionFriction.start` tries on the record ``d`` whose
    stroke's half-width is ``half``: :data:`START_WAVELENGTHS` half-widths, and the shorter
    waves the record resolves on a grid uniform in the wavenumber (see
    :data:`START_PHASE_STEP`)."""
    longs = START_WAVELENGTHS * half
    if not SHORT_WAVES:
        return longs
    per = float(getattr(d.cycles, "period_samples", np.nan) or np.nan)
    sig = float(d.extra.get("u_noise", 0.0) or 0.0)
    shortest = SHORTEST_WAVE * half
    if np.isfinite(per) and per > 0:
        # a branch covers 2 half-widths in per/2 samples, π/2 faster than that at mid-stroke
        shortest = max(shortest, SHORT_WAVE_SAMPLES * np.pi * half / per)
    shortest = min(max(shortest, SHORT_WAVE_NOISE * sig), START_WAVELENGTHS[0] * half)
    # the wavenumber's step that turns the phase over the stroke by π/START_PHASE_STEP, from
    # the longest wave of the grid to the shortest resolved (beside the geometric grid,
    # which steps by more than that below 2.5 half-widths)
    dk = np.pi / START_PHASE_STEP / (2.0 * half)
    k = np.arange(2.0 * np.pi / longs[-1], 2.0 * np.pi / shortest * (1 + 1e-9), dk)
    return np.r_[longs, 2.0 * np.pi / k]


def track_phase(x: np.ndarray, d, wavelength: float) -> np.ndarray:
    """``2π (x - x_mid) / L``: the phase of the track's wave at the positions ``x``."""
    return (2.0 * np.pi / max(wavelength, 1e-300)) * (x - d.extra["x_mid"])


#: the amplitudes of the friction's wave along the track (in phase and in quadrature with
#: the stroke's middle)
TRACK_TERMS = ("a1", "b1")


#: the share of the search's ``min_gain`` its held-out gain must reach, and the share of the
#: input-noise budget it must beat (:func:`contactlab.diagnose.search.own_gain_floor`,
#: ``search._noise_floor``): on 36 clean records of both generators (tuning seeds 1000-1035
#: of ``benches/eval_clean_gains.py --open``, every floor off) its largest held-out gain was
#: 0.050 σ² at t <= 2.05 (at most 0.10 of the budget on records with a budget above 0.1 σ²)
GAIN_FLOOR_SCALE = 0.2
INPUT_NOISE_SHARE = 0.25


@register
class PositionFriction(EffectModel):
    """Friction varying along the track: ``h0(x) = h0 (1 + a1 cos φ + b1 sin φ)``, ``φ = 2π
    (x - x_mid)/L`` (docs/effects.md §1: one wave of free length ``L``; ``x_mid`` the middle
    of the stroke).

    The same bumps at the same ``x`` on both branches, every cycle; locked to position (not
    to time or to the cycle's phase). The wavelength is fitted: a track feature is a wave of
    its own length, not a harmonic of the stroke.
    """

    name = "position_friction"
    kind = "tangential"
    params = (
        ParamSpec("a1", "-", 0.0, -0.3, 0.3, "one"),
        ParamSpec("b1", "-", 0.0, -0.3, 0.3, "one"),
        ParamSpec("L", "m", np.nan, 0.0, np.inf, "x"),
    )
    description = (
        "friction varying along the track (wavy plateaus): F = h (1 + a1 cos φ + b1 sin φ), "
        "φ = 2π (x - x_mid)/L, a wave of length L along the track"
    )
    physics = (
        "The friction coefficient varies along the track (waviness, wear scar, debris): the "
        "plateaus bend with position, the same on every stroke, up and down alike as a "
        "function of x: h0(x) = h0 (1 + a1 cos 2π(x - x_mid)/L + b1 sin 2π(x - x_mid)/L). "
        "A normal load fluctuating at the drive's harmonics depends on time (the same along "
        "up and down strokes only for even harmonics in phase)."
    )
    acts_through = "friction along the branch"
    stage = "factor"
    rank = 1
    order = 12
    size_param = "a1"
    #: per-effect floors (see GAIN_FLOOR_SCALE, INPUT_NOISE_SHARE above)
    gain_floor_scale = GAIN_FLOOR_SCALE
    input_noise_share = INPUT_NOISE_SHARE
    #: a function of the measured position, it cannot filter the input: of the input's
    #: noise it can take only the bias the noise leaves locked to the cycle, which the
    #: record's own simulation measures (``search.locked_noise_budget``)
    input_noise_locked = True
    #: the stated bound's widening (:func:`contactlab.diagnose.power.power_margin`): hidden
    #: at the linearised bound, a wave was named 6 times in 8 last stop
    #: (``benches/eval_slow_power.py``, seeds 20777000-7) and 6 in 6 on rig tuning seeds
    #: 73000-73005 of ``benches/eval_bound_power.py``: 12 in 14, short of 95 %
    power_margin = 1.2

    def size(self, p, se):
        """The wave's amplitude ``√(a1² + b1²)``, with its delta-method error."""
        v = float(np.hypot(p.get("a1", 0.0), p.get("b1", 0.0)))
        if v == 0:
            return 0.0, float(np.inf)
        e2 = sum((p.get(n, 0.0) / v * se.get(n, np.inf)) ** 2 for n in TRACK_TERMS)
        return v, float(np.sqrt(e2))

    def power_shape(self, d, p):
        """The wavelength the stated power is given at: :data:`POWER_WAVELENGTH` half-widths
        of the stroke (a wave of the track's own length, between one and two strokes' worth
        of the half-widths :meth:`start` searches), not the parameter's generic starting
        value (a hundredth of the stroke)."""
        half = float(d.extra.get("x_half", 0.5 * float(np.ptp(d.u))))
        return {"L": POWER_WAVELENGTH * half} if half > 0 else {}

    def start(self, p, d, residual, family=None):
        """The wavelength whose wave, on the current model's force (``d.y - residual``),
        explains most of the residual, with its least-squares amplitudes (the term is linear
        in them at a given ``L``).

        The wavelengths of :func:`start_wavelengths` are judged across cycles: the wave's
        amplitudes fitted on the even cycles must lower the residual of the odd ones and
        the other way round (a track's wave repeats at the same x every cycle); the one
        whose held-out gain is largest is taken. Where none gains held out, or the record
        has fewer than two cycles, the wavelength of :data:`START_WAVELENGTHS` half-widths
        that explains most of the residual in-sample (the start before the short waves).
        Judged in-sample, the short waves' grid took a measured record's start to a wave
        that fitted the held-out cycles worse (the friction damper ``damper_12`` of
        ``benches/eval_measured_diagnose.py``: the wave's held-out gain fell from 0.155 to
        0.083 σ², and a mass of 271 kg was named in its place)."""
        half = float(d.extra.get("x_half", 0.5 * float(np.ptp(d.u))))
        best: dict[str, float] = {"L": 2.0 * half if half > 0 else 1.0}
        model = d.y - residual
        if not (half > 0 and np.all(np.isfinite(model))):
            return best
        cyc = getattr(d.cycles, "cycle", None)
        folds = None
        if SHORT_WAVES and cyc is not None and np.shape(cyc) == np.shape(residual):
            cyc = np.asarray(cyc)
            even, odd = (cyc >= 0) & (cyc % 2 == 0), (cyc >= 0) & (cyc % 2 == 1)
            if np.count_nonzero(even) >= 8 and np.count_nonzero(odd) >= 8:
                folds = (even, odd)
        top, top_cv, pick = 0.0, 0.0, None
        for wl in start_wavelengths(d, half) if folds is not None else START_WAVELENGTHS * half:
            ph = track_phase(d.u, d, wl)
            cols = np.column_stack((model * np.cos(ph), model * np.sin(ph)))
            coef, *_ = np.linalg.lstsq(cols, residual, rcond=None)
            gain = float(residual @ (cols @ coef))
            entry = {"L": float(wl), "a1": float(np.clip(coef[0], -0.25, 0.25)),
                     "b1": float(np.clip(coef[1], -0.25, 0.25))}  # fmt: skip
            if gain > top and wl >= START_WAVELENGTHS[0] * half * (1 - 1e-9):
                top, best = gain, entry
            if folds is None:
                continue
            cv = 0.0
            for fit, test in (folds, folds[::-1]):
                c, *_ = np.linalg.lstsq(cols[fit], residual[fit], rcond=None)
                r = residual[test]
                e = r - cols[test] @ c
                cv += float(r @ r - e @ e)
            if cv > top_cv:
                top_cv, pick = cv, entry
        return pick if pick is not None else best

    def signature_parts(self, d, p, effects, family):
        """The residual of the model ``(p, effects)`` without the wave (its amplitudes at 0,
        the rest as fitted) and the wave's direction at the fitted length (columns ``a1``,
        ``b1``), or None: what the closing checks test for the wave's own signature beyond
        any virgin curve (``workflow.signature_beyond_virgin``) before withdrawing it as an
        absorber of a virgin curve of another shape.

        At one amplitude a Masing loop is point-symmetric and every point-symmetric change
        of its branches is a change of the virgin curve; a wave's part even about the
        stroke's middle is one (a free-form virgin curve explained 1.2-1.3 times the held-out
        gain of rig waves at twice the ideal size, 2 kHz, 7.1-10.7 Hz, 35-50 cycles: each
        named, then withdrawn, ``benches/eval_ideal_bound.py`` tuning seeds 52200100-1).
        Its odd part no virgin curve draws; a virgin curve of another shape (a tanh) is
        point-symmetric and leaves none."""
        if not all(k in p for k in (*TRACK_TERMS, "L", "ac")):
            return None
        p0 = {**p, "a1": 0.0, "b1": 0.0}
        base = np.asarray(family.predict(p0, effects, d), float)
        cols = []
        for k in TRACK_TERMS:
            up = {**p0, k: 1e-3}
            cols.append((np.asarray(family.predict(up, effects, d), float) - base) / 1e-3)
        return d.y - base, np.column_stack(cols)

    def apply(self, h, p, ctx):
        d = ctx.d
        x = ctx.pick(ctx.x)
        ph = track_phase(x, d, p["L"])
        return h * (1.0 + p["a1"] * np.cos(ph) + p["b1"] * np.sin(ph))

    def plausible(self, d, p):
        base = super().plausible(d, p)
        if not base.ok:
            return base
        half = float(d.extra.get("x_half", np.nan))
        if np.isfinite(half) and half > 0 and p["L"] > LONGEST_WAVE * half:
            return Plausibility(
                False,
                f"a wave of {p['L']:.3g} m is {p['L'] / (2 * half):.1f} strokes long: a level "
                "or gradient of the friction over the stroke, not a feature of the track",
            )
        return base

    def argument(self, d, p):
        amp = float(np.hypot(p.get("a1", 0.0), p.get("b1", 0.0)))
        return (
            f"the friction varies by ±{100 * amp:.0f} % along the track in a wave of "
            f"{p['L']:.3g} m, the same on every stroke (a function of position, not of time)"
        )
