"""One candidate's held-out gain on clean and on effect records, its floors open (issue 29,
helper loadslip): what the input's noise alone gives it, against what the effect gives it.

Records of ``benches/chain_loadslip.py`` and of the rig (``eval_loadslip.rig_case``); the
diagnosis is restricted to ``--candidate`` with its per-effect floors off
(``gain_floor_scale`` tiny, ``input_noise_gain`` False), and the first step's verdict is
printed beside the search's input-noise budget and ``min_gain``.

    nice .venv/bin/python benches/eval_loadslip_gains.py --candidate stick_slip \
        --seed-base 930000 --clean 16 --n 8 --effect stick_slip
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


def one(gen, effect, seed, name):
    import contactlab
    from contactlab.diagnose import search
    from contactlab.diagnose.effects import registry

    warnings.simplefilter("ignore")
    eff = registry("tangential")[name]
    eff.gain_floor_scale = 1e-6
    eff.input_noise_gain = False
    seen = {}
    orig = search._noise_floor

    def spy(family, names, budget):
        seen["budget"] = budget
        return orig(family, names, budget)

    search._noise_floor = spy
    if gen == "chain":
        case = chain_loadslip.draw(np.random.default_rng([seed, 77]), effect)
        t, x, F, truth = chain_loadslip.make(case, seed)
        data = (t, x, F)
    else:
        data, truth = rig_case(effect, seed)
    rep = contactlab.diagnose(data, model="tangential", candidates=[name], max_effects=1)
    search._noise_floor = orig
    v = next((v for v in rep.steps[0].candidates if v.name == name), None)
    fac = truth["factors"]
    return {
        "gen": gen,
        "effect": effect,
        "seed": seed,
        "acA": fac["acA"],
        "xn": fac["x_noise"],
        "gain": np.nan if v is None else v.gain,
        "t": np.nan if v is None else v.t_stat,
        "budget": seen.get("budget", np.nan),
        "named": rep.effect_names,
    }


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--candidate", required=True)
    ap.add_argument("--effect", default=None)
    ap.add_argument("--seed-base", type=int, required=True)
    ap.add_argument("--clean", type=int, default=12)
    ap.add_argument("--n", type=int, default=6)
    ap.add_argument("--gens", default="chain,rig")
    a = ap.parse_args(argv)
    rows = []
    i = 0
    for g in a.gens.split(","):
        for e in [None] * a.clean + ([a.effect] * a.n if a.effect else []):
            r = one(g, e, a.seed_base + i, a.candidate)
            i += 1
            rows.append(r)
            print(
                f"{g:5s} {e!s:12s} seed {r['seed']} acA {r['acA']:.2f} xn {100 * r['xn']:.2f}% "
                f"gain {r['gain']:.4f} t {r['t']:.2f} budget {r['budget']:.3f} "
                f"share {r['gain'] / r['budget'] if r['budget'] > 0 else np.nan:.3f}",
                flush=True,
            )
    clean = [r for r in rows if r["effect"] is None and np.isfinite(r["gain"])]
    if clean:
        big = [r for r in clean if r["budget"] > 0.1]
        print(
            f"clean: largest gain {max(r['gain'] for r in clean):.4f} σ², largest t "
            f"{max(r['t'] for r in clean):.2f}; largest share of the budget (budget > 0.1 σ²) "
            f"{max((r['gain'] / r['budget'] for r in big), default=np.nan):.3f}"
        )


if __name__ == "__main__":
    main()
