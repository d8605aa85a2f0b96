"""The ideal test of a normal-contact effect against the package's stated bound (issue 29).

A single-tone record ``p = p0 + pa sin ωt`` from ``t = 0`` (the joint at rest under ``p0``,
δ from the package's Kelvin-Voigt solve or an effect's, :mod:`contactlab.diagnose.
candidates_normal`), white noise on both channels as a fraction of each channel's range.

The ideal test (:func:`ideal_size`): weighted least squares with weights
``1/(σ_δ² + (dδ/dp)² σ_p²)`` (``dδ/dp`` the joint's static compliance ``1/k``), the effect's
noise-free linearised direction as the regressor after the Kelvin-Voigt base (k, ψ, p0) is
refitted (projected out) and the nearest other candidate's direction (the one leaving the
least) is projected off; the effect is visible at noncentrality ``λ >= 44.8``, i.e. at
``|θ| >= sqrt(44.8 / Σ w j⊥²)``.

The package's bound comes from ``contactlab.diagnose`` on the noisy clean record
(``not_detected``), optionally with parts of the bound's model switched off
(``--ablate``: what each rule costs), and its ratio to the ideal size is printed.

    nice .venv/bin/python benches/eval_normal_ideal.py --set blind --seed 49700000
"""

from __future__ import annotations

import argparse
import json
import math
import warnings
from pathlib import Path

import numpy as np

LAMBDA_VISIBLE = 44.8
K, P0 = 1.3e12, 5e5
#: ψ and pa of the records (``--psi``, ``--naming`` draws them per record)
PSI, PA = 0.0887, 0.5 * P0

#: the conditions of the issue's misses: (fs, f, cycles, x noise, y noise)
BLIND = {
    "stiff_2k_5.4": (2000.0, 5.4, 50, 0.016, 0.007),
    "stiff_5k_2.8": (5000.0, 2.8, 8, 0.013, 0.010),
    "asym_2k_34.7": (2000.0, 34.7, 35, 0.012, 0.012),
    "creep_5k_4.6": (5000.0, 4.6, 8, 0.012, 0.012),
    "creep_2k_30": (2000.0, 30.0, 12, 0.012, 0.012),
    "creep_10k_17.3": (10000.0, 17.3, 20, 0.012, 0.012),
    "creep_1k_13.9": (1000.0, 13.9, 20, 0.012, 0.012),
    "creep_1k_11.8": (1000.0, 11.8, 20, 0.012, 0.012),
    "asym_10k_21.8": (10000.0, 21.8, 12, 0.012, 0.012),
    "asym_5k_4.0": (5000.0, 4.0, 12, 0.012, 0.012),
}
#: stop 52: the blind misses of issue 29's normal family as the brief gives them:
#: (fs, f, cycles, p noise, δ noise, pa/p0) (noise fractions of each channel's range)
BLIND52 = {
    "stiff_5k_29.4": (5000.0, 29.4, 35, 0.017, 0.011, 0.37),
    "stiff_5k_3.3": (5000.0, 3.3, 8, 0.012, 0.013, 0.51),
    "stiff_1k_1.8": (1000.0, 1.8, 35, 0.009, 0.005, 0.45),
    "stiff_2k_6.1": (2000.0, 6.1, 50, 0.019, 0.017, 0.24),
    "creep_10k_16.3": (10000.0, 16.3, 12, 0.011, 0.018, 0.66),
    "creep_1k_1.1": (1000.0, 1.1, 12, 0.020, 0.013, 0.70),
    "creep_1k_2.7": (1000.0, 2.7, 5, 0.017, 0.012, 0.26),
    "asym_1k_2.6": (1000.0, 2.6, 12, 0.007, 0.005, 0.62),
    "asym_5k_10.5": (5000.0, 10.5, 8, 0.016, 0.017, 0.36),
    "asym_2k_7.9": (2000.0, 7.9, 8, 0.013, 0.011, 0.57),
}
#: stop 53: the blind misses as the brief gives them: (fs, f, cycles, p noise, δ noise,
#: pa/p0 or None when not given)
BLIND53 = {
    "asym_2k_3.7": (2000.0, 3.7, 12, 0.007, 0.006, None),
    "asym_5k_10.5": (5000.0, 10.5, 8, 0.016, 0.017, None),
    "asym_2k_7.9": (2000.0, 7.9, 8, 0.013, 0.011, None),
    "stiff_5k_4.2": (5000.0, 4.2, 8, 0.007, 0.008, None),
    "stiff_1k_1.8": (1000.0, 1.8, 35, 0.009, 0.005, None),
    "stiff_2k_6.1": (2000.0, 6.1, 50, 0.019, 0.017, None),
    "creep_1k_1.1": (1000.0, 1.1, 12, 0.020, 0.013, None),
}
EFFECTS = ("creep_drift", "stiffness_nonlinearity", "asymmetric_branches")


