"""Sensor-chain ablation of clean rig records (issue 29, stop 46): one chain component alone
(plain chain plus X) or all but one (full chain minus X), per seed, diagnosed.

Usage: sensor_chain_ablation.py RECORDS.json SEEDS VARIANTS OUT.json, RECORDS.json the --raw
output of eval_diagnose_rig.py --chain sensors; VARIANTS e.g. full,none,minus:hum,only:hum.
"""

import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
os.environ["CONTACTLAB_RIG_CHAIN"] = "sensors"
import eval_diagnose_rig as E

OFF = {
    "x_lowpass": None,
    "F_highpass": None,
    "aa_kind": "butterworth",
    "hum": 0.0,
    "jitter": 0.0,
    "drive_harmonics": (),
    "ramp_cycles": 1.0,
}
COMP = list(OFF)
orig = E.chain_kwargs
src = sys.argv[1]
seeds = [int(s) for s in sys.argv[2].split(",")]
variants = sys.argv[3].split(",")  # full, none, only:<c>, minus:<c>
out = sys.argv[4]
recs = {r["seed"]: r for r in json.load(open(src)) if r["kind"] == "tangential"}
res = []
for seed in seeds:
    r = recs[seed]
    case = {k: r[k] for k in ("gen", "kind", "effect", "variant", "seed", "factors")}
    full = orig(seed, r["factors"])
    for v in variants:
        if v == "full":
            kw = dict(full)
        elif v == "none":
            kw = dict(OFF)
        elif v.startswith("only:"):
            c = v[5:]
            kw = dict(OFF)
            kw[c] = full[c]
        elif v.startswith("minus:"):
            c = v[6:]
            kw = dict(full)
            kw[c] = OFF[c]
        E.chain_kwargs = lambda s, f, kw=kw: dict(kw)
        E.POWER_VIEW = False
        o = E.run_case(case)
        row = {
            "seed": seed,
            "variant": v,
            "named": o["named"],
            "params": o["params"],
            "skew": o.get("skew"),
            "error": o.get("error"),
            "cpu": round(o["cpu"], 1),
        }
        res.append(row)
        print(json.dumps(row, default=float), flush=True)
        with open(out, "w") as fh:
            json.dump(res, fh, default=float)
