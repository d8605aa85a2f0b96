"""A small tangential chain written from ``docs/effects.md`` alone (issue 29, helper loadslip).

Independent of the package's generators: a plain-Python Masing element with memory
(exponential virgin curve, turning-point stack with wiping out) driven by a sine from rest,
the effects of the document's table applied to its force, white noise on both channels from
independent streams (as a share of each channel's peak-to-peak range). Nothing here imports
``contactlab``.

Effects (docs/effects.md §1):

- ``normal_load``: N(t)/N̄ = 1 + ε cos(2π f_N t + φ), F = (N/N̄)·M[x];
- ``stick_slip``: F = M[x] + b h0 sgn(ẋ) (s/d_c) e^(1 − s/d_c), s = |x − x_r| since the
  last turning point (optionally also on the first loading from rest, x_r = 0);
- ``stribeck``: F = (1 + s e^(−(ẋ/v_s)²))·M[x];
- ``parallel_stiffness``: F = M[x] + k_p x;
- ``position_friction``: F = (1 + a cos(2π x/L + φ))·M[x].

    from chain_loadslip import record
    t, x, F, truth = record("normal_load", seed=3)
"""

from __future__ import annotations

import math

import numpy as np

EFFECTS = ("normal_load", "stick_slip", "stribeck", "parallel_stiffness", "position_friction")
MAX_SAMPLES = 30000


def masing(x: np.ndarray, h0: float, ac: float) -> np.ndarray:
    """Masing's rules with memory for any ``x`` from rest (x[0] is the rest point 0)."""

    def f(u):  # odd-extended exponential virgin curve
        return math.copysign(h0 * -math.expm1(-ac * abs(u)), u)

    out = np.empty(x.size)
    stack: list[tuple[float, float]] = []
    direction = 0.0
    prev_x, prev_F = float(x[0]), f(float(x[0]))
    out[0] = prev_F
    for i in range(1, x.size):
        xi = float(x[i])
        step = xi - prev_x
        if step != 0.0:
            d = 1.0 if step > 0 else -1.0
            if direction != 0.0 and d != direction:
                stack.append((prev_x, prev_F))
            direction = d
            # wiping out: the branch passed the start of the branch it turned from
            while stack:
                if len(stack) >= 2:
                    if (xi - stack[-2][0]) * direction > 0:
                        del stack[-2:]
                        continue
                elif (xi + stack[-1][0]) * direction > 0:  # met the (odd) virgin curve
                    stack.pop()
                    continue
                break
        if stack:
            xr, Fr = stack[-1]
            Fi = Fr + 2.0 * f((xi - xr) / 2.0)
        else:
            Fi = f(xi)
        out[i] = Fi
        prev_x, prev_F = xi, Fi
    return out


def travel_since_turn(x: np.ndarray, first_loading: bool) -> tuple[np.ndarray, np.ndarray]:
    """``(s, sgn ẋ)``: the travel since the last turning point, and the direction; before
    the first turn, from the rest point 0 when ``first_loading`` (else s = 0 there)."""
    n = x.size
    dx = np.diff(x, prepend=x[0])
    sgn = np.sign(dx)
    for i in range(1, n):  # hold the direction across flat samples
        if sgn[i] == 0:
            sgn[i] = sgn[i - 1]
    if sgn[0] == 0:
        sgn[0] = sgn[1] if n > 1 else 1.0
    s = np.zeros(n)
    xr = 0.0
    turned = False
    for i in range(1, n):
        if sgn[i] != sgn[i - 1]:
            xr = x[i - 1]
            turned = True
        s[i] = abs(x[i] - xr) if (turned or first_loading) else 0.0
    return s, sgn


