"""Is the stated bound honest? Each effect hidden at 1x and 2x the bound the clean twin
states (issue 29, item 2: "detectable above b" promises 95 % power at b), on the rig
simulator (``contactlab.synthetic.rig``), fresh noise for the hidden record.

Per (seed, effect): record factors as ``benches/eval_slow_power.py`` draws them (fs 1-10 kHz,
1-50 Hz, 5-50 cycles, ac·A 0.3-5, x noise 0-2 %, F noise 0.5-2 %, a displacement-sensor
drift up to ±0.3 % of the amplitude; an inertia record at 20-50 Hz, where a fixture's mass
can show, as ``benches/eval_diagnose_rig.py`` draws it; ``--inertia-any-f`` keeps the drawn
frequency), the clean twin diagnosed (its names are false alarms; its stated bound for the
effect), then the effect hidden at each ``--mults`` times that bound and diagnosed. An effect
whose clean twin states no bound is counted as such (with the reason).

``--visible`` adds, per seed, the effect at the "visible" size of
``benches/eval_diagnose_rig.py`` (series compliance k_s = h0·ac·U(0.7, 1.5), a mass whose
``m ω² A`` is 10 % of the plateau, ...): what is named when the truth is below its bound
(wrong names) and above it (misses).

    nice .venv/bin/python benches/eval_bound_power.py --seeds tune --n 4 \
        --effects inertia,series_compliance
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

EFFECTS = (
    "inertia",
    "parallel_stiffness",
    "series_compliance",
    "force_drift",
    "position_friction",
    "backlash",
)
TUNE_BASE = 73_000
H0, AC = 40.0, 4.0e4


def factors(seed: int, effect: str, any_f: bool, aca=None) -> dict:
    """The record's factors; ``aca``: (lo, hi) to draw ac·A from instead (log-uniform, its
    own stream: ``--aca``, e.g. records whose loops reach a plateau)."""
    from eval_diagnose_rig import MAX_SAMPLES as RIG_MAX
    from eval_diagnose_rig import _loguniform
    from eval_slow_power import MAX_SAMPLES, factors

    fac = factors(seed, 0.0)
    if aca is not None:
        fac["acA"] = round(_loguniform(np.random.default_rng(seed + 2_000_003), *aca), 3)
    if effect == "inertia" and not any_f:
        rng = np.random.default_rng(seed + 1_000_003)
        fac["f"] = round(_loguniform(rng, 20.0, 50.0), 3)
        fac["fs"] = min(fac["fs"], RIG_MAX * fac["f"] / 5)
        fac["cycles"] = max(5, min(fac["cycles"], int(MAX_SAMPLES * fac["f"] / fac["fs"])))
    return fac


def rig_params(effect: str, size: float, fac: dict) -> dict:
    """Rig parameters of ``effect`` at ``size`` in the diagnosis's parameter."""
    from eval_slow_power import rig_params as slow

    if effect == "inertia":
        return {"m": size}
    if effect == "parallel_stiffness":
        return {"k_p": size}
    if effect == "series_compliance":
        return {"k_s": 1.0 / size}
    if effect == "backlash":
        return {"b": size}
    return slow(effect, size, fac)


def visible_size(effect: str, fac: dict, rng) -> float:
    """The "visible" size of ``benches/eval_diagnose_rig.py`` in the diagnosis's parameter."""
    A = fac["acA"] / AC
    hm = H0 * (1 - math.exp(-fac["acA"]))
    w = 2 * math.pi * fac["f"]
    T_rec = fac["cycles"] / fac["f"]
    return {
        "inertia": 0.1 * hm / (A * w * w),
        "parallel_stiffness": 0.1 * hm / A,
        "series_compliance": 1.0 / (H0 * AC * float(rng.uniform(0.7, 1.5))),
        "force_drift": 1.5 * 0.1 * hm / T_rec * T_rec,
        "position_friction": 0.1,
        "backlash": 0.05 * A,
    }[effect]


def run_job(job):
    import warnings

    import contactlab
    from eval_slow_power import read, record

    warnings.simplefilter("ignore")
    seed, effect, mults, visible, any_f, *rest = job
    fac = factors(seed, effect, any_f, rest[0] if rest else None)
    t0 = time.process_time()
    out = {"seed": seed, "effect": effect, "factors": fac, "runs": []}
    try:
        rep = contactlab.diagnose(read(record({}, fac, seed)), model="tangential")
    except Exception as exc:
        out["error"] = f"{type(exc).__name__}: {exc}"[:200]
        return out
    out["clean_named"] = rep.effect_names
    b = {x.effect: x for x in rep.not_detected}.get(effect)
    bound = None if b is None else b.detectable_above
    out["bound"] = bound
    out["reason"] = "" if b is None else (b.reason or "")[:200]
    out["note"] = "" if b is None else (b.note or "")[:200]
    sizes = []
    if bound is not None and not rep.effect_names:
        sizes += [(f"{m:g}x bound", m * bound) for m in mults]
    if visible:
        rng = np.random.default_rng(seed + 55_555)
        sizes.append(("visible", visible_size(effect, fac, rng)))
    for k, (label, size) in enumerate(sizes):
        s2 = seed + 7919 * (1 + k)
        try:
            r = contactlab.diagnose(
                read(record({effect: rig_params(effect, size, fac)}, fac, s2)),
                model="tangential",
            )
            names = r.effect_names
            vs = [v for st in r.steps for v in st.candidates if v.name == effect]
            v = vs[0] if vs else None
            why = None if v is None else {"gain": v.gain, "t": v.t_stat, "reason": v.reason[:160]}
            own = {x.effect: x.detectable_above for x in r.not_detected}.get(effect)
        except Exception as exc:
            names, why, own = [f"error: {type(exc).__name__}: {exc}"[:100]], None, None
        out["runs"].append({"label": label, "size": size, "named": names, "verdict": why,
                            "over_bound": None if bound is None else size / bound,
                            "own_bound": own})  # fmt: skip
    out["cpu"] = time.process_time() - t0
    return json.loads(json.dumps(out, default=float))


