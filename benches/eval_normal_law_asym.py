"""The stiffening law against the loss asymmetry at the law's stated bound (stop 47).

Each seed draws a chain of ``chain_normal`` (``draw_factors``, redrawn until the record has
at most ``--max-n`` samples, as the chain integrates the nonlinear joint in Python), states
the bounds on the clean record, hides a κ1-type law (``a2``, either sign) at ``--factor``
times its stated bound in the chain's units, and logs what is named with
:func:`~contactlab.diagnose.effects.normal.asymmetric_branches.shape_evidence` at each
verdict of the two rivals (total, held-out, start-up; positive: the law fits better).

    nice .venv/bin/python benches/eval_normal_law_asym.py --seeds 0-9 --base 5610500
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from chain_normal import chain_record, draw_factors
from eval_normal_power import bound_in_chain_units, diagnose

_LOG: list = []


def _hook() -> None:
    from contactlab.diagnose.effects.normal import asymmetric_branches as ab

    orig = ab.shape_evidence

    def shape_evidence(d, current, stiff, asym):
        out = orig(d, current, stiff, asym)
        _LOG.append([float(x) for x in out] + [float(asym.full.params.get("a", np.nan)),
                     float(stiff.full.params.get("kappa1", np.nan)),
                     float(stiff.full.params.get("kappa", np.nan))])  # fmt: skip
        return out

    ab.shape_evidence = shape_evidence


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", default="0-3")
    ap.add_argument("--base", type=int, default=5610500)
    ap.add_argument("--factor", type=float, default=1.0)
    ap.add_argument("--max-n", type=int, default=8000)
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    _hook()
    lo, hi = (int(s) for s in a.seeds.split("-"))
    rows, tally = [], {}
    for s in range(lo, hi + 1):
        seed = a.base + s
        rng = np.random.default_rng(seed)
        while True:
            fac = draw_factors(rng)
            if (
                fac["f"] >= 1.0
                and fac["fs"] / fac["f"] >= 20
                and fac["cycles"] * fac["fs"] / fac["f"] <= a.max_n
            ):
                break
        fac["law"] = "a2"
        t, p, d, clean = chain_record(None, 0.0, fac, seed)
        cn, bounds, _ = diagnose(t, p, d)
        bc = bound_in_chain_units(
            "stiffness_nonlinearity", bounds.get("stiffness_nonlinearity", {}), clean
        )
        row = {"seed": seed, "fac": fac, "clean": cn, "bound": bc}
        if np.isfinite(bc):
            size = a.factor * bc * float(rng.choice([-1.0, 1.0]))
            _LOG.clear()
            tt, pp, dd, _ = chain_record("stiffness_nonlinearity", size, fac, seed + 500)
            nm, _, _ = diagnose(tt, pp, dd)
            row.update({"size": size, "named": nm, "evidence": list(_LOG)})
            key = "exact" if nm == ["stiffness_nonlinearity"] else "+".join(nm) or "nothing"
            tally[key] = tally.get(key, 0) + 1
        rows.append(row)
        print(f"seed {seed}: fs {fac['fs']:.0f} f {fac['f']:.2f} cyc {fac['cycles']} noise "
              f"{100 * fac['noise_p']:.2f}/{100 * fac['noise_d']:.2f} % clean {cn} bound {bc:.3g} "
              f"size {row.get('size', float('nan')):+.3g} -> {row.get('named')} "
              f"{row.get('evidence')}", flush=True)  # fmt: skip
        if a.out:
            Path(a.out).write_text(json.dumps(rows, indent=1, default=str))
    print(f"\nfactor {a.factor}: " + ", ".join(f"{k} {v}" for k, v in sorted(tally.items())))


if __name__ == "__main__":
    main()
