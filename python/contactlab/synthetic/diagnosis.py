"""Recordings with hidden effects: the experiment behind the discrepancy workflow's tests.

:func:`hidden_effect_recording` simulates a test-rig recording of a contact joint with zero,
one or several effects of the candidate library switched on, adds sensor noise, and returns
the recording together with the truth (which the workflow is never shown). Users can run
the same experiment on their own rig parameters to see what the workflow can and cannot
tell apart at their noise level.

Excitation. A sine whose amplitude and frequency step smoothly through three blocks
(amplitudes ``(0.6, 1.5, 3.0) / ac``, frequencies ``(1, 1.7, 0.6) · f0`` for the tangential
joint), as on a rig tested at several amplitudes and rates. Several rates are needed to tell
rate-dependent effects (viscous damping, inertia) from rate-independent ones, and several
amplitudes to separate the virgin-curve parameters. Transitions use a cubic smooth-step, so
the displacement is twice differentiable and known in closed form at any time.

Magnitude. The size of an effect is the RMS change of the measured output it causes (all
else equal, before any fit), relative to the RMS of the output. The physical parameter is
solved for that size; its sign is drawn from the seed where both signs are physical.

Every effect is simulated by its own route where one exists: the delay by evaluating the
excitation at ``t - τ`` in closed form, viscous and inertial forces from the exact
derivatives of the excitation, series compliance by adding ``F/k_s`` to the contact
displacement, so agreement with the workflow's models is a real check.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence

import numpy as np
from scipy.optimize import brentq

from ..diagnose.candidates_tangential import breakaway
from ..diagnose.effects.tangential.non_masing_scaling import turning_point_force, turning_points
from ..errors import InputError
from ..masing import Masing
from ._common import (
    HiddenEffectRecording,
    block_excitation,
    block_frequencies,
    effect_sizes,
    measure,
    rms,
    start_index,
)
from .diagnosis_normal import hidden_effect_recording_normal

TANGENTIAL_EFFECTS = (
    "viscous_damping",
    "inertia",
    "parallel_stiffness",
    "series_compliance",
    "force_offset",
    "force_drift",
    "displacement_offset",
    "channel_delay",
    "asymmetry",
    "non_masing_scaling",
    "parameter_drift",
    "stribeck",
    "position_friction",
    "stick_slip",
    "normal_load",
)

#: fixed shapes of the real-friction effects (the size parameter is solved for): Stribeck
#: speed as a fraction of the RMS sliding speed, slip distance of the breakaway in units of
#: 1/ac, the wave of friction along the track (one wave over the stroke, phase), and the
#: normal-load fluctuation's frequency (in units of the fastest block's, no harmonic of
#: any block's drive) and phase
STRIBECK_SPEED = 0.5
BREAKAWAY_DISTANCE = 1.0
TRACK_WAVES, TRACK_PHASE = 1.0, 0.7
LOAD_FREQUENCY, LOAD_PHASE = 0.23, 0.3


def _derivs(fun: Callable[[np.ndarray], np.ndarray], t: np.ndarray, T: float):
    h = 1e-4 * T
    d1 = (fun(t + h) - fun(t - h)) / (2 * h)
    d2 = (fun(t + h) - 2 * fun(t) + fun(t - h)) / (h * h)
    return d1, d2


def _tangential_force(
    effects: Mapping[str, float],
    t: np.ndarray,
    xfun: Callable[[np.ndarray], np.ndarray],
    h0: float,
    ac: float,
    period: float,
    t_start: float | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Noise-free measured ``(x, F)`` with the given effect parameters (by effect name).
    ``t_start``: where the record will begin (a steady start cuts the start-up off); the
    force drift is zero there, as the candidate's is at the record's first sample (anchored
    at ``t[0]`` of the uncut axis, a steady record began with an offset F1·t_cut/T that the
    truth did not list)."""
    tau = effects.get("channel_delay", 0.0)
    xc = xfun(t - tau)  # the contact moves as x(t - τ) when the force channel lags by τ
    if "non_masing_scaling" in effects:
        # from rest at the actual turning points of the contact's motion (docs/effects.md)
        turns = turning_points(xc, 1e-9 * float(np.ptp(xc)))
        lam = effects["non_masing_scaling"]
        h = turning_point_force(Masing(h0, ac).virgin, lam, xc, turns)
    else:
        h = Masing(h0, ac).force(xc)
    if "asymmetry" in effects:
        h = h + effects["asymmetry"] * np.abs(h)
    if "parameter_drift" in effects:
        # h0(t) = h0 (1 + β (t - t_m)/T) over the record kept (docs/effects.md: h0 the
        # mid-record value), t_m its middle and T its length
        t0 = t[0] if t_start is None else t_start
        h = h * (1.0 + effects["parameter_drift"] * ((t - t0) / (t[-1] - t0) - 0.5))
    v, a = _derivs(xfun, t - tau, period)
    if "stick_slip" in effects:
        # reversals of the contact's own motion (sign changes of its exact velocity)
        rev = np.flatnonzero(np.diff(np.sign(v)) != 0)
        rev = rev[np.abs(xc[rev]) > 0.05 * np.max(np.abs(xc))]
        h = breakaway(h, xc, rev, effects["stick_slip"], BREAKAWAY_DISTANCE / ac)
    if "stribeck" in effects:
        vs = STRIBECK_SPEED * rms(v)
        h = h * (1.0 + effects["stribeck"] * np.exp(-((v / vs) ** 2)))  # docs/effects.md
    if "position_friction" in effects:
        xi = xc / np.max(np.abs(xc))
        h = h * (
            1.0 + effects["position_friction"] * np.sin(TRACK_WAVES * 2 * np.pi * xi + TRACK_PHASE)
        )
    if "normal_load" in effects:
        ph = 2 * np.pi * LOAD_FREQUENCY / period * (t - t[0]) + LOAD_PHASE
        h = h * (1.0 + effects["normal_load"] * np.sin(ph))
    x_meas = xfun(t)
    if "displacement_offset" in effects:
        x_meas = x_meas + effects["displacement_offset"]
    if "series_compliance" in effects:
        x_meas = x_meas + h * effects["series_compliance"]
    F = h
    if "parallel_stiffness" in effects:
        F = F + effects["parallel_stiffness"] * xc
    if "viscous_damping" in effects:
        F = F + effects["viscous_damping"] * v
    if "inertia" in effects:
        F = F + effects["inertia"] * a
    if "force_offset" in effects:
        F = F + effects["force_offset"]
    if "force_drift" in effects:
        ts = t[0] if t_start is None else t_start
        F = F + effects["force_drift"] * (t - ts) / (t[-1] - ts)
    return x_meas, F


