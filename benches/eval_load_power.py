"""Power for a normal load fluctuating in time (``normal_load``), on the rig simulator
(``contactlab.synthetic.rig``): per seed, record factors as ``benches/eval_slow_power.py``
draws them (fs 1-10 kHz, 1-50 Hz, 5-50 cycles, ac·A 0.3-5, x noise 0-2 %, F noise 0.5-2 %,
a displacement-sensor drift), the clean twin diagnosed (its names are false alarms; its
stated bound for the load), then a load hidden at ``--mults`` times the record's force noise
(relative: ``eps = m · F_noise``, so that each multiple asks the same held-out gain per
sample whatever the record) at a frequency locked to the drive (2f) and at one off its
harmonics (drawn uniform between two periods in the record and 3f, at least 1.5 frequency
bins from a harmonic), each diagnosed with fresh noise. Also each load hidden at the clean
twin's stated bound (``bound``: is it found?).

    nice .venv/bin/python benches/eval_load_power.py --seed-base 62000 --n 6
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))


def load_frequency(seed: int, fac: dict, kind: str) -> float:
    if kind == "2f":
        return 2.0 * fac["f"]
    rng = np.random.default_rng(seed + 3_000_017)
    T = fac["cycles"] / fac["f"]
    for _ in range(100):
        fn = float(rng.uniform(2.0 / T, 3.0 * fac["f"]))
        k = round(fn / fac["f"])
        if abs(fn - k * fac["f"]) * T >= 1.5:
            return fn
    return fn


def run_seed(seed: int, mults: list[float], kinds: list[str]) -> dict:
    import contactlab
    from eval_slow_power import factors, read, record

    warnings.simplefilter("ignore")
    fac = factors(seed, 0.0)
    t0 = time.process_time()
    out = {"seed": seed, "factors": fac, "runs": []}
    rep = contactlab.diagnose(read(record({}, fac, seed)), model="tangential")
    out["clean_named"] = list(rep.effect_names)
    b = next((b for b in rep.not_detected if b.effect == "normal_load"), None)
    out["bound"] = None if b is None else b.detectable_above
    out["bound_rel"] = None if b is None else b.relative_size
    for kind in kinds:
        fn = load_frequency(seed, fac, kind)
        sizes = [(f"x{m:g}", m * fac["F_noise"]) for m in mults]
        if out["bound"] and not out["clean_named"]:
            sizes.append(("bound", out["bound"]))
        for label, eps in sizes:
            s2 = seed + 7919 * (1 + len(out["runs"]))
            eff = {"normal_load": {"eps": eps, "f_n": fn, "phi": fac["phi"]}}
            r = contactlab.diagnose(read(record(eff, fac, s2)), model="tangential")
            vs = [v for st in r.steps for v in st.candidates if v.name == "normal_load"]
            v = vs[0] if vs else None
            out["runs"].append({
                "kind": kind, "label": label, "eps": eps, "f_n": fn,
                "off_bins": abs(fn - round(fn / fac["f"]) * fac["f"]) * fac["cycles"] / fac["f"],
                "named": list(r.effect_names),
                "first": None if v is None else {"gain": v.gain, "t": v.t_stat,
                                                 "reason": v.reason[:100]},
            })  # fmt: skip
    out["cpu"] = time.process_time() - t0
    return json.loads(json.dumps(out, default=float))


def tables(results: list[dict]) -> str:
    lines = []
    fa = [r for r in results if r.get("clean_named")]
    lines.append(f"{len(results)} seeds; clean twins with a name: {len(fa)} "
                 f"({'; '.join('+'.join(r['clean_named']) for r in fa)})")  # fmt: skip
    lines.append("")
    lines.append("| kind | run | n | exact | named | other names |")
    lines.append("|---|---|---|---|---|---|")
    by = defaultdict(list)
    for r in results:
        for run in r.get("runs", []):
            by[(run["kind"], run["label"])].append(run)
    for (kind, label), runs in sorted(by.items()):
        ex = sum(run["named"] == ["normal_load"] for run in runs)
        nm = sum("normal_load" in run["named"] for run in runs)
        other = defaultdict(int)
        for run in runs:
            for n in run["named"]:
                if n != "normal_load":
                    other[n] += 1
        o = ", ".join(f"{k}×{v}" for k, v in sorted(other.items()))
        lines.append(f"| {kind} | {label} | {len(runs)} | {ex} | {nm} | {o} |")
    lines.append("")
    lines.append("Missed (first verdict on the load):")
    for r in results:
        f = r["factors"]
        for run in r.get("runs", []):
            if "normal_load" in run["named"]:
                continue
            lines.append(
                f"- seed {r['seed']} {run['kind']} {run['label']} eps {run['eps']:.4g} "
                f"(off {run['off_bins']:.1f} bins) named {run['named']} {run['first']} "
                f"(fs {f['fs']}, f {f['f']}, cyc {f['cycles']}, acA {f['acA']}, "
                f"xn {f['x_noise']}, Fn {f['F_noise']})"
            )
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed-base", type=int, required=True)
    ap.add_argument("--n", type=int, default=6)
    ap.add_argument("--mults", default="0.5,1", help="eps as multiples of the F noise")
    ap.add_argument("--kinds", default="off,2f")
    ap.add_argument("--raw", type=Path, default=None)
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args(argv)
    mults = [float(m) for m in a.mults.split(",")]
    kinds = a.kinds.split(",")
    results = []
    for s in range(a.seed_base, a.seed_base + a.n):
        r = run_seed(s, mults, kinds)
        results.append(r)
        print(json.dumps(r), flush=True, file=sys.stderr)
        if a.raw:
            a.raw.write_text("\n".join(json.dumps(x) for x in results))
    text = f"seed base {a.seed_base}, n {a.n}, mults {mults}\n\n" + tables(results)
    print(text)
    if a.out:
        a.out.write_text(text + "\n")


if __name__ == "__main__":
    main()
