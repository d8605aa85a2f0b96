"""Independent evaluation of `contactlab diagnose` (issue 29, item 7).

Recordings from two generators — the rig simulator written from ``docs/effects.md``
(``contactlab.synthetic.rig``: actuator from rest, load cell, anti-alias filters, quantisation,
displacement noise and drift) and the package's own public ``hidden_effect_recording`` — across
fs 1-10 kHz, 1-50 Hz, 5-50 cycles, ac·A 0.3-5, x noise 0-2 % of the amplitude, F noise
0.5-2 %, all starting from rest; then every measured record in ``../shared/data``.

Seeds: ``--seeds tune`` uses the published TUNE seeds (for anyone tuning); ``--seeds fresh``
(the default) draws a base seed from the clock, prints it, and uses it only for this report.

Tables: false alarms on clean records by factor; by effect (exact / named with extra /
missed / wrong) with confusion pairs; exact rate by x-noise band and ac·A band; the
"unnameable misfit flagged" rate (any JSON key containing "unexplained" that is truthy); what
diagnose names on each measured record with the plausibility text it gives.

    nice .venv/bin/python benches/eval_diagnose_rig.py --quick          # ~2 CPU-min
    nice .venv/bin/python benches/eval_diagnose_rig.py --jobs 2 --out benches/results/x.md
"""

from __future__ import annotations

import argparse
import itertools
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from collections import Counter, defaultdict
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data"
CLI = [sys.executable, "-m", "contactlab"]

#: Published seeds for tuning (anyone may tune on these); FRESH seeds come from the clock.
TUNE_BASE = 1000

