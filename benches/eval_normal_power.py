"""Power of the normal-contact diagnosis against what the data hold (issue 29, items 1-3).

On records of ``chain_normal`` (an actuator from rest, sensors, Bessel filters, hum, jitter,
ADC, 0.5-2 % noise per channel, fs 1-10 kHz, 5-50 cycles, one tone): for each effect the size
that its noncentrality needs (λ = 44.8 with the base and the nearest other candidate
projected out), the bound ``diagnose`` states on the clean twin over that size, and what is
named with the effect hidden at ``--factor`` times the needed size. Clean records: names.

    nice .venv/bin/python benches/eval_normal_power.py --seeds 0-7 --factor 1.5
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
import warnings
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from chain_normal import EFFECTS, LAMBDA_VISIBLE, chain_record, draw_factors, noncentrality

#: reference sizes (docs parameters): a2 relative, creep D relative to the amplitude, a, τ (s)
REF = {"stiffness_nonlinearity": 0.1, "creep_drift": 0.1, "asymmetric_branches": 0.5,
       "channel_delay": 1e-4}  # fmt: skip
#: largest size the chain holds (a stiffness that stays positive, |a| < 1, 5 % of a period)
CAP = {
    "stiffness_nonlinearity": lambda f: 0.45,
    "creep_drift": lambda f: 3.0,
    "asymmetric_branches": lambda f: 0.9,
    "channel_delay": lambda f: 0.05 / f["f"],
}
#: the report's parameter per effect and how its bound compares with the chain's size
PARAM = {"stiffness_nonlinearity": "kappa", "creep_drift": "D", "asymmetric_branches": "a",
         "channel_delay": "tau"}  # fmt: skip


#: hide the effects at ``--factor`` times the stated bound instead of the needed size
AT_BOUND = False
#: keyword arguments passed to diagnose (``--min-gain``)
KW: dict = {}


def diagnose(t, p, d):
    import contactlab

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = contactlab.diagnose({"t": t, "p": p, "delta": d}, "normal", **KW)
    names = list(r.effect_names)
    bounds = {}
    for b in r.not_detected:
        bd = b.to_dict()
        bounds[bd["effect"]] = bd
    return names, bounds, r


def bound_in_chain_units(effect, bd, clean, r=None):
    """The stated bound in the chain's size units (a2·D/k for the stiffness, D/D_amp)."""
    v = bd.get("detectable_above")
    if v is None:
        return math.inf
    if effect == "stiffness_nonlinearity":
        # kappa: k_s = k(1 + κ1 δ/δ_r + κ(δ/δ_r)²); the chain's a2 = s k / D ⇒ κ1 = s δ_r / D
        dr = float(np.sqrt(np.mean((clean["delta"] - np.mean(clean["delta"])) ** 2)))
        per = bd.get("per_parameter", {})
        k1 = per.get("kappa1", v)
        return float(k1) * clean["D"] / dr if k1 is not None else math.inf
    if effect == "creep_drift":
        return v / clean["D"]
    return float(v)


def run(seed, factor, effects):
    rng = np.random.default_rng(10_000 + seed)
    fac = draw_factors(rng)
    out = {"seed": seed, "fac": fac, "effects": {}}
    t0 = time.process_time()
    t, p, d, clean = chain_record(None, 0.0, fac, seed)
    names, bounds, _ = diagnose(t, p, d)
    out["clean_names"] = names
    out["n"] = int(t.size)
    for e in effects:
        lam, lam_base, nearest = noncentrality(e, REF[e], fac, seed)
        need = REF[e] * math.sqrt(LAMBDA_VISIBLE / lam) if lam > 0 else math.inf
        b = bounds.get(e, {})
        bc = bound_in_chain_units(e, b, clean) if b else math.nan
        # --at-bound: the effect hidden at `factor` times the bound stated on the clean twin
        size = factor * (bc if AT_BOUND else need)
        if not np.isfinite(size):
            out["effects"][e] = {"lam_ref": lam, "lam_base": lam_base, "nearest": nearest,
                                 "need": need, "bound": bc, "ratio": bc / need, "size": size,
                                 "named": ["(no bound)"]}  # fmt: skip
            continue
        if size > CAP[e](fac):  # not reachable: the joint or the chain would not hold it
            nm = ["(beyond reach)"]
        else:
            tt, pp, dd, _ = chain_record(e, size, fac, seed + 500)
            nm, _, _ = diagnose(tt, pp, dd)
        out["effects"][e] = {"lam_ref": lam, "lam_base": lam_base, "nearest": nearest,
                             "need": need, "bound": bc, "ratio": bc / need, "size": size,
                             "named": nm}  # fmt: skip
    out["cpu"] = time.process_time() - t0
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", default="0-3")
    ap.add_argument("--factor", type=float, default=1.5)
    ap.add_argument("--effects", default=",".join(EFFECTS))
    ap.add_argument("--out", default=None)
    ap.add_argument("--min-gain", type=float, default=None)
    ap.add_argument("--at-bound", action="store_true")
    a = ap.parse_args()
    global AT_BOUND
    AT_BOUND = a.at_bound
    if a.min_gain is not None:
        KW["min_gain"] = a.min_gain
    lo, hi = (int(s) for s in a.seeds.split("-"))
    effects = a.effects.split(",")
    rows = []
    for s in range(lo, hi + 1):
        r = run(s, a.factor, effects)
        rows.append(r)
        f = r["fac"]
        print(f"seed {s}: fs {f['fs']:.0f} f {f['f']:.2f} cycles {f['cycles']} n {r['n']} "
              f"noise p/d {100 * f['noise_p']:.2f}/{100 * f['noise_d']:.2f} % ψ {f['psi']:.2f} "
              f"clean {r['clean_names']} cpu {r['cpu']:.0f}s", flush=True)  # fmt: skip
        for e, v in r["effects"].items():
            print(
                f"   {e:24s} need {v['need']:.3g} bound {v['bound']:.3g} ratio "
                f"{v['ratio']:.2f} (nearest {v['nearest']}) named {v['named']}",
                flush=True,
            )
    summary = defaultdict(lambda: defaultdict(int))
    ratios = defaultdict(list)
    for r in rows:
        for e, v in r["effects"].items():
            n = v["named"]
            key = ("exact" if n == [e] else "extra" if e in n else "missed" if not n
                   else "wrong")  # fmt: skip
            summary[e][key] += 1
            ratios[e].append(v["ratio"])
    print(f"\nfactor {a.factor} x needed size; clean named: "
          f"{sum(bool(r['clean_names']) for r in rows)}/{len(rows)}")  # fmt: skip
    for e in effects:
        rr = np.array(ratios[e])
        counts = " ".join(f"{k} {summary[e][k]}" for k in ("exact", "extra", "missed", "wrong"))
        lo_hi = f"({np.nanmin(rr):.2f}-{np.nanmax(rr):.2f})"
        print(f"{e:24s} {counts}  bound/need median {np.nanmedian(rr):.2f} {lo_hi}")
    if a.out:
        Path(a.out).write_text(json.dumps(rows, indent=1, default=str))


if __name__ == "__main__":
    main()