_PARAM_NAME = {
    "viscous_damping": "c",
    "inertia": "m",
    "parallel_stiffness": "k_p",
    "series_compliance": "C_s",
    "force_offset": "F0",
    "force_drift": "F1",
    "displacement_offset": "x0",
    "channel_delay": "tau",
    "asymmetry": "alpha",
    "non_masing_scaling": "lam",
    "parameter_drift": "beta",
    "stribeck": "s",
    "position_friction": "eps",
    "stick_slip": "s_b",
    "normal_load": "eps",
}


def hidden_effect_recording(
    effects: Iterable[str] | Mapping[str, float] = (),
    *,
    model: str = "tangential",
    magnitude: float = 0.05,
    noise: float = 0.01,
    seed: int = 0,
    cycles_per_block: int = 6,
    samples_per_cycle: int = 120,
    input_noise: float | None = None,
    anti_alias: tuple[float, float] | None = None,
    bits: int | None = None,
    start: str = "rest",
    frequencies: Sequence[float] | None = None,
    **base: float,
) -> HiddenEffectRecording:
    """Simulate a recording with hidden effects and sensor noise.

    Parameters
    ----------
    effects : iterable of str or mapping
        Effect names from the candidate library, or ``{name: magnitude}`` to give each its
        own size. Empty: the base model only (clean data).
    model : {"tangential", "normal"}
        Which joint and candidate library.
    magnitude : float
        Size of each effect: RMS change of the measured output it causes, relative to the
        output's RMS (0.05 = 5 %).
    noise : float
        Output sensor noise RMS relative to the output's RMS; the input channel gets a
        fifth of that (relative to its own RMS). White, Gaussian.
    seed : int
        Random seed (noise and the sign of effects that may have either sign).
    cycles_per_block, samples_per_cycle : int
        Excitation cycles per amplitude block (three blocks) and samples per cycle at the
        reference frequency.
    input_noise : float, optional
        Input sensor noise RMS relative to the input's amplitude (``max |x|``; 0.002 =
        0.2 %), instead of the default fifth of ``noise`` relative to its RMS.
    anti_alias : (float, float), optional
        Cut-offs of causal 4th-order Butterworth anti-alias filters on the input and output
        channels, as fractions of the Nyquist frequency; different cut-offs skew the
        channels (``truth["filter_skew"]``, s).
    bits : int, optional
        ADC resolution: each channel quantised to ``bits`` over ±1.25 × its peak.
    start : {"rest", "steady"}
        ``"rest"``: the record starts with the joint at rest on its virgin curve;
        ``"steady"``: the first 1.5 reference cycles after the amplitude ramp are cut, so
        the record starts in the middle of a loop with its history unseen.
    frequencies : sequence of float, optional
        Frequencies of the three amplitude blocks relative to ``f0`` (default
        ``(1, 1.7, 0.6)``); one value gives a single-tone record (every block at that
        frequency), on which e.g. a normal joint's channel delay and viscous lag cannot be
        told apart.
    **base
        Base-model parameters: tangential ``h0`` (N, default 50), ``ac`` (1/m, default 5e4),
        ``f0`` (Hz, default 5).

    Returns
    -------
    HiddenEffectRecording
        ``t``, ``data`` (``x``, ``F`` in SI units) and ``truth``.

    Examples
    --------
    >>> from contactlab.synthetic.diagnosis import hidden_effect_recording
    >>> rec = hidden_effect_recording(["channel_delay"], magnitude=0.05, seed=1)
    >>> sorted(rec.data), rec.truth["effects"]["channel_delay"]["tau"] > 0
    (['F', 'x'], True)
    """
    if model not in ("tangential", "normal"):
        raise InputError(f"model must be 'tangential' or 'normal', got {model!r}")
    generate = hidden_effect_recording_normal if model == "normal" else _tangential_recording
    return generate(
        effects,
        magnitude=magnitude,
        noise=noise,
        seed=seed,
        cycles_per_block=cycles_per_block,
        samples_per_cycle=samples_per_cycle,
        input_noise=input_noise,
        anti_alias=anti_alias,
        bits=bits,
        start=start,
        frequencies=frequencies,
        **base,
    )


