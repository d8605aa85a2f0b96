"""Issue 29 (stop 50, helper confuse): a dashpot and a channel delay near their stated bound
on ``benches/misfit_chain.py``'s measurement chain (coloured x noise, Bessel anti-alias
filters, a servo's start from rest with drive harmonics, hum, jitter, an ADC), at the
factors of the blind records that were named wrongly:

- ``damp``: a dashpot (``c ẋ``) named ``stick_slip`` + ``stribeck``: 5 kHz, 17-20 Hz, 20-50
  cycles, ac·A 0.8-1.35, x noise 0.8-0.9 %, F noise 1.1-1.2 % of the range;
- ``delay``: a force lagging by ``tau`` named ``normal_load``: 10 kHz, 22-27 Hz, 35-50 cycles,
  ac·A 1.1-1.2, x noise 1.5-1.9 %, F noise 1.6-1.7 %.

Per seed the clean twin (same factors and chain) is diagnosed (its names are false alarms,
its stated bound for the true effect), then the effect is added at each multiple of that
bound under fresh sensor noise (``noise_seed``) and diagnosed. One process, ``nice``::

    nice .venv/bin/python benches/eval_chain_near.py --cases damp --base 50300000 --n 4
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import warnings
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

CASES: dict[str, dict[str, Any]] = {
    "damp": {"effect": "viscous_damping", "param": "c", "fs": 5000.0, "f": (17.0, 20.0),
             "cycles": (20, 50), "acA": (0.8, 1.35), "xn": (0.008, 0.009),
             "fn": (0.011, 0.012)},
    "delay": {"effect": "channel_delay", "param": "tau", "fs": 10000.0, "f": (22.0, 27.0),
              "cycles": (35, 50), "acA": (1.1, 1.2), "xn": (0.015, 0.019),
              "fn": (0.016, 0.017)},
}  # fmt: skip
RIVALS = ("stick_slip", "stribeck", "normal_load", "channel_delay", "viscous_damping")


def factors(case: str, seed: int) -> dict[str, Any]:
    c = CASES[case]
    rng = np.random.default_rng([seed, list(CASES).index(case), 5050])
    return {
        "fs": c["fs"], "f": round(float(rng.uniform(*c["f"])), 3),
        "cycles": int(rng.integers(c["cycles"][0], c["cycles"][1] + 1)),
        "acA": round(float(rng.uniform(*c["acA"])), 3),
        "x_noise": round(float(rng.uniform(*c["xn"])), 4),
        "F_noise": round(float(rng.uniform(*c["fn"])), 4),
    }  # fmt: skip


def diagnose_one(seed: int, fac: dict[str, Any], extra: dict[str, float], noise: int | None):
    import contactlab
    from misfit_chain import chain_record

    rec, _ = chain_record(seed, "exp", noise_seed=noise, **fac, **extra)
    return contactlab.diagnose(rec, model="tangential")


def summary(rep: Any, effect: str) -> dict[str, Any]:
    nd = {x.effect: x for x in rep.not_detected}
    steps = []
    for st in rep.steps:
        row = {v.name: [round(float(v.gain), 3), bool(v.accepted), (v.reason or "")[:140]]
               for v in st.candidates if v.name in (effect, *RIVALS)}  # fmt: skip
        steps.append(row)
    un = rep.unexplained
    return {
        "named": list(rep.effect_names),
        "params": {k: float(v) for e in rep.effects for k, v in e.parameters.items()},
        "flagged": bool(un is not None and un.flagged),
        "bound": None if effect not in nd else nd[effect].detectable_above,
        "steps": steps,
    }


def verdict(effect: str, named: list[str]) -> str:
    s = set(named)
    return "exact" if s == {effect} else "none" if not s else "wrong"


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", type=int, required=True)
    ap.add_argument("--n", type=int, default=4)
    ap.add_argument("--cases", default="damp,delay")
    ap.add_argument("--mults", default="0.7,1,2")
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument("--without", default="", help="dashpot: Stribeck's dashpot rule off")
    a = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    if "dashpot" in a.without.split(","):
        from contactlab.diagnose.effects import registry

        type(registry("tangential")["stribeck"]).dashpot_check = False
    mults = [float(m) for m in a.mults.split(",")]
    rows, tally = [], defaultdict(list)
    for case in a.cases.split(","):
        c = CASES[case]
        for seed in range(a.base, a.base + a.n):
            fac = factors(case, seed)
            clean = summary(diagnose_one(seed, fac, {}, None), c["effect"])
            bound = clean["bound"]
            print(f"{case} {seed} {fac} clean {clean['named']} flag {clean['flagged']} "
                  f"bound {bound}", flush=True)  # fmt: skip
            row = {"case": case, "seed": seed, "fac": fac, "clean": clean, "runs": []}
            if bound is not None and math.isfinite(bound):
                for k, m in enumerate(mults):
                    r = summary(diagnose_one(seed, fac, {c["param"]: m * bound}, 1 + k),
                                c["effect"])  # fmt: skip
                    r["mult"] = m
                    row["runs"].append(r)
                    tally[(case, m)].append(verdict(c["effect"], r["named"]))
                    print(f"   {m:g}x {m * bound:.3g} -> {r['named']} flag {r['flagged']} "
                          f"[{verdict(c['effect'], r['named'])}] steps {r['steps'][:2]}",
                          flush=True)  # fmt: skip
            rows.append(row)
            if a.out:
                a.out.write_text(json.dumps(rows, indent=1, default=float))
    print("\n| case | x bound | n | exact | wrong | none |\n|---|---|---|---|---|---|")
    for (case, m), v in sorted(tally.items()):
        print(f"| {case} | {m:g} | {len(v)} | {v.count('exact')} | {v.count('wrong')} | "
              f"{v.count('none')} |")  # fmt: skip
    quiet = sum(not r["clean"]["named"] and not r["clean"]["flagged"] for r in rows)
    print(f"\nclean twins: nothing named or flagged {quiet}/{len(rows)}")


if __name__ == "__main__":
    main()