def draw(rng: np.random.Generator, effect: str | None) -> dict:
    """Factors across the brief's ranges and an effect of a drawn size."""
    fs = float(np.exp(rng.uniform(np.log(1000.0), np.log(10000.0))))
    f = float(np.exp(rng.uniform(np.log(1.0), np.log(50.0))))
    cycles = int(rng.integers(5, 51))
    fs = min(fs, MAX_SAMPLES * f / 5)
    cycles = max(5, min(cycles, int(MAX_SAMPLES * f / fs)))
    fac = {
        "fs": fs,
        "f": f,
        "cycles": cycles,
        "acA": float(np.exp(rng.uniform(np.log(0.3), np.log(5.0)))),
        "x_noise": float(rng.uniform(0.0, 0.02)),
        "F_noise": float(rng.uniform(0.005, 0.02)),
        "h0": float(np.exp(rng.uniform(np.log(1.0), np.log(100.0)))),
        "ac": float(np.exp(rng.uniform(np.log(1e3), np.log(1e5)))),
    }
    A = fac["acA"] / fac["ac"]
    w = 2 * math.pi * f
    p: dict = {}
    if effect == "normal_load":
        p = {"eps": float(rng.uniform(0.01, 0.15)), "f_n": 2 * f,
             "phi": float(rng.uniform(0, 2 * math.pi))}  # fmt: skip
    elif effect == "stick_slip":
        p = {"b": float(rng.uniform(0.05, 0.35)), "d_c": float(rng.uniform(0.03, 0.3)) * A,
             "first_loading": bool(rng.random() < 0.5)}  # fmt: skip
    elif effect == "stribeck":
        p = {"s": float(rng.uniform(0.05, 0.35)), "v_s": float(rng.uniform(0.1, 0.5)) * A * w}
    elif effect == "parallel_stiffness":
        hm = fac["h0"] * -math.expm1(-fac["acA"])
        p = {"k_p": float(rng.uniform(0.03, 0.25)) * hm / A}
    elif effect == "position_friction":
        p = {"a": float(rng.uniform(0.03, 0.15)), "L": float(rng.uniform(1.0, 2.0)) * A,
             "phi": float(rng.uniform(0, 2 * math.pi))}  # fmt: skip
    return {"factors": fac, "effect": effect, "params": p}


def make(case: dict, seed: int):
    """``(t, x, F, truth)`` of a drawn ``case``; ``truth['size']``: the effect's force
    change, RMS and peak, over the clean force's peak."""
    fac, effect, p = case["factors"], case["effect"], case["params"]
    fs, f, h0, ac = fac["fs"], fac["f"], fac["h0"], fac["ac"]
    A = fac["acA"] / ac
    n = round(fac["cycles"] * fs / f)
    t = np.arange(n) / fs
    w = 2 * math.pi * f
    x = A * np.sin(w * t)
    M = masing(x, h0, ac)
    F = M.copy()
    v = A * w * np.cos(w * t)
    if effect == "normal_load":
        F = (1 + p["eps"] * np.cos(2 * math.pi * p["f_n"] * t + p["phi"])) * M
    elif effect == "stick_slip":
        s, sgn = travel_since_turn(x, p["first_loading"])
        F = M + p["b"] * h0 * sgn * (s / p["d_c"]) * np.exp(1 - s / p["d_c"])
    elif effect == "stribeck":
        F = (1 + p["s"] * np.exp(-((v / p["v_s"]) ** 2))) * M
    elif effect == "parallel_stiffness":
        F = M + p["k_p"] * x
    elif effect == "position_friction":
        F = (1 + p["a"] * np.cos(2 * math.pi * x / p["L"] + p["phi"])) * M
    rng_x = np.random.default_rng([seed, 1])
    rng_F = np.random.default_rng([seed, 2])
    sx = fac["x_noise"] * float(np.ptp(x))
    sF = fac["F_noise"] * float(np.ptp(F))
    xm = x + sx * rng_x.standard_normal(n)
    Fm = F + sF * rng_F.standard_normal(n)
    peak = float(np.max(np.abs(M)))
    truth = {
        **case,
        "size_rms": float(np.sqrt(np.mean((F - M) ** 2)) / peak),
        "size_peak": float(np.max(np.abs(F - M)) / peak),
        "noise": {"x": sx, "F": sF},
    }
    return t, xm, Fm, truth