TANGENTIAL = (
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
NORMAL = (
    "stiffness_nonlinearity",
    "hysteretic_damping",
    "creep_drift",
    "channel_delay",
    "asymmetric_branches",
)
UNNAMEABLE = ("tanh_virgin", "power_law_microslip", "backlash", "rate_dependent_presliding")
MAX_SAMPLES = 30000


# ---------------------------------------------------------------------------------------------
# the plan
# ---------------------------------------------------------------------------------------------


def _loguniform(rng, lo, hi):
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


def draw_factors(rng, kind):
    """Record factors; cycles are cut so that a record has at most MAX_SAMPLES samples."""
    fs = _loguniform(rng, 1000.0, 10000.0)
    f = _loguniform(rng, 1.0, 50.0 if kind == "tangential" else 20.0)
    cycles = int(rng.integers(5, 51))
    fs = min(fs, MAX_SAMPLES * f / 5)  # at least 5 cycles within MAX_SAMPLES
    cycles = max(5, min(cycles, int(MAX_SAMPLES * f / fs)))
    return {
        "fs": round(fs, 1),
        "f": round(f, 3),
        "cycles": cycles,
        "acA": round(_loguniform(rng, 0.3, 5.0), 3),
        "x_noise": round(float(rng.uniform(0.0, 0.02)), 4),
        "F_noise": round(float(rng.uniform(0.005, 0.02)), 4),
    }


#: ``--chain sensors`` (or CONTACTLAB_RIG_CHAIN=sensors in the environment, which the worker
#: processes and benches/eval_false_alarm.py inherit): every rig record also passes an LVDT
#: demodulator's low-pass on x, a piezo (high-pass) or strain-gauge load cell, Bessel
#: anti-alias filters, mains hum, clock jitter, drive harmonics and an abrupt start from rest
CHAIN_ENV = "CONTACTLAB_RIG_CHAIN"


def chain_kwargs(seed, fac):
    """The sensor figures of a rig record under ``--chain sensors`` (``{}`` otherwise), drawn
    from their own stream so that the record's factors and noise are those of the plain
    chain."""
    if os.environ.get(CHAIN_ENV, "plain") != "sensors":
        return {}
    rng = np.random.default_rng(int(seed) + 424_242)
    fs = fac["fs"]
    return {
        # an LVDT conditioner's demodulator low-pass (2nd order) at 0.3-2 kHz
        "x_lowpass": round(min(_loguniform(rng, 300.0, 2000.0), 0.45 * fs), 3),
        # a piezo cell: its charge amplifier's time constant 1.6-30 s; else a strain gauge
        "F_highpass": (round(_loguniform(rng, 0.005, 0.1), 5) if rng.random() < 0.5
                       else None),
        "aa_kind": "bessel",
        "hum": round(float(rng.uniform(0.0, 0.005)), 5),
        "jitter": float(rng.uniform(0.0, 0.02)) / fs,
        "drive_harmonics": (round(float(rng.uniform(0, 0.01)), 4),
                            round(float(rng.uniform(0, 0.01)), 4)),
        "ramp_cycles": round(float(rng.uniform(0.0, 1.0)), 3),
    }  # fmt: skip


def plan(mode, base_seed, scale=1.0):
    """Cases: (generator, kind, effect or None, variant, seed, factors).

    ``scale`` multiplies the number of records per cell of the full plan (at least 1 each).
    """
    sizes = {
        "quick": {
            "rig_t_clean": 6,
            "rig_t_eff": 1,
            "pkg_t_clean": 3,
            "pkg_t_eff": 0,
            "rig_n_clean": 1,
            "rig_n_eff": 0,
            "pkg_n_clean": 1,
            "pkg_n_eff": 0,
            "unnameable": 1,
            "quick_effects": (
                "channel_delay",
                "parallel_stiffness",
                "non_masing_scaling",
                "force_offset",
            ),
        },
        "full": {
            "rig_t_clean": 24,
            "rig_t_eff": 4,
            "pkg_t_clean": 12,
            "pkg_t_eff": 2,
            "rig_n_clean": 4,
            "rig_n_eff": 2,
            "pkg_n_clean": 4,
            "pkg_n_eff": 2,
            "unnameable": 3,
            "quick_effects": (),
        },
    }[mode]
    if scale != 1.0:
        sizes = {
            k: (max(1, round(v * scale)) if isinstance(v, int) and v else v)
            for k, v in sizes.items()
        }
    cases = []
    seed = base_seed

    def add(gen, kind, effect, variant=""):
        nonlocal seed
        rng = np.random.default_rng(seed)
        fac = draw_factors(rng, kind)
        if effect == "inertia":  # a plausible fixture mass is only visible at higher f
            fac["f"] = round(_loguniform(rng, 20.0, 50.0), 3)
            fac["cycles"] = max(5, min(fac["cycles"], int(MAX_SAMPLES * fac["f"] / fac["fs"])))
        cases.append(
            {
                "gen": gen,
                "kind": kind,
                "effect": effect,
                "variant": variant,
                "seed": seed,
                "factors": fac,
            }
        )
        seed += 1

    for _ in range(sizes["rig_t_clean"]):
        add("rig", "tangential", None)
    for _ in range(sizes["pkg_t_clean"]):
        add("pkg", "tangential", None)
    for _ in range(sizes["rig_n_clean"]):
        add("rig", "normal", None)
    for _ in range(sizes["pkg_n_clean"]):
        add("pkg", "normal", None)
    t_effects = sizes["quick_effects"] or TANGENTIAL
    for e in t_effects:
        n_rig = sizes["rig_t_eff"]
        for i in range(n_rig):
            variant = ("2f" if i % 2 == 0 else "1.37f") if e == "normal_load" else ""
            add("rig", "tangential", e, variant)
        for _ in range(sizes["pkg_t_eff"]):
            add("pkg", "tangential", e)
    for e in NORMAL:
        for _ in range(sizes["rig_n_eff"]):
            add("rig", "normal", e)
        for _ in range(sizes["pkg_n_eff"]):
            add("pkg", "normal", e)
    for e in UNNAMEABLE:
        for _ in range(sizes["unnameable"]):
            add("rig", "tangential", e)
    return cases


# ---------------------------------------------------------------------------------------------
# effect sizes from docs/effects.md, "visible": several times the noise
# ---------------------------------------------------------------------------------------------


def rig_effect(effect, variant, fac, rng, h0=40.0, ac=4.0e4):
    """Parameters of one visible effect for the rig (SI, docs/effects.md)."""
    A = fac["acA"] / ac
    hm = h0 * (1 - math.exp(-fac["acA"]))
    w = 2 * math.pi * fac["f"]
    T = 1 / fac["f"]
    T_rec = fac["cycles"] * T
    sgn = 1.0 if rng.random() < 0.5 else -1.0
    m = 0.10  # relative size of the force change it makes
    if effect is None:
        return {}
    p = {
        "viscous_damping": {"c": m * hm / (A * w)},
        "inertia": {"m": m * hm / (A * w * w)},
        "parallel_stiffness": {"k_p": m * hm / A},
        "series_compliance": {"k_s": h0 * ac * float(rng.uniform(0.7, 1.5))},
        "force_offset": {"F0": sgn * m * hm},
        "force_drift": {"rate": sgn * 1.5 * m * hm / T_rec},
        "displacement_offset": {"x0": sgn * 0.2 * A},
        "channel_delay": {"tau": float(np.clip(0.015 * T, 1e-4, 1.5e-3))},
        "asymmetry": {"a": sgn * m},
        "non_masing_scaling": {"lam": float(rng.uniform(1.3, 1.6))},
        "parameter_drift": {"beta": sgn * 1.5 * m / T_rec},
        "stribeck": {"s": 0.2},
        "position_friction": {
            "eps": m,
            "L": 2 * A * float(rng.uniform(0.5, 1.0)),
            "phi": float(rng.uniform(0, 2 * math.pi)),
        },
        "stick_slip": {"b": 0.2, "d_c": 0.25 * A},
        "normal_load": {
            "eps": m,
            "f_n": (2.0 if variant == "2f" else 1.37) * fac["f"],
            "phi": float(rng.uniform(0, 2 * math.pi)),
        },
        "tanh_virgin": {},
        "power_law_microslip": {"chi": -0.5, "beta": 0.1},
        "backlash": {"b": 0.1 * A},
        "rate_dependent_presliding": {"sigma1": 0.02 * T * h0 * ac},
    }[effect]
    return {effect: p}


def rig_normal_effect(effect, fac, rng, k=1.3e12, pa=0.4e6):
    da = pa / k
    T_rec = max(2, fac["cycles"] // 3) * (1 / fac["f"]) * (1 + 1 / 1.7 + 1 / 0.6)
    sgn = 1.0 if rng.random() < 0.5 else -1.0
    if effect is None:
        return {}
    return {
        effect: {
            # hardening in compression (δ > 0); k + a2·δ stays monotone beyond the stroke
            "stiffness_nonlinearity": {"a2": 0.2 * k / da},
            "hysteretic_damping": {"eta": 0.05},
            "creep_drift": {"D": sgn * 0.3 * da, "tau_c": 0.2 * T_rec},
            "channel_delay": {"tau": 0.015 / fac["f"]},
            "asymmetric_branches": {"a": 0.8},
        }[effect]
    }


# ---------------------------------------------------------------------------------------------
# one case
# ---------------------------------------------------------------------------------------------


def _unexplained(obj):
    """Keys containing 'unexplained' whose flag is set (``{"flagged": bool, ...}``, a bool, or
    any other truthy value): the flag's name is not assumed beyond that."""
    found = []
    if isinstance(obj, dict):
        for key, val in obj.items():
            if "unexplained" in str(key).lower():
                flag = val.get("flagged") if isinstance(val, dict) and "flagged" in val else val
                if flag not in (None, False, [], {}, "", 0):
                    found.append(key)
            found += _unexplained(val)
    elif isinstance(obj, list):
        for v in obj:
            found += _unexplained(v)
    return found


def _init_worker():
    try:
        os.nice(10)
    except OSError:
        pass


# ---------------------------------------------------------------------------------------------
# visible or below the record's power: the stated bound, and an independent criterion
# ---------------------------------------------------------------------------------------------

#: noncentrality above which an effect counts as visible by the independent criterion: a
#: one-degree-of-freedom test at a 3 % false-alarm rate has 95 % power at
#: (1.88 + 1.645)² = 12.4; the diagnosis's two-fold cross-validation sees each half of the
#: record with the effect fitted on the other half, which costs about a factor 2
LAMBDA_VISIBLE = 25.0
#: False: skip the clean twin's diagnosis and the noncentrality (--no-power-view)
POWER_VIEW = True

#: rig parameter -> (the diagnosis's parameter, map of the value); None: no common measure
RIG_TO_DIAGNOSE = {
    "viscous_damping": ("c", "c", lambda v: v),
    "inertia": ("m", "m", lambda v: v),
    "parallel_stiffness": ("k_p", "k_p", lambda v: v),
    "force_offset": ("F0", "F0", lambda v: v),
    "channel_delay": ("tau", "tau", lambda v: v),
    "displacement_offset": ("x0", "x0", lambda v: v),
    "non_masing_scaling": ("lam", "lam", lambda v: v),
    "stribeck": ("s", "s", lambda v: v),
    "series_compliance": ("k_s", "C_s", lambda v: 1.0 / v),
}


def noncentrality(x0, F0, x1, F1, h0, ac, sx, sF):
    """``Σ Δ⊥² / V``: the true effect signature (force with minus without the effect, both
    noise-free, less what the base model predicts from the change of the measured
    displacement) after projecting out the base model's parameter directions (h0, ac),
    against the two-channel effective variance ``σF² + (k σx)²`` (``k`` the base model's
    local slope). Independent of the diagnosis's own bound."""
    from contactlab.masing import Masing

    m0 = Masing(h0, ac).force(x0)
    delta = (F1 - F0) - (Masing(h0, ac).force(x1) - m0)
    d_ac = (Masing(h0, ac * 1.001).force(x0) - Masing(h0, ac * 0.999).force(x0)) / (0.002 * ac)
    J = np.column_stack([m0 / h0, d_ac])
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.abs(np.gradient(m0) / np.gradient(x0))
    k = np.clip(np.nan_to_num(k, nan=h0 * ac, posinf=h0 * ac), 0.0, h0 * ac)
    V = sF**2 + (k * sx) ** 2
    w = 1.0 / np.sqrt(V)
    beta, *_ = np.linalg.lstsq(J * w[:, None], delta * w, rcond=None)
    r = (delta - J @ beta) * w
    return float(np.sum(r[np.isfinite(r)] ** 2))


def truth_size(case, truth):
    """``(parameter, |value - null|)`` of the true effect in the diagnosis's parameter, or
    None where the generators' parameters have no common measure."""
    e = case["effect"]
    p = truth.get(e, {})
    if case["gen"] == "pkg":
        for k, v in p.items():
            if isinstance(v, (int, float)) and k not in ("f_n", "phase", "ell"):
                null = 2.0 if e == "non_masing_scaling" else 0.0
                return k, abs(float(v) - null)
        return None
    if e not in RIG_TO_DIAGNOSE:
        return None
    rk, dk, f = RIG_TO_DIAGNOSE[e]
    null = 2.0 if e == "non_masing_scaling" else 0.0
    return dk, abs(f(float(p[rk])) - null)


def _power_view(case, rec_args, out, diagnose):
    """Fill ``lambda`` (independent), ``clean_bound`` (the bound the diagnosis states on the
    clean twin: same factors and seed, no effect) and ``truth_size`` of a single-effect
    tangential record."""
    e = case["effect"]
    if case["gen"] == "rig":
        from contactlab.synthetic.rig import rig_recording

        eff, kw, noise = rec_args
        quiet = {**kw, "x_noise": 0.0, "F_noise": 0.0, "bits": None}
        r0, r1 = rig_recording({}, "tangential", **quiet), rig_recording(eff, "tangential", **quiet)
        x0, F0, x1, F1 = r0.channels["x"], r0.channels["F"], r1.channels["x"], r1.channels["F"]
        h0, ac = 40.0, 4.0e4
        sx, sF = noise["x"], noise["F"]
        with tempfile.TemporaryDirectory() as tmp:
            import contactlab

            path = rig_recording({}, "tangential", **kw).to_csv(Path(tmp) / "clean.csv")
            clean = contactlab.read_recording(str(path))
    else:
        from contactlab.synthetic.diagnosis import hidden_effect_recording

        effects, kw, noisy = rec_args
        quiet = {**kw, "noise": 0.0, "input_noise": 0.0}
        r0 = hidden_effect_recording({}, **quiet)
        r1 = hidden_effect_recording(effects, **quiet)
        x0, F0 = np.asarray(r0.data["x"]), np.asarray(r0.data["F"])
        x1, F1 = np.asarray(r1.data["x"]), np.asarray(r1.data["F"])
        h0, ac = r0.truth["base"]["h0"], r0.truth["base"]["ac"]
        sx, sF = noisy.truth["noise_rms"]["x"], noisy.truth["noise_rms"]["F"]
        clean = hidden_effect_recording({}, **kw)
    if x0.size == x1.size:
        out["lambda"] = noncentrality(x0, F0, x1, F1, h0, ac, sx, sF)
    rep = diagnose(clean, model="tangential")
    nd = [b for b in rep.not_detected if b.effect == e]
    if nd and not rep.effect_names:
        b = nd[0]
        out["clean_bound"] = {"parameter": b.parameter, "detectable_above": b.detectable_above,
                              "unit": b.unit}  # fmt: skip
    ts = truth_size(case, out.get("truth", {}))
    if ts is not None:
        out["truth_size"] = {"parameter": ts[0], "value": ts[1]}


def run_case(case):
    import warnings

    import contactlab
    from contactlab.synthetic.rig import rig_recording

    try:  # its home after issue 32; the old path is deprecated
        from contactlab.synthetic.diagnosis import hidden_effect_recording
    except ImportError:
        from contactlab.diagnose import hidden_effect_recording

    warnings.simplefilter("ignore")
    fac = case["factors"]
    rng = np.random.default_rng(case["seed"] + 7919)
    kind, effect = case["kind"], case["effect"]
    t0 = time.time()
    c0 = time.process_time()
    out = dict(case)
    try:
        if case["gen"] == "rig":
            if kind == "tangential":
                eff = rig_effect(effect, case["variant"], fac, rng)
                x_drift = float(rng.uniform(-0.003, 0.003))
                sensors = chain_kwargs(case["seed"], fac)
                out["sensors"] = sensors
                rec = rig_recording(
                    eff,
                    "tangential",
                    seed=case["seed"],
                    fs=fac["fs"],
                    f=fac["f"],
                    cycles=fac["cycles"],
                    acA=fac["acA"],
                    x_noise=fac["x_noise"],
                    F_noise=fac["F_noise"],
                    x_drift=x_drift,
                    bits=int(rng.integers(12, 17)),
                    **sensors,
                )
            else:
                eff = rig_normal_effect(effect, fac, rng)
                x_drift = 0.0  # (the normal rig records have no drift; rec_args names it)
                rec = rig_recording(
                    eff,
                    "normal",
                    seed=case["seed"],
                    fs=fac["fs"],
                    f=fac["f"],
                    cycles=max(2, fac["cycles"] // 3),
                    frequencies=(1.0, 1.7, 0.6),
                    x_noise=fac["x_noise"],
                    F_noise=fac["F_noise"],
                    bits=int(rng.integers(12, 17)),
                )
            out["truth"] = {k: v for k, v in eff.items()}
            out["skew"] = rec.truth["chain"]["channel_skew"]
            rec_args = (eff, {"seed": case["seed"], "fs": fac["fs"], "f": fac["f"],
                              "cycles": fac["cycles"], "acA": fac["acA"],
                              "x_noise": fac["x_noise"], "F_noise": fac["F_noise"],
                              "x_drift": x_drift, "bits": rec.truth.get("chain", {}).get("bits"),
                              **(chain_kwargs(case["seed"], fac) if kind == "tangential" else {})},
                        rec.truth["chain"]["noise_rms"])  # fmt: skip

            with tempfile.TemporaryDirectory() as tmp:
                path = rec.to_csv(Path(tmp) / "rec.csv")
                recording = contactlab.read_recording(str(path))
        else:
            effects = {effect: 0.08} if effect else {}
            # three blocks at (1, 1.7, 0.6) f: ~3.25 × spc × cycles per block samples
            spc = max(20, min(round(fac["fs"] / fac["f"]), int(MAX_SAMPLES / (3.25 * 2))))
            cpb = max(2, min(fac["cycles"] // 3, int(MAX_SAMPLES / (3.25 * spc))))
            base = {"f0": fac["f"]} if kind == "tangential" else {}
            kw = {"model": kind, "noise": fac["F_noise"], "seed": case["seed"],
                  "input_noise": fac["x_noise"], "samples_per_cycle": spc,
                  "cycles_per_block": cpb, "start": "rest", **base}  # fmt: skip
            recording = hidden_effect_recording(effects, **kw)
            rec_args = (effects, kw, recording)
            out["pkg_samples"] = int(recording.t.size)
            if kind == "tangential":  # the generator sets its own amplitude: ac·A as made
                ac = recording.truth.get("base", {}).get("ac", 5e4)
                x = np.asarray(recording.data["x"])
                out["factors"] = {
                    **fac,
                    "acA": round(float(ac * np.percentile(np.abs(x), 99.5)), 3),
                }
            out["truth"] = {k: v for k, v in recording.truth.get("effects", {}).items()}
        rep = contactlab.diagnose(recording, model=kind)
        d = rep.to_dict()
        out["named"] = [e["name"] for e in d.get("effects", [])]
        out["params"] = {e["name"]: e.get("parameters", {}) for e in d.get("effects", [])}
        out["unexplained"] = _unexplained(d)
        out["keys"] = sorted(d)
        out["where_last"] = (d.get("where") or [""])[-1][:300]
        # the stated power for the true effect when it was not named (issue 29 item 2)
        if effect and effect not in out["named"]:
            nd = [x for x in d.get("not_detected", []) or [] if x.get("effect") == effect]
            if nd:
                out["bound"] = {k: nd[0].get(k) for k in ("parameter", "detectable_above", "unit")}
        if effect and kind == "tangential" and effect not in UNNAMEABLE and POWER_VIEW:
            try:
                _power_view(case, rec_args, out, contactlab.diagnose)
            except Exception as exc:  # a figure too
                out["power_view_error"] = f"{type(exc).__name__}: {exc}"[:200]
        out["error"] = None
    except Exception as exc:  # a failure is a result, reported as a figure
        out["named"], out["unexplained"], out["error"] = [], [], f"{type(exc).__name__}: {exc}"
        out["params"] = {}
    out["wall"] = time.time() - t0
    out["cpu"] = time.process_time() - c0
    return json.loads(json.dumps(out, default=float))


# ---------------------------------------------------------------------------------------------
# tables
# ---------------------------------------------------------------------------------------------


def _band(value, edges, fmt="{:g}"):
    for lo, hi in itertools.pairwise(edges):
        if lo <= value < hi:
            return f"{fmt.format(lo)}-{fmt.format(hi)}"
    return f"≥{fmt.format(edges[-1])}"


BANDS = {
    "fs [kHz]": (lambda f: f["fs"] / 1000, (1, 2, 5, 10.01)),
    "f [Hz]": (lambda f: f["f"], (1, 5, 20, 50.01)),
    "cycles": (lambda f: f["cycles"], (5, 10, 25, 51)),
    "ac·A": (lambda f: f["acA"], (0.3, 1, 2.5, 5.01)),
    "x noise [%]": (lambda f: 100 * f["x_noise"], (0, 0.5, 1, 1.5, 2.01)),
    "F noise [%]": (lambda f: 100 * f["F_noise"], (0.5, 1, 1.5, 2.01)),
}


def outcome(r):
    if r.get("error"):
        return "error"
    named = set(r["named"])
    e = r["effect"]
    if e is None:
        return "clean-ok" if not named else "false-alarm"
    if e in UNNAMEABLE:
        if named == {e}:  # the library has since gained this candidate
            return "named-exact"
        if r["unexplained"]:
            return "flagged"
        return "absorbed" if named else "silent"
    if named == {e}:
        return "exact"
    if e in named:
        return "extra"
    return "missed" if not named else "wrong"


def tables(results, label):
    lines = [f"## {label}", ""]
    cpu = sum(r["cpu"] for r in results)
    wall = sum(r["wall"] for r in results)
    errors = [r for r in results if r.get("error")]
    lines.append(
        f"{len(results)} records, diagnose CPU {cpu:.0f} s (wall {wall:.0f} s summed over "
        f"workers), slowest {max((r['wall'] for r in results), default=0):.1f} s, "
        f"errors {len(errors)}"
    )
    lines.append("")
    # false alarms
    clean_all = [r for r in results if r["effect"] is None]
    clean = [r for r in clean_all if not r.get("error")]
    lines += ["### False alarms on clean records (fraction with anything named)", ""]
    lines.append("| group | n | false alarms | rate | names | flagged unexplained | errors |")
    lines.append("|---|---|---|---|---|---|---|")
    for key in sorted({(r["gen"], r["kind"]) for r in clean_all}):
        rs = [r for r in clean if (r["gen"], r["kind"]) == key]
        n_err = sum(1 for r in clean_all if (r["gen"], r["kind"]) == key and r.get("error"))
        fa = [r for r in rs if outcome(r) != "clean-ok"]
        fl = sum(bool(r["unexplained"]) for r in rs)
        names = Counter(n for r in fa for n in r["named"])
        lines.append(
            f"| {key[0]} {key[1]} | {len(rs)} | {len(fa)} | {len(fa) / max(len(rs), 1):.0%}"
            f" | {', '.join(f'{k}×{v}' for k, v in names.most_common())} | {fl} | {n_err} |"
        )
    lines.append("")
    lines.append(
        "By factor (clean records of both generators and kinds that ran; ac·A: tangential):"
    )
    lines.append("")
    lines.append("| factor | band | n | false alarms |")
    lines.append("|---|---|---|---|")
    for name, (get, edges) in BANDS.items():
        groups = defaultdict(list)
        for r in clean:
            if name == "ac·A" and r["kind"] != "tangential":
                continue
            groups[_band(get(r["factors"]), edges)].append(r)
        for band in sorted(groups, key=lambda b: float(b.split("-")[0].lstrip("≥"))):
            rs = groups[band]
            fa = sum(outcome(r) != "clean-ok" for r in rs)
            lines.append(f"| {name} | {band} | {len(rs)} | {fa} ({fa / len(rs):.0%}) |")
    lines.append("")
    # by effect
    eff = [r for r in results if r["effect"] is not None and r["effect"] not in UNNAMEABLE]
    lines += ["### By effect (single visible effect)", ""]
    lines.append(
        "| generator | kind | effect | n | exact | named+extra | missed | wrong | error |"
        " confusions (named) |"
    )
    lines.append("|---|---|---|---|---|---|---|---|---|---|")
    keys = sorted(
        {
            (r["gen"], r["kind"], r["effect"] + (f"@{r['variant']}" if r["variant"] else ""))
            for r in eff
        }
    )
    for g, k, e in keys:
        rs = [
            r
            for r in eff
            if (r["gen"], r["kind"]) == (g, k)
            and r["effect"] + (f"@{r['variant']}" if r["variant"] else "") == e
        ]
        c = Counter(outcome(r) for r in rs)
        conf = Counter("+".join(sorted(r["named"])) or "∅" for r in rs if outcome(r) != "exact")
        lines.append(
            f"| {g} | {k} | {e} | {len(rs)} | {c['exact']} | {c['extra']} | "
            f"{c['missed']} | {c['wrong']} | {c['error']} | "
            f"{', '.join(f'{a}×{b}' for a, b in conf.most_common())} |"
        )
    tot = Counter(outcome(r) for r in eff)
    lines.append(
        f"| all | | | {len(eff)} | {tot['exact']} ({tot['exact'] / max(len(eff), 1):.0%})"
        f" | {tot['extra']} | {tot['missed']} | {tot['wrong']} | {tot['error']} | |"
    )
    for g in ("rig", "pkg"):
        rs = [r for r in eff if r["gen"] == g]
        if rs:
            ex = sum(outcome(r) == "exact" for r in rs)
            lines.append(f"| {g} total | | | {len(rs)} | {ex} ({ex / len(rs):.0%}) | | | | | |")
    lines.append("")
    for name in ("x noise [%]", "ac·A", "f [Hz]", "fs [kHz]"):
        get, edges = BANDS[name]
        lines.append(f"Exact rate by {name} (effect records):")
        lines.append("")
        lines.append("| band | rig | pkg |")
        lines.append("|---|---|---|")
        groups = defaultdict(lambda: defaultdict(list))
        for r in eff:
            if r.get("error") or (name == "ac·A" and r["kind"] != "tangential"):
                continue
            groups[_band(get(r["factors"]), edges)][r["gen"]].append(r)
        for band in sorted(groups, key=lambda b: float(b.split("-")[0].lstrip("≥"))):
            cells = []
            for g in ("rig", "pkg"):
                rs = groups[band][g]
                ex = sum(outcome(r) == "exact" for r in rs)
                cells.append(f"{ex}/{len(rs)}" if rs else "–")
            lines.append(f"| {band} | {cells[0]} | {cells[1]} |")
        lines.append("")
    missed = [r for r in eff if outcome(r) in ("missed", "wrong") and r.get("bound")]
    if missed:
        lines += ["Missed effects against the bound the report states (95 % power):", ""]
        lines.append("| generator | effect | truth | named | stated bound |")
        lines.append("|---|---|---|---|---|")
        for r in missed:
            b = r["bound"]
            tr = json.dumps(r.get("truth", {}).get(r["effect"], {}), default=float)[:90]
            lines.append(
                f"| {r['gen']} | {r['effect']} | {tr} | {'+'.join(r['named']) or '∅'} | "
                f"{b.get('parameter')} > {b.get('detectable_above')} {b.get('unit')} |"
            )
        lines.append("")
    lines += visible_tables(eff)
    # unnameable
    un = [r for r in results if r["effect"] in UNNAMEABLE]
    if un:
        lines += ["### Misfits no current candidate names (rig)", ""]
        lines.append(
            "| misfit | n | named exactly (new candidate) | flagged unexplained |"
            " absorbed by a named effect | silent | named |"
        )
        lines.append("|---|---|---|---|---|---|---|")
        for e in UNNAMEABLE:
            rs = [r for r in un if r["effect"] == e]
            c = Counter(outcome(r) for r in rs)
            names = Counter("+".join(sorted(r["named"])) or "∅" for r in rs)
            lines.append(
                f"| {e} | {len(rs)} | {c['named-exact']} | {c['flagged']} | {c['absorbed']} | "
                f"{c['silent']} | "
                f"{', '.join(f'{a}×{b}' for a, b in names.most_common())} |"
            )
        fl = sum(outcome(r) == "flagged" for r in un)
        ne = sum(outcome(r) == "named-exact" for r in un)
        lines.append(
            f"| all | {len(un)} | {ne} | {fl} ({fl / len(un):.0%}); flagged or named exactly "
            f"{fl + ne} ({(fl + ne) / len(un):.0%}) | | | |"
        )
        lines.append("")
    if errors:
        lines += ["### Errors", ""]
        for r in errors[:20]:
            lines.append(
                f"- {r['gen']} {r['kind']} {r['effect']} seed {r['seed']}: {r['error'][:200]}"
            )
        lines.append("")
    return lines


def _vis_bound(r):
    """True/False: the true size above/below the bound stated on the clean twin; None when
    unknown (no bound stated, or no common measure of the size)."""
    b, ts = r.get("clean_bound"), r.get("truth_size")
    if not b or not ts or b.get("parameter") != ts.get("parameter"):
        return None
    if b.get("detectable_above") is None:
        return False  # "not detectable on this record"
    return ts["value"] > b["detectable_above"]


def visible_tables(eff):
    """Exact naming on visible single effects, by the stated bound (on the clean twin) and
    by the independent noncentrality; misses above the stated bound (dishonest bounds)."""
    rs = [r for r in eff if "lambda" in r or "clean_bound" in r]
    if not rs:
        return []
    lines = ["### Visible or below the record's power (single tangential effects)", ""]
    lines.append(
        f"Visible by the bound: true size above the bound diagnose states on the clean twin "
        f"(same factors and seed, no effect). Visible by λ: noncentrality of the true signature "
        f"(with minus without the effect, base directions projected out, two-channel noise) "
        f">= {LAMBDA_VISIBLE:g}."
    )
    lines.append("")
    lines.append(
        "| generator | effect | n | by bound: visible | exact | below | exact | unknown |"
        " by λ: visible | exact | below | exact | median λ |"
    )
    lines.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|")

    def row(g, e, sel):
        vb = [_vis_bound(r) for r in sel]
        ex = [outcome(r) == "exact" for r in sel]
        lam = [r.get("lambda") for r in sel]
        vl = [x is not None and x >= LAMBDA_VISIBLE for x in lam]
        c = {
            "bv": sum(v is True for v in vb),
            "bve": sum(v is True and x for v, x in zip(vb, ex, strict=True)),
            "bb": sum(v is False for v in vb),
            "bbe": sum(v is False and x for v, x in zip(vb, ex, strict=True)),
            "bu": sum(v is None for v in vb),
            "lv": sum(vl),
            "lve": sum(v and x for v, x in zip(vl, ex, strict=True)),
        }
        c["lb"] = len(sel) - c["lv"]
        c["lbe"] = sum(ex) - c["lve"]
        fin = [x for x in lam if x is not None]
        med = f"{np.median(fin):.3g}" if fin else "–"
        return (
            f"| {g} | {e} | {len(sel)} | {c['bv']} | {c['bve']} | {c['bb']} | {c['bbe']} | "
            f"{c['bu']} | {c['lv']} | {c['lve']} | {c['lb']} | {c['lbe']} | {med} |"
        ), c

    tot = Counter()
    for g in ("pkg", "rig"):
        for e in sorted({r["effect"] for r in rs if r["gen"] == g}):
            ln, _ = row(g, e, [r for r in rs if r["gen"] == g and r["effect"] == e])
            lines.append(ln)
        ln, c = row(g, "all", [r for r in rs if r["gen"] == g])
        lines.append(ln)
        tot.update(c)
    ln, c = row("all", "all", rs)
    lines.append(ln)
    lines.append("")
    for what, v, e in (("bound", c["bv"], c["bve"]), ("λ", c["lv"], c["lve"])):
        lines.append(
            f"- exact on visible single effects (by {what}): {e}/{v} "
            f"({100 * e / max(v, 1):.0f} %; bar 90 %)"
        )
    dis = [r for r in rs if _vis_bound(r) is True and outcome(r) in ("missed", "wrong")]
    lines.append(
        f"- missed or named wrongly although the truth exceeds the stated bound (dishonest "
        f"bounds): {len(dis)} of {c['bv']}"
    )
    for r in dis:
        b, ts = r["clean_bound"], r["truth_size"]
        lines.append(
            f"  - {r['gen']} {r['effect']} seed {r['seed']}: truth {ts['parameter']} = "
            f"{ts['value']:.3g} > bound {b['detectable_above']:.3g} {b['unit']}; named "
            f"{'+'.join(r['named']) or '∅'}; λ = {r.get('lambda', float('nan')):.3g}"
        )
    lines.append("")
    lines.append("Exact rate by noncentrality band:")
    lines.append("")
    lines.append("| λ | n | exact |")
    lines.append("|---|---|---|")
    for lo, hi in (
        (0, 12.4),
        (12.4, LAMBDA_VISIBLE),
        (LAMBDA_VISIBLE, 100),
        (100, 1e3),
        (1e3, np.inf),
    ):
        sel = [r for r in rs if r.get("lambda") is not None and lo <= r["lambda"] < hi]
        ex = sum(outcome(r) == "exact" for r in sel)
        lines.append(f"| {lo:g}-{hi:g} | {len(sel)} | {ex} |")
    lines.append("")
    errs = [r for r in rs if r.get("power_view_error")]
    if errs:
        lines.append(f"power view failed on {len(errs)}: {errs[0]['power_view_error']}")
        lines.append("")
    return lines


# ---------------------------------------------------------------------------------------------
# measured records
# ---------------------------------------------------------------------------------------------


def _cli(args, timeout=900):
    t0 = time.time()
    p = subprocess.run(
        ["nice", "-n", "10", *CLI, *args], capture_output=True, text=True, timeout=timeout, cwd=ROOT
    )
    return p, time.time() - t0


def _has_flag(verb, flag):
    p = subprocess.run([*CLI, verb, "--help"], capture_output=True, text=True, cwd=ROOT)
    return flag in p.stdout


def measured_cases(quick, tmp):
    """(label, args for diagnose, args for analyze or None, note)."""
    cases = []
    frame = DATA / "friction_frame"
    if frame.is_dir():
        for f in sorted(frame.glob("*.csv")):
            fr = ["--frame", "3.0799,0.669,1191"]
            cases.append(
                (
                    f"friction_frame/{f.name}",
                    [str(f), "--model", "tangential", *fr],
                    [str(f), "--model", "tangential", *fr],
                    "frame reconstruction",
                )
            )
    tri = DATA / "microtribometer" / "test_data_2.txt"
    if tri.is_file():
        raw = np.genfromtxt(tri, skip_header=1)
        t, x_mm, F_uN = raw[:, 0], raw[:, 2], raw[:, 3]
        keep = (t >= 7.7) & (t <= 209.8)  # the loaded part (README)
        sign_flag = _has_flag("diagnose", "--force-sign")
        path = tmp / "microtribometer.csv"
        F = F_uN[keep] * 1e-6
        note = "x = Position (m), F = Friction (N), t 7.7-209.8 s (loaded)"
        if sign_flag:
            extra = ["--force-sign", "auto"]
            note += ", raw sign with --force-sign auto"
        else:
            F = -F
            extra = []
            note += ", force negated by hand (diagnose has no --force-sign)"
        np.savetxt(
            path,
            np.column_stack([t[keep], x_mm[keep] * 1e-3, F]),
            delimiter=",",
            header="t,x,F",
            comments="",
        )
        an_extra = ["--force-sign", "auto"] if sign_flag else []
        cases.append(
            (
                "microtribometer/test_data_2.txt",
                [str(path), "--model", "tangential", *extra],
                [str(path), "--model", "tangential", *an_extra],
                note,
            )
        )
    damper = DATA / "friction_damper"
    if damper.is_dir():
        idx = range(13) if not quick else (4,)
        for i in idx:
            fx, fF = damper / f"harmonic_test{i}_x.npy", damper / f"harmonic_test{i}_F.npy"
            if not fx.is_file():
                continue
            x = np.load(fx).ravel()
            F = np.load(fF).ravel()
            path = tmp / f"damper_{i}.csv"
            np.savetxt(
                path,
                np.column_stack([np.arange(x.size) / 1024.0, x, F]),
                delimiter=",",
                header="t,x,F",
                comments="",
            )
            cases.append(
                (
                    f"friction_damper/harmonic_test{i}",
                    [str(path), "--model", "tangential"],
                    [str(path), "--model", "tangential"],
                    f"{x.size} samples at 1024 Hz",
                )
            )
    return cases


def measured(quick):
    lines = ["### Measured records in ../shared/data", ""]
    if not DATA.is_dir():
        return [*lines, "../shared/data absent: skipped", ""]
    with tempfile.TemporaryDirectory() as tmpd:
        tmp = Path(tmpd)
        for label, dargs, aargs, note in measured_cases(quick, tmp):
            out = tmp / "d.json"
            p, dt = _cli(["diagnose", *dargs, "--json", str(out)])
            lines.append(f"**{label}** ({note}; {dt:.0f} s)")
            lines.append("")
            if p.returncode != 0 or not out.is_file():
                msg = (p.stderr.strip().splitlines() or ["?"])[-1]
                lines += [f"- diagnose exit {p.returncode}: {msg[:300]}", ""]
                continue
            d = json.loads(out.read_text())
            h0_an = None
            if aargs:
                aout = tmp / "a.json"
                pa, _ = _cli(["analyze", *aargs, "--json", str(aout)])
                if pa.returncode == 0 and aout.is_file():
                    a = json.loads(aout.read_text())
                    a = a[0] if isinstance(a, list) else a
                    a = a.get("results", [a])[0] if isinstance(a.get("results"), list) else a
                    h0_an = a.get("h0")
                    lines.append(f"- analyze: regime {a.get('regime')}, h0 {a.get('h0')}")
            fm = d.get("final_model", {}).get("parameters", {})
            if "h0" in fm:
                rel = f" ({fm['h0'] / h0_an - 1:+.1%} vs analyze)" if h0_an else ""
                lines.append(f"- final model h0 {fm['h0']:.4g}{rel}")
            effs = d.get("effects", [])
            if not effs:
                lines.append("- named: nothing")
            for e in effs:
                extra = {k: v for k, v in e.items() if k not in ("name", "parameters", "stderr")}
                par = ", ".join(
                    f"{k}={v:.4g}"
                    for k, v in e.get("parameters", {}).items()
                    if isinstance(v, (int, float))
                )
                lines.append(
                    f"- named `{e['name']}` ({par})"
                    + (f"; {json.dumps(extra, default=str)[:400]}" if extra else "")
                )
            un = _unexplained(d)
            if un:
                lines.append(f"- unexplained flag: {un}")
            for w in (d.get("where") or [])[:1] + (d.get("where") or [])[-2:]:
                lines.append(f"- where: {w[:400]}")
            lines.append("")
        # the Bouc-Wen benchmark is a structure: identify, then diagnose against it
        bw = DATA / "boucwen" / "train_multisine.csv"
        if bw.is_file():
            raw = np.genfromtxt(bw, delimiter=",", comments="#")
            n = 8192 if quick else 2 * 8192
            path = tmp / "boucwen.csv"
            np.savetxt(
                path,
                np.column_stack([np.arange(n) / 750.0, raw[8192 : 8192 + n]]),
                delimiter=",",
                header="t,u_force_N,y_displacement_m",
                comments="",
            )
            model = tmp / "bw_model.json"
            p, dt = _cli(
                [
                    "identify",
                    str(path),
                    "--joint",
                    "bouc_wen",
                    "--excitation",
                    "force",
                    "--u",
                    "u_force_N",
                    "--y",
                    "y_displacement_m",
                    "--json",
                    str(model),
                ],
                timeout=600,
            )
            lines.append(
                f"**boucwen/train_multisine.csv** (structure; periods 2-{1 + n // 8192},"
                f" identify bouc_wen {dt:.0f} s)"
            )
            lines.append("")
            if p.returncode != 0:
                lines += [
                    f"- identify exit {p.returncode}: "
                    f"{(p.stderr.strip().splitlines() or ['?'])[-1][:300]}",
                    "",
                ]
            else:
                out = tmp / "bw_d.json"
                p, dt = _cli(
                    [
                        "diagnose",
                        str(path),
                        "--structure",
                        str(model),
                        "--u",
                        "u_force_N",
                        "--y",
                        "y_displacement_m",
                        "--json",
                        str(out),
                    ],
                    timeout=900,
                )
                if p.returncode != 0 or not out.is_file():
                    lines.append(
                        f"- diagnose exit {p.returncode}: "
                        f"{(p.stderr.strip().splitlines() or ['?'])[-1][:300]}"
                    )
                else:
                    d = json.loads(out.read_text())
                    names = d.get("effects", [])
                    names = [e if isinstance(e, str) else e.get("name") for e in names]
                    lines.append(
                        f"- named: {names or 'nothing'} ({dt:.0f} s); unexplained: "
                        f"{d.get('unexplained')}"
                    )
                    for w in (d.get("where") or [])[:3]:
                        lines.append(f"- where: {str(w)[:300]}")
                lines.append("")
        lines += [
            "**brake_reuss_beam**: first-harmonic stepped-sine responses (no time record);"
            " `diagnose` takes time records only — not applicable.",
            "",
        ]
    return lines


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="~2 CPU-minutes: a few records")
    ap.add_argument("--seeds", choices=("fresh", "tune"), default="fresh")
    ap.add_argument("--seed-base", type=int, default=None, help="replay a FRESH run")
    ap.add_argument("--jobs", type=int, default=2, help="worker processes (at most 2)")
    ap.add_argument("--scale", type=float, default=1.0, help="records per cell × this")
    ap.add_argument("--no-measured", action="store_true")
    ap.add_argument("--measured-only", action="store_true")
    ap.add_argument("--kinds", default="tangential,normal", help="which kinds of records")
    ap.add_argument(
        "--effects",
        default=None,
        help="comma-separated effects to run (from the plan, seeds unchanged; 'clean' for "
        "the records without an effect)",
    )
    ap.add_argument("--gens", default="rig,pkg", help="generators to run (rig, pkg)")
    ap.add_argument("--chain", choices=("plain", "sensors"), default=None,
                    help="rig chain: plain, or sensors (LVDT low-pass, piezo/strain-gauge cell, "
                    "Bessel, hum, jitter, drive harmonics; see chain_kwargs)")  # fmt: skip
    ap.add_argument("--label", default="")
    ap.add_argument("--out", type=Path, default=None, help="also write the tables here")
    ap.add_argument("--raw", type=Path, default=None, help="write per-record results (JSON)")
    ap.add_argument(
        "--tables-from",
        type=Path,
        nargs="+",
        default=None,
        help="print the tables of saved --raw results (merged) and stop",
    )
    args = ap.parse_args(argv)
    if args.chain:
        os.environ[CHAIN_ENV] = args.chain
    jobs = max(1, min(2, args.jobs))
    if args.tables_from:
        results = [r for p in args.tables_from for r in json.loads(p.read_text())]
        text = "\n".join(tables(results, args.label or "saved results"))
        print(text)
        if args.out:
            args.out.write_text(text + "\n")
        return
    os.environ.setdefault("CONTACTLAB_DIAGNOSE_THREADS", "1")
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")
    if args.seed_base is not None:
        base = args.seed_base
    elif args.seeds == "tune":
        base = TUNE_BASE
    else:
        base = 10_000_000 + (int(time.time()) % 1_000_000) * 1000
    mode = "quick" if args.quick else "full"
    if args.measured_only:
        text = "\n".join(
            [
                f"## {args.label} measured records, "
                f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}",
                "",
                *measured(args.quick),
            ]
        )
        print(text)
        if args.out:
            args.out.write_text(text + "\n")
        return
    kinds = set(args.kinds.split(","))
    cases = [c for c in plan(mode, base, args.scale) if c["kind"] in kinds]
    if args.effects:
        wanted = set(args.effects.split(","))
        cases = [c for c in cases if (c["effect"] or "clean") in wanted]
    gens = set(args.gens.split(","))
    cases = [c for c in cases if c["gen"] in gens]
    print(
        f"seeds: {args.seeds} base {base} ({len(cases)} records, mode {mode}, jobs {jobs})",
        flush=True,
    )
    t0 = time.time()
    with ProcessPoolExecutor(max_workers=jobs, initializer=_init_worker) as pool:
        results = []
        for i, r in enumerate(pool.map(run_case, cases, chunksize=1), 1):
            results.append(r)
            if i % 10 == 0 or i == len(cases):
                print(
                    f"  {i}/{len(cases)} records, {time.time() - t0:.0f} s",
                    file=sys.stderr,
                    flush=True,
                )
    head = (
        f"{args.label} seeds {args.seeds} base {base}, {mode}, "
        f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, wall {time.time() - t0:.0f} s"
    )
    lines = tables(results, head)
    if not args.no_measured:
        lines += measured(args.quick)
    text = "\n".join(lines)
    print(text)
    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(text + "\n")
    if args.raw:
        args.raw.parent.mkdir(parents=True, exist_ok=True)
        args.raw.write_text(json.dumps(results, indent=1, default=float))


if __name__ == "__main__":
    main()
