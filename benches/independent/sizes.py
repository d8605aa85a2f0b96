"""Effect sizes drawn "visible" or "near the bound" by the independent criterion (eval-only).

Every effect has a magnitude parameter in the units of ``docs/effects.md`` (``MAG``), a trial
size, a physical cap and, where the document gives one, shape parameters drawn at random.
The size is scaled so that the independent noncentrality ``lam_identify`` (visibility.py)
hits a target: 3-10 x the threshold ("visible") or 0.5-2 x ("near the bound"), then capped;
the record is classified afterwards by the criterion on the final record, not by the intent.
"""

from __future__ import annotations

import math

import numpy as np
from generator import normal_record, tangential_output, tangential_record
from visibility import (
    THRESHOLD,
    normal_directions,
    normal_visibility,
    tangential_directions,
    tangential_visibility,
)

# magnitude parameter of each effect (document units) and its name in diagnose's JSON
MAG = {
    "viscous_damping": "c",
    "inertia": "m",
    "parallel_stiffness": "k_p",
    "series_compliance": "C_s",
    "force_offset": "F0",
    "force_drift": "Fdot",
    "displacement_offset": "x0",
    "channel_delay": "tau",
    "asymmetry": "a",
    "non_masing_scaling": "lam-2",
    "parameter_drift": "beta",
    "stribeck": "s",
    "position_friction": "a_k",
    "stick_slip": "b",
    "normal_load": "eps",
    "stiffness_nonlinearity": "kappa",
    "creep_drift": "D",
    "asymmetric_branches": "a",
}


def _tangential_spec(effect, truth, rng):
    """(trial magnitude, cap, sign, builder(mag) -> params) for a tangential effect."""
    h0, A, f = truth["h0"], truth["A"], truth["f"]
    w = 2 * math.pi * f
    T = truth["cycles"] / f
    sgn = float(rng.choice([-1.0, 1.0]))
    if effect == "viscous_damping":
        return 0.05 * h0 / (A * w), 0.5 * h0 / (A * w), 1.0, lambda m: {"c": m}
    if effect == "inertia":
        return (
            min(0.05 * h0 / (A * w * w), 1.0),
            min(0.5 * h0 / (A * w * w), 20.0),
            1.0,
            lambda m: {"m": m},
        )
    if effect == "parallel_stiffness":
        return 0.05 * h0 / A, 2.0 * h0 / A, 1.0, lambda m: {"k_p": m}
    if effect == "series_compliance":
        return 0.05 * A / h0, 0.5 * A / h0, 1.0, lambda m: {"k_s": 1.0 / m, "C_s": m}
    if effect == "force_offset":
        return 0.02 * h0, 0.3 * h0, sgn, lambda m: {"F0": m}
    if effect == "force_drift":
        return 0.02 * h0 / T, 0.3 * h0 / T, sgn, lambda m: {"Fdot": m}
    if effect == "displacement_offset":
        return 0.05 * A, 0.5 * A, sgn, lambda m: {"x0": m}
    if effect == "channel_delay":
        return 0.002 / f, min(1e-3, 0.015 / f), 1.0, lambda m: {"tau": m}
    if effect == "asymmetry":
        return 0.02, 0.3, sgn, lambda m: {"a": m}
    if effect == "non_masing_scaling":
        return 0.05, 0.7, sgn, lambda m: {"lam": 2.0 + m, "lam-2": m}
    if effect == "parameter_drift":
        return 0.02 / T, 0.4 / T, sgn, lambda m: {"beta": m}
    if effect == "stribeck":
        v_s = float(rng.uniform(0.2, 0.7)) * A * w
        return 0.05, 0.5, 1.0, lambda m: {"s": m, "v_s": v_s}
    if effect == "position_friction":
        L = float(rng.uniform(1.0, 2.0)) * A
        phi = float(rng.uniform(0, 2 * math.pi))
        return 0.02, 0.3, 1.0, lambda m: {"a_k": m, "L": L, "phi": phi}
    if effect == "stick_slip":
        d_c = float(rng.uniform(0.05, 0.2)) * A
        return 0.05, 0.5, 1.0, lambda m: {"b": m, "d_c": d_c}
    if effect == "normal_load":
        if rng.random() < 0.5:
            f_N, variant = 2.0 * f, "coupled_2f"
        else:
            r = float(rng.uniform(0.3, 3.7))
            while abs(r - round(r)) < 0.15:
                r = float(rng.uniform(0.3, 3.7))
            f_N, variant = r * f, "beat"
        phi = float(rng.uniform(0, 2 * math.pi))
        return 0.02, 0.15, 1.0, lambda m: {"eps": m, "f_N": f_N, "phi": phi, "variant": variant}
    raise ValueError(effect)