def _tangential_recording(
    effects: Iterable[str] | Mapping[str, float],
    *,
    magnitude: float,
    noise: float,
    seed: int,
    cycles_per_block: int,
    samples_per_cycle: int,
    input_noise: float | None,
    anti_alias: tuple[float, float] | None,
    bits: int | None,
    start: str,
    frequencies: Sequence[float] | None,
    **base: float,
) -> HiddenEffectRecording:
    """:func:`hidden_effect_recording` of a tangential joint (``model="tangential"``)."""
    sizes = effect_sizes(effects, magnitude, TANGENTIAL_EFFECTS)
    h0 = float(base.pop("h0", 50.0))
    ac = float(base.pop("ac", 5e4))
    f0 = float(base.pop("f0", 5.0))
    if base:
        raise InputError(f"unknown base parameter(s) {sorted(base)} for the tangential model")
    rng = np.random.default_rng(seed)
    xfun, T, fmax = block_excitation(
        np.array([0.6, 1.5, 3.0]) / ac, block_frequencies(frequencies) * f0, cycles_per_block
    )
    fs = samples_per_cycle * f0
    t = np.arange(round(T * fs) + 1) / fs
    period = 1.0 / fmax
    keep = start_index(start, t, f0, 0.6 * f0)
    params = _effect_parameters(sizes, rng, t, xfun, h0, ac, period, keep)
    x, F = _tangential_force(params, t, xfun, h0, ac, period, float(t[keep]))
    t, x, F = t[keep:] - t[keep], x[keep:], F[keep:]
    x_noise = (
        0.2 * noise * rms(x) if input_noise is None else input_noise * float(np.max(np.abs(x)))
    )
    F_noise = noise * rms(F)
    xm, Fm, info = measure(
        t,
        x,
        F,
        rng,
        u_noise=x_noise,
        y_noise=F_noise,
        anti_alias=anti_alias,
        bits=bits,
        f_ref=f0,
    )
    truth = {
        "model": "tangential",
        "base": {"h0": h0, "ac": ac, "f0": f0},
        "effects": {n: {_PARAM_NAME[n]: v, **_fixed(n, ac, period)} for n, v in params.items()},
        "magnitudes": dict(sizes),
        "noise_rms": {"x": x_noise, "F": F_noise},
        "sensors": {"anti_alias": anti_alias, "bits": bits, "start": start, **info},
    }
    return HiddenEffectRecording(
        t,
        {"x": xm, "F": Fm},
        {"x": "m", "F": "N"},
        source="hidden_effect_recording",
        meta={"kind": "tangential"},
        truth=truth,
        model="tangential",
    )


