"""Inertia on single-frequency records (issue 29): is a mass named, and does anything else
change? Records from the package's own generators, each starting from rest:

- ``rig``: the rig simulator (``contactlab.synthetic.rig``: servo from rest with its ramp,
  load cell, anti-alias filters, quantisation, displacement noise and drift), one drive
  frequency;
- ``pkg``: ``hidden_effect_recording`` with one frequency (``frequencies=(1,)``), its three
  amplitude blocks at one frequency.

Factors: fs 1-10 kHz, 1-50 Hz, 5-50 cycles (at most 23 000 samples), ac·A 0.3-5, x noise
0-2 % of the amplitude, F noise 0.5-2 %. Effects:

- ``inertia``: a mass whose force at the peak acceleration ``m ω² A`` is 3-10 % of the force
  amplitude ``h0 (1 - exp(-ac·A))`` (rig; the package generator: an RMS share 3-10 %);
- ``parallel_stiffness``: ``k_p A`` 5-15 % of that amplitude (package: RMS 5-15 %);
- ``series_compliance``: ``1/C_s = h0·ac·U(0.7, 1.5)`` (package: RMS 5-15 %);
- ``clean``: nothing.

Per record: what ``diagnose`` names, whether the misfit flag is set, the verdict on the
``inertia`` candidate at its last try, and its stated bound.

    nice .venv/bin/python benches/eval_inertia_single.py --base 900000 --n 6 --jobs 1 \
        --out benches/results/inertia_single_x.md
"""

from __future__ import annotations

import argparse
import itertools
import json
import math
import sys
import tempfile
import time
from collections import defaultdict
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

H0, AC = 40.0, 4.0e4
MAX_SAMPLES = 23_000
EFFECTS = ("inertia", "parallel_stiffness", "series_compliance", "clean")


def _logu(rng, lo, hi):
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


#: the range of the mass's share of the force (``--share``) and the generator forced
#: (``--gen``; None: 60 % rig); set by :func:`main`, read by :func:`factors`
SHARE = (0.03, 0.10)
GEN: str | None = None
#: the range ac·A is drawn from (log-uniform; ``--aca``)
ACA = (0.3, 5.0)


def factors(seed: int, effect: str = "clean", share=None, gen=None, aca=None) -> dict:
    """The record's factors: drawn from ``seed`` and the effect (each effect its own draws);
    ``share``: the mass's share range (default :data:`SHARE`), ``gen``: force a generator."""
    share = SHARE if share is None else share
    gen = GEN if gen is None else gen
    aca = ACA if aca is None else aca
    rng = np.random.default_rng([seed, EFFECTS.index(effect)])
    fs = _logu(rng, 1000.0, 10000.0)
    f = _logu(rng, 1.0, 50.0)
    cycles = int(rng.integers(5, 51))
    fs = min(fs, MAX_SAMPLES * f / 5)
    cycles = max(5, min(cycles, int(MAX_SAMPLES * f / fs)))
    return {
        "fs": round(fs, 1),
        "f": round(f, 3),
        "cycles": cycles,
        "acA": round(_logu(rng, *aca), 3),
        "x_noise": round(float(rng.uniform(0.0, 0.02)), 4),
        "F_noise": round(float(rng.uniform(0.005, 0.02)), 4),
        "x_drift": float(rng.uniform(-0.003, 0.003)),
        "bits": int(rng.integers(12, 17)),
        "share": float(rng.uniform(*share)),
        "kshare": float(rng.uniform(0.05, 0.15)),
        "ks": float(rng.uniform(0.7, 1.5)),
        "gen": ("rig" if rng.random() < 0.6 else "pkg") if gen is None else gen,
        "spc": int(rng.integers(60, 400)),
    }


def rig_effects(effect: str, fac: dict) -> dict:
    A = fac["acA"] / AC
    hm = H0 * (1 - math.exp(-fac["acA"]))
    w = 2 * math.pi * fac["f"]
    if effect == "inertia":
        return {"inertia": {"m": fac["share"] * hm / (A * w * w)}}
    if effect == "parallel_stiffness":
        return {"parallel_stiffness": {"k_p": fac["kshare"] * hm / A}}
    if effect == "series_compliance":
        return {"series_compliance": {"k_s": H0 * AC * fac["ks"]}}
    return {}