def _normal_spec(effect, truth, rng):
    k, pa, f = truth["k"], truth["pa"], truth["f"]
    D = pa / k
    T = truth["cycles"] / f
    if effect == "stiffness_nonlinearity":
        return 0.02, 0.3, 1.0, lambda m: {"a1": k, "a2": m * k / D, "a3": 0.0, "kappa": m}
    if effect == "creep_drift":
        tau_c = float(rng.uniform(0.1, 0.3)) * T
        return 0.05 * D, 1.0 * D, 1.0, lambda m: {"D": m, "tau_c": tau_c}
    if effect == "channel_delay":
        return 0.002 / f, min(1e-3, 0.015 / f), 1.0, lambda m: {"tau": m}
    if effect == "asymmetric_branches":
        return 0.05, 0.5, float(rng.choice([-1.0, 1.0])), lambda m: {"a": m}
    raise ValueError(effect)


def _ideal_with(effect, params, twin):
    """Ideal sample-grid signals of the twin's drive with an effect applied (no chain)."""
    sig = dict(twin.ideal)
    T = twin.truth
    x_rep, F = tangential_output(
        effect, params, sig["t"], sig["x_true"], sig["v"], sig["a"], T["h0"], T["ac"]
    )
    if effect == "channel_delay":
        from generator import _shift

        F = _shift(sig["t"], F, params["tau"])
    elif effect == "force_offset":
        F = F + params["F0"]
    elif effect == "force_drift":
        F = F + params["Fdot"] * sig["t"]
    sig["x_rep"], sig["F"] = x_rep, F
    return sig


def make_pair(kind, effect, seed, size_class, rng):
    """(twin, record, info): a clean twin and the effect record on the same chain and noise.

    size_class "visible" or "near"; info holds the size, the criterion on the final record.
    """
    maker = tangential_record if kind == "tangential" else normal_record
    twin = maker(seed, "clean")
    T = twin.truth
    spec = _tangential_spec if kind == "tangential" else _normal_spec
    trial, cap, sgn, build = spec(effect, T, rng)
    if kind == "tangential":
        dirs = tangential_directions(twin.ideal, T["h0"], T["ac"], T["A"], T["f"])

        def lam_of(m):
            return tangential_visibility(_ideal_with(effect, build(m), twin), T, effect, dirs)
    else:
        dirs = normal_directions(twin.ideal, T)

        def lam_of(m):
            rec = normal_record(seed, effect, build(m), chain=twin.chain, base=_nbase(T))
            return normal_visibility(rec.ideal, T, effect, dirs)

    lo, hi = (3.0, 10.0) if size_class == "visible" else (0.5, 2.0)
    target = THRESHOLD * float(np.exp(rng.uniform(math.log(lo), math.log(hi))))
    m = trial * sgn
    for _ in range(2):
        lam_id = lam_of(m)[1]
        if not np.isfinite(lam_id) or lam_id <= 0:
            break
        m = m * math.sqrt(target / lam_id)
        if abs(m) > cap:
            m = math.copysign(cap, m)
            break
    capped = abs(abs(m) - cap) < 1e-12 * cap
    params = build(m)
    if kind == "tangential":
        rec = tangential_record(
            seed,
            effect,
            params,
            chain=twin.chain,
            base={"h0": T["h0"], "ac": T["ac"], "A": T["A_target"]},
        )
        lam_d, lam_i, near, _refit = tangential_visibility(rec.ideal, T, effect, dirs)
    else:
        rec = normal_record(seed, effect, params, chain=twin.chain, base=_nbase(T))
        lam_d, lam_i, near, _refit = normal_visibility(rec.ideal, T, effect, dirs)
    info = {
        "size_class": size_class,
        "magnitude": m,
        "capped": bool(capped),
        "target": target,
        "lam_detect": lam_d,
        "lam_identify": lam_i,
        "nearest": near,
        "visible_own": bool(lam_i >= THRESHOLD),
    }
    return twin, rec, info


def _nbase(T):
    return {"p0": T["p0"], "pa": T["pa"], "k": T["k"], "psi": T["psi"]}
