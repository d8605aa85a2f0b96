"""The rig's measurement chain: analogue filters discretised exactly for piecewise-linear
input (first-order hold), load cell, ADC range and quantisation, delayed sampling.

Part of the rig simulator :mod:`contactlab.synthetic.rig`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import interpolate, signal

__all__ = ["bessel", "butterworth", "discretise", "group_delay", "highpass", "load_cell"]


def butterworth(fc: float, order: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """Analogue Butterworth low-pass (b, a) in s, corner fc (Hz)."""
    return signal.butter(order, 2 * math.pi * fc, analog=True)


def bessel(fc: float, order: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """Analogue Bessel low-pass (b, a) in s, −3 dB at fc (Hz): the flat group delay of an
    anti-alias filter that keeps the waveform."""
    return signal.bessel(order, 2 * math.pi * fc, analog=True, norm="mag")


def highpass(fc: float) -> tuple[np.ndarray, np.ndarray]:
    """First-order high-pass s / (s + ωc), corner fc (Hz): a piezoelectric load cell's charge
    leaking through its amplifier's time constant 1/ωc."""
    return np.array([1.0, 0.0]), np.array([1.0, 2 * math.pi * fc])


def load_cell(fn: float, zeta: float) -> tuple[np.ndarray, np.ndarray]:
    """Second-order sensor ωn² / (s² + 2ζωn s + ωn²), natural frequency fn (Hz)."""
    wn = 2 * math.pi * fn
    return np.array([wn**2]), np.array([1.0, 2 * zeta * wn, wn**2])


