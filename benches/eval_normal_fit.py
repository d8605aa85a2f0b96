"""Normal-contact diagnosis on a wide chain: the stiffness law against the loss asymmetry,
creep that settles in 0.2-1 s, a straight drift of the displacement sensor (issue 29).

Each seed draws one chain of ``chain_normal`` over a wider range than
``eval_normal_visible`` (fs 1-10 kHz, 1-50 Hz at 20 samples a cycle or more, 5-50 cycles,
noise 0.5-2 % of range on both channels from independent streams, ψ 0.05-0.3, actuator from
rest) and diagnoses on it:

- ``clean``: nothing but the chain;
- ``drift``: the clean chain with a straight drift of the displacement sensor of 1-2 % of its
  range over the record (docs/effects.md §2: a sensor drift, neither creep nor a loss);
- ``stiffness_nonlinearity``: a change of the stiffness 0.015-0.08 at the amplitude, by one
  of the laws ``a2`` (k + a2 δ, either sign), ``a3`` (k + a3 δ², both sides harden), ``a23``,
  ``eq17`` (``a2`` with the damping following the stiffness, the paper's eq. 17) and ``p``
  (a stiffness that depends on the pressure, the paper's eq. 16);
- ``creep_drift``: ``D`` 0.05-0.5 of the displacement amplitude settling with ``τ_c``
  0.2-1 s on a record of 2-6 s (cycles and frequency drawn so);
- ``asymmetric_branches``: ``a`` 0.2-0.7 either sign.

Prints what ``diagnose`` names, whether the misfit is flagged and the bound it states for the
effect; tallies by effect and by the noise band (the larger of the two channels').

    nice .venv/bin/python benches/eval_normal_fit.py --seeds 0-9 --out /tmp/x.json
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
from chain_normal import chain_record

ROWS = ("clean", "drift", "stiffness_nonlinearity", "creep_drift", "asymmetric_branches")
LAWS = ("a2", "a3", "a23", "eq17", "p")


def diagnose(t, p, d):
    import contactlab

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = contactlab.diagnose({"t": t, "p": p, "delta": d}, "normal")
    rd = r.to_dict()
    flagged = bool(rd.get("unexplained", {}).get("flagged", False))
    bounds = {}
    for b in r.not_detected:
        bd = b.to_dict()
        bounds[bd["effect"]] = bd.get("detectable_above")
    params = {e["name"]: e.get("parameters", {}) for e in rd.get("effects", [])}
    return list(r.effect_names), flagged, bounds, params


def factors(rng: np.random.Generator) -> dict:
    fs = float(rng.choice([1000.0, 2000.0, 5000.0, 10000.0]))
    f = float(np.exp(rng.uniform(np.log(1.0), np.log(min(50.0, fs / 20.0)))))
    return {
        "fs": fs,
        "f": f,
        "cycles": int(rng.integers(5, 51)),
        "ratio": float(rng.uniform(0.2, 0.8)),
        "noise_p": float(rng.uniform(0.005, 0.02)),
        "noise_d": float(rng.uniform(0.005, 0.02)),
        "bits": int(rng.choice([14, 16])),
        "psi": float(rng.uniform(0.05, 0.3)),
    }


def row_factors(rng: np.random.Generator, row: str, base: dict) -> tuple[dict, float]:
    """Settings and size of one row on the seed's chain ``base``."""
    fac = dict(base)
    if row == "drift":
        fac["sensor_drift"] = float(rng.uniform(0.01, 0.02)) * float(rng.choice([-1, 1]))
        fac["sensor_bow"] = 0.0
        return fac, 0.0
    if row == "stiffness_nonlinearity":
        fac["law"] = str(rng.choice(LAWS))
        sign = float(rng.choice([-1, 1])) if fac["law"] in ("a2", "eq17", "p") else 1.0
        return fac, sign * float(rng.uniform(0.015, 0.08))
    if row == "creep_drift":
        T = float(rng.uniform(2.0, 6.0))
        cyc = int(rng.integers(5, 51))
        f = cyc / T
        fac["f"], fac["cycles"] = f, cyc
        fac["fs"] = max(fac["fs"], float(2 ** math.ceil(math.log2(20 * f))) * 1.0)
        fac["tau_c"] = float(np.exp(rng.uniform(np.log(0.2), np.log(1.0))))
        return fac, float(rng.uniform(0.05, 0.5)) * float(rng.choice([-1, 1]))
    if row == "asymmetric_branches":
        return fac, float(rng.uniform(0.2, 0.7)) * float(rng.choice([-1, 1]))
    return fac, 0.0