def condition_set(name):
    """``{key: (fs, f, cycles, p noise, δ noise, pa/p0 or None)}`` of ``--set``."""
    if name == "blind52":
        return BLIND52
    if name == "blind53":
        return BLIND53
    return {k: (*v, None) for k, v in BLIND.items()}


def signals(fs, f, cycles, effect=None, size=0.0, tau_c=None, law="kappa1"):
    """Noise-free ``(t, p, δ, δ_r)``; ``size`` in the diagnosis's parameter (``D`` in m,
    ``kappa1``/``kappa`` relative to the clean δ's RMS δ_r, ``a``)."""
    from contactlab.diagnose.candidates_normal import (
        kelvin_voigt,
        kelvin_voigt_asymmetric,
        nonlinear_viscous,
    )

    n = round(cycles * fs / f)
    t = np.arange(n) / fs
    omega = 2 * math.pi * f
    pd = PA * np.sin(omega * t)
    d0 = kelvin_voigt(t, pd, K, PSI, omega)
    dr = float(np.sqrt(np.mean(d0 * d0)))
    if effect == "stiffness_nonlinearity" and size:
        co = (K, K * size / dr, 0.0) if law == "kappa1" else (K, 0.0, K * size / dr**2)
        d = nonlinear_viscous(t, pd, co, PSI, omega, passes=8)
    elif effect == "asymmetric_branches" and size:
        d = kelvin_voigt_asymmetric(t, pd, K, PSI, omega, size, passes=50, tol=1e-12)
    else:
        d = d0.copy()
    if effect == "creep_drift" and size:
        d = d + size * -np.expm1(-t / tau_c)
    return t, P0 + pd, d, dr


def directions(t, p, f, dr, tau_c):
    """Base columns (k, ψ, p0) and each candidate's unit directions at its null."""
    from contactlab.diagnose.candidates_normal import (
        kelvin_voigt,
        kelvin_voigt_asymmetric,
        nonlinear_viscous,
    )

    omega = 2 * math.pi * f
    pd = p - P0
    y0 = kelvin_voigt(t, pd, K, PSI, omega)
    base = np.column_stack([
        (kelvin_voigt(t, pd, K * 1.001, PSI, omega) - kelvin_voigt(t, pd, K * 0.999, PSI, omega))
        / 0.002,
        (kelvin_voigt(t, pd, K, PSI * 1.001, omega) - kelvin_voigt(t, pd, K, PSI * 0.999, omega))
        / 0.002,
        kelvin_voigt(t, np.full_like(pd, -1.0), K, PSI, omega) * PA,
    ])  # fmt: skip
    e = 2e-3
    j1 = (
        nonlinear_viscous(t, pd, (K, e * K / dr, 0.0), PSI, omega, passes=8)
        - nonlinear_viscous(t, pd, (K, -e * K / dr, 0.0), PSI, omega, passes=8)
    ) / (2 * e)
    j2 = (
        nonlinear_viscous(t, pd, (K, 0.0, e * K / dr**2), PSI, omega, passes=8)
        - nonlinear_viscous(t, pd, (K, 0.0, -e * K / dr**2), PSI, omega, passes=8)
    ) / (2 * e)
    ea = 0.01
    ja = (
        kelvin_voigt_asymmetric(t, pd, K, PSI, omega, ea, passes=50, tol=1e-12)
        - kelvin_voigt_asymmetric(t, pd, K, PSI, omega, -ea, passes=50, tol=1e-12)
    ) / (2 * ea)
    cand = {
        "kappa1": j1,
        "kappa": j2,
        "stiffness_nonlinearity": np.column_stack([j1, j2]),
        "asymmetric_branches": ja,
        "creep_drift": -np.expm1(-t / tau_c),
        "channel_delay": -np.gradient(y0, t),
    }
    return base, cand


def _resid(s, X, sw):
    X = X[:, None] if X.ndim == 1 else X
    a = X * sw[:, None]
    beta, *_ = np.linalg.lstsq(a, s * sw, rcond=None)
    return s - X @ beta


_CACHE: dict = {}


