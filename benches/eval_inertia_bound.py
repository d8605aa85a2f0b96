"""The inertia bound on one drive frequency below a plateau (issue 29, item 2): is the mass
bound stated from the record's own simulated null honest, and why are visible masses missed?

On the rig simulator (``contactlab.synthetic.rig``, via ``benches/eval_slow_power.py``'s
``record``), one drive frequency from rest, ac·A below 2.5 (where ``Inertia.null_test``
acts). Two modes:

- ``--mode misses``: records at stated factors (``--factors``: ``acA,x_noise,F_noise,cycles,
  fs,f,share`` separated by ``;``; ``share`` is ``m ω² A`` over the force amplitude
  ``h0 (1 - exp(-ac·A))``), each with ``--n`` noise seeds: what is named, the mass null's
  ``(size, bound, z)`` of each call, the last verdict on ``inertia`` and the stated bound;
- ``--mode calibrate``: factors drawn as ``benches/eval_bound_power.py`` draws an inertia
  record (20-50 Hz) with ac·A in ``--aca``; the clean twin diagnosed (its names are false
  alarms, its stated inertia bound), then the mass hidden at ``--mults`` times the bound
  with fresh noise and diagnosed (named inertia or not).

    nice .venv/bin/python benches/eval_inertia_bound.py --mode calibrate --seed-base 5100 \
        --n 8 --out benches/results/inertia_bound_x.md
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

H0, AC = 40.0, 4.0e4


def _spy():
    """Wrap ``mass_null.linear_term_null`` and collect its results."""
    from contactlab.diagnose import mass_null

    calls: list = []
    orig = mass_null.linear_term_null

    def spy(*a, **k):
        res = orig(*a, **k)
        calls.append(None if res is None else (res.size, res.threshold, res.z))
        return res

    mass_null.linear_term_null = spy
    return calls, lambda: setattr(mass_null, "linear_term_null", orig)


def diagnose(effects: dict, fac: dict, seed: int) -> dict:
    import contactlab
    from eval_slow_power import read, record

    calls, undo = _spy()
    t0 = time.process_time()
    try:
        rep = contactlab.diagnose(read(record(effects, fac, seed)), model="tangential")
    except Exception as exc:
        undo()
        return {"named": [f"error: {type(exc).__name__}: {exc}"[:120]], "calls": []}
    undo()
    vs = [v for st in rep.steps for v in st.candidates if v.name == "inertia"]
    nd = {x.effect: x for x in rep.not_detected}.get("inertia")
    return {
        "named": list(rep.effect_names),
        "params": {e.name: dict(e.parameters) for e in rep.effects},
        "flagged": bool(getattr(rep.unexplained, "flagged", False)),
        "calls": calls,
        "last": ""
        if not vs
        else f"g={vs[-1].gain:.3g} t={vs[-1].t_stat:.3g} " + (vs[-1].reason or "")[:200],
        "bound": None if nd is None else nd.detectable_above,
        "reason": "" if nd is None else (nd.reason or "")[:300],
        "cpu": time.process_time() - t0,
    }


def mass_of(fac: dict) -> float:
    A = fac["acA"] / AC
    hm = H0 * (1 - math.exp(-fac["acA"]))
    return fac["share"] * hm / (A * (2 * math.pi * fac["f"]) ** 2)


def misses(a) -> list[dict]:
    out = []
    for k, spec in enumerate(a.factors.split(";")):
        aca, xn, fn, cyc, fs, f, share = (float(v) for v in spec.split(","))
        fac = {"acA": aca, "x_noise": xn, "F_noise": fn, "cycles": int(cyc), "fs": fs, "f": f,
               "share": share, "x_drift": 0.0, "bits": 16}  # fmt: skip
        for i in range(a.n):
            seed = a.seed_base + 100 * k + i
            m = mass_of(fac)
            r = diagnose({"inertia": {"m": m}}, fac, seed)
            r.update(seed=seed, factors=fac, m=m)
            print(json.dumps(r, default=float), flush=True)
            out.append(r)
    return out


def calibrate(a) -> list[dict]:
    from eval_bound_power import factors

    aca = tuple(float(v) for v in a.aca.split(","))
    mults = [float(v) for v in a.mults.split(",")]
    out = []
    for i in range(a.n):
        seed = a.seed_base + i
        fac = factors(seed, "inertia", False, aca)
        clean = diagnose({}, fac, seed)
        row = {"seed": seed, "factors": fac, "clean": clean, "runs": []}
        if clean["bound"] is not None and not clean["named"]:
            for j, mu in enumerate(mults):
                m = mu * clean["bound"]
                r = diagnose({"inertia": {"m": m}}, fac, seed + 7919 * (1 + j))
                r.update(mult=mu, m=m)
                row["runs"].append(r)
        print(json.dumps(row, default=float), flush=True)
        out.append(row)
    return out


def table(mode: str, res: list[dict]) -> str:
    lines = []
    if mode == "misses":
        head = "| seed | ac·A | x noise | cycles | f | m (kg) | named | bound (kg) | null | last |"
        lines += [head, "|---|---|---|---|---|---|---|---|---|---|"]
        for r in res:
            f = r["factors"]
            b = "-" if r["bound"] is None else f"{r['bound']:.3g}"
            calls = "; ".join(f"{c[0]:.3g}, {c[1]:.3g}, {c[2]:.2f}" for c in r["calls"] if c)
            lines.append(
                f"| {r['seed']} | {f['acA']:g} | {100 * f['x_noise']:.1f} % | {f['cycles']} | "
                f"{f['f']:g} | {r['m']:.3g} | {'+'.join(r['named']) or '-'} | {b} | {calls} | "
                f"{r['last'][:120].replace('|', '/')} |"
            )
        named = sum("inertia" in r["named"] for r in res)
        lines.append(f"\nnamed inertia {named}/{len(res)}; bound stated "
                     f"{sum(r['bound'] is not None for r in res)}/{len(res)}")  # fmt: skip
        return "\n".join(lines)
    head = "| seed | ac·A | x noise | cycles | f | clean named | bound (kg) | at bound | null |"
    lines += [head, "|---|---|---|---|---|---|---|---|---|"]
    hit: dict[float, list[bool]] = {}
    for r in res:
        f, c = r["factors"], r["clean"]
        b = "-" if c["bound"] is None else f"{c['bound']:.3g}"
        runs = "; ".join(f"{x['mult']:g}x: {'+'.join(x['named']) or '-'}" for x in r["runs"])
        calls = "; ".join(
            f"{x['mult']:g}x " + ", ".join(f"{q[0]:.3g}/{q[1]:.3g}" for q in x["calls"] if q)
            for x in r["runs"]
        )
        for x in r["runs"]:
            hit.setdefault(x["mult"], []).append("inertia" in x["named"])
        lines.append(
            f"| {r['seed']} | {f['acA']:g} | {100 * f['x_noise']:.1f} % | {f['cycles']} | "
            f"{f['f']:g} | {'+'.join(c['named']) or '-'} | {b if b != '-' else c['reason'][:80]} "
            f"| {runs} | {calls} |"
        )
    lines.append("")
    quiet = sum(not r["clean"]["named"] for r in res)
    lines.append(f"clean twins quiet {quiet}/{len(res)}; bound stated "
                 f"{sum(r['clean']['bound'] is not None for r in res)}/{len(res)}")  # fmt: skip
    for mu, v in sorted(hit.items()):
        lines.append(f"mass at {mu:g}x the bound named {sum(v)}/{len(v)}")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--mode", choices=("misses", "calibrate"), default="calibrate")
    ap.add_argument("--seed-base", type=int, required=True)
    ap.add_argument("--n", type=int, default=4)
    ap.add_argument("--factors", default="1.29,0.018,0.005,50,10000,46.6,0.081")
    ap.add_argument("--aca", default="0.3,2.5")
    ap.add_argument("--mults", default="1")
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args(argv)
    os.environ.setdefault("CONTACTLAB_DIAGNOSE_THREADS", "1")
    import warnings

    warnings.simplefilter("ignore")
    res = misses(a) if a.mode == "misses" else calibrate(a)
    text = f"mode {a.mode}, seed base {a.seed_base}, n {a.n}\n\n" + table(a.mode, res)
    print(text)
    if a.out:
        a.out.write_text(text + "\n")
        a.out.with_suffix(".json").write_text(json.dumps(res, indent=1, default=float))


if __name__ == "__main__":
    main()
