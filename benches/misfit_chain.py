"""A measurement chain for calibrating the misfit flag (issue 29, item 3), written here apart
from the package's generators: coloured input noise, Bessel anti-alias filters, a start from
rest with drive harmonics, mains hum, clock jitter and an ADC.

The contact is a Masing element whose virgin curve is the exponential one (``virgin="exp"``:
a clean record, nothing to flag) or one no candidate draws: ``"tanh"`` (``h0 tanh(ac s)``),
``"rational"`` (``h0 ac s / (1 + ac s)``) or ``"gamma"`` (``h0 (1 - (1 + ac s) e^(-ac s))``:
zero initial slope), all with Masing's branch scale 2 (:func:`scaled_force`); for evaluation
only (:data:`EVAL_VIRGINS`) ``"arctan"``, ``"bilinear"`` (two slopes to a plateau),
``"weibull"`` (``1 - exp(-(ac s)^0.7)``) and ``"cubic"`` (``1 - (1 - ac s/3)³`` to full slip
at ``3/ac``).

The chain, on a grid ``OVERSAMPLE`` times finer than the ADC's:

- actuator: a second-order servo (natural frequency 6-15 drive frequencies, damping
  0.3-0.7) follows a command that starts from rest with a sine of the drive frequency plus
  2nd and 3rd harmonics (0.5-2 % each); so the first cycles carry a transient;
- x channel: white sensor noise through an LVDT demodulator low-pass (2nd order, corner
  0.03-0.25 fs, at least 10 drive frequencies), plus a small white share after it (20 % of the
  variance), then a 4th-order Bessel anti-alias filter at 0.2-0.4 fs; the noise's RMS after
  both is ``x_noise`` of the range; 50 Hz hum (0.1-0.3 % of range) unless ``hum=False``;
- F channel: white noise, a piezo (first-order high-pass at 0.0002-0.002 Hz: a time
  constant of 80-800 s) or a strain-gauge cell (second-order, 2-5 kHz, at least 50 drive
  frequencies, damping 0.05-0.2), hum, the same Bessel filter;
- sampling with clock jitter (0-2 µs RMS, ``jitter=False`` for none), 14- or 16-bit ADC over
  1.25 times each channel's peak.

:func:`draw` draws the factors from a seed; :func:`chain_record` builds a record.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy import interpolate, signal

OVERSAMPLE = 4
VIRGINS = ("exp", "tanh", "rational", "gamma", "arctan", "bilinear", "weibull", "cubic")
#: virgin curves written for evaluating the misfit flag only (flagcal, stop 39): none was used
#: for tuning (the flag was tuned on tanh, rational and gamma)
EVAL_VIRGINS = ("arctan", "bilinear", "weibull", "cubic")


def virgin_curve(kind: str, h0: float, ac: float):
    """The virgin curve ``f(s)`` (odd) of each kind."""
    if kind == "exp":
        return lambda s: h0 * np.sign(s) * (1.0 - np.exp(-ac * np.abs(s)))
    if kind == "tanh":
        return lambda s: h0 * np.tanh(ac * s)
    if kind == "rational":
        return lambda s: h0 * ac * s / (1.0 + ac * np.abs(s))
    if kind == "gamma":

        def g(s: np.ndarray) -> np.ndarray:
            a = ac * np.abs(s)
            return h0 * np.sign(s) * (1.0 - (1.0 + a) * np.exp(-a))

        return g
    if kind == "arctan":  # initial slope h0 ac, slow approach to the plateau (1/s)
        return lambda s: h0 * (2.0 / np.pi) * np.arctan(0.5 * np.pi * ac * s)
    if kind == "bilinear":  # two slopes, then a plateau at h0 (an Iwan model of 3 elements)
        return lambda s: (
            h0
            * np.sign(s)
            * np.minimum(np.minimum(ac * np.abs(s), 0.4 + 0.3 * (ac * np.abs(s) - 0.4)), 1.0)
        )
    if kind == "weibull":  # a stretched exponential: infinite initial slope
        return lambda s: h0 * np.sign(s) * (1.0 - np.exp(-((ac * np.abs(s)) ** 0.7)))
    if kind == "cubic":  # polynomial to full slip at a finite slip (3/ac), smooth there
        return lambda s: (
            h0 * np.sign(s) * (1.0 - (1.0 - np.minimum(ac * np.abs(s) / 3.0, 1.0)) ** 3)
        )
    raise ValueError(kind)


def draw(seed: int, **over: Any) -> dict[str, Any]:
    """Factors of one record (any of them fixed by keyword)."""
    rng = np.random.default_rng(seed)
    f = {
        "fs": float(rng.choice((1000.0, 2000.0, 5000.0, 10000.0))),
        "cycles": int(rng.integers(5, 51)),
        "x_noise": float(rng.uniform(0.0, 0.02)),
        "acA": float(np.exp(rng.uniform(np.log(0.3), np.log(5.0)))),
        "F_noise": float(rng.uniform(0.005, 0.02)),
        "f": float(np.exp(rng.uniform(0.0, np.log(50.0)))),
        "bits": int(rng.choice((14, 16))),
        "cell": str(rng.choice(("piezo", "gauge"))),
    }
    f.update(over)
    f["f"] = min(f["f"], f["fs"] / 20.0)
    return f


def _bessel(fc: float, fs_fine: float):
    return signal.bessel(4, fc, fs=fs_fine, norm="phase", output="sos")


def chain_record(
    seed: int,
    virgin: str = "exp",
    *,
    hum: bool = True,
    jitter: bool = True,
    lvdt: bool = True,
    x_colour: str = "lvdt",
    scale: float = 2.0,
    noise_seed: int | None = None,
    c: float = 0.0,
    tau: float = 0.0,
    **over: Any,
) -> tuple[tuple[np.ndarray, np.ndarray, np.ndarray], dict[str, Any]]:
    """``((t, x, F), factors)`` of one record (see the module docstring).

    ``x_colour`` shapes the x sensor's noise before the anti-alias filter: ``"lvdt"`` (a
    2nd-order demodulator low-pass plus a white share, ``lvdt=False``: white only),
    ``"lp1"`` (a first-order low-pass at 0.02-0.2 fs, at least 10 drive frequencies, plus
    the white share) or ``"white"``. ``scale`` is the branch scale of the Masing rules (2:
    Masing; 1.3-1.6: non-Masing scaling applied from rest, the virgin curve exponential).
    The draws of the default settings are those of earlier versions (same seeds, same
    records). ``c`` adds a dashpot ``c ẋ`` (N s/m) to the contact's force, ``tau`` delays the
    force by ``tau`` (s) before its cell (the draws unchanged). ``noise_seed`` draws the
    sensor noises of both channels (not the hum, the jitter or anything else) from a stream
    of its own: the same record under other noise."""
    fac = draw(seed, **over)
    rng = np.random.default_rng([seed, 7])
    fs, f, cycles = fac["fs"], fac["f"], fac["cycles"]
    ffine = fs * OVERSAMPLE
    A, h0 = 1e-5, float(rng.uniform(20.0, 100.0))
    ac = fac["acA"] / A
    ramp = 1.5  # cycles of the command's rise from rest
    n_out = round((cycles + ramp + 1.5) / f * fs)
    n_fine = n_out * OVERSAMPLE + 8 * OVERSAMPLE
    tf = np.arange(n_fine) / ffine
    env = np.clip(tf * f / ramp, 0.0, 1.0)
    env = 0.5 - 0.5 * np.cos(np.pi * env)
    h2, h3 = rng.uniform(0.005, 0.02, 2)
    ph = rng.uniform(0, 2 * np.pi, 2)
    w = 2 * np.pi * f
    harm = h2 * np.sin(2 * w * tf + ph[0]) + h3 * np.sin(3 * w * tf + ph[1])
    cmd = A * env * (np.sin(w * tf) + harm)
    # the actuator: second-order servo from rest
    wn = 2 * np.pi * f * rng.uniform(6.0, 15.0)
    zeta = rng.uniform(0.3, 0.7)
    b, a = signal.bilinear([wn * wn], [1.0, 2 * zeta * wn, wn * wn], fs=ffine)
    x = signal.lfilter(b, a, cmd)
    x *= A / max(float(np.max(np.abs(x))), 1e-300)
    from contactlab.diagnose.scaled_masing import memory, scaled_force

    F = scaled_force(virgin_curve(virgin, h0, ac), scale, memory(x))
    if c:
        F = F + c * np.gradient(x, 1.0 / ffine)
    if tau:
        F = np.interp(tf - tau, tf, F)
    xr, Fr = float(np.ptp(x)), float(np.ptp(F))
    aa = _bessel(rng.uniform(0.2, 0.4) * fs, ffine)
    # x: LVDT demodulator low-pass on the sensor noise, then a small white share, then AA
    fl = max(rng.uniform(0.03, 0.25) * fs, 10.0 * f)
    lv = signal.butter(2, fl, fs=ffine, output="sos")
    if x_colour == "lp1":  # a first-order low-pass (an RC stage) in place of the demodulator
        fl = max(np.random.default_rng([seed, 11]).uniform(0.02, 0.2) * fs, 10.0 * f)
        lv = signal.butter(1, fl, fs=ffine, output="sos")
    nrng = rng if noise_seed is None else np.random.default_rng([seed, 13, noise_seed])
    n1 = signal.sosfilt(lv, rng.standard_normal(n_fine))
    n2 = rng.standard_normal(n_fine)
    if noise_seed is not None:  # the main stream drawn as before, the noise from its own
        n1 = signal.sosfilt(lv, nrng.standard_normal(n_fine))
        n2 = nrng.standard_normal(n_fine)
    share = 0.8 if lvdt and x_colour != "white" else 0.0
    nx = signal.sosfilt(aa, math.sqrt(share) * n1 / np.std(n1) + math.sqrt(1 - share) * n2)
    nx *= fac["x_noise"] * xr / max(float(np.std(nx[n_fine // 10 :])), 1e-300)
    # F: white noise, piezo high-pass or strain-gauge resonance, AA
    if fac["cell"] == "piezo":  # charge amplifier: a first-order high-pass far below f
        hp = signal.butter(1, rng.uniform(0.0002, 0.002), btype="high", fs=ffine, output="sos")
        Fc = signal.sosfilt(hp, F)
    else:  # strain-gauge cell: a resonance at kHz, exact for piecewise-linear input
        wc = 2 * np.pi * max(rng.uniform(2000.0, 5000.0), 50.0 * f)
        zc = rng.uniform(0.05, 0.2)
        bd, ad, _ = signal.cont2discrete(([wc * wc], [1.0, 2 * zc * wc, wc * wc]), 1 / ffine, "foh")
        Fc = signal.lfilter(np.squeeze(bd), np.squeeze(ad), F)
    nF = signal.sosfilt(aa, rng.standard_normal(n_fine))
    if noise_seed is not None:
        nF = signal.sosfilt(aa, nrng.standard_normal(n_fine))
    nF *= fac["F_noise"] * Fr / max(float(np.std(nF[n_fine // 10 :])), 1e-300)
    xm = signal.sosfilt(aa, x) + nx
    Fm = signal.sosfilt(aa, Fc) + nF
    if hum:
        hph = rng.uniform(0, 2 * np.pi, 2)
        xm += rng.uniform(0.001, 0.003) * xr * np.sin(2 * np.pi * 50.0 * tf + hph[0])
        Fm += rng.uniform(0.001, 0.003) * Fr * np.sin(2 * np.pi * 50.0 * tf + hph[1])
    # sampling with jitter, the ADC
    t = np.arange(n_out) / fs
    tq = t + 4.0 / fs
    if jitter:
        tq = tq + rng.normal(0.0, rng.uniform(0.0, 2e-6), n_out)
    out = []
    for v in (xm, Fm):
        sp = interpolate.CubicSpline(tf, v)
        s = sp(tq)
        fsr = 1.25 * float(np.max(np.abs(s)))
        q = 2 * fsr / 2 ** fac["bits"]
        out.append(np.round(s / q) * q)
    fac.update(h0=h0, virgin=virgin, lvdt_corner=fl, x_colour=x_colour, scale=scale)
    return (t, out[0], out[1]), fac