def ideal_size(fs, f, cycles, xn, yn, which, tau_c):
    """``(ideal |θ|, nearest other candidate, share of the direction left)`` of ``which``
    (``creep_drift``'s D in m at ``tau_c``, ``kappa1``, ``kappa``, ``asymmetric_branches``'s
    a) on the noise-free record."""
    key = (fs, f, cycles, tau_c, PSI, PA)
    if key not in _CACHE:
        t, p, d, dr = signals(fs, f, cycles)
        _CACHE.clear()
        _CACHE[key] = (t, p, d, *directions(t, p, f, dr, tau_c))
    t, p, d, base, cand = _CACHE[key]
    sp, sd = xn * np.ptp(p), yn * np.ptp(d)
    w = np.full(t.size, 1.0 / (sd * sd + (sp / K) ** 2))
    sw = np.sqrt(w)
    j = cand[which]
    own = {"kappa1": "stiffness_nonlinearity", "kappa": "stiffness_nonlinearity"}.get(which, which)
    jb = _resid(j, base, sw)
    lam = {}
    for other, X in cand.items():
        if other in (own, which, "kappa1", "kappa"):
            continue
        r = _resid(j, np.column_stack([base, X]), sw)
        lam[other] = float(np.sum(w * r * r))
    nearest = min(lam, key=lam.get)
    left = lam[nearest] / float(np.sum(w * jb * jb))
    return math.sqrt(LAMBDA_VISIBLE / lam[nearest]), nearest, left


def noisy(fs, f, cycles, xn, yn, seed, effect=None, size=0.0, tau_c=None, law="kappa1"):
    t, p, d, _ = signals(fs, f, cycles, effect, size, tau_c, law)
    rng = np.random.default_rng(seed)
    return (
        t,
        p + rng.normal(0, xn * np.ptp(p), t.size),
        d + rng.normal(0, yn * np.ptp(d), t.size),
    )


def diagnose(t, p, d):
    import contactlab

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = contactlab.diagnose({"t": t, "p": p, "delta": d}, "normal")
    return r


def bounds_of(rep, seed=0):
    from contactlab.diagnose.power import stated_power

    out = {}
    for b in stated_power(rep, seed=seed):
        bd = b.to_dict()
        out[bd["effect"]] = bd
    return out


ABLATIONS = {
    "none": {},
    "no_scatter": {"power.GAIN_SCATTER": 0.0},
    "no_floor": {"floor": 0.0},
    "z2": {"z": 2.0},
    "no_ident": {"ident": 0.0},
    "no_margin": {"margin": 1.0},
    "no_rival_z": {"rival_z": 0.0},
    "no_infl": {"infl": 1.0},
    "no_strong": {"strong": None},
}


def ablated_bounds(rep, what):
    """The bounds stated with one part of the bound's model switched off."""
    from contactlab.diagnose import power

    saved = {}
    try:
        if "power.GAIN_SCATTER" in what:
            saved["GAIN_SCATTER"] = power.GAIN_SCATTER
            power.GAIN_SCATTER = what["power.GAIN_SCATTER"]
        if "floor" in what:
            saved["_own_floor"] = power._own_floor
            power._own_floor = lambda fam, n, d, st, *at: power.dataclasses.replace(
                st, gain_floor=1e-9, rel_floor=0.0
            )
        if "ident" in what:
            saved["identified_sigmas"] = power.identified_sigmas
            power.identified_sigmas = lambda fam, n: 0.0
        if "margin" in what:
            saved["power_margin"] = power.power_margin
            power.power_margin = lambda fam, n: 1.0
        if "rival_z" in what:
            from contactlab.diagnose.effects.normal import asymmetric_branches as ab
            from contactlab.diagnose.effects.normal import stiffness_nonlinearity as sn

            for cls in (ab.AsymmetricBranches, sn.StiffnessNonlinearity):
                saved.setdefault("rival_z", []).append((cls, cls.rival_z))
                cls.rival_z = what["rival_z"]
        if "infl" in what:
            saved["correlation_time"] = power.correlation_time
            power.correlation_time = lambda r, lag: 1.0
        if "strong" in what:
            saved["_strong_route"] = power._strong_route
            power._strong_route = lambda fam, n, z: None
        if "z" in what:
            rep.location.setdefault("detection", {})
            saved["z"] = rep.location["detection"].get("z", 3.0)
            rep.location["detection"]["z"] = what["z"]
        return bounds_of(rep, seed=1)
    finally:
        for k, v in saved.items():
            if k == "z":
                rep.location["detection"]["z"] = v
            elif k == "rival_z":
                for cls, z0 in v:
                    cls.rival_z = z0
            else:
                setattr(power, k, v)


