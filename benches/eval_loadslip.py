"""Normal load, stick-slip and Stribeck and their look-alikes (issue 29, helper loadslip).

Records from two sources: ``chain`` (``benches/chain_loadslip.py``, written from
docs/effects.md alone) and ``rig`` (the package's rig simulator, sized effects), across fs
1-10 kHz, 1-50 Hz, 5-50 cycles, ac·A 0.3-5, x noise 0-2 %; for each of normal_load (2f,
±1-15 %), stick_slip, stribeck, parallel_stiffness, position_friction, and clean records.
``contactlab.diagnose`` on each; the table gives exact / extra / missed / wrong by effect,
the confusions, the misses above and below the bound the diagnosis states, and on clean
records: anything named, anything flagged.

    nice .venv/bin/python benches/eval_loadslip.py --seed-base 500000 --n 6 --clean 20 \
        --out benches/results/eval_loadslip_x.json
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
import warnings
from collections import Counter, defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import chain_loadslip

EFFECTS = chain_loadslip.EFFECTS
UNNAMEABLE = ("tanh_virgin",)


def rig_case(effect, seed):
    """A rig record with the effect at a drawn size (the rig's parameters)."""
    from contactlab.synthetic.rig import rig_recording

    rng = np.random.default_rng([seed, 77])
    case = chain_loadslip.draw(rng, effect)
    fac = case["factors"]
    h0, ac = 40.0, 4.0e4
    A = fac["acA"] / ac
    w = 2 * math.pi * fac["f"]
    p = case["params"]
    eff = {}
    if effect == "normal_load":
        eff = {"normal_load": {"eps": p["eps"], "f_n": p["f_n"], "phi": p["phi"]}}
    elif effect == "stick_slip":
        eff = {"stick_slip": {"b": p["b"], "d_c": p["d_c"] / fac["acA"] * fac["ac"] * A}}
    elif effect == "stribeck":
        eff = {"stribeck": {"s": p["s"], "v_s": p["v_s"] / (fac["acA"] / fac["ac"] * w) * A * w}}
    elif effect == "parallel_stiffness":
        hm = fac["h0"] * -math.expm1(-fac["acA"])
        share = p["k_p"] * (fac["acA"] / fac["ac"]) / hm
        eff = {"parallel_stiffness": {"k_p": share * h0 * -math.expm1(-fac["acA"]) / A}}
    elif effect == "position_friction":
        Lr = p["L"] / (fac["acA"] / fac["ac"])
        eff = {"position_friction": {"eps": p["a"], "L": Lr * A, "phi": p["phi"]}}
    elif effect == "tanh_virgin":  # an unnameable misfit: a virgin curve of another shape
        eff = {"tanh_virgin": {}}
    rec = rig_recording(
        eff,
        "tangential",
        seed=seed,
        fs=fac["fs"],
        f=fac["f"],
        cycles=fac["cycles"],
        acA=fac["acA"],
        x_noise=fac["x_noise"],
        F_noise=fac["F_noise"],
        h0=h0,
        ac=ac,
    )
    truth = {"factors": fac, "effect": effect, "params": eff.get(effect, {})}
    return (rec.t, rec.channels["x"], rec.channels["F"]), truth


def run(gen, effect, seed):
    import contactlab

    warnings.simplefilter("ignore")
    t0 = time.process_time()
    if gen == "chain":
        case = chain_loadslip.draw(np.random.default_rng([seed, 77]), effect)
        t, x, F, truth = chain_loadslip.make(case, seed)
        data = (t, x, F)
    else:
        data, truth = rig_case(effect, seed)
    out = {"gen": gen, "effect": effect, "seed": seed, "truth": truth}
    try:
        rep = contactlab.diagnose(data, model="tangential")
        d = rep.to_dict()
        out["named"] = [e["name"] for e in d.get("effects", [])]
        out["params"] = {e["name"]: e.get("parameters", {}) for e in d.get("effects", [])}
        un = d.get("unexplained") or {}
        out["flagged"] = bool(un.get("flagged")) if isinstance(un, dict) else bool(un)
        if effect and effect not in out["named"]:
            nd = [b for b in d.get("not_detected", []) or [] if b.get("effect") == effect]
            if nd:
                out["bound"] = {k: nd[0].get(k) for k in ("parameter", "detectable_above")}
            ref = [r for r in (d.get("location") or {}).get("refused", []) or []
                   if isinstance(r, dict) and r.get("effect") == effect]  # fmt: skip
            if ref:
                out["refused"] = str(ref[0])[:300]
        out["error"] = None
    except Exception as exc:
        out["named"], out["flagged"], out["error"] = [], False, f"{type(exc).__name__}: {exc}"
    out["cpu"] = time.process_time() - t0
    return json.loads(json.dumps(out, default=float))


def outcome(r):
    if r["error"]:
        return "error"
    named = set(r["named"])
    e = r["effect"]
    if e is None:
        return "clean-ok" if not named and not r["flagged"] else "clean-bad"
    if e in UNNAMEABLE:
        return "flagged" if r["flagged"] else ("absorbed" if named else "silent")
    if named == {e}:
        return "exact"
    if e in named:
        return "extra"
    return "missed" if not named else "wrong"


def table(results):
    lines = []
    by = defaultdict(list)
    for r in results:
        by[(r["gen"], r["effect"] or "clean")].append(r)
    lines.append("| gen | effect | n | exact | extra | missed | wrong | confused with |")
    lines.append("|---|---|---|---|---|---|---|---|")
    for (g, e), rs in sorted(by.items()):
        if e == "clean":
            named = sum(bool(r["named"]) for r in rs)
            fl = sum(bool(r["flagged"]) for r in rs)
            ok = sum(outcome(r) == "clean-ok" for r in rs)
            lines.append(
                f"| {g} | clean | {len(rs)} | nothing named or flagged {ok} | named {named} "
                f"| flagged {fl} | | {dict(Counter(n for r in rs for n in r['named']))} |"
            )
            continue
        c = Counter(outcome(r) for r in rs)
        if e in UNNAMEABLE:
            lines.append(
                f"| {g} | {e} | {len(rs)} | flagged {c['flagged']} | absorbed {c['absorbed']} "
                f"| silent {c['silent']} | | {dict(Counter(n for r in rs for n in r['named']))} |"
            )
            continue
        conf = Counter("+".join(sorted(r["named"])) for r in rs if outcome(r) == "wrong")
        lines.append(
            f"| {g} | {e} | {len(rs)} | {c['exact']} | {c['extra']} | {c['missed']} | "
            f"{c['wrong']} | {dict(conf)} |"
        )
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed-base", type=int, required=True)
    ap.add_argument("--n", type=int, default=4, help="records per effect and generator")
    ap.add_argument("--clean", type=int, default=10, help="clean records per generator")
    ap.add_argument("--gens", default="chain,rig")
    ap.add_argument("--effects", default=",".join(EFFECTS))
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument(
        "--only", default=None, help="run only these effects (clean: 'clean'), same seeds"
    )
    a = ap.parse_args(argv)
    only = None if a.only is None else set(a.only.split(","))
    jobs = []
    for g in a.gens.split(","):
        for e in [None] * a.clean + [e for e in a.effects.split(",") if e for _ in range(a.n)]:
            if not (g == "chain" and e in UNNAMEABLE):  # the chain's element is exponential
                jobs.append((g, e))
    results = []
    for i, (g, e) in enumerate(jobs):
        if only is not None and (e or "clean") not in only:
            continue
        r = run(g, e, a.seed_base + i)
        results.append(r)
        fac = r["truth"]["factors"]
        print(
            f"{g:5s} {e or 'clean':18s} seed {r['seed']} acA {fac['acA']:.2f} "
            f"xn {100 * fac['x_noise']:.2f}% fs {fac['fs']:.0f} f {fac['f']:.2f} "
            f"-> {outcome(r):9s} {r['named']} flag={r['flagged']} cpu {r['cpu']:.1f}"
            + (f" bound {r.get('bound')}" if r.get("bound") else "")
            + (f" ERR {r['error']}" if r["error"] else ""),
            flush=True,
        )
        if a.out:
            a.out.write_text(json.dumps(results, indent=1))
    print(table(results))


if __name__ == "__main__":
    main()
