"""What each candidate gains on clean LONG records (35-50 cycles), floors off (issue 29, stop 52).

The blind judge's visible single effects were named 93 % at 0-10 cycles but 73 % at 25-51:
the search's per-sample floors (``min_gain`` σ² times the effect's ``gain_floor_scale``,
its share of the input-noise budget) ask a noncentrality that grows with the record's
length. What a candidate gains on a clean record is what the floors must hold off: this
draws clean records of both generators (the rig simulator and the package's
``hidden_effect_recording``) at 35-50 cycles, x noise 0.5-2 % of the range, ac·A 0.5-5,
diagnoses them with every floor off (``eval_clean_gains.one``'s ``open``) and tabulates per
candidate the first step's held-out gain (σ²), its t and its ratio to the input-noise
budget.

    nice .venv/bin/python benches/eval_long_gains.py --seed-base 52300000 --n 8 --jobs 1
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

MAX_SAMPLES = 23_000


def draw(seed: int, gen: str, cycles: tuple[int, int] = (35, 50)) -> dict:
    rng = np.random.default_rng(seed)
    fs = float(np.exp(rng.uniform(math.log(1000.0), math.log(10000.0))))
    cyc = int(rng.integers(cycles[0], cycles[1] + 1))
    # at least 1 kHz and the whole record within MAX_SAMPLES: f from cyc·1 kHz/MAX_SAMPLES up
    f = float(np.exp(rng.uniform(math.log(1000.0 * cyc / MAX_SAMPLES), math.log(50.0))))
    fs = max(1000.0, min(fs, MAX_SAMPLES * f / cyc))
    return {
        "gen": gen, "seed": seed,
        "factors": {
            "fs": round(fs, 1), "f": round(f, 3), "cycles": cyc,
            "acA": round(float(np.exp(rng.uniform(math.log(0.5), math.log(5.0)))), 3),
            "x_noise": round(float(rng.uniform(0.005, 0.02)), 4),
            "F_noise": round(float(rng.uniform(0.005, 0.02)), 4),
        },
    }  # fmt: skip


def main(argv=None):
    from eval_clean_gains import one

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed-base", type=int, required=True)
    ap.add_argument("--n", type=int, default=6, help="records per generator")
    ap.add_argument("--gens", default="rig,pkg")
    ap.add_argument("--closed", action="store_true", help="the floors on (what is named)")
    ap.add_argument("--raw", type=Path, default=None)
    ap.add_argument("--tables-from", type=Path, default=None)
    a = ap.parse_args(argv)
    if a.tables_from:
        res = json.loads(a.tables_from.read_text())
    else:
        os.environ.setdefault("CONTACTLAB_DIAGNOSE_THREADS", "1")
        res = []
        for i in range(a.n):
            for gen in a.gens.split(","):
                c = draw(a.seed_base + i, gen)
                c["open"] = not a.closed
                res.append(one(c))
                r = res[-1]
                print(
                    json.dumps(
                        {k: r[k] for k in ("gen", "seed", "factors", "named", "budget", "n")}
                    ),
                    flush=True,
                )
                if a.raw:
                    a.raw.write_text(json.dumps(res, indent=1))
    print(
        f"named: {sum(bool(r['named']) for r in res)}/{len(res)} "
        f"{[(r['gen'], r['seed'], r['named']) for r in res if r['named']]}"
    )
    per = defaultdict(list)
    for r in res:
        for name, v in r["verdicts"].items():
            per[name].append((r, v))
    print(
        "| candidate | n | gain max | gain 90 % | t at max | gain/budget max | "
        "records with gain > 0.02 and t > 2.5 |"
    )
    print("|---|---|---|---|---|---|---|")
    for name, rows in sorted(per.items()):
        g = np.array([v["gain"] for _, v in rows], float)
        t = np.array([v["t"] for _, v in rows], float)
        b = np.array([r["budget"] or 0.0 for r, _ in rows], float)
        fin = np.isfinite(g)
        if not fin.any():
            continue
        k = int(np.nanargmax(g))
        ratio = np.where(b > 0, g / np.where(b > 0, b, 1), np.nan)
        hits = [f"{r['gen']}{r['seed'] % 1000}" for (r, v) in rows
                if v["gain"] > 0.02 and v["t"] > 2.5]  # fmt: skip
        print(
            f"| {name} | {len(rows)} | {g[k]:.3g} | {np.quantile(g[fin], 0.9):.3g} | "
            f"{t[k]:.3g} | {np.nanmax(ratio):.3g} | {' '.join(hits)} |"
        )


if __name__ == "__main__":
    main()
