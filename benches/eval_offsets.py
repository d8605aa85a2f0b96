"""Displacement offset, normal load, position friction and parallel stiffness on realistic
records (issue 29, helper offsets).

Records of the package's rig simulator (``contactlab.synthetic.rig``) with the whole
sensor chain switched on (an LVDT demodulator's low-pass on x, a piezo or strain-gauge
cell, Bessel anti-alias filters, hum, clock jitter, drive harmonics, a start from rest
with a ramp of 0-1 cycles), x noise 1-2 % of the amplitude (``--xn``), F noise 0.5-2 %,
fs 1-10 kHz, f 1-50 Hz, 5-50 cycles, ac·A 0.5-5; for each of displacement_offset,
normal_load (a 2f load at any phase), position_friction, parallel_stiffness, clean records
(the rig and ``benches/misfit_chain.py``'s exponential contact) and unnameable virgin
curves (``misfit_chain``'s rational and gamma). Sizes are drawn across 0.5-2 times a
visible size (the effect's force change near 10 % of the loop's height; x0 0.1-0.4 A).

Per record: what ``contactlab.diagnose`` names, the flag, the bound it states for a missed
effect (``not_detected``), the reason a candidate was refused. The table: exact / extra /
missed / wrong per effect with confusions, misses above the stated bound, clean records
with nothing named or flagged, unnameable records named ``normal_load``.

    nice .venv/bin/python benches/eval_offsets.py --seed-base 610000 --n 6 --clean 6 \
        --out benches/results/eval_offsets_x.json
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

EFFECTS = ("displacement_offset", "normal_load", "position_friction", "parallel_stiffness")
#: effects that may be asked for besides (``--effects``): the offsets' look-alike
OTHER_EFFECTS = ("force_offset", "non_masing_scaling")
UNNAMEABLE = ("rational", "gamma")
#: the rig's parameter that the diagnosis's own parameter compares with
BOUND_PARAM = {
    "displacement_offset": "x0",
    "parallel_stiffness": "k_p",
    "position_friction": "eps",
    "normal_load": "eps",
    "force_offset": "F0",
}


def _lu(rng, lo, hi):
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


#: the ac·A range of the records (``--aca``)
ACA = (0.5, 5.0)


def factors(seed: int, xn: tuple[float, float]) -> dict:
    rng = np.random.default_rng([seed, 31])
    fs = float(rng.choice((1000.0, 2000.0, 5000.0, 10000.0)))
    f = min(_lu(rng, 1.0, 50.0), fs / 20.0)
    cycles = int(rng.integers(5, 51))
    cycles = max(5, min(cycles, int(30000 * f / fs)))
    return {
        "fs": fs,
        "f": round(f, 3),
        "cycles": cycles,
        "acA": round(_lu(rng, *ACA), 3),
        "x_noise": round(float(rng.uniform(*xn)), 4),
        "F_noise": round(float(rng.uniform(0.005, 0.02)), 4),
    }


def sensors(seed: int, fac: dict) -> dict:
    rng = np.random.default_rng([seed, 37])
    fs = fac["fs"]
    return {
        "x_lowpass": round(min(_lu(rng, 300.0, 2000.0), 0.45 * fs), 3),
        "F_highpass": round(_lu(rng, 0.005, 0.1), 5) if rng.random() < 0.5 else None,
        "aa_kind": "bessel",
        "hum": round(float(rng.uniform(0.0, 0.005)), 5),
        "jitter": float(rng.uniform(0.0, 0.02)) / fs,
        "drive_harmonics": (round(float(rng.uniform(0, 0.01)), 4),
                            round(float(rng.uniform(0, 0.01)), 4)),
        "ramp_cycles": round(float(rng.uniform(0.0, 1.0)), 3),
        "x_drift": round(float(rng.uniform(-0.02, 0.02)), 4),
    }  # fmt: skip


def effect_params(effect: str, seed: int, fac: dict, h0=40.0, ac=4.0e4) -> dict:
    rng = np.random.default_rng([seed, 41])
    A = fac["acA"] / ac
    hm = h0 * -math.expm1(-fac["acA"])
    k = _lu(rng, 0.5, 2.0)  # size over the visible size
    sgn = 1.0 if rng.random() < 0.5 else -1.0
    if effect == "displacement_offset":
        return {"x0": sgn * 0.2 * k * A}
    if effect == "normal_load":
        return {"eps": 0.08 * k, "f_n": 2.0 * fac["f"], "phi": float(rng.uniform(0, 2 * math.pi))}
    if effect == "position_friction":
        return {"eps": 0.08 * k, "L": 2 * A * float(rng.uniform(0.5, 1.0)),
                "phi": float(rng.uniform(0, 2 * math.pi))}  # fmt: skip
    if effect == "parallel_stiffness":
        return {"k_p": 0.1 * k * hm / A}
    if effect == "force_offset":  # the look-alikes of a displacement offset (--effects)
        return {"F0": sgn * 0.1 * k * hm}
    if effect == "non_masing_scaling":
        return {"lam": float(rng.uniform(1.3, 1.6))}
    return {}


def record(gen: str, effect: str | None, seed: int, xn: tuple[float, float]):
    """``((t, x, F), truth)``."""
    fac = factors(seed, xn)
    if gen == "chain":  # benches/misfit_chain.py: exp (clean) or an unnameable virgin curve
        import misfit_chain

        over = {k: fac[k] for k in ("fs", "f", "cycles", "acA", "x_noise", "F_noise")}
        (t, x, F), _cf = misfit_chain.chain_record(seed, effect or "exp", x_colour="lp1", **over)
        return (t, x, F), {"factors": fac, "effect": effect, "params": {}, "gen": gen}
    from contactlab.synthetic.rig import rig_recording

    sen = sensors(seed, fac)
    p = effect_params(effect, seed, fac) if effect else {}
    rec = rig_recording(
        {effect: p} if effect else {},
        "tangential",
        seed=seed,
        fs=fac["fs"],
        f=fac["f"],
        cycles=fac["cycles"],
        acA=fac["acA"],
        x_noise=fac["x_noise"],
        F_noise=fac["F_noise"],
        h0=40.0,
        ac=4.0e4,
        **sen,
    )
    return (rec.t, rec.channels["x"], rec.channels["F"]), {
        "factors": fac,
        "sensors": sen,
        "effect": effect,
        "params": p,
        "gen": gen,
    }


def run(gen, effect, seed, xn):
    import contactlab

    warnings.simplefilter("ignore")
    t0 = time.process_time()
    data, truth = record(gen, effect, seed, xn)
    out = {"gen": gen, "effect": effect, "seed": seed, "truth": truth}
    try:
        d = contactlab.diagnose(data, model="tangential").to_dict()
        out["named"] = [e["name"] for e in d.get("effects", [])]
        out["params"] = {e["name"]: e.get("parameters", {}) for e in d.get("effects", [])}
        un = d.get("unexplained") or {}
        out["flagged"] = bool(un.get("flagged")) if isinstance(un, dict) else bool(un)
        out["withdrawn"] = d.get("withdrawn")
        if effect in BOUND_PARAM and effect not in out["named"]:
            nd = [b for b in d.get("not_detected", []) or [] if b.get("effect") == effect]
            if nd:
                out["bound"] = {k: nd[0].get(k) for k in ("parameter", "detectable_above",
                                                          "note")}  # fmt: skip
            ref = [r for r in (d.get("location") or {}).get("refused", []) or []
                   if isinstance(r, dict) and r.get("effect") == effect]  # fmt: skip
            if ref:
                out["refused"] = str(ref[0])[:400]
        out["error"] = None
    except Exception as exc:  # a failed run is a result
        out["named"], out["flagged"], out["error"] = [], False, f"{type(exc).__name__}: {exc}"
    out["cpu"] = time.process_time() - t0
    return json.loads(json.dumps(out, default=float))


def outcome(r):
    if r["error"]:
        return "error"
    named, e = set(r["named"]), r["effect"]
    if e is None:
        return "clean-ok" if not named and not r["flagged"] else "clean-bad"
    if e in UNNAMEABLE:
        return "flagged" if r["flagged"] else ("absorbed" if named else "silent")
    if named == {e}:
        return "exact"
    if e in named:
        return "extra"
    return "missed" if not named else "wrong"


def above_bound(r) -> bool | None:
    """Whether the true size exceeds the bound the diagnosis stated for the missed effect
    (None: no bound stated or not comparable)."""
    b = r.get("bound") or {}
    above = b.get("detectable_above")
    if not isinstance(above, (int, float)) or not math.isfinite(above):
        return None
    e = r["effect"]
    true = abs(float(r["truth"]["params"].get(BOUND_PARAM[e], math.nan)))
    return bool(true > abs(above))


def table(results) -> str:
    by = defaultdict(list)
    for r in results:
        by[r["effect"] or f"clean ({r['gen']})"].append(r)
    lines = ["| effect | n | exact | extra | missed | wrong | missed above bound | named |",
             "|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for e, rs in sorted(by.items()):
        named = dict(Counter(n for r in rs for n in r["named"]))
        if e.startswith("clean"):
            ok = sum(outcome(r) == "clean-ok" for r in rs)
            fl = sum(bool(r["flagged"]) for r in rs)
            nm = sum(bool(r["named"]) for r in rs)
            lines.append(f"| {e} | {len(rs)} | ok {ok} | named {nm} | flagged {fl} | | | {named} |")
            continue
        c = Counter(outcome(r) for r in rs)
        if e in UNNAMEABLE:
            nl = sum("normal_load" in r["named"] for r in rs)
            lines.append(
                f"| {e} | {len(rs)} | flagged {c['flagged']} | absorbed {c['absorbed']} | "
                f"silent {c['silent']} | normal_load {nl} | | {named} |"
            )
            continue
        ab = sum(1 for r in rs if outcome(r) in ("missed", "wrong") and above_bound(r) is not False)
        lines.append(
            f"| {e} | {len(rs)} | {c['exact']} | {c['extra']} | {c['missed']} | {c['wrong']} "
            f"| {ab} | {named} |"
        )
    return "\n".join(lines)


def jobs_of(n: int, clean: int, unnameable: int, effects) -> list[tuple[str, str | None]]:
    jobs: list[tuple[str, str | None]] = []
    for i in range(clean):
        jobs.append(("rig" if i % 2 == 0 else "chain", None))
    for e in effects:
        jobs += [("rig", e)] * n
    for v in UNNAMEABLE:
        jobs += [("chain", v)] * unnameable
    return jobs


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed-base", type=int, required=True)
    ap.add_argument("--n", type=int, default=4, help="records per effect")
    ap.add_argument("--clean", type=int, default=6)
    ap.add_argument("--unnameable", type=int, default=2, help="records per unnameable shape")
    ap.add_argument("--effects", default=",".join(EFFECTS))
    ap.add_argument("--xn", default="0.01,0.02", help="x noise range (fraction)")
    ap.add_argument("--aca", default="0.5,5", help="ac·A range")
    ap.add_argument("--only", default=None, help="comma list of effects ('clean', shapes)")
    ap.add_argument(
        "--max-per-group",
        type=int,
        default=None,
        help="run at most this many records of each group (the seeds stay those of the plan)",
    )
    ap.add_argument("--resume", type=Path, default=None, help="skip the seeds of this JSON")
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args(argv)
    xn = tuple(float(v) for v in a.xn.split(","))
    global ACA
    ACA = tuple(float(v) for v in a.aca.split(","))
    only = None if a.only is None else set(a.only.split(","))
    results = json.loads(a.resume.read_text()) if a.resume else []
    done = {r["seed"] for r in results}
    count: Counter = Counter()
    for i, (g, e) in enumerate(jobs_of(a.n, a.clean, a.unnameable, a.effects.split(","))):
        if only is not None and (e or "clean") not in only:
            continue
        count[e] += 1
        if a.max_per_group is not None and count[e] > a.max_per_group:
            continue
        if a.seed_base + i in done:
            continue
        r = run(g, e, a.seed_base + i, xn)
        results.append(r)
        fac = r["truth"]["factors"]
        pr = {k: (float(f"{v:.3g}") if isinstance(v, float) else v)
              for k, v in r["truth"]["params"].items()}  # fmt: skip
        print(
            f"{g:5s} {e or 'clean':19s} seed {r['seed']} acA {fac['acA']:.2f} "
            f"xn {100 * fac['x_noise']:.2f}% fs {fac['fs']:.0f} f {fac['f']:.2f} "
            f"cyc {fac['cycles']} {pr} -> {outcome(r):9s} {r['named']} flag={r['flagged']} "
            f"cpu {r['cpu']:.1f}"
            + (f" bound {r.get('bound')}" if r.get("bound") else "")
            + (f" refused {r.get('refused')}" if r.get("refused") else "")
            + (f" ERR {r['error']}" if r["error"] else ""),
            flush=True,
        )
        if a.out:
            a.out.write_text(json.dumps(results, indent=1))
    print(table(results))


if __name__ == "__main__":
    main()
