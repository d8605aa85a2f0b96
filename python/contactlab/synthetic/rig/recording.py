"""The rig's recording: the effects it knows, and the whole chain from the command to the
stored samples (:func:`rig_recording`).

Part of the rig simulator :mod:`contactlab.synthetic.rig`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from contactlab.errors import InputError

from .chain import _design_chain, _measure
from .normal import _normal
from .shaker import shaker_parameters
from .tangential import _tangential

__all__ = ["NEW_EFFECTS", "NORMAL_EFFECTS", "TANGENTIAL_EFFECTS", "RigRecording", "rig_recording"]

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
NORMAL_EFFECTS = (
    "stiffness_nonlinearity",
    "hysteretic_damping",
    "creep_drift",
    "channel_delay",
    "asymmetric_branches",
)
#: Candidates ``docs/effects.md`` reserves for real joints (tangential), plus a virgin curve
#: of another shape (``tanh_virgin``) that no candidate names.
NEW_EFFECTS = ("power_law_microslip", "backlash", "rate_dependent_presliding", "tanh_virgin")

# Each effect's parameters (docs/effects.md names), with the value used when not given.
_DEFAULTS: dict[str, dict[str, float]] = {
    "viscous_damping": {"c": 0.0},
    "inertia": {"m": 0.0},
    "parallel_stiffness": {"k_p": 0.0},
    "series_compliance": {"k_s": math.inf},
    "force_offset": {"F0": 0.0},
    "force_drift": {"rate": 0.0},
    "displacement_offset": {"x0": 0.0},
    "channel_delay": {"tau": 0.0},
    "asymmetry": {"a": 0.0},
    "non_masing_scaling": {"lam": 2.0},
    "parameter_drift": {"beta": 0.0},
    "stribeck": {"s": 0.0, "v_s": math.nan},
    "position_friction": {"eps": 0.0, "L": math.nan, "phi": 0.0},
    "stick_slip": {"b": 0.0, "d_c": math.nan},
    "normal_load": {"eps": 0.0, "f_n": math.nan, "phi": 0.0},
    "power_law_microslip": {"chi": -0.5, "beta": 0.0},
    "backlash": {"b": 0.0},
    "rate_dependent_presliding": {"sigma1": 0.0, "fs_over_fc": 1.0, "v_s": math.nan},
    "tanh_virgin": {},
    "stiffness_nonlinearity": {"a2": 0.0, "a3": 0.0},
    "hysteretic_damping": {"eta": 0.0},
    "creep_drift": {"D": 0.0, "tau_c": math.nan},
    "asymmetric_branches": {"a": 0.0},
}


@dataclass
class RigRecording:
    """A simulated recording with its truth.

    Attributes
    ----------
    kind : str
        "tangential" (channels ``x`` m, ``F`` N) or "normal" (``p`` Pa, ``delta`` m).
    t : ndarray
        Sample times (s).
    channels : dict
        The measured channels.
    truth : dict
        Effects with their parameters (docs/effects.md units), the base model, the chain.
    """

    kind: str
    t: np.ndarray
    channels: dict[str, np.ndarray]
    truth: dict[str, Any] = field(default_factory=dict)

    def __getattr__(self, name: str) -> np.ndarray:
        ch = self.__dict__.get("channels", {})
        if name in ch:
            return ch[name]
        raise AttributeError(name)

    def to_csv(self, path: str | Path) -> Path:
        """Write ``t`` and the channels as a CSV (SI units, one header line)."""
        path = Path(path)
        names = list(self.channels)
        cols = np.column_stack([self.t] + [self.channels[k] for k in names])
        np.savetxt(
            path, cols, delimiter=",", header=",".join(["t", *names]), comments="", fmt="%.10g"
        )
        return path


def _effect_params(effects: Mapping[str, Mapping[str, float]] | Sequence[str], allowed: tuple):
    if not isinstance(effects, Mapping):
        effects = {name: {} for name in effects}
    out: dict[str, dict[str, float]] = {}
    for name, params in effects.items():
        if name not in allowed:
            raise InputError(
                f"rig_recording: unknown effect {name!r} for this kind; known: {', '.join(allowed)}"
            )
        base = dict(_DEFAULTS[name])
        for k, v in dict(params or {}).items():
            if k not in base:
                raise InputError(
                    f"rig_recording: effect {name!r} has no parameter {k!r} "
                    f"(parameters: {', '.join(base) or 'none'})"
                )
            if not np.isfinite(float(v)) and not (k == "k_s" and v == math.inf):
                raise InputError(f"rig_recording: {name}.{k} must be finite, got {v}")
            base[k] = float(v)
        out[name] = base
    return out


def _check_positive(**kw: float) -> None:
    for k, v in kw.items():
        if not (np.isfinite(v) and v > 0):
            raise InputError(f"rig_recording: {k} must be a finite number > 0, got {v}")


def rig_recording(
    effects: Mapping[str, Mapping[str, float]] | Sequence[str] = (),
    kind: str = "tangential",
    *,
    seed: int = 0,
    fs: float = 2000.0,
    f: float = 5.0,
    cycles: int = 10,
    acA: float = 2.0,
    h0: float = 40.0,
    ac: float = 4.0e4,
    k: float = 1.3e12,
    psi: float = 0.0887,
    p0: float = 0.5e6,
    pa: float = 0.4e6,
    frequencies: Sequence[float] = (1.0,),
    x_noise: float = 0.01,
    F_noise: float = 0.01,
    x_drift: float = 0.0,
    ramp_cycles: float = 1.0,
    actuator_f: float | None = None,
    actuator_zeta: float = 0.7,
    cell_fn: float | None = None,
    cell_zeta: float = 0.05,
    aa_ratio: float = 0.4,
    aa_tolerance: float = 0.01,
    bits: int | None = 16,
    oversample: int | None = None,
    x_lowpass: float | None = None,
    F_highpass: float | None = None,
    aa_kind: str = "butterworth",
    hum: float = 0.0,
    jitter: float = 0.0,
    drive_harmonics: Sequence[float] = (),
    shaker: Mapping[str, float] | None = None,
) -> RigRecording:
    """Simulate a recording of the whole measurement chain with the given effects.

    Parameters
    ----------
    effects : mapping or sequence of str
        ``{name: {parameter: value}}`` with names and parameters of ``docs/effects.md``
        (SI units); missing parameters take defaults (see ``_DEFAULTS``). Tangential also takes
        ``NEW_EFFECTS``. A sequence of names uses the defaults (mostly "no effect").
    kind : {"tangential", "normal"}
        Which joint.
    seed : int
        Seed of the independent random streams (noise of each channel, filter tolerances).
    fs : float
        Sampling rate (Hz).
    f : float
        Drive frequency (Hz); for ``normal`` the reference of ``frequencies``.
    cycles : int
        Cycles of the drive (per frequency block for ``normal``).
    acA : float
        Tangential: ac·A, the regime (A = acA/ac is the displacement amplitude).
    h0, ac : float
        Tangential virgin curve: saturation force (N) and curvature (1/m).
    k, psi, p0, pa : float
        Normal Kelvin-Voigt joint: stiffness (Pa/m), loss coefficient ψ (c = ψk/(2π·2πf)),
        static and dynamic pressure (Pa).
    frequencies : sequence of float
        Normal: frequencies of successive tone blocks relative to ``f``.
    x_noise : float
        Displacement-sensor noise RMS as a fraction of the displacement amplitude (``max |x|`` or
        ``max |δ|``), after the anti-alias filter.
    F_noise : float
        Force (pressure) channel noise RMS as a fraction of the force amplitude (``max |F|``,
        or pa).
    x_drift : float
        Drift of the displacement sensor over the record, fraction of the amplitude.
    ramp_cycles : float
        Length of the raised-cosine start-up of the command (cycles); 0 starts the sine
        abruptly (still from rest: the actuator smooths it).
    actuator_f, actuator_zeta : float
        Position servo: natural frequency (Hz; default 15 f) and damping.
    cell_fn, cell_zeta : float
        Load cell: natural frequency (Hz; default max(2.5 fs, 50 f)) and damping.
    aa_ratio, aa_tolerance : float
        Anti-alias corners = aa_ratio·fs·(1 + tolerance·N(0,1)), independently per channel.
    bits : int or None
        ADC resolution (None: no quantisation).
    oversample : int, optional
        Internal grid rate / fs (default: enough for the load cell, ≥ 8).
    x_lowpass : float, optional
        Corner (Hz) of the displacement sensor's own second-order Butterworth low-pass (an
        LVDT's demodulator), before its noise and the anti-alias filter; None: none.
    F_highpass : float, optional
        Tangential: corner (Hz) of a first-order high-pass on the force (a piezoelectric load
        cell's charge leaking away, from zero charge at rest); None: a strain-gauge cell.
    aa_kind : {"butterworth", "bessel"}
        The anti-alias filters' type (4th order, −3 dB at the corner).
    hum : float
        Mains hum (50 Hz) on both channels, amplitude as a fraction of each channel's
        amplitude, each with its own phase.
    jitter : float
        RMS jitter (s) of the sampling clock, common to both channels.
    drive_harmonics : sequence of float
        Tangential: the command's 2nd, 3rd, ... harmonics as fractions of its fundamental
        (an actuator's distortion), in phase with it.
    shaker : mapping, optional
        Tangential: drive ``x`` by an electrodynamic shaker in place of the position servo
        (:mod:`contactlab.synthetic.rig.shaker`): an armature of ``mass`` (kg, default 0.2)
        on a suspension of natural frequency ``fn`` (Hz, default 20) and damping ratio
        ``zeta`` (default 0.05), pushed by the sine force ``F0·sin ωt`` (after the
        ``ramp_cycles`` start-up; 0 switches it on at t = 0 from rest), the contact's force
        acting back on it, ``F0`` found so the steady amplitude is ``A``; ``x`` then
        carries the suspension's start-up transient and odd harmonics of the drive. The
        truth's ``base["shaker"]`` holds the figures and ``F0``. None: the servo.

    Returns
    -------
    RigRecording
        ``t``, ``channels`` and ``truth``.
    """
    _check_arguments(
        kind, cycles, f, fs, x_noise, F_noise, h0=h0, ac=ac, acA=acA, k=k, psi=psi, pa=pa
    )
    sensors = _check_sensors(x_lowpass, F_highpass, aa_kind, hum, jitter, drive_harmonics)
    allowed = TANGENTIAL_EFFECTS + NEW_EFFECTS if kind == "tangential" else NORMAL_EFFECTS
    eff = _effect_params(effects, allowed)
    shaker_fig = shaker_parameters(shaker)
    if shaker_fig is not None and kind != "tangential":
        raise InputError("rig_recording: a shaker drives the tangential rig only")

    ss = np.random.SeedSequence(int(seed))
    rngs = [np.random.default_rng(s) for s in ss.spawn(4)]
    cell_fn = float(cell_fn) if cell_fn is not None else max(2.5 * fs, 50 * f)
    if oversample is None:
        oversample = int(max(8, math.ceil(6 * cell_fn / fs)))
    fsi = fs * oversample
    dt = 1.0 / fsi
    ti, t = _grids(kind, fs, f, cycles, frequencies, oversample, dt)
    chain, truth = _design_chain(
        kind, eff, rngs, fs, oversample, dt, cell_fn, cell_zeta, aa_ratio, aa_tolerance, bits,
        sensors,
    )  # fmt: skip
    truth["chain"]["ramp_cycles"] = ramp_cycles

    if kind == "tangential":
        actuator = (actuator_f or 15 * f, actuator_zeta)
        out_ch, in_ch, meta = _tangential(
            ti, eff, f, h0, ac, acA, ramp_cycles, *actuator, chain.cell, dt,
            tuple(sensors["drive_harmonics"]), shaker_fig,
        )  # fmt: skip
    else:
        out_ch, in_ch, meta = _normal(
            ti, eff, f, k, psi, p0, pa, frequencies, cycles, ramp_cycles, chain.cell, dt
        )
    truth["base"] = meta
    channels = _measure(chain, eff, ti, t, out_ch, in_ch, meta, truth, x_noise, F_noise, x_drift)
    return RigRecording(kind, t, channels, truth)


def _check_sensors(
    x_lowpass: float | None,
    F_highpass: float | None,
    aa_kind: str,
    hum: float,
    jitter: float,
    drive_harmonics: Sequence[float],
) -> dict[str, Any]:
    """The optional sensor figures of :func:`rig_recording`, checked."""
    for name, v in (("x_lowpass", x_lowpass), ("F_highpass", F_highpass)):
        if v is not None and not (np.isfinite(v) and v > 0):
            raise InputError(f"rig_recording: {name} must be None or a finite number > 0, got {v}")
    if aa_kind not in ("butterworth", "bessel"):
        raise InputError(
            f"rig_recording: aa_kind must be 'butterworth' or 'bessel', got {aa_kind!r}"
        )
    for name, v in (("hum", hum), ("jitter", jitter)):
        if not (np.isfinite(v) and v >= 0):
            raise InputError(f"rig_recording: {name} must be >= 0, got {v}")
    harm = [float(h) for h in drive_harmonics]
    if any(not np.isfinite(h) for h in harm):
        raise InputError(f"rig_recording: drive_harmonics must be finite, got {harm}")
    return {"x_lowpass": x_lowpass, "F_highpass": F_highpass, "aa_kind": aa_kind, "hum": hum,
            "jitter": jitter, "drive_harmonics": harm}  # fmt: skip


def _check_arguments(
    kind: str, cycles: int, f: float, fs: float, x_noise: float, F_noise: float, **positive: float
) -> None:
    """Refuse a kind, a count, a rate or a noise level :func:`rig_recording` cannot use."""
    if kind not in ("tangential", "normal"):
        raise InputError(f"rig_recording: kind must be 'tangential' or 'normal', got {kind!r}")
    _check_positive(fs=fs, f=f, **positive)
    if not (isinstance(cycles, (int, np.integer)) and cycles >= 1):
        raise InputError(f"rig_recording: cycles must be an integer >= 1, got {cycles}")
    if f > fs / 8:
        raise InputError(f"rig_recording: f = {f} Hz needs fs >= 8 f (fs = {fs} Hz)")
    for name, v in (("x_noise", x_noise), ("F_noise", F_noise)):
        if not (np.isfinite(v) and v >= 0):
            raise InputError(f"rig_recording: {name} must be >= 0, got {v}")


def _grids(
    kind: str,
    fs: float,
    f: float,
    cycles: int,
    frequencies: Sequence[float],
    oversample: int,
    dt: float,
) -> tuple[np.ndarray, np.ndarray]:
    """The internal grid ``ti`` (step ``dt``) and the sample times ``t`` (every
    ``oversample``-th point) of the whole drive."""
    if kind == "tangential":
        duration = cycles / f
    else:
        if not frequencies or any(not (r > 0) for r in frequencies):
            raise InputError("rig_recording: frequencies must be positive ratios")
        duration = sum(cycles / (f * r) for r in frequencies)
    n = round(duration * fs) + 1
    ti = np.arange((n - 1) * oversample + 1) * dt
    t = ti[::oversample].copy()
    return ti, t
