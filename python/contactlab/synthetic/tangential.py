"""Synthetic tangential recordings: a Masing contact (PHYSICS.md §1) driven by a sine, seen
through imperfect sensors.

The true force is computed by the Rust Masing operator from rest (so the first quarter cycle is
the virgin curve). The "measurement" then adds what real rigs add: white noise on both
channels, a force offset (load-cell zero), a displacement offset (sensor zero), optional slow
force drift, mains hum, and ADC quantisation.
"""

from __future__ import annotations

import numpy as np

from .._arrays import positive
from ..errors import InputError
from ..io import Recording
from ..masing import Masing


def synthetic_recording(
    h0: float,
    ac: float,
    amplitude: float,
    frequency: float = 1.0,
    n_cycles: float = 10.0,
    fs: float = 1000.0,
    noise: float = 0.01,
    seed: int | None = None,
    offset: float = 0.0,
    *,
    x_noise: float | None = None,
    x_offset: float = 0.0,
    drift: float = 0.0,
    x_drift: float = 0.0,
    hum: float = 0.0,
    hum_frequency: float = 50.0,
    adc_bits: int | None = None,
    scale: float = 2.0,
    meta: dict | None = None,
) -> Recording:
    """Simulate a tangential recording ``(t, x, F)`` of a Masing contact.

    Parameters
    ----------
    h0, ac : float
        True model parameters (N, 1/m).
    amplitude : float
        Displacement amplitude A (m); ``x = x_offset + A sin(2π f t)``.
    frequency : float, default 1.0
        Excitation frequency, Hz.
    n_cycles : float, default 10
        Duration in periods.
    fs : float, default 1000
        Sampling rate, Hz.
    noise : float, default 0.01
        Force noise standard deviation as a fraction of the peak force ``f(A)``.
    seed : int, optional
        Random seed (reproducible recordings).
    offset : float, default 0
        Force offset of the load cell, N.
    x_noise : float, optional
        Displacement noise standard deviation as a fraction of ``A`` (default ``noise / 10``:
        displacement sensors are usually much cleaner than load cells).
    x_offset : float
        Zero offset of the displacement sensor, m.
    drift : float
        Linear force drift, N/s.
    x_drift : float
        Linear drift of the displacement sensor, m/s.
    hum, hum_frequency : float
        Amplitude (N) and frequency (Hz) of mains hum on the force.
    adc_bits : int, optional
        Quantise both channels to this many bits over ±1.25 × their range.
    scale : float
        Masing branch scale λ.

    Returns
    -------
    Recording
        SI channels ``x``, ``F``; ``meta["truth"]`` holds the true parameters.

    Examples
    --------
    >>> rec = synthetic_recording(h0=20.0, ac=1e5, amplitude=10e-6, n_cycles=3, seed=1)
    >>> rec.kind, len(rec), rec.meta["truth"]["h0"]
    ('tangential', 3000, 20.0)
    """
    model = Masing(h0, ac, scale)
    A = positive(amplitude, "amplitude")
    f = positive(frequency, "frequency")
    fs = positive(fs, "fs")
    n_cycles = positive(n_cycles, "n_cycles")
    if noise < 0 or (x_noise is not None and x_noise < 0):
        raise InputError("noise levels must be >= 0")
    n = round(n_cycles * fs / f)
    if n < 4:
        raise InputError(f"{n} samples is too short a recording")
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    x_true = A * np.sin(2 * np.pi * f * t)
    F_true = model.force(x_true)
    hm = float(model.virgin(A))
    F = F_true + offset + drift * t + noise * hm * rng.standard_normal(n)
    if hum:
        F = F + hum * np.sin(2 * np.pi * hum_frequency * t + rng.uniform(0, 2 * np.pi))
    xn = noise / 10 if x_noise is None else x_noise
    x = x_true + x_offset + x_drift * t + xn * A * rng.standard_normal(n)
    if adc_bits is not None:
        if not 4 <= int(adc_bits) <= 32:
            raise InputError(f"adc_bits must be in 4..32, got {adc_bits}")
        for arr, span in ((x, 1.25 * (A + abs(x_offset))), (F, 1.25 * (hm + abs(offset)))):
            q = 2 * span / 2 ** int(adc_bits)
            arr[:] = np.round(arr / q) * q
    truth = {
        "h0": float(h0),
        "ac": float(ac),
        "amplitude": A,
        "frequency": f,
        "offset": float(offset),
        "x_offset": float(x_offset),
        "drift": float(drift),
        "x_drift": float(x_drift),
        "noise_F": noise * hm,
        "noise_x": xn * A,
        "scale": float(scale),
    }
    m = {"kind": "tangential", "truth": truth, "generator": "contactlab.tangential"}
    m.update(meta or {})
    return Recording(t, {"x": x, "F": F}, {"x": "m", "F": "N"}, source="synthetic", meta=m)
