"""Normal-contact diagnosis at fixed, visible sizes on ``chain_normal`` (issue 29).

Each seed draws one chain (fs 1-10 kHz, 0.5-20 Hz, 5-50 cycles, noise 0.5-2 % on both
channels, actuator from rest, sensor filters, hum, jitter, ADC) and, with probability 1/2, a
slow drift of the displacement sensor (0.2-2 % of its range over the record, straight or
bowed). On that chain: the clean record, and one record per effect at a size drawn in a
visible range:

- ``stiffness_nonlinearity``: relative change of the stiffness at the amplitude 0.015-0.08,
  as ``a2`` (κ1-type), ``a3`` (both sides alike) or both;
- ``creep_drift``: ``D`` 0.05-0.5 of the displacement amplitude, ``τ_c`` 0.05-1 of the
  record's duration;
- ``asymmetric_branches``: ``a`` 0.2-0.7.

Prints what ``diagnose`` names and whether the misfit is flagged; counts exact names and
clean records with nothing named or flagged.

    nice .venv/bin/python benches/eval_normal_visible.py --seeds 0-9
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from chain_normal import chain_record, draw_factors

EFFECTS = ("stiffness_nonlinearity", "creep_drift", "asymmetric_branches")


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
    return list(r.effect_names), flagged, bounds


def draw(rng, effect, fac):
    """Size and per-record settings of ``effect``."""
    if effect == "stiffness_nonlinearity":
        fac["law"] = str(rng.choice(["a2", "a3", "a23"]))
        return float(rng.uniform(0.015, 0.08)) * float(rng.choice([-1, 1]) if fac["law"] == "a2"
                                                         else 1.0)  # fmt: skip
    if effect == "creep_drift":
        fac["tau_frac"] = float(np.exp(rng.uniform(np.log(0.05), np.log(1.0))))
        return float(rng.uniform(0.05, 0.5)) * float(rng.choice([-1, 1]))
    return float(rng.uniform(0.2, 0.7)) * float(rng.choice([-1, 1]))


def run(seed):
    rng = np.random.default_rng(70_000 + seed)
    fac = draw_factors(rng)
    if rng.uniform() < 0.5:
        fac["sensor_drift"] = float(rng.uniform(0.002, 0.02)) * float(rng.choice([-1, 1]))
        fac["sensor_bow"] = float(rng.uniform(-1, 1))
    out = {"seed": seed, "fac": dict(fac), "rows": {}}
    t0 = time.process_time()
    t, p, d, _ = chain_record(None, 0.0, fac, seed)
    out["rows"]["clean"] = {"size": 0.0, **dict(zip(("named", "flagged", "bounds"),
                                                    diagnose(t, p, d), strict=True))}  # fmt: skip
    for e in EFFECTS:
        f2 = dict(fac)
        size = draw(rng, e, f2)
        if e == "creep_drift":
            T = min(f2["cycles"], max(5, int(150_000 * f2["f"] / f2["fs"]))) / f2["f"]
            f2["tau_c"] = f2["tau_frac"] * T
        t, p, d, _ = chain_record(e, size, f2, seed + 500)
        nm, fl, bd = diagnose(t, p, d)
        out["rows"][e] = {"size": size, "law": f2.get("law"), "tau_frac": f2.get("tau_frac"),
                          "named": nm, "flagged": fl, "bounds": bd}  # fmt: skip
    out["cpu"] = time.process_time() - t0
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", default="0-3")
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    lo, hi = (int(s) for s in a.seeds.split("-"))
    res = []
    tally = defaultdict(lambda: defaultdict(int))
    for s in range(lo, hi + 1):
        r = run(s)
        res.append(r)
        f = r["fac"]
        print(f"seed {s}: fs {f['fs']:.0f} f {f['f']:.2f} cyc {f['cycles']} noise p/d "
              f"{100 * f['noise_p']:.2f}/{100 * f['noise_d']:.2f} % ψ {f['psi']:.2f} drift "
              f"{100 * f.get('sensor_drift', 0):.2f} % cpu {r['cpu']:.0f}s",
              flush=True)  # fmt: skip
        for e, v in r["rows"].items():
            extra = f" law {v['law']}" if v.get("law") else ""
            extra += f" τ/T {v['tau_frac']:.2f}" if v.get("tau_frac") else ""
            print(f"   {e:24s} size {v['size']:+.3f}{extra} named {v['named']} "
                  f"flagged {v['flagged']}", flush=True)  # fmt: skip
            if e == "clean":
                tally[e]["ok" if not v["named"] and not v["flagged"] else "alarm"] += 1
            else:
                tally[e]["exact" if v["named"] == [e] else "other"] += 1
    print()
    for e, c in tally.items():
        print(f"{e:24s} " + " ".join(f"{k} {n}" for k, n in sorted(c.items())))
    if a.out:
        Path(a.out).write_text(json.dumps(res, indent=1, default=str))


if __name__ == "__main__":
    main()
