"""The flag route (issue 29): flagged records that name nothing, at issue 29's conditions.

Records of the rig simulator (``contactlab.synthetic.rig.rig_recording``) driven by the
shaker from rest (``ramp_cycles`` 0, armature 0.1-1 kg, suspension at 0.4-2.5 f, damping
0.02-0.1, drawn per seed), noise on both channels, with one effect hidden at the size of
issue 29's flagged blind misses (``CONDITIONS``: those sizes lie between the ideal test's
size and the package's stated bound) times ``--mults``. Each record is diagnosed once; the
report's ``location["flag_route"]`` says what the final model was before the route (named,
flagged) and what the route named. Counted: flagged-and-unnamed before the route, correctly
named by the route, wrongly named by it.

    nice .venv/bin/python benches/eval_flag_route.py --seeds 51300000-51300003 \
        --dump /tmp/fr.jsonl
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

H0, AC = 40.0, 4.0e4
#: label: (effect, fs, f, cycles, x noise, F noise, ac·A, size in the diagnosis's parameter)
CONDITIONS: dict[str, tuple[str, float, float, int, float, float, float, float]] = {
    "posfric_a": ("position_friction", 1000.0, 3.1, 50, 0.0072, 0.0108, 2.45, 0.0113),
    "posfric_b": ("position_friction", 5000.0, 19.4, 35, 0.0078, 0.0110, 1.94, 0.0071),
    "load_a": ("normal_load", 1000.0, 3.9, 20, 0.010, 0.0056, 2.94, 0.0154),
    "load_b": ("normal_load", 10000.0, 6.8, 8, 0.010, 0.010, 2.19, 0.025),
    "delay": ("channel_delay", 5000.0, 24.3, 20, 0.020, 0.015, 1.75, 0.62e-3),
    "drift": ("parameter_drift", 10000.0, 25.3, 50, 0.0156, 0.0186, 3.6, 0.0027),
    "fdrift": ("force_drift", 10000.0, 16.8, 12, 0.010, 0.010, 2.0, 0.03),
    "clean": ("", 2000.0, 10.0, 20, 0.012, 0.012, 2.0, 0.0),
    # normal contact (``benches/chain_normal.py``'s chain: actuator from rest, LVDT, pressure
    # cell, Bessel anti-alias, hum, jitter, ADC), the size ``mult`` times the ideal test's
    # (noncentrality 44.8, base and nearest rival projected out); ac·A unused
    "nstiff": ("stiffness_nonlinearity", 5000.0, 29.4, 35, 0.0106, 0.0165, 0.0, 0.01),
    "nasym": ("asymmetric_branches", 1000.0, 2.6, 12, 0.0053, 0.0069, 0.0, 0.3),
}


def shaker_figures(seed: int, f: float) -> dict[str, float]:
    rng = np.random.default_rng([seed, 4242])
    return {
        "mass": round(float(rng.uniform(0.1, 1.0)), 3),
        "fn": round(float(f * rng.uniform(0.4, 2.5)), 3),
        "zeta": round(float(rng.uniform(0.02, 0.1)), 3),
    }


def rig_effect(effect: str, size: float, fac: dict[str, Any], rng: np.random.Generator) -> dict:
    T = fac["cycles"] / fac["f"]
    A = fac["acA"] / AC
    s = 1.0 if rng.random() < 0.5 else -1.0
    hm = H0 * (1 - math.exp(-fac["acA"]))
    phi = float(rng.uniform(0, 2 * math.pi))
    return {
        "position_friction": {"eps": size, "L": 2 * A * float(rng.uniform(0.5, 1.0)), "phi": phi},
        "normal_load": {"eps": size, "f_n": 2.0 * fac["f"], "phi": phi},
        "channel_delay": {"tau": size},
        "parameter_drift": {"beta": s * size / T},
        "force_drift": {"rate": s * size * hm / T},
    }[effect]


def run_one(label: str, seed: int, mult: float) -> dict[str, Any]:
    import warnings

    import contactlab
    from contactlab.synthetic.rig import rig_recording

    effect, fs, f, cyc, xn, Fn, aca, size = CONDITIONS[label]
    if label.startswith("n"):
        return _run_normal(label, seed, mult)
    fac = {"fs": fs, "f": f, "cycles": cyc, "acA": aca}
    rng = np.random.default_rng([seed, 7])
    eff = {effect: rig_effect(effect, size * mult, fac, rng)} if effect else {}
    rec = rig_recording(
        eff, seed=seed, fs=fs, f=f, cycles=cyc, acA=aca, x_noise=xn, F_noise=Fn,
        ramp_cycles=0.0, shaker=shaker_figures(seed, f),
    )  # fmt: skip
    t0 = time.time()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rep = contactlab.diagnose({"t": rec.t, **rec.channels}, model="tangential")
    u = rep.unexplained
    route = rep.location.get("flag_route")
    return {
        "label": label, "seed": seed, "mult": mult, "effect": effect,
        "named": list(rep.effect_names), "flagged": bool(u is not None and u.flagged),
        "route": route, "seconds": round(time.time() - t0, 1),
    }  # fmt: skip


def _run_normal(label: str, seed: int, mult: float) -> dict[str, Any]:
    import warnings

    import contactlab
    from chain_normal import LAMBDA_VISIBLE, chain_record, noncentrality

    effect, fs, f, cyc, xn, yn, _, ref = CONDITIONS[label]
    rng = np.random.default_rng([seed, 7])
    fac = {"fs": fs, "f": f, "cycles": cyc, "ratio": float(rng.uniform(0.3, 0.8)),
           "noise_p": xn, "noise_d": yn, "bits": 16, "psi": float(rng.uniform(0.08, 0.3)),
           "law": "a2"}  # fmt: skip
    lam, _, _ = noncentrality(effect, ref, fac, seed)
    size = mult * ref * math.sqrt(LAMBDA_VISIBLE / lam) * float(rng.choice([-1, 1]))
    t, p, d, _ = chain_record(effect, size, fac, seed + 1000)
    t0 = time.time()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rep = contactlab.diagnose({"t": t, "p": p, "delta": d}, model="normal")
    u = rep.unexplained
    return {
        "label": label, "seed": seed, "mult": mult, "effect": effect, "size": size,
        "named": list(rep.effect_names), "flagged": bool(u is not None and u.flagged),
        "route": rep.location.get("flag_route"), "seconds": round(time.time() - t0, 1),
    }  # fmt: skip


def _seeds(s: str) -> list[int]:
    a, _, b = s.partition("-")
    return list(range(int(a), int(b or a) + 1))


def summary(rs: list[dict[str, Any]]) -> str:
    lines = ["| label | mult | n | flagged+unnamed before | route named right | wrong | "
             "named right (final) |", "|---|---|---|---|---|---|---|"]  # fmt: skip
    keys = sorted({(r["label"], r["mult"]) for r in rs})
    for lab, m in keys:
        g = [r for r in rs if r["label"] == lab and r["mult"] == m]
        before = [r for r in g if (r["route"] or {}).get("ran")]
        fu = [r for r in before if not r["route"]["before"]["named"]]
        right = [r for r in before if r["route"].get("named") == r["effect"]]
        wrong = [r for r in before if r["route"].get("named") not in (None, r["effect"])]
        fin = [r for r in g if r["effect"] and r["effect"] in r["named"]]
        lines.append(f"| {lab} | {m:g} | {len(g)} | {len(fu)} (flag route ran {len(before)}) "
                     f"| {len(right)} | {len(wrong)} | {len(fin)} |")  # fmt: skip
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", default="51300000-51300001")
    ap.add_argument("--labels", default=",".join(CONDITIONS))
    ap.add_argument("--mults", default="1")
    ap.add_argument("--dump", default=None)
    ap.add_argument("--table", nargs="*", default=None)
    a = ap.parse_args()
    from contactlab.errors import ContactLabError

    if a.table is not None:
        rs = [json.loads(x) for p in a.table for x in open(p) if x.strip()]
        print(summary(rs))
        return
    rs = []
    for seed in _seeds(a.seeds):
        for lab in a.labels.split(","):
            for m in (float(v) for v in a.mults.split(",")):
                try:
                    r = run_one(lab, seed, m)
                except ContactLabError as exc:  # (the normal chain's NaN beyond its range)
                    print(f"{lab} {seed} {m:g}: {exc}", flush=True)
                    continue
                rs.append(r)
                print(json.dumps(r, default=str), flush=True)
                if a.dump:
                    with open(a.dump, "a") as fh:
                        fh.write(json.dumps(r, default=str) + "\n")
    print(summary(rs))


if __name__ == "__main__":
    main()