#: Effects that may have either sign: the sign is drawn (one draw each, in this order).
_EITHER_SIGN = (
    "force_offset",
    "force_drift",
    "displacement_offset",
    "asymmetry",
    "parameter_drift",
    "non_masing_scaling",
    "position_friction",
    "normal_load",
)


def _effect_parameters(
    sizes: Mapping[str, float],
    rng: np.random.Generator,
    t: np.ndarray,
    xfun: Callable[[np.ndarray], np.ndarray],
    h0: float,
    ac: float,
    period: float,
    keep: int,
) -> dict[str, float]:
    """The physical parameter of each effect whose output change has its requested relative
    RMS (signs drawn from ``rng`` where the effect may have either)."""
    _x0, F0 = _tangential_force({}, t, xfun, h0, ac, period)
    Fr = rms(F0)

    def size(name: str, value: float) -> float:
        x1, F1 = _tangential_force({name: value}, t, xfun, h0, ac, period, float(t[keep]))
        # measured output change, on the measured displacement (what a base fit would see)
        F_on_x1 = Masing(h0, ac).force(x1)
        return rms(F1 - F_on_x1) / Fr

    params: dict[str, float] = {}
    for name, target in sizes.items():
        sign = 1.0
        if name in _EITHER_SIGN:
            sign = 1.0 if rng.random() < 0.5 else -1.0
        params[name] = _solve_size(name, target, sign, size, h0, ac, Fr, period)
    return params


def _fixed(name: str, ac: float, period: float) -> dict[str, float]:
    """The fixed shape parameters of a real-friction effect, for the truth."""
    if name == "stick_slip":
        return {"ell": BREAKAWAY_DISTANCE / ac}
    if name == "stribeck":
        return {"v_s_over_rms_speed": STRIBECK_SPEED}
    if name == "position_friction":
        return {"waves_over_stroke": TRACK_WAVES, "phase": TRACK_PHASE}
    if name == "normal_load":
        return {"f_n": LOAD_FREQUENCY / period, "phase": LOAD_PHASE}
    return {}


def _solve_size(
    name: str,
    target: float,
    sign: float,
    size: Callable[[str, float], float],
    h0: float,
    ac: float,
    Fr: float,
    period: float,
) -> float:
    """Physical parameter value whose output change has the requested relative RMS."""
    null = 2.0 if name == "non_masing_scaling" else 0.0
    hi = {
        "viscous_damping": 10.0 * Fr * period * ac,
        "inertia": 10.0 * Fr * period**2 * ac,
        "parallel_stiffness": 10.0 * h0 * ac,
        "series_compliance": 10.0 / (h0 * ac),
        "force_offset": 2.0 * Fr,
        "force_drift": 6.0 * Fr,
        "displacement_offset": 2.0 / ac,
        "channel_delay": 0.25 * period,
        "stribeck": 3.0,
        "position_friction": 0.9,
        "stick_slip": 3.0,
        "normal_load": 0.5,
        "asymmetry": 0.9,
        "non_masing_scaling": 1.5 if sign > 0 else 0.9,
        "parameter_drift": 0.9,
    }[name]

    def g(s: float) -> float:
        return size(name, null + sign * s) - target

    if g(hi) < 0:
        raise InputError(f"magnitude {target:g} is out of reach for {name}")
    s = brentq(g, 0.0, hi, xtol=1e-12 * hi, rtol=1e-6)
    return null + sign * s
