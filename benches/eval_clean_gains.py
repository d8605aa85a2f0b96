"""What each candidate gains on clean records (calibration of the per-effect floors of
``contactlab.diagnose.search.own_gain_floor`` and the input-noise budget's share).

Clean tangential records of both generators, drawn as ``benches/eval_diagnose_rig.py``
draws them (its ``plan``; ``--seeds tune`` its published tuning seeds), are diagnosed and
the first step's verdict on each candidate kept: the held-out gain (σ²) when it was
cross-validated, else the in-sample one, its t statistic, and the search's floors (the
input-noise budget, ``min_gain``). Tables: per candidate, the largest gain and t seen, and
the records where gain and t would both pass a floor of a given share.

    nice .venv/bin/python benches/eval_clean_gains.py --seeds tune --jobs 2
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from collections import defaultdict
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))


def one(case):
    import warnings

    import contactlab
    from contactlab.synthetic.diagnosis import hidden_effect_recording
    from contactlab.synthetic.rig import rig_recording

    warnings.simplefilter("ignore")
    if case.get("open"):  # every candidate cross-validated: its held-out gain is seen
        from contactlab.diagnose.effects import registry

        for eff in registry("tangential").values():
            eff.gain_floor_scale = 1e-6
            eff.input_noise_gain = False
    fac = case["factors"]
    rng = np.random.default_rng(case["seed"] + 7919)
    if case["gen"] == "rig":
        x_drift = float(rng.uniform(-0.003, 0.003))
        rec = rig_recording(
            {}, "tangential", seed=case["seed"], fs=fac["fs"], f=fac["f"], cycles=fac["cycles"],
            acA=fac["acA"], x_noise=fac["x_noise"], F_noise=fac["F_noise"], x_drift=x_drift,
            bits=int(rng.integers(12, 17)),
        )  # fmt: skip
        with tempfile.TemporaryDirectory() as tmp:
            recording = contactlab.read_recording(str(rec.to_csv(Path(tmp) / "r.csv")))
    else:
        from eval_diagnose_rig import MAX_SAMPLES

        spc = max(20, min(round(fac["fs"] / fac["f"]), int(MAX_SAMPLES / 6.5)))
        cpb = max(2, min(fac["cycles"] // 3, int(MAX_SAMPLES / (3.25 * spc))))
        recording = hidden_effect_recording(
            {}, model="tangential", noise=fac["F_noise"], seed=case["seed"],
            input_noise=fac["x_noise"], samples_per_cycle=spc, cycles_per_block=cpb,
            start="rest", f0=fac["f"],
        )  # fmt: skip
    rep = contactlab.diagnose(recording, model="tangential")
    rules = rep.prepared.extra.get("gain_rules", {}) if rep.prepared is not None else {}
    first = rep.steps[1].candidates if len(rep.steps) > 1 else rep.steps[0].candidates
    out = {
        "gen": case["gen"], "seed": case["seed"], "factors": fac, "named": rep.effect_names,
        "budget": rules.get("budget"), "n": int(rep.prepared.t.size),
        "verdicts": {
            v.name: {"gain": v.gain, "t": v.t_stat, "reason": v.reason[:80]} for v in first
        },
    }  # fmt: skip
    return json.loads(json.dumps(out, default=float))


def main(argv=None):
    from eval_diagnose_rig import TUNE_BASE, plan

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", choices=("tune", "fresh"), default="tune")
    ap.add_argument("--seed-base", type=int, default=None)
    ap.add_argument("--scale", type=float, default=1.0)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--raw", type=Path, default=None)
    ap.add_argument("--open", action="store_true", help="floors off: held-out gains of all")
    ap.add_argument("--tables-from", type=Path, default=None)
    a = ap.parse_args(argv)
    if a.tables_from:
        res = json.loads(a.tables_from.read_text())
    else:
        os.environ.setdefault("CONTACTLAB_DIAGNOSE_THREADS", "1")
        fresh = 30_000_000 + int(time.time()) % 10**6
        base = a.seed_base or (TUNE_BASE if a.seeds == "tune" else fresh)
        cases = [c for c in plan("full", base, a.scale) if c["kind"] == "tangential"
                 and c["effect"] is None]  # fmt: skip
        for c in cases:
            c["open"] = a.open
        print(f"seeds {a.seeds} base {base}: {len(cases)} clean records", flush=True)
        with ProcessPoolExecutor(max(1, min(2, a.jobs))) as ex:
            res = list(ex.map(one, cases))
        if a.raw:
            a.raw.write_text(json.dumps(res, indent=1))
    print(f"named on clean records: {[r['named'] for r in res if r['named']]}")
    per = defaultdict(list)
    for r in res:
        for name, v in r["verdicts"].items():
            per[name].append((r, v))
    print("| candidate | n | gain max | gain 90 % | t max | budget median | gain/budget max |")
    print("|---|---|---|---|---|---|---|")
    for name, rows in sorted(per.items()):
        g = np.array([v["gain"] for _, v in rows], float)
        t = np.array([v["t"] for _, v in rows], float)
        b = np.array([r["budget"] or 0.0 for r, _ in rows], float)
        ratio = np.where(b > 0, g / np.where(b > 0, b, 1), np.nan)
        fin = np.isfinite(g)
        print(
            f"| {name} | {len(rows)} | {np.nanmax(g):.3g} | "
            f"{np.quantile(g[fin], 0.9) if fin.any() else float('nan'):.3g} | "
            f"{np.nanmax(t) if np.isfinite(t).any() else float('nan'):.3g} | "
            f"{np.median(b):.3g} | "
            f"{np.nanmax(ratio) if np.isfinite(ratio).any() else float('nan'):.3g} |"
        )


if __name__ == "__main__":
    main()
