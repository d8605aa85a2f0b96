"""Clean tangential records of both package generators (``benches/eval_diagnose_rig.py``'s
plan: the rig and ``hidden_effect_recording``), diagnosed: named set and misfit flag per
record, then the share with nothing named and nothing flagged (helper lookalike, stop 41).

    PYTHONPATH=<tree>/python python benches/eval_clean_quiet.py 48000 1.0

(run it once per tree for a before/after on the same seeds: the first line says which
``contactlab`` was imported).
"""

import json
import sys
import warnings
from pathlib import Path

import numpy as np

import contactlab

warnings.simplefilter("ignore")
sys.path.insert(0, str(Path(__file__).resolve().parent))
print(contactlab.__file__, file=sys.stderr)
from contactlab.synthetic.diagnosis import hidden_effect_recording  # noqa: E402
from contactlab.synthetic.rig import rig_recording  # noqa: E402
from eval_diagnose_rig import MAX_SAMPLES, plan  # noqa: E402

cases = [
    c
    for c in plan("full", int(sys.argv[1]), float(sys.argv[2]))
    if c["kind"] == "tangential" and c["effect"] is None
]
out = []
for case in cases:
    fac = case["factors"]
    rng = np.random.default_rng(case["seed"] + 7919)
    if case["gen"] == "rig":
        rec = rig_recording(
            {},
            "tangential",
            seed=case["seed"],
            fs=fac["fs"],
            f=fac["f"],
            cycles=fac["cycles"],
            acA=fac["acA"],
            x_noise=fac["x_noise"],
            F_noise=fac["F_noise"],
            x_drift=float(rng.uniform(-0.003, 0.003)),
            bits=int(rng.integers(12, 17)),
        )
        data = (rec.t, rec.x, rec.F)
    else:
        spc = max(20, min(round(fac["fs"] / fac["f"]), int(MAX_SAMPLES / 6.5)))
        cpb = max(2, min(fac["cycles"] // 3, int(MAX_SAMPLES / (3.25 * spc))))
        data = hidden_effect_recording(
            {},
            model="tangential",
            noise=fac["F_noise"],
            seed=case["seed"],
            input_noise=fac["x_noise"],
            samples_per_cycle=spc,
            cycles_per_block=cpb,
            start="rest",
            f0=fac["f"],
        )
    rep = contactlab.diagnose(data, model="tangential")
    un = rep.unexplained
    r = {
        "gen": case["gen"],
        "seed": case["seed"],
        "named": list(rep.effect_names),
        "flagged": bool(un is not None and un.flagged),
        "xn": fac["x_noise"],
        # flagged by the alternative virgin curve alone (misfit.alternative_virgin, stop 49)
        "by_alternative": bool(
            un is not None and any(p.get("alternative") for p in (un.patches or ()))
        ),
        # named by the flag route (contactlab.diagnose.flag_route): a flag turned into a name
        "by_flag_route": (rep.location.get("flag_route") or {}).get("named"),
    }
    print(json.dumps(r), flush=True)
    out.append(r)
q = sum(1 for r in out if not r["named"] and not r["flagged"])
n_named = sum(1 for r in out if r["named"])
n_flagged = sum(1 for r in out if r["flagged"])
n_alt = sum(1 for r in out if r["by_alternative"])
n_route = sum(1 for r in out if r["by_flag_route"])
print(
    f"quiet {q}/{len(out)} named {n_named} flagged {n_flagged} (by the alternative only "
    f"{n_alt}; named by the flag route {n_route})"
)
