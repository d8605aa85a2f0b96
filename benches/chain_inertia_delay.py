"""A measurement chain for inertia and channel delay on single-frequency records (issue 29),
written here apart from the package's generators.

Each record is one drive frequency, started from rest, seen through a realistic sensor
chain on a grid ``OVERSAMPLE`` times finer than the ADC's:

- drive: ``A sin ωt`` started at rest, either abruptly (``start="abrupt"``: the servo alone
  smooths the jump in velocity) or behind a raised-cosine ramp of 0.5-2 cycles
  (``start="ramp"``); the servo is second order, natural frequency 8-20 drive frequencies,
  damping 0.5-0.8;
- contact: a Masing element with the exponential virgin curve ``h0 (1 - exp(-ac s))``
  (:func:`contactlab.diagnose.scaled_masing.scaled_force`, branch scale 2) from its
  virgin state;
- ``inertia``: a mass ``m`` between contact and load cell: the cell feels
  ``F_contact + m ẍ`` (ẍ of the true motion); its size drawn so that ``m ω² A`` is 3-15 %
  of the force amplitude;
- load cell: second order, natural frequency 1-5 kHz (at least 30 drive frequencies),
  damping 0.02-0.2;
- anti-alias: Butterworth of order 2-4 at 0.2-0.4 fs on both channels, the corners drawn
  independently within ±2 % (so the channels skew by a few microseconds);
- ``backlash``: lost motion of half-width ``b`` (2-10 % of the amplitude) between the
  displacement sensor and the contact (a play operator on x before the contact);
- ``channel_delay``: the force channel sampled ``tau`` later than the displacement channel
  (0.3 or 1.5 ms, or drawn 0.2-2 ms with ``delay="uniform"``);
- noise: white on each channel before the anti-alias filter, from independent streams,
  scaled so that its RMS after the filter is 0.5-2 % of the channel's range (x) and 0.5-2 %
  (F); displacement-sensor drift of ±0.5 % of the range over the record; 12-16 bit ADC
  over 1.25 times each channel's peak.

:func:`draw` draws the factors from a seed; :func:`record` builds ``(t, x, F)`` and its
truth, and :func:`effect_signal` the noise-free difference the effect makes at the ADC
(for a visibility figure independent of the diagnosis).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy import signal

OVERSAMPLE = 8
EFFECTS = ("inertia", "channel_delay", "clean", "backlash")
MAX_SAMPLES = 24_000


def _logu(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


def draw(seed: int, effect: str = "clean", **over: Any) -> dict[str, Any]:
    """Factors of one record (any of them fixed by keyword)."""
    rng = np.random.default_rng([seed, EFFECTS.index(effect), 31])
    fs = float(rng.choice((1000.0, 2000.0, 5000.0, 10000.0)))
    # (a mass's force m ω² A of 3-15 % of the friction force needs a tonne below 5 Hz)
    f = min(_logu(rng, 5.0 if effect == "inertia" else 1.0, 50.0), fs / 20.0)
    cycles = int(rng.integers(5, 51))
    cycles = max(5, min(cycles, int(MAX_SAMPLES * f / fs)))
    fac = {
        "fs": fs,
        "f": round(f, 3),
        "cycles": cycles,
        "acA": round(_logu(rng, 0.5, 5.0), 3),
        "x_noise": round(float(rng.uniform(0.005, 0.02)), 4),
        "F_noise": round(float(rng.uniform(0.005, 0.02)), 4),
        "x_drift": float(rng.uniform(-0.005, 0.005)),
        "bits": int(rng.integers(12, 17)),
        "aa_order": int(rng.integers(2, 5)),
        "aa_ratio": float(rng.uniform(0.2, 0.4)),
        "aa_tol": rng.uniform(-0.02, 0.02, 2).tolist(),
        "cell_fn": float(rng.uniform(1000.0, 5000.0)),
        "cell_zeta": float(rng.uniform(0.02, 0.2)),
        "servo_ratio": float(rng.uniform(8.0, 20.0)),
        "servo_zeta": float(rng.uniform(0.5, 0.8)),
        "start": str(rng.choice(("abrupt", "ramp"))),
        "ramp": float(rng.uniform(0.5, 2.0)),
        "share": float(rng.uniform(0.03, 0.15)),
        "tau": float(rng.choice((0.3e-3, 1.5e-3))),
        "tau_u": float(rng.uniform(0.2e-3, 2.0e-3)),
        "h0": float(rng.uniform(20.0, 100.0)),
        "gap": float(rng.uniform(0.02, 0.10)),
    }
    fac["cell_fn"] = max(fac["cell_fn"], 30.0 * fac["f"])
    for key in [k for k in over if k.endswith("_range")]:  # a factor drawn from a sub-range
        lo, hi = over.pop(key)
        name = key[: -len("_range")]
        fac[name] = round(lo + (hi - lo) * float(np.random.default_rng([seed, 77]).random()), 4)
    fac.update(over)
    return fac


def _truth_motion(fac: dict[str, Any]) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """``(tf, x, ẍ, A)`` of the servo's true motion on the fine grid."""
    fs, f, cycles = fac["fs"], fac["f"], fac["cycles"]
    ffine = fs * OVERSAMPLE
    A = 1e-5
    n_out = round(cycles / f * fs) + 1
    n_fine = (n_out - 1) * OVERSAMPLE + 1 + 16 * OVERSAMPLE
    tf = np.arange(n_fine) / ffine
    w = 2 * math.pi * f
    if fac["start"] == "ramp":
        env = np.clip(tf * f / fac["ramp"], 0.0, 1.0)
        env = 0.5 - 0.5 * np.cos(math.pi * env)
    else:
        env = np.ones_like(tf)
    wn = 2 * math.pi * f * fac["servo_ratio"]
    zeta = fac["servo_zeta"]
    servo = ([wn * wn], [1.0, 2 * zeta * wn, wn * wn])
    _, H = signal.freqs(*servo, worN=[w])
    cmd = (A / abs(H[0])) * env * np.sin(w * tf)
    bd, ad, _ = signal.cont2discrete(servo, 1 / ffine, "foh")
    x = signal.lfilter(np.squeeze(bd), np.squeeze(ad), cmd)
    # ẍ exactly from the servo's state: ẍ = wn² (cmd - x) - 2 ζ wn ẋ
    v = np.gradient(x, 1 / ffine, edge_order=2)
    acc = wn * wn * (cmd - x) - 2 * zeta * wn * v
    return tf, x, acc, A


