"""Creep on ``chain_normal`` over a grid of size and settling time (issue 29, stop 46).

Chains drawn at the settings of the issue's missed creeps (fs, cycles, white noise given
in % of each channel's *amplitude*, i.e. half that of its range), drive frequency drawn
1-50 Hz (at least 20 samples a cycle), ψ 0.05-0.3, pa/p0 0.2-0.8; on each a creep
``D (1 - exp(-t/τc))`` with ``D`` a fraction of the displacement amplitude and ``τc`` a
fraction of the record, and its clean twin (with ``--drift``: a bowed sensor drift of
0.2-2 % of the range on every chain). Prints what ``diagnose`` names, the first step's
creep verdict (held-out gain in σ², t, reason) and the creep bound stated on the twin.

    nice .venv/bin/python benches/eval_normal_creep_grid.py --seeds 0-3 --base 291100
"""

from __future__ import annotations

import argparse
import json
import sys
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from chain_normal import chain_record

#: (fs, cycles, noise δ, noise p) in % of the amplitude: the settings of the missed creeps
SETTINGS = ((10000.0, 20, 1.7, 1.6), (1000.0, 35, 1.5, 1.7), (5000.0, 8, 1.8, 1.6),
            (2000.0, 50, 1.2, 1.3))  # fmt: skip


def diagnose(t, p, d):
    import contactlab

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = contactlab.diagnose({"t": t, "p": p, "delta": d}, "normal")
    first = {}
    for st in r.steps[:1]:
        for v in st.candidates:
            first[v.name] = {"gain": v.gain, "t": v.t_stat, "reason": v.reason}
    bound = {}
    for b in r.not_detected:
        bd = b.to_dict()
        if bd["effect"] == "creep_drift":
            bound = {"D": bd.get("detectable_above"), "rel": bd.get("relative_size"),
                     "at": bd.get("at"), "reason": bd.get("reason")}  # fmt: skip
    flagged = bool(r.to_dict().get("unexplained", {}).get("flagged", False))
    return {"named": list(r.effect_names), "flagged": flagged,
            "creep": first.get("creep_drift"), "bound": bound}  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", default="0-3")
    ap.add_argument("--base", type=int, default=291100)
    ap.add_argument("--sizes", default="0.01,0.02,0.03")
    ap.add_argument("--taus", default="0.03,0.1,0.3,1.0")
    ap.add_argument("--drift", action="store_true")
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    sizes = [float(x) for x in a.sizes.split(",")]
    taus = [float(x) for x in a.taus.split(",")]
    lo, hi = (int(s) for s in a.seeds.split("-"))
    res = []
    for s in range(lo, hi + 1):
        seed = a.base + s
        rng = np.random.default_rng(seed)
        fs, cyc, nd, npr = SETTINGS[s % len(SETTINGS)]
        f = float(np.exp(rng.uniform(np.log(1.0), np.log(min(50.0, fs / 20.0)))))
        fac = {"fs": fs, "f": f, "cycles": cyc, "ratio": float(rng.uniform(0.2, 0.8)),
               "noise_p": npr / 200.0, "noise_d": nd / 200.0, "bits": 16,
               "psi": float(rng.uniform(0.05, 0.3))}  # fmt: skip
        if a.drift:
            fac["sensor_drift"] = float(rng.uniform(0.002, 0.02)) * float(rng.choice([-1, 1]))
            fac["sensor_bow"] = float(rng.uniform(-1, 1))
        T = min(cyc, max(5, int(150_000 * f / fs))) / f
        t, p, d, _ = chain_record(None, 0.0, fac, seed)
        row = {"seed": seed, "fac": fac, "clean": diagnose(t, p, d), "creep": []}
        c = row["clean"]
        print(
            f"seed {seed}: fs {fs:.0f} f {f:.2f} cyc {cyc} T {T:.3g}s  clean named "
            f"{c['named']} flagged {c['flagged']} bound {c['bound']}",
            flush=True,
        )
        for tf in taus:
            for D in sizes:
                sign = float(rng.choice([-1, 1]))
                f2 = dict(fac, tau_c=tf * T)
                t, p, d, _ = chain_record("creep_drift", sign * D, f2, seed + 500)
                v = diagnose(t, p, d)
                row["creep"].append({"tau_frac": tf, "D": sign * D, **v})
                cv = v["creep"] or {}
                print(
                    f"   τc {tf:5.2f} T  D {sign * D:+.3f}  named {v['named']} flagged "
                    f"{v['flagged']}  creep g {cv.get('gain', float('nan')):.3g} t "
                    f"{cv.get('t', float('nan')):.2f} {cv.get('reason', '')[:110]}",
                    flush=True,
                )
        res.append(row)
        if a.out:
            Path(a.out).write_text(json.dumps(res, indent=1, default=str))


if __name__ == "__main__":
    main()
