"""The look-alike pair one amplitude cannot separate (issue 29, helper loadslip): a 2f load
in phase with the stroke (φ within 0.5 rad of 0 or π: 1 - 2(x/A)², the same on both
strokes) against a Stribeck term whose speed v_s is 0.6-1.5 Aω (its e^(-(v/v_s)²) is then
nearly a parabola in v, hence in x). Records of ``benches/chain_loadslip.py``; prints what
``diagnose`` names on each.

    nice .venv/bin/python benches/eval_loadslip_tradeoff.py --seed-base 5180000 --n 8
"""

from __future__ import annotations

import argparse
import math
import sys
import warnings
from collections import Counter
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import chain_loadslip


def case(kind, seed):
    rng = np.random.default_rng([seed, 77])
    effect = "normal_load" if kind == "load_in_phase" else "stribeck"
    c = chain_loadslip.draw(rng, effect)
    fac = c["factors"]
    if kind == "load_in_phase":
        c["params"]["phi"] = float(rng.uniform(-0.5, 0.5) + (math.pi if rng.random() < 0.5 else 0))
    else:
        aw = fac["acA"] / fac["ac"] * 2 * math.pi * fac["f"]
        c["params"]["v_s"] = float(rng.uniform(0.6, 1.5)) * aw
    return c


def main(argv=None):
    import contactlab

    warnings.simplefilter("ignore")
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed-base", type=int, required=True)
    ap.add_argument("--n", type=int, default=8)
    a = ap.parse_args(argv)
    seed = a.seed_base
    for kind in ("load_in_phase", "stribeck_wide"):
        tally = Counter()
        for _ in range(a.n):
            c = case(kind, seed)
            t, x, F, truth = chain_loadslip.make(c, seed)
            named = contactlab.diagnose((t, x, F), model="tangential").effect_names
            tally["+".join(sorted(named)) or "nothing"] += 1
            fac = c["factors"]
            print(f"{kind:14s} {seed} acA {fac['acA']:.2f} xn {100 * fac['x_noise']:.2f}% "
                  f"size {truth['size_peak']:.3f} -> {named}", flush=True)  # fmt: skip
            seed += 1
        print(f"{kind}: {dict(tally)}")


if __name__ == "__main__":
    main()