def _play(x: np.ndarray, b: float) -> np.ndarray:
    """The play operator of half-width ``b`` sample by sample (from rest at 0)."""
    u = np.empty_like(x)
    v = 0.0
    for i, xi in enumerate(x.tolist()):
        v = min(max(v, xi - b), xi + b)
        u[i] = v
    return u


def _lowpass(order: int, fc: float, ffine: float):
    return signal.butter(order, fc, fs=ffine, output="sos")


def _chain(fac: dict[str, Any], effect: str, noise: bool = True):
    """``(t, x, F, info)`` of one record through the chain (``noise=False``: no noise, no
    drift, no quantisation)."""
    from contactlab.diagnose.scaled_masing import memory, scaled_force

    fs, f = fac["fs"], fac["f"]
    ffine = fs * OVERSAMPLE
    tf, x, acc, A = _truth_motion(fac)
    h0 = fac["h0"]
    ac = fac["acA"] / A
    u = _play(x, fac["gap"] * A) if effect == "backlash" else x
    F = scaled_force(lambda s: h0 * np.sign(s) * (1.0 - np.exp(-ac * np.abs(s))), 2.0, memory(u))
    Famp = h0 * (1.0 - math.exp(-fac["acA"]))
    m = 0.0
    if effect == "inertia":
        m = fac["share"] * Famp / (A * (2 * math.pi * f) ** 2)
        F = F + m * acc
    wc = 2 * math.pi * fac["cell_fn"]
    zc = fac["cell_zeta"]
    bd, ad, _ = signal.cont2discrete(([wc * wc], [1.0, 2 * zc * wc, wc * wc]), 1 / ffine, "foh")
    Fc = signal.lfilter(np.squeeze(bd), np.squeeze(ad), F)
    rng = np.random.default_rng([int(fac.get("seed", 0)), 5])
    rng_x, rng_F = (np.random.default_rng(s) for s in np.random.SeedSequence(
        int(fac.get("seed", 0)) + 7919).spawn(2))  # fmt: skip
    aa_x = _lowpass(fac["aa_order"], fac["aa_ratio"] * fs * (1 + fac["aa_tol"][0]), ffine)
    aa_F = _lowpass(fac["aa_order"], fac["aa_ratio"] * fs * (1 + fac["aa_tol"][1]), ffine)
    xr, Fr = 2 * A, 2 * Famp
    xs = x.copy()
    if noise:
        xs = xs + fac["x_drift"] * xr * tf / tf[-1]
        nx = signal.sosfilt(aa_x, rng_x.standard_normal(tf.size))
        nF = signal.sosfilt(aa_F, rng_F.standard_normal(tf.size))
        nx *= fac["x_noise"] * xr / float(np.std(nx[tf.size // 10 :]))
        nF *= fac["F_noise"] * Fr / float(np.std(nF[tf.size // 10 :]))
    xm = signal.sosfilt(aa_x, xs)
    Fm = signal.sosfilt(aa_F, Fc)
    if noise:
        xm = xm + nx
        Fm = Fm + nF
    n_out = round(fac["cycles"] / f * fs) + 1
    t = np.arange(n_out) / fs
    idx = np.arange(n_out) * OVERSAMPLE
    xo = xm[idx]
    tau = 0.0
    if effect == "channel_delay":
        tau = fac["tau_u"] if fac.get("delay") == "uniform" else fac["tau"]
    Fo = np.interp(t - tau, tf, Fm, left=Fm[0]) if tau else Fm[idx]
    if noise:
        out = []
        for v in (xo, Fo):
            fsr = 1.25 * float(np.max(np.abs(v)))
            q = 2 * fsr / 2 ** fac["bits"]
            out.append(np.round(v / q) * q)
        xo, Fo = out
    del rng
    b = fac["gap"] * A if effect == "backlash" else 0.0
    info = {"m": m, "tau": tau, "b": b, "A": A, "ac": ac, "h0": h0, "Famp": Famp,
            "sigma_F": fac["F_noise"] * Fr, "sigma_x": fac["x_noise"] * xr}  # fmt: skip
    return t, xo, Fo, info


def record(seed: int, effect: str = "clean", **over: Any):
    """``((t, x, F), factors, truth)`` of one record."""
    fac = draw(seed, effect, **over)
    fac["seed"] = seed
    t, x, F, info = _chain(fac, effect)
    return (t, x, F), fac, info


def effect_signal(fac: dict[str, Any], effect: str) -> np.ndarray:
    """The noise-free force the effect adds at the ADC (with minus without it)."""
    _, _, F1, _ = _chain(fac, effect, noise=False)
    _, _, F0, _ = _chain(fac, "clean", noise=False)
    return F1 - F0
