"""Are the stated normal-contact bounds found at their own size on the package's generator?
(issue 29, item 2; stop 47)

For each seed: a clean normal record of
:func:`contactlab.synthetic.diagnosis.hidden_effect_recording` (``model="normal"``, from rest,
one tone or three blocks, 5-16 cycles a block, 40-300 samples a cycle, noise 0.5-2 % on both
channels); ``diagnose`` states each effect's bound as a relative size (RMS change of δ over
its RMS, the generator's ``magnitude``); then the effect hidden at ``--factor`` times that
size (same settings, fresh noise: seed + 1) and diagnosed. ``creep_drift`` is left to
``benches/eval_normal_creep_bound.py`` (its bound holds at a stated τc).

    nice .venv/bin/python benches/eval_normal_bound_package.py --seeds 0-9 --base 5620200
"""

from __future__ import annotations

import argparse
import json
import warnings
from collections import defaultdict
from pathlib import Path

import numpy as np

EFFECTS = ("stiffness_nonlinearity", "asymmetric_branches")


def diagnose(r):
    import contactlab

    ch = r.channels if isinstance(getattr(r, "channels", None), dict) else r.data
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = contactlab.diagnose({"t": r.t, "p": ch["p"], "delta": ch["delta"]}, "normal")
    b = {x.to_dict()["effect"]: x.to_dict() for x in res.not_detected}
    flagged = bool(res.to_dict().get("unexplained", {}).get("flagged", False))
    return list(res.effect_names), flagged, b


def main() -> None:
    from contactlab.synthetic.diagnosis import hidden_effect_recording

    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", default="0-3")
    ap.add_argument("--base", type=int, default=5620200)
    ap.add_argument("--factor", type=float, default=1.0)
    ap.add_argument("--effects", default=",".join(EFFECTS))
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    lo, hi = (int(s) for s in a.seeds.split("-"))
    rows, tally, clean_alarm = [], defaultdict(lambda: defaultdict(int)), 0
    for s in range(lo, hi + 1):
        seed = a.base + s
        rng = np.random.default_rng(seed)
        noise = float(rng.uniform(0.005, 0.02))
        kw = {"noise": noise, "input_noise": noise, "cycles_per_block": int(rng.integers(5, 17)),
              "samples_per_cycle": int(rng.choice([40, 120, 300])), "start": "rest",
              "frequencies": [1.0] if rng.uniform() < 0.5 else None}  # fmt: skip
        cn, cf, bounds = diagnose(hidden_effect_recording([], model="normal", seed=seed, **kw))
        clean_alarm += bool(cn or cf)
        row = {"seed": seed, "kw": kw, "clean": cn, "clean_flagged": cf, "effects": {}}
        for e in a.effects.split(","):
            rel = bounds.get(e, {}).get("relative_size")
            if rel is None or not np.isfinite(rel) or rel <= 0:
                tally[e]["no bound"] += 1
                row["effects"][e] = {"bound": None}
                continue
            r = hidden_effect_recording({e: a.factor * float(rel)}, model="normal",
                                        seed=seed + 1, **kw)  # fmt: skip
            nm, fl, _ = diagnose(r)
            key = "exact" if nm == [e] else "extra" if e in nm else "missed" if not nm else "wrong"
            tally[e][key] += 1
            row["effects"][e] = {"bound": rel, "truth": r.truth.get("effects", {}).get(e),
                                 "named": nm, "flagged": fl}  # fmt: skip
        rows.append(row)
        print(f"seed {seed}: {kw} clean {cn} {cf}; " + "; ".join(
            f"{e} rel {v.get('bound') or float('nan'):.3g} -> {v.get('named')} {v.get('truth')}"
            for e, v in row["effects"].items()), flush=True)  # fmt: skip
        if a.out:
            Path(a.out).write_text(json.dumps(rows, indent=1, default=str))
    print(f"\nfactor {a.factor}: clean named or flagged {clean_alarm}/{len(rows)}")
    for e, c in tally.items():
        print(f"{e:24s} " + " ".join(f"{k} {n}" for k, n in sorted(c.items())))


if __name__ == "__main__":
    main()