def tables(res: list[dict]) -> str:
    lines = []
    clean = [r for r in res if "clean_named" in r]
    fa = [r for r in clean if r["clean_named"]]
    lines.append(
        f"{len(res)} jobs; clean twins with a name: {len(fa)}/{len(clean)} "
        f"({'; '.join('+'.join(r['clean_named']) for r in fa)}); "
        f"errors {sum(1 for r in res if r.get('error'))}"
    )
    lines.append("")
    lines.append("| effect | no bound stated | run | n | exact | named | other names |")
    lines.append("|---|---|---|---|---|---|---|")
    by = defaultdict(list)
    for r in clean:
        by[r["effect"]].append(r)
    for e in EFFECTS:
        rows = by.get(e)
        if not rows:
            continue
        nob = sum(r["bound"] is None for r in rows)
        labels = sorted({run["label"] for r in rows for run in r["runs"]})
        for i, lab in enumerate(labels or ["–"]):
            runs = [run for r in rows for run in r["runs"] if run["label"] == lab]
            ex = sum(run["named"] == [e] for run in runs)
            nm = sum(e in run["named"] for run in runs)
            other = defaultdict(int)
            for run in runs:
                for n in run["named"]:
                    if n != e:
                        other[n] += 1
            oth = ", ".join(f"{k}×{v}" for k, v in sorted(other.items()))
            lines.append(
                f"| {e if i == 0 else ''} | {f'{nob}/{len(rows)}' if i == 0 else ''} | {lab} "
                f"| {len(runs)} | {ex} | {nm} | {oth} |"
            )
    lines.append("")
    lines.append("Per record:")
    for r in res:
        f = r["factors"]
        head = (
            f"- {r['effect']} seed {r['seed']} (fs {f['fs']}, f {f['f']}, cyc {f['cycles']}, "
            f"acA {f['acA']}, xn {f['x_noise']}, Fn {f['F_noise']}): "
        )
        if r.get("error"):
            lines.append(head + "error " + r["error"])
            continue
        b = r["bound"]
        lines.append(
            head
            + f"clean {r['clean_named']}, bound {b if b is None else f'{b:.3g}'}"
            + (f" ({r['reason'][:90]})" if b is None else "")
        )
        for run in r["runs"]:
            ob = run["over_bound"]
            lines.append(
                f"    {run['label']}: size {run['size']:.3g}"
                + ("" if ob is None else f" ({ob:.2g}x bound)")
                + f" named {run['named']}"
                + ("" if run["verdict"] is None else f" verdict {run['verdict']}")
            )
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", choices=("tune", "fresh"), default="fresh")
    ap.add_argument("--seed-base", type=int, default=None)
    ap.add_argument("--n", type=int, default=4)
    ap.add_argument("--effects", default=",".join(EFFECTS))
    ap.add_argument("--mults", default="1,2", help="multiples of the stated bound")
    ap.add_argument("--visible", action="store_true")
    ap.add_argument("--inertia-any-f", action="store_true")
    ap.add_argument("--aca", default=None, help="lo,hi: draw ac·A log-uniform from this range")
    ap.add_argument("--raw", type=Path, default=None)
    ap.add_argument("--tables-from", type=Path, nargs="+", default=None)
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args(argv)
    if a.tables_from:
        print(tables([r for p in a.tables_from for r in json.loads(p.read_text())]))
        return
    os.environ.setdefault("CONTACTLAB_DIAGNOSE_THREADS", "1")
    if a.seed_base is not None:
        base = a.seed_base
    elif a.seeds == "tune":
        base = TUNE_BASE
    else:
        base = 30_000_000 + (int(time.time()) % 1_000_000) * 100
    mults = tuple(float(m) for m in a.mults.split(",") if m)
    aca = None if a.aca is None else tuple(float(v) for v in a.aca.split(","))
    effects = tuple(a.effects.split(","))
    print(f"seeds {a.seeds} base {base}, {a.n} seeds, effects {effects}", flush=True)
    t0 = time.time()
    res = []
    for i in range(a.n):
        for e in effects:
            res.append(run_job((base + i, e, mults, a.visible, a.inertia_any_f, aca)))
            if a.raw:
                a.raw.write_text(json.dumps(res, indent=1, default=float))
    cpu = sum(r.get("cpu", 0) for r in res)
    text = tables(res) + f"\n\nwall {time.time() - t0:.0f} s, cpu {cpu:.0f} s"
    print(text)
    if a.out:
        a.out.write_text(f"seeds {a.seeds} base {base}\n\n" + text + "\n")


if __name__ == "__main__":
    main()
