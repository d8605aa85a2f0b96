"""What the search's shape comparison (``asymmetric_branches.shape_test``) reads on the
package's chain (``benches/chain_normal.py``): per record, every comparison of the loss
asymmetry with the stiffening law the search makes, its z (positive: the law fits better),
the half-gap G = ‖f_s - f_a‖_w/(2σ) between the two fits and the residual's correlation
factor c; and what is named (stop 53, issue 29).

Were one shape alone true and drawn exactly by its candidate, the other's z would be about
-G + c·N(0, 1) (c the ratio's noise over its white deviation, ``c`` the current residual's
correlation factor, ``c_cycles`` from the spread of the ratio's per-cycle parts): on the
chain it is not (stop 53: the true shape's z ran from -1.8 to +14 at G 1.7-8), which is why a
margin that shrinks with the gap (the encompassing test) named a wrong shape there.

    nice .venv/bin/python benches/eval_normal_shape_z.py --seed 53300200 --n 6
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))


def main() -> None:
    from chain_normal import chain_record, noncentrality
    from contactlab.diagnose.effects.normal import asymmetric_branches as ab
    from contactlab.diagnose.select import correlation_time
    from eval_normal_ideal import BLIND53, LAMBDA_VISIBLE, diagnose

    ap = argparse.ArgumentParser()
    ap.add_argument("--seed", type=int, default=53300200)
    ap.add_argument("--n", type=int, default=6)
    ap.add_argument("--factors", default="1")
    ap.add_argument("--effects", default="stiffness_nonlinearity,asymmetric_branches")
    ap.add_argument("--psi-range", default="0.3,0.8")
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    lo, hi = (float(x) for x in a.psi_range.split(","))
    log: list = []
    orig = ab.shape_test

    def cycles_c(d, current, stiff, asym):
        """The ratio's noise over its white deviation from the spread of its per-cycle
        parts ``q_k = Σ_k w r g`` (``r`` the residual of the two fits' mean, ``g`` their
        gap): ``c² = n Var(q_k) / (σ² Σ w g²)``."""
        from contactlab.diagnose._signal import noise_rms
        from contactlab.diagnose.select import sample_weight

        s2 = noise_rms(current.full_residual(d)) ** 2
        cyc = d.cycles.cycle
        gap = np.asarray(stiff.fitted, float) - np.asarray(asym.fitted, float)
        r = d.y - 0.5 * (np.asarray(stiff.fitted, float) + np.asarray(asym.fitted, float))
        w = sample_weight(d)
        ok = (cyc >= 0) & np.isfinite(gap) & np.isfinite(r)
        ids = np.unique(cyc[ok])
        if ids.size < 4 or not s2 > 0:
            return float("nan")
        q = np.bincount(np.searchsorted(ids, cyc[ok]), weights=(w * r * gap)[ok])
        white = s2 * float(np.sum((w * gap * gap)[ok]))
        return float(np.sqrt(ids.size * float(np.var(q, ddof=1)) / white))

    def traced(d, current, stiff, asym):
        total, held, start, z = orig(d, current, stiff, asym)
        scale = total / z if z else float("nan")
        r = np.asarray(current.full_residual(d), float)
        r = r[np.isfinite(r)]
        c = math.sqrt(max(correlation_time(r, int(d.cycles.period_samples)), 1.0))
        cn = cycles_c(d, current, stiff, asym)
        log.append({"z": z, "G": scale / 4.0, "c": c, "c_cycles": cn, "total": total})
        return total, held, start, z

    ab.shape_test = traced
    keys = [k for k in BLIND53 if not k.startswith("creep")]
    rows = []
    for i in range(a.n):
        key = keys[i % len(keys)]
        fs, f, cyc, xn, yn, _ = BLIND53[key]
        seed = a.seed + i
        rng = np.random.default_rng(seed)
        fac = {"fs": fs, "f": f, "cycles": cyc, "ratio": float(rng.uniform(0.3, 0.8)),
               "noise_p": xn, "noise_d": yn, "bits": 16, "psi": float(rng.uniform(lo, hi)),
               "law": "a2"}  # fmt: skip
        for e in [None, *a.effects.split(",")]:
            ref = {"stiffness_nonlinearity": 0.01, "asymmetric_branches": 0.3}.get(e)
            facs = [0.0] if e is None else [float(x) for x in a.factors.split(",")]
            for fc in facs:
                size = 0.0
                if e is not None:
                    lam, _, _ = noncentrality(e, ref, fac, seed)
                    size = fc * ref * math.sqrt(LAMBDA_VISIBLE / lam) * float(rng.choice([-1, 1]))
                    if e == "asymmetric_branches" and abs(size) >= 0.95:
                        continue
                log.clear()
                t, p, d, _ = chain_record(e, size, fac, seed + 1000)
                rep = diagnose(t, p, d)
                nm = list(rep.effect_names)
                row = {"key": key, "seed": seed, "psi": fac["psi"], "effect": e, "factor": fc,
                       "size": size, "named": nm, "tests": list(log)}  # fmt: skip
                rows.append(row)
                zs = " ".join(
                    f"z {x['z']:+.2f} G {x['G']:.2f} c {x['c']:.2f}/{x['c_cycles']:.2f}"
                    for x in log[:1]
                )
                print(f"{key:14s} {seed} ψ {fac['psi']:.2f} {e} {fc:g}x {size:+.3g} -> {nm} | "
                      f"{zs}", flush=True)  # fmt: skip
        if a.out:
            Path(a.out).write_text(json.dumps(rows, indent=1, default=str))
    tally: dict = {}
    for r in rows:
        k = "clean" if r["effect"] is None else f"{r['effect']} {r['factor']:g}x"
        nm, e = r["named"], r["effect"]
        res = (
            ("quiet" if not nm else "named")
            if e is None
            else ("exact" if nm == [e] else "extra" if e in nm else "missed" if not nm else "wrong")
        )
        tally.setdefault(k, {}).setdefault(res, 0)
        tally[k][res] += 1
    for k, c in tally.items():
        print(f"{k:32s} " + " ".join(f"{x} {n}" for x, n in sorted(c.items())))


if __name__ == "__main__":
    main()