def make_record(effect: str, fac: dict, seed: int):
    import contactlab

    if fac["gen"] == "rig":
        from contactlab.synthetic.rig import rig_recording

        kw = {k: fac[k] for k in ("fs", "f", "cycles", "acA", "x_noise", "F_noise", "x_drift")}
        rec = rig_recording(rig_effects(effect, fac), "tangential", seed=seed, bits=fac["bits"],
                            **kw)  # fmt: skip
        with tempfile.TemporaryDirectory() as tmp:
            return contactlab.read_recording(str(rec.to_csv(Path(tmp) / "r.csv"))), rec.truth
    from contactlab.synthetic.diagnosis import hidden_effect_recording

    size = {"inertia": fac["share"], "parallel_stiffness": fac["kshare"],
            "series_compliance": fac["kshare"]}.get(effect)  # fmt: skip
    eff = {} if size is None else {effect: size}
    cpb = max(2, min(int(fac["cycles"] / 3) + 1, 12))
    rec = hidden_effect_recording(
        eff, noise=fac["F_noise"], seed=seed, input_noise=fac["x_noise"], frequencies=(1.0,),
        cycles_per_block=cpb, samples_per_cycle=fac["spc"], f0=fac["f"], start="rest",
    )  # fmt: skip
    return rec, rec.truth


def run_job(job):
    import warnings

    import contactlab

    warnings.simplefilter("ignore")
    seed, effect, share, gen, aca = job
    fac = factors(seed, effect, share, gen, aca)
    out = {"seed": seed, "effect": effect, "factors": fac}
    t0 = time.process_time()
    try:
        rec, truth = make_record(effect, fac, seed + 17)
        rep = contactlab.diagnose(rec, model="tangential")
    except Exception as exc:
        out["error"] = f"{type(exc).__name__}: {exc}"[:300]
        out["named"], out["flagged"] = [], False
        return out
    out["truth"] = json.loads(json.dumps(truth.get("effects", {}), default=float))
    out["named"] = list(rep.effect_names)
    out["params"] = {e.name: dict(e.parameters) for e in rep.effects}
    un = rep.unexplained
    out["flagged"] = bool(un is not None and getattr(un, "flagged", False))
    vs = [v for st in rep.steps for v in st.candidates if v.name == "inertia"]
    out["inertia_verdicts"] = [
        {"gain": v.gain, "t": v.t_stat, "accepted": v.accepted, "reason": (v.reason or "")[:240]}
        for v in vs
    ]
    nd = {x.effect: x for x in rep.not_detected}.get("inertia")
    out["inertia_bound"] = None if nd is None else nd.detectable_above
    out["inertia_reason"] = "" if nd is None else (nd.reason or "")[:200]
    out["where"] = [w[:200] for w in rep.where] if hasattr(rep, "where") else []
    out["cpu"] = time.process_time() - t0
    return json.loads(json.dumps(out, default=float))


def band(v, edges):
    for lo, hi in itertools.pairwise(edges):
        if lo <= v < hi:
            return f"{lo:g}-{hi:g}"
    return f">={edges[-1]:g}"