def naming(a) -> None:
    """Named at ``--factors`` times the ideal size, per condition of :data:`BLIND` with ψ
    drawn in 0.08-0.3 and pa/p0 in 0.3-0.8 (seeded), and the clean twin."""
    global PSI, PA
    rows, tally = [], {}
    facs = [float(x) for x in a.factors.split(",")]
    for i, (key, (fs, f, cyc, xn, yn, ratio)) in enumerate(condition_set(a.set).items()):
        if a.only and a.only not in key:
            continue
        seed = a.seed + i
        rng = np.random.default_rng(seed)
        PSI, PA = float(rng.uniform(*a.psi_range)), float(rng.uniform(0.3, 0.8)) * P0
        PA = PA if ratio is None else ratio * P0
        t, p, d = noisy(fs, f, cyc, xn, yn, seed)
        rep = diagnose(t, p, d)
        clean = list(rep.effect_names)
        flagged = bool(rep.to_dict().get("unexplained", {}).get("flagged", False))
        tally.setdefault("clean", {}).setdefault("quiet" if not clean else "named", 0)
        tally["clean"]["quiet" if not clean else "named"] += 1
        tau = 0.25 * float(t[-1])
        bnd = bounds_of(rep)
        tau = (bnd.get("creep_drift", {}).get("at") or {}).get("tau_c") or tau
        row = {"key": key, "seed": seed, "psi": PSI, "pa": PA, "clean": clean,
               "flagged": flagged, "runs": []}  # fmt: skip
        print(f"{key:16s} seed {seed} ψ {PSI:.3f} pa/p0 {PA / P0:.2f} clean {clean} "
              f"flagged {flagged}", flush=True)  # fmt: skip
        for e, par in (("stiffness_nonlinearity", "kappa1"), ("asymmetric_branches", "a"),
                       ("creep_drift", "D")):  # fmt: skip
            if e not in a.effects.split(","):
                continue
            ideal, near, left = ideal_size(fs, f, cyc, xn, yn, par if par == "kappa1" else e, tau)
            b = (bnd.get(e, {}).get("per_parameter") or {}).get(par)
            for fac in facs:
                size = fac * ideal * float(rng.choice([-1, 1]))
                span = {"kappa1": 0.4, "a": 0.95}.get(par, np.inf)
                if abs(size) >= span:
                    print(f"   {par:7s} {fac:g}x ideal {ideal:.3g}: beyond the range", flush=True)
                    key2 = f"{e} {fac:g}x"
                    tally.setdefault(key2, {}).setdefault("beyond range", 0)
                    tally[key2]["beyond range"] += 1
                    continue
                tn, pn, dn = noisy(fs, f, cyc, xn, yn, seed + 1000, e, size, tau)
                r2 = diagnose(tn, pn, dn)
                nm = list(r2.effect_names)
                res = (
                    "exact" if nm == [e] else "extra" if e in nm else "missed" if not nm
                    else "wrong"
                )  # fmt: skip
                key2 = f"{e} {fac:g}x"
                tally.setdefault(key2, {}).setdefault(res, 0)
                tally[key2][res] += 1
                row["runs"].append({"effect": e, "factor": fac, "size": size, "ideal": ideal,
                                    "bound": b, "named": nm, "result": res})  # fmt: skip
                bs = "none" if b is None else f"{b:.3g}"
                print(f"   {par:7s} {fac:g}x ideal {ideal:.3g} (bound {bs}, near {near} "
                      f"{left:.2f}) size {size:+.3g} -> {nm} {res}", flush=True)  # fmt: skip
        rows.append(row)
        if a.out:
            Path(a.out).write_text(json.dumps(rows, indent=1, default=str))
    print()
    for k2, c in tally.items():
        print(f"{k2:30s} " + " ".join(f"{k} {n}" for k, n in sorted(c.items())))


CHAIN_KEYS = ("stiff_2k_5.4", "stiff_5k_2.8", "asym_2k_34.7", "asym_10k_21.8", "asym_5k_4.0")


