"""The first step's held-out gains of a 2f load and its look-alikes on one record each
(issue 29, helper loadslip): normal_load (with the share of its fitted fluctuation that
differs between the strokes), stribeck, position_friction, parallel_stiffness, stick_slip.

    nice .venv/bin/python benches/eval_loadslip_rivals.py --seed-base 940000 --n 6 \
        --effects normal_load,stribeck,position_friction
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import chain_loadslip
from eval_loadslip import rig_case

RIVALS = ("normal_load", "stribeck", "position_friction", "parallel_stiffness", "stick_slip")


def one(gen, effect, seed):
    import contactlab

    warnings.simplefilter("ignore")
    if gen == "chain":
        case = chain_loadslip.draw(np.random.default_rng([seed, 77]), effect)
        t, x, F, truth = chain_loadslip.make(case, seed)
        data = (t, x, F)
    else:
        data, truth = rig_case(effect, seed)
    rep = contactlab.diagnose(data, model="tangential")
    gains = {v.name: (v.gain, v.accepted) for v in rep.steps[0].candidates if v.name in RIVALS}
    return truth, gains, rep.effect_names


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed-base", type=int, required=True)
    ap.add_argument("--n", type=int, default=6)
    ap.add_argument("--effects", default="normal_load,stribeck,position_friction")
    ap.add_argument("--gens", default="chain,rig")
    a = ap.parse_args(argv)
    i = 0
    for g in a.gens.split(","):
        for e in a.effects.split(","):
            for _ in range(a.n):
                truth, gains, named = one(g, e, a.seed_base + i)
                i += 1
                fac, p = truth["factors"], truth["params"]
                ref = gains.get("normal_load", (np.nan, False))[0]
                cells = " ".join(
                    f"{n[:6]} {gains[n][0]:.3g}{'*' if gains[n][1] else ''}"
                    + (f"({gains[n][0] / ref:.2f})" if np.isfinite(ref) and ref > 0 else "")
                    for n in RIVALS
                    if n in gains
                )
                pp = {k: round(v, 4) if isinstance(v, float) else v for k, v in p.items()}
                print(
                    f"{g:5s} {e:18s} {a.seed_base + i - 1} acA {fac['acA']:.2f} "
                    f"xn {100 * fac['x_noise']:.2f}% {pp} -> {named} | {cells}",
                    flush=True,
                )


if __name__ == "__main__":
    main()
