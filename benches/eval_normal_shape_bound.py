"""Are the stated bounds of the normal shapes (``stiffness_nonlinearity``'s κ1,
``asymmetric_branches``' a) found at their own size? (issue 29, stop 52)

Package solver, one tone ``p = p0 + pa sin ωt`` from rest at the conditions of
``benches/eval_normal_ideal.py --set blind52`` (fs, f, cycles, noise on p and δ, pa/p0), ψ
given: per seed the clean record is diagnosed, each shape hidden at ``--factor`` times the
bound it states (fresh noise) and diagnosed again.

    nice .venv/bin/python benches/eval_normal_shape_bound.py --seed 52100200 --n 3 --psi 0.6
"""

from __future__ import annotations

import argparse
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import eval_normal_ideal as E


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seed", type=int, default=52100200)
    ap.add_argument("--n", type=int, default=3)
    ap.add_argument("--psi", type=float, default=0.6)
    ap.add_argument("--factor", type=float, default=1.0)
    ap.add_argument("--only", default=None)
    a = ap.parse_args()
    tally = defaultdict(lambda: defaultdict(int))
    E.PSI = a.psi
    for i, (key, (fs, f, cyc, xn, yn, ratio)) in enumerate(E.BLIND52.items()):
        if a.only and a.only not in key:
            continue
        E.PA = ratio * E.P0
        for j in range(a.n):
            seed = a.seed + 100 * i + j
            rng = np.random.default_rng(seed)
            t, p, d = E.noisy(fs, f, cyc, xn, yn, seed)
            rep = E.diagnose(t, p, d)
            fl = bool(rep.to_dict().get("unexplained", {}).get("flagged", False))
            tally["clean"]["named" if rep.effect_names else "flagged" if fl else "quiet"] += 1
            bnd = E.bounds_of(rep)
            line = f"{key:15s} {seed} clean {list(rep.effect_names)} {fl}"
            for e, par in (("stiffness_nonlinearity", "kappa1"), ("asymmetric_branches", "a")):
                b = (bnd.get(e, {}).get("per_parameter") or {}).get(par)
                if b is None:
                    tally[e]["no bound"] += 1
                    line += f"; {par} no bound"
                    continue
                size = a.factor * b * float(rng.choice([-1, 1]))
                if abs(size) >= {"kappa1": 0.4, "a": 0.95}[par]:
                    tally[e]["beyond range"] += 1
                    continue
                tn, pn, dn = E.noisy(fs, f, cyc, xn, yn, seed + 1000, e, size)
                r2 = E.diagnose(tn, pn, dn)
                nm = list(r2.effect_names)
                f2 = bool(r2.to_dict().get("unexplained", {}).get("flagged", False))
                res = (
                    "exact"
                    if nm == [e]
                    else "extra"
                    if e in nm
                    else "missed"
                    if not nm
                    else "wrong"
                )
                tally[e][res] += 1
                line += f"; {par} {size:+.3g} -> {nm} {'flagged' if f2 else ''}"
            print(line, flush=True)
    print(f"\nfactor {a.factor} psi {a.psi}")
    for k, c in tally.items():
        print(f"{k:24s} " + " ".join(f"{x} {n}" for x, n in sorted(c.items())))


if __name__ == "__main__":
    main()