def discretise(ba: tuple[np.ndarray, np.ndarray], dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Discrete (b, a) of an analogue filter, exact for piecewise-linear input (FOH)."""
    bd, ad, _ = signal.cont2discrete(ba, dt, method="foh")
    return np.atleast_1d(np.squeeze(bd)), np.atleast_1d(np.squeeze(ad))


def _filter(ba: tuple[np.ndarray, np.ndarray], dt: float, u: np.ndarray) -> np.ndarray:
    """Filter from rest (the chain starts at rest: zero initial state, input starting at u[0])."""
    b, a = discretise(ba, dt)
    # start in the steady state for a constant u[0] (a sensor at rest reading a constant)
    zi = signal.lfilter_zi(b, a) * u[0]
    y, _ = signal.lfilter(b, a, u, zi=zi)
    return y


def _noise_gain(ba: tuple[np.ndarray, np.ndarray], dt: float) -> float:
    """RMS gain of the discretised filter for white input (√Σh²)."""
    b, a = discretise(ba, dt)
    imp = np.zeros(20000)
    imp[0] = 1.0
    h = signal.lfilter(b, a, imp)
    return float(np.sqrt(np.sum(h**2)))


def _adc_range(peak: float) -> float:
    """Full-scale range of an ADC channel: the 1-2-5 step at or above 1.25 × peak."""
    need = 1.25 * peak
    if not need > 0:
        return 1.0
    e = math.floor(math.log10(need))
    for m in (1.0, 2.0, 5.0, 10.0):
        if m * 10**e >= need:
            return m * 10**e
    return 10.0 ** (e + 1)


def _quantise(y: np.ndarray, fsr: float, bits: int | None) -> tuple[np.ndarray, float]:
    if bits is None:
        return y, 0.0
    q = 2 * fsr / 2**bits
    return np.clip(np.round(y / q) * q, -fsr, fsr - q), q


# --------------------------------------------------------------------------------------------
# The recording
# --------------------------------------------------------------------------------------------


def group_delay(ba: tuple[np.ndarray, np.ndarray]) -> float:
    """Low-frequency group delay (s) of an analogue filter: a1/a0 − b1/b0 (coefficients in s).

    Parameters
    ----------
    ba : tuple of ndarray
        Numerator and denominator coefficients in s, highest power first.

    Returns
    -------
    float
        The group delay at zero frequency (s).
    """
    b, a = (np.asarray(c, dtype=float) for c in ba)
    a0, a1 = a[-1], (a[-2] if a.size > 1 else 0.0)
    b0, b1 = b[-1], (b[-2] if b.size > 1 else 0.0)
    return float(a1 / a0 - b1 / b0)


def _sample_at(ti: np.ndarray, y: np.ndarray, tq: np.ndarray) -> np.ndarray:
    """Cubic interpolation of the fine-grid signal (before the record: its first value)."""
    spline = interpolate.CubicSpline(ti, y)
    return np.where(tq < ti[0], y[0], spline(np.clip(tq, ti[0], ti[-1])))


def _ramp(ti: np.ndarray, f: float, ramp_cycles: float) -> np.ndarray:
    if ramp_cycles <= 0:
        return np.ones_like(ti)
    tr = ramp_cycles / f
    r = np.clip(ti / tr, 0.0, 1.0)
    return 0.5 - 0.5 * np.cos(math.pi * r)


@dataclass(frozen=True)
class _Chain:
    """The measurement chain of one recording: its filters on the internal grid, the ADC
    resolution and the noise streams of the two channels."""

    kind: str
    oversample: int
    dt: float
    aa_x: tuple[np.ndarray, np.ndarray]
    aa_F: tuple[np.ndarray, np.ndarray]
    cell: tuple[np.ndarray, np.ndarray]
    bits: int | None
    rng_x: np.random.Generator
    rng_F: np.random.Generator
    #: the displacement sensor's own low-pass (an LVDT demodulator), None: none
    x_sensor: tuple[np.ndarray, np.ndarray] | None = None
    #: the force sensor's high-pass (a piezoelectric cell's charge amplifier), None: none
    F_highpass: tuple[np.ndarray, np.ndarray] | None = None
    #: mains hum on both channels (fraction of each channel's amplitude), its frequency (Hz)
    hum: float = 0.0
    hum_f: float = 50.0
    #: RMS jitter of the sampling clock (s)
    jitter: float = 0.0


def _design_chain(
    kind: str,
    eff: dict[str, dict[str, float]],
    rngs: list[np.random.Generator],
    fs: float,
    oversample: int,
    dt: float,
    cell_fn: float,
    cell_zeta: float,
    aa_ratio: float,
    aa_tolerance: float,
    bits: int | None,
    sensors: dict[str, Any] | None = None,
) -> tuple[_Chain, dict[str, Any]]:
    """The chain with its anti-alias corners drawn (tolerances), and the truth it starts."""
    rng_x, rng_F, rng_tol, _spare = rngs
    fc_x = aa_ratio * fs * (1 + aa_tolerance * rng_tol.standard_normal())
    fc_F = aa_ratio * fs * (1 + aa_tolerance * rng_tol.standard_normal())
    sensors = dict(sensors or {})
    aa = bessel if sensors.get("aa_kind", "butterworth") == "bessel" else butterworth
    aa_x, aa_F = aa(fc_x), aa(fc_F)
    cell = load_cell(cell_fn, cell_zeta)
    x_lp = sensors.get("x_lowpass")
    x_sensor = butterworth(float(x_lp), int(sensors.get("x_lowpass_order", 2))) if x_lp else None
    f_hp = sensors.get("F_highpass")
    F_highpass = highpass(float(f_hp)) if f_hp else None
    # low-frequency group delays (s): Butterworth 4: Σ 1/(ωc·sin θk); cell: 2ζ/ωn
    gd_x = group_delay(aa_x) + (group_delay(x_sensor) if x_sensor is not None else 0.0)
    gd_F = group_delay(aa_F) + group_delay(cell)
    truth: dict[str, Any] = {
        "kind": kind,
        "effects": eff,
        "chain": {
            "fs": fs,
            "oversample": oversample,
            "aa_corner": {"x": fc_x, "F": fc_F},
            "cell_fn": cell_fn,
            "cell_zeta": cell_zeta,
            "bits": bits,
            "aa_kind": sensors.get("aa_kind", "butterworth"),
            "x_lowpass": x_lp,
            "F_highpass": f_hp,
            "hum": float(sensors.get("hum", 0.0)),
            "jitter": float(sensors.get("jitter", 0.0)),
            # the output channel behind the input at low frequency (s)
            "channel_skew": (gd_F - gd_x) if kind == "tangential" else (gd_x - gd_F),
        },
    }
    chain = _Chain(
        kind, oversample, dt, aa_x, aa_F, cell, bits, rng_x, rng_F, x_sensor, F_highpass,
        float(sensors.get("hum", 0.0)), float(sensors.get("hum_f", 50.0)),
        float(sensors.get("jitter", 0.0)),
    )  # fmt: skip
    return chain, truth


def _measure(
    chain: _Chain,
    eff: dict[str, dict[str, float]],
    ti: np.ndarray,
    t: np.ndarray,
    out_ch: np.ndarray,
    in_ch: np.ndarray,
    meta: dict[str, Any],
    truth: dict[str, Any],
    x_noise: float,
    F_noise: float,
    x_drift: float,
) -> dict[str, np.ndarray]:
    """The stored channels: sensor noise and drift, anti-alias filters, sampling (the output
    channel delayed), force offset and drift, quantisation; the chain's figures go into
    ``truth["chain"]``."""
    kind, dt, oversample, bits = chain.kind, chain.dt, chain.oversample, chain.bits
    aa_x, aa_F = chain.aa_x, chain.aa_F
    # displacement channel: x = in_ch for tangential, delta = out_ch for normal
    force, disp = out_ch, in_ch
    disp_amp = meta["displacement_amplitude"]
    force_amp = meta["force_amplitude"]
    if chain.x_sensor is not None:  # the displacement sensor's own low-pass (from rest)
        disp = _filter(chain.x_sensor, dt, disp)
    if chain.F_highpass is not None and kind == "tangential":  # a piezo cell: from zero charge
        b, a = discretise(chain.F_highpass, dt)
        force = signal.lfilter(b, a, force)
    disp = disp + x_drift * disp_amp * ti / ti[-1]
    if chain.hum > 0.0:  # mains hum, its own phase on each channel
        ph_x, ph_F = chain.rng_x.uniform(0, 2 * math.pi), chain.rng_F.uniform(0, 2 * math.pi)
        disp = disp + chain.hum * disp_amp * np.sin(2 * math.pi * chain.hum_f * ti + ph_x)
        force = force + chain.hum * force_amp * np.sin(2 * math.pi * chain.hum_f * ti + ph_F)
    g_x = _noise_gain(aa_x, dt)
    g_F = _noise_gain(aa_F, dt)
    disp = disp + chain.rng_x.standard_normal(ti.size) * (x_noise * disp_amp / g_x)
    force = force + chain.rng_F.standard_normal(ti.size) * (F_noise * force_amp / g_F)
    disp_f = _filter(aa_x, dt, disp)
    force_f = _filter(aa_F, dt, force)

    tau = 0.0
    if "channel_delay" in eff:
        tau = eff["channel_delay"]["tau"]
    # the delayed channel (F tangential, δ normal: the output) is sampled at t − τ
    disp_s = disp_f[::oversample]
    force_s = force_f[::oversample]
    if chain.jitter > 0.0:  # one clock samples both channels, each instant off by its jitter
        tj = t + chain.jitter * chain.rng_x.standard_normal(t.size)
        disp_s = _sample_at(ti, disp_f, tj)
        force_s = _sample_at(ti, force_f, tj)
        t = tj
    if tau != 0.0:
        if kind == "tangential":
            force_s = _sample_at(ti, force_f, t - tau)
        else:
            disp_s = _sample_at(ti, disp_f, t - tau)
    if kind == "tangential" and "force_offset" in eff:
        force_s = force_s + eff["force_offset"]["F0"]
    if kind == "tangential" and "force_drift" in eff:
        force_s = force_s + eff["force_drift"]["rate"] * t
    fsr_x = _adc_range(float(np.max(np.abs(disp_s))))
    fsr_F = _adc_range(float(np.max(np.abs(force_s))))
    disp_q, q_x = _quantise(disp_s, fsr_x, bits)
    force_q, q_F = _quantise(force_s, fsr_F, bits)
    truth["chain"].update(
        {
            "adc_range": {"x": fsr_x, "F": fsr_F},
            "quantum": {"x": q_x, "F": q_F},
            "noise_rms": {"x": x_noise * disp_amp, "F": F_noise * force_amp},
            "x_drift": x_drift * disp_amp,
        }
    )
    if kind == "tangential":
        channels = {"x": disp_q, "F": force_q}
    else:
        channels = {"p": force_q, "delta": disp_q}
    return channels