def run(seed: int, rows: tuple[str, ...]) -> dict:
    rng = np.random.default_rng(90_000 + seed)
    base = factors(rng)
    out = {"seed": seed, "fac": dict(base), "rows": {}}
    for row in ROWS:
        fac, size = row_factors(rng, row, base)
        if row not in rows:
            continue
        effect = row if row not in ("clean", "drift") else None
        t0 = time.process_time()
        t, p, d, _ = chain_record(effect, size, fac, seed * 7 + ROWS.index(row))
        nm, fl, bd, par = diagnose(t, p, d)
        out["rows"][row] = {"size": size, "law": fac.get("law"), "tau_c": fac.get("tau_c"),
                            "T": float(t[-1] - t[0]), "f": fac["f"],
                            "drift": fac.get("sensor_drift"), "named": nm, "flagged": fl,
                            "bound": bd.get(row), "params": par,
                            "cpu": time.process_time() - t0}  # fmt: skip
    return out


def verdict(row: str, v: dict) -> str:
    if row in ("clean", "drift"):
        if v["named"]:
            return "named"
        return "flagged" if v["flagged"] else "ok"
    return "exact" if v["named"] == [row] else "other"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", default="0-3")
    ap.add_argument("--rows", default=",".join(ROWS))
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    lo, hi = (int(s) for s in a.seeds.split("-"))
    rows = tuple(a.rows.split(","))
    res = []
    tally = defaultdict(lambda: defaultdict(int))
    band = defaultdict(lambda: defaultdict(int))
    for s in range(lo, hi + 1):
        r = run(s, rows)
        res.append(r)
        f = r["fac"]
        nz = max(f["noise_p"], f["noise_d"])
        print(f"seed {s}: fs {f['fs']:.0f} f {f['f']:.2f} cyc {f['cycles']} noise p/d "
              f"{100 * f['noise_p']:.2f}/{100 * f['noise_d']:.2f} % ψ {f['psi']:.2f}",
              flush=True)  # fmt: skip
        for e, v in r["rows"].items():
            extra = f" law {v['law']}" if v.get("law") else ""
            if v.get("tau_c"):
                extra += f" τc {v['tau_c']:.2f} s T {v['T']:.1f} s f {v['f']:.2f}"
            if v.get("drift"):
                extra += f" drift {100 * v['drift']:+.2f} %"
            b = v.get("bound")
            extra += f" bound {b:.3g}" if isinstance(b, float) else ""
            print(f"   {e:24s} size {v['size']:+.3f}{extra} named {v['named']} "
                  f"flagged {v['flagged']} cpu {v['cpu']:.0f}s", flush=True)  # fmt: skip
            w = verdict(e, v)
            tally[e][w] += 1
            key = "0.5-1 %" if nz < 0.01 else ("1-1.5 %" if nz < 0.015 else "1.5-2 %")
            band[(e, key)][w] += 1
    print()
    for e, c in tally.items():
        print(f"{e:24s} " + " ".join(f"{k} {n}" for k, n in sorted(c.items())))
    print()
    for (e, key), c in sorted(band.items()):
        print(f"{e:24s} {key:8s} " + " ".join(f"{k} {n}" for k, n in sorted(c.items())))
    if a.out:
        Path(a.out).write_text(json.dumps(res, indent=1, default=str))


if __name__ == "__main__":
    main()