def tables(res: list[dict]) -> str:
    lines = []
    by = defaultdict(list)
    for r in res:
        by[r["effect"]].append(r)
    lines.append(
        "| effect | n | exact | named with extra | missed (nothing) | wrong | flagged | errors |"
    )
    lines.append("|---|---|---|---|---|---|---|---|")
    for e in EFFECTS:
        rows = by.get(e, [])
        if not rows:
            continue
        if e == "clean":
            ok = sum(not r["named"] for r in rows)
            extra, missed, wrong = 0, 0, sum(bool(r["named"]) for r in rows)
        else:
            ok = sum(r["named"] == [e] for r in rows)
            extra = sum(e in r["named"] and r["named"] != [e] for r in rows)
            missed = sum(not r["named"] for r in rows)
            wrong = sum(bool(r["named"]) and e not in r["named"] for r in rows)
        fl = sum(r["flagged"] for r in rows)
        er = sum(bool(r.get("error")) for r in rows)
        lines.append(f"| {e} | {len(rows)} | {ok} | {extra} | {missed} | {wrong} | {fl} | {er} |")
    lines.append("")
    lines.append("clean: nothing named and nothing flagged: "
                 f"{sum(not r['named'] and not r['flagged'] for r in by.get('clean', []))}"
                 f"/{len(by.get('clean', []))}")  # fmt: skip
    lines.append("")
    lines.append("| effect | band | n | exact |")
    lines.append("|---|---|---|---|")
    for e in EFFECTS[:3]:
        bb = defaultdict(list)
        for r in by.get(e, []):
            bb[band(r["factors"]["acA"], [0.3, 1.0, 2.0, 5.01])].append(r["named"] == [e])
            bb["x noise " + band(100 * r["factors"]["x_noise"], [0.0, 1.0, 2.01]) + " %"].append(
                r["named"] == [e]
            )
        for k in sorted(bb):
            lines.append(f"| {e} | {k} | {len(bb[k])} | {sum(bb[k])} |")
    lines.append("")
    lines.append(
        "| seed | effect | gen | fs | f | cycles | ac·A | x noise | share | named | flag | "
        "inertia verdict (last) |"
    )
    lines.append("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in sorted(res, key=lambda r: (EFFECTS.index(r["effect"]), r["seed"])):
        fac = r["factors"]
        v = r.get("inertia_verdicts") or [{}]
        last = v[-1]
        vt = (
            (
                f"{'acc' if last.get('accepted') else 'no'} g={last.get('gain', float('nan')):.3g} "
                f"t={last.get('t', float('nan')):.3g} {last.get('reason', '')[:110]}"
            )
            if last
            else ""
        )
        vt = vt.replace("|", "/")
        sh = (
            fac["share"]
            if r["effect"] == "inertia"
            else (fac["kshare"] if r["effect"] != "clean" else 0)
        )
        named = "+".join(r["named"]) or "-"
        if r.get("error"):
            named = "ERROR " + r["error"][:60]
        lines.append(
            f"| {r['seed']} | {r['effect']} | {fac['gen']} | {fac['fs']:g} | {fac['f']:g} | "
            f"{fac['cycles']} | {fac['acA']:g} | {100 * fac['x_noise']:.2f} % | {sh:.3f} | "
            f"{named} | {'F' if r['flagged'] else ''} | {vt} |"
        )
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--base", type=int, required=True)
    ap.add_argument("--n", type=int, default=6)
    ap.add_argument("--n-clean", type=int, default=None)
    ap.add_argument("--effects", default=",".join(EFFECTS))
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--out", default=None)
    ap.add_argument("--share", default="0.03,0.10",
                    help="lo,hi of the mass's share of the force (rig: m ω² A over the force "
                    "amplitude; pkg: the RMS share)")  # fmt: skip
    ap.add_argument("--gen", choices=("rig", "pkg"), default=None,
                    help="force one generator (default: 60 %% rig)")  # fmt: skip
    ap.add_argument("--aca", default="0.3,5.0", help="lo,hi of ac·A (log-uniform)")
    ap.add_argument("--old-acc", action="store_true",
                    help="the mass reads the older ẍ (MASS_GAP off), --jobs 1 only")  # fmt: skip
    a = ap.parse_args(argv)
    if a.old_acc:
        from contactlab.diagnose.effects.tangential import inertia

        inertia.MASS_GAP = False
    share = tuple(float(v) for v in a.share.split(","))
    aca = tuple(float(v) for v in a.aca.split(","))
    effects = a.effects.split(",")
    jobs = []
    for e in effects:
        n = a.n_clean if (e == "clean" and a.n_clean) else a.n
        jobs += [(a.base + i, e, share, a.gen, aca) for i in range(n)]
    t0 = time.time()
    if a.jobs > 1:
        with ProcessPoolExecutor(a.jobs) as ex:
            res = list(ex.map(run_job, jobs))
    else:
        res = []
        for j in jobs:
            res.append(run_job(j))
            r = res[-1]
            print(j, r["named"], "F" if r["flagged"] else "", f"{r.get('cpu', 0):.0f}s",
                  file=sys.stderr, flush=True)  # fmt: skip
    text = (
        f"base {a.base}, n {a.n}, share {a.share}, ac·A {a.aca}, gen {a.gen or 'mixed'}, "
        f"{time.time() - t0:.0f} s\n\n" + tables(res)
    )
    print(text)
    if a.out:
        Path(a.out).write_text(text + "\n")
        Path(a.out).with_suffix(".json").write_text(json.dumps(res, indent=1))


if __name__ == "__main__":
    main()
