"""Normal contact, issue 29: loss asymmetry and creep under the conditions the blind
generator missed them at (stop 48: ``asymmetric_branches`` a -0.3 to -0.5 at 12-35 Hz,
``creep_drift`` τc 0.2-1.2 s at 2.7-9.5 Hz), on ``chain_normal``'s measurement chain.

Per seed: the clean chain (what is named, the stated bounds of both effects), the chain with
a loss asymmetry ``a`` drawn in -0.5..-0.3 (or ``--a-lo``/``--a-hi``), and the chain with a
creep of ``D`` drawn log-uniform in 0.01-0.15 of the static displacement amplitude and ``τc``
in 0.2-1.2 s; each line gives what is named and the effect's size against the bound stated
on the clean record.

    nice .venv/bin/python benches/eval_normal_asym_creep.py --seeds 0-9 --base 49300000
"""

from __future__ import annotations

import argparse
import json
import sys
import warnings
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from chain_normal import chain_record


def diagnose(t, p, d):
    import contactlab

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = contactlab.diagnose({"t": t, "p": p, "delta": d}, "normal")
    b = {x.effect: x.to_dict() for x in r.not_detected}
    flagged = bool(r.to_dict().get("unexplained", {}).get("flagged", False))
    return list(r.effect_names), flagged, b


def factors(rng, effect, fs_choices):
    if effect == "asymmetric_branches":
        f = float(rng.uniform(12.0, 35.0))
        ratio = float(rng.uniform(0.33, 0.70))
        noise_p, noise_d = float(rng.uniform(0.005, 0.02)), float(rng.uniform(0.005, 0.02))
    else:
        f = float(rng.uniform(2.7, 9.5))
        ratio = float(rng.uniform(0.29, 0.62))
        noise_p, noise_d = float(rng.uniform(0.009, 0.018)), float(rng.uniform(0.005, 0.019))
        fs_choices = [c for c in fs_choices if c <= 2000.0] or fs_choices
    return {"fs": float(rng.choice(fs_choices)), "f": f, "cycles": int(rng.integers(12, 36)),
            "ratio": ratio, "noise_p": noise_p, "noise_d": noise_d, "bits": 16,
            "psi": float(rng.uniform(0.05, 0.3))}  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", default="0-3")
    ap.add_argument("--base", type=int, default=49300000)
    ap.add_argument("--effects", default="asymmetric_branches,creep_drift")
    ap.add_argument("--fs", default="1000,2000,5000,10000")
    ap.add_argument("--a-lo", type=float, default=0.3)
    ap.add_argument("--a-hi", type=float, default=0.5)
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    lo, hi = (int(s) for s in a.seeds.split("-"))
    fs_choices = [float(x) for x in a.fs.split(",")]
    tally = defaultdict(lambda: defaultdict(int))
    rows = []
    for s in range(lo, hi + 1):
        seed = a.base + s
        for e in a.effects.split(","):
            rng = np.random.default_rng([seed, len(e)])
            fac = factors(rng, e, fs_choices)
            t, p, d, clean = chain_record(None, 0.0, fac, seed)
            cn, cf, bounds = diagnose(t, p, d)
            tally["clean"]["named" if cn else "flagged" if cf else "quiet"] += 1
            b = bounds.get(e, {})
            if e == "asymmetric_branches":
                size = -float(rng.uniform(a.a_lo, a.a_hi))
                ratio = abs(size) / b["detectable_above"] if b.get("detectable_above") else None
            else:
                fac["tau_c"] = float(rng.uniform(0.2, 1.2))
                size = float(np.exp(rng.uniform(np.log(0.01), np.log(0.15))))
                db = b.get("detectable_above")
                ratio = size * clean["D"] / db if db else None
            t, p, d, _ = chain_record(e, size, fac, seed + 1)
            nm, fl, after = diagnose(t, p, d)
            key = "exact" if nm == [e] else "missed" if not nm else "other"
            band = "no bound" if ratio is None else "above" if ratio >= 1 else "below"
            tally[e][key] += 1
            tally[e + " " + band][key] += 1
            row = {"seed": seed, "effect": e, "fac": fac, "clean": cn, "clean_flagged": cf,
                   "bound": b.get("detectable_above"), "reason": b.get("reason", "")[:200],
                   "size": size, "over_bound": ratio, "named": nm, "flagged": fl,
                   "bound_with_effect": after.get(e, {}).get("detectable_above")}  # fmt: skip
            rows.append(row)
            print(f"{seed} {e}: fs {fac['fs']:.0f} f {fac['f']:.1f} cyc {fac['cycles']} ratio "
                  f"{fac['ratio']:.2f} noise {100 * fac['noise_p']:.1f}/"
                  f"{100 * fac['noise_d']:.1f} % tau_c {fac.get('tau_c', float('nan')):.2f}: "
                  f"clean {cn}; size {size:+.3g} bound {b.get('detectable_above')} "
                  f"size/bound {ratio if ratio is None else round(ratio, 2)} -> {nm}",
                  flush=True)  # fmt: skip
            if a.out:
                Path(a.out).write_text(json.dumps(rows, indent=1, default=str))
    print()
    for k, c in sorted(tally.items()):
        print(f"{k:34s} " + " ".join(f"{x} {n}" for x, n in sorted(c.items())))


if __name__ == "__main__":
    main()