def naming_chain(a) -> None:
    """As :func:`naming` on ``benches/chain_normal.py``'s chain (actuator from rest, LVDT,
    pressure cell, Bessel anti-alias, hum, jitter, ADC) at the conditions of
    :data:`CHAIN_KEYS`, the ideal size from its ``noncentrality`` (λ 44.8, the base and the
    nearest other candidate projected out); stiffness as the κ1-type law ``a2``."""
    import sys

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from chain_normal import chain_record, noncentrality

    facs = [float(x) for x in a.factors.split(",") if x]
    tally: dict = {}
    rows = []
    conds = (
        condition_set(a.set)
        if a.set in ("blind52", "blind53")
        else {k: (*BLIND[k], None) for k in CHAIN_KEYS}
    )
    for i, (key, (fs, f, cyc, xn, yn, ratio)) in enumerate(conds.items()):
        if a.only and a.only not in key:
            continue
        seed = a.seed + i
        rng = np.random.default_rng(seed)
        fac = {"fs": fs, "f": f, "cycles": cyc, "ratio": float(rng.uniform(0.3, 0.8)),
               "noise_p": xn, "noise_d": yn, "bits": 16,
               "psi": float(rng.uniform(*a.psi_range)), "law": a.law}  # fmt: skip
        fac["ratio"] = fac["ratio"] if ratio is None else ratio
        if a.noise_stage:
            fac["noise_stage"] = a.noise_stage
        t, p, d, cl = chain_record(None, 0.0, fac, seed)
        rep = diagnose(t, p, d)
        clean = list(rep.effect_names)
        flagged = bool(rep.to_dict().get("unexplained", {}).get("flagged", False))
        bnd = bounds_of(rep)
        tcb = (bnd.get("creep_drift", {}).get("at") or {}).get("tau_c")
        if tcb:
            fac["tau_c"] = float(tcb)
        # the bound in the chain's own sizes (size = bound × factor): κ1 = size·δ_r/D
        # (a2 = κ1 k/δ_r), a as is, creep relative to D
        d_r = float(np.sqrt(np.mean((d - np.mean(d)) ** 2)))
        conv = {
            "stiffness_nonlinearity": ("kappa1", cl["D"] / d_r),
            "asymmetric_branches": ("a", 1.0),
            "creep_drift": ("D", 1.0 / cl["D"]),
        }
        res_c = "quiet" if not clean else "named"
        tally.setdefault("clean", {}).setdefault(res_c, 0)
        tally["clean"][res_c] += 1
        tally.setdefault("clean flagged", {}).setdefault(str(flagged), 0)
        tally["clean flagged"][str(flagged)] += 1
        print(f"{key:16s} seed {seed} ψ {fac['psi']:.3f} pa/p0 {fac['ratio']:.2f} clean {clean}"
              f" flagged {flagged}", flush=True)  # fmt: skip
        row = {"key": key, "seed": seed, "fac": fac, "clean": clean, "runs": []}
        for e, ref, span in (("stiffness_nonlinearity", 0.01, 0.4),
                             ("asymmetric_branches", 0.3, 0.95),
                             ("creep_drift", 0.01, np.inf)):  # fmt: skip
            if e not in a.effects.split(","):
                continue
            lam, _, near = noncentrality(e, ref, fac, seed)
            ideal = ref * math.sqrt(LAMBDA_VISIBLE / lam)
            par, cf = conv[e]
            b = (bnd.get(e, {}).get("per_parameter") or {}).get(par)
            rb = None if b is None else round(b * cf / ideal, 2)
            print(f"   {e[:5]} ideal {ideal:.3g} bound/ideal {rb}", flush=True)
            if a.ablate:
                for nm_ab, what in ABLATIONS.items():
                    bab = (ablated_bounds(rep, what).get(e, {}).get("per_parameter") or {}).get(par)
                    rab = None if bab is None else round(bab * cf / ideal, 2)
                    tally.setdefault(f"{e} bound/ideal {nm_ab}", {}).setdefault("values", [])
                    tally[f"{e} bound/ideal {nm_ab}"]["values"].append(rab)
            tally.setdefault(f"{e} bound/ideal", {}).setdefault("values", [])
            tally[f"{e} bound/ideal"]["values"].append(rb)
            for fc in facs:
                size = fc * ideal * float(rng.choice([-1, 1]))
                k2 = f"{e} {fc:g}x"
                if abs(size) >= span:
                    tally.setdefault(k2, {}).setdefault("beyond range", 0)
                    tally[k2]["beyond range"] += 1
                    print(f"   {e[:5]} {fc:g}x ideal {ideal:.3g}: beyond the range", flush=True)
                    continue
                tn, pn, dn, _ = chain_record(e, size, fac, seed + 1000)
                r2 = diagnose(tn, pn, dn)
                nm = list(r2.effect_names)
                fl = bool(r2.to_dict().get("unexplained", {}).get("flagged", False))
                res = "flagged " if fl and e not in nm else ""
                res = res + (
                    "exact" if nm == [e] else "extra" if e in nm else "missed" if not nm
                    else "wrong"
                )  # fmt: skip
                tally.setdefault(k2, {}).setdefault(res, 0)
                tally[k2][res] += 1
                row["runs"].append({"effect": e, "factor": fc, "size": size, "ideal": ideal,
                                    "near": near, "named": nm, "result": res})  # fmt: skip
                print(f"   {e[:5]} {fc:g}x ideal {ideal:.3g} (near {near}) size {size:+.3g} -> "
                      f"{nm} {res}", flush=True)  # fmt: skip
        rows.append(row)
        if a.out:
            Path(a.out).write_text(json.dumps(rows, indent=1, default=str))
    print()
    for k2, c in tally.items():
        print(f"{k2:30s} " + " ".join(f"{k} {n}" for k, n in sorted(c.items())))


