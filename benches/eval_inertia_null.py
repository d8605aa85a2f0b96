"""A mass on one drive frequency with no plateau against the record's own simulated null
(issue 29): before (``Inertia.null_test = False``, the start-up rule alone) and after, on the
rig simulator's single-frequency records of ``benches/eval_inertia_single.py``, ac·A drawn in
``--aca`` (default 0.3-2.5), x noise in ``--xnoise`` (default 0.5-2 % of the range).

Per record and setting: what ``diagnose`` names, the misfit flag, and every call of
:func:`contactlab.diagnose.mass_null.linear_term_null` (the mass's linearised size on the
record, the null's upper bound, z).

    nice .venv/bin/python benches/eval_inertia_null.py --base 910000 --n 8 \
        --effects inertia,clean --out benches/results/inertia_null_x.md
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import eval_inertia_single as single


def run(seed: int, effect: str, share, aca, xnoise, null_test: bool) -> dict:
    import warnings

    import contactlab
    from contactlab.diagnose import mass_null
    from contactlab.diagnose.effects import registry

    warnings.simplefilter("ignore")
    fac = single.factors(seed, effect, share, "rig", aca)
    rng = np.random.default_rng([seed, 99])
    fac["x_noise"] = round(float(rng.uniform(*xnoise)), 4)
    eff = registry("tangential").get("inertia")
    old = eff.null_test
    eff.null_test = null_test
    calls = []
    orig = mass_null.linear_term_null

    def spy(*a, **k):
        res = orig(*a, **k)
        calls.append(None if res is None else {
            "size": res.size, "thr": res.threshold, "z": res.z, "beyond": res.beyond,
            "null_mean": float(np.mean(res.null)), "null_sd": float(np.std(res.null, ddof=1)),
            "base": list(a[2])})  # fmt: skip
        return res

    mass_null.linear_term_null = spy
    out = {"seed": seed, "effect": effect, "factors": fac, "null_test": null_test}
    t0 = time.process_time()
    try:
        rec, truth = single.make_record(effect, fac, seed + 17)
        rep = contactlab.diagnose(rec, model="tangential")
        out["named"] = list(rep.effect_names)
        un = rep.unexplained
        out["flagged"] = bool(un is not None and getattr(un, "flagged", False))
        out["params"] = {e.name: dict(e.parameters) for e in rep.effects}
        out["truth"] = truth.get("effects", {})
        vs = [v for st in rep.steps for v in st.candidates if v.name == "inertia"]
        out["inertia_last"] = (vs[-1].reason or "")[:160] if vs else ""
    except Exception as exc:
        out["named"], out["flagged"] = [], False
        out["error"] = f"{type(exc).__name__}: {exc}"[:300]
    finally:
        mass_null.linear_term_null = orig
        eff.null_test = old
    out["calls"] = calls
    out["cpu"] = time.process_time() - t0
    return json.loads(json.dumps(out, default=float))


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--base", type=int, required=True)
    ap.add_argument("--n", type=int, default=6)
    ap.add_argument("--effects", default="inertia,parallel_stiffness,series_compliance,clean")
    ap.add_argument("--share", default="0.01,0.13")
    ap.add_argument("--aca", default="0.3,2.5")
    ap.add_argument("--xnoise", default="0.005,0.02")
    ap.add_argument("--settings", default="before,after")
    ap.add_argument("--out", default=None)
    a = ap.parse_args(argv)
    share = tuple(float(v) for v in a.share.split(","))
    aca = tuple(float(v) for v in a.aca.split(","))
    xn = tuple(float(v) for v in a.xnoise.split(","))
    res = []
    for e in a.effects.split(","):
        for i in range(a.n):
            for s in a.settings.split(","):
                r = run(a.base + i, e, share, aca, xn, s == "after")
                r["setting"] = s
                res.append(r)
                print(a.base + i, e, s, r["named"], "F" if r["flagged"] else "",
                      f"{r['cpu']:.0f}s", [(round(c["size"], 4), round(c["thr"], 4),
                      round(c["z"], 2)) for c in r["calls"] if c], r.get("error", ""),
                      file=sys.stderr, flush=True)  # fmt: skip
    lines = [f"base {a.base}, n {a.n}, share {a.share}, ac·A {a.aca}, x noise {a.xnoise}", ""]
    lines.append("| effect | setting | n | exact | named inertia | nothing named | flagged |")
    lines.append("|---|---|---|---|---|---|---|")
    by = defaultdict(list)
    for r in res:
        by[(r["effect"], r["setting"])].append(r)
    for (e, s), rows in by.items():
        exact = sum(r["named"] == ([] if e == "clean" else [e]) for r in rows)
        named = sum("inertia" in r["named"] for r in rows)
        nothing = sum(not r["named"] for r in rows)
        flagged = sum(r["flagged"] for r in rows)
        lines.append(f"| {e} | {s} | {len(rows)} | {exact} | {named} | {nothing} | {flagged} |")
    lines += [
        "",
        "| seed | effect | setting | ac·A | x noise | share | named | flag | "
        "null (size, bound, z) | cpu |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in res:
        f = r["factors"]
        sh = f["share"] if r["effect"] == "inertia" else f["kshare"]
        calls = "; ".join(f"{c['size']:.3g}, {c['thr']:.3g}, {c['z']:.2f}" for c in r["calls"] if c)
        lines.append(f"| {r['seed']} | {r['effect']} | {r['setting']} | {f['acA']:g} | "
                     f"{100 * f['x_noise']:.2f} % | {sh:.3f} | {'+'.join(r['named']) or '-'} | "
                     f"{'F' if r['flagged'] else ''} | {calls} | {r['cpu']:.0f} |")  # fmt: skip
    text = "\n".join(lines)
    print(text)
    if a.out:
        Path(a.out).write_text(text + "\n")
        Path(a.out).with_suffix(".json").write_text(json.dumps(res, indent=1))


if __name__ == "__main__":
    main()