def main() -> None:
    global PSI, PA
    ap = argparse.ArgumentParser()
    ap.add_argument("--chain", action="store_true")
    ap.add_argument("--naming", action="store_true")
    ap.add_argument("--factors", default="1,2")
    ap.add_argument("--effects", default="stiffness_nonlinearity,asymmetric_branches,creep_drift")
    ap.add_argument("--set", default="blind")
    ap.add_argument("--only", default=None)
    ap.add_argument("--seed", type=int, default=49700000)
    ap.add_argument("--ablate", action="store_true")
    ap.add_argument("--psi", type=float, default=PSI)
    ap.add_argument("--law", default="a2")
    #: the chain's noise: "analog" (before the anti-alias filter, band-limited) or white
    ap.add_argument("--noise-stage", default=None)
    ap.add_argument("--psi-range", type=lambda v: tuple(float(x) for x in v.split(",")),
                    default=(0.08, 0.3))  # fmt: skip
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    if a.naming:
        (naming_chain if a.chain else naming)(a)
        return
    rows = []
    PSI = a.psi
    for i, (key, (fs, f, cyc, xn, yn, ratio)) in enumerate(condition_set(a.set).items()):
        if a.only and a.only not in key:
            continue
        seed = a.seed + i
        PA = 0.5 * P0 if ratio is None else ratio * P0
        t, p, d = noisy(fs, f, cyc, xn, yn, seed)
        rep = diagnose(t, p, d)
        bnd = bounds_of(rep)
        row = {"key": key, "seed": seed, "named": list(rep.effect_names), "ratio": {}}
        tau = (bnd.get("creep_drift", {}).get("at") or {}).get("tau_c") or 0.25 * t[-1]
        line = f"{key:16s} seed {seed} clean named {row['named']}:"
        for e, par in (("creep_drift", "D"), ("stiffness_nonlinearity", "kappa1"),
                       ("stiffness_nonlinearity", "kappa"),
                       ("asymmetric_branches", "a")):  # fmt: skip
            ideal, near, left = ideal_size(fs, f, cyc, xn, yn, par if par.startswith("kappa")
                                           else e, tau)  # fmt: skip
            b = (bnd.get(e, {}).get("per_parameter") or {}).get(par)
            r = None if b is None else b / ideal
            why = bnd.get(e, {}).get("reason", "")
            row["ratio"][par] = {"ideal": ideal, "bound": b, "ratio": r, "nearest": near,
                                 "left": left, "reason": why}  # fmt: skip
            rs = None if r is None else round(r, 2)
            line += f" {par} {rs} (ideal {ideal:.3g}, near {near} {left:.2f})"
        print(line, flush=True)
        if a.ablate:
            for nm, what in ABLATIONS.items():
                ab = ablated_bounds(rep, what)
                parts = []
                for e, par in (("creep_drift", "D"), ("stiffness_nonlinearity", "kappa1"),
                               ("asymmetric_branches", "a")):  # fmt: skip
                    b = (ab.get(e, {}).get("per_parameter") or {}).get(par)
                    i0 = row["ratio"][par]["ideal"]
                    parts.append(f"{par} {None if b is None else round(b / i0, 2)}")
                row.setdefault("ablate", {})[nm] = parts
                print(f"    {nm:10s} " + " ".join(parts), flush=True)
        rows.append(row)
        if a.out:
            Path(a.out).write_text(json.dumps(rows, indent=1, default=str))


if __name__ == "__main__":
    main()
