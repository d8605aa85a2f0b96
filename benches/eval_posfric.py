"""Confusions around ``position_friction`` (issue 29, helper posfric), on the package's rig
simulator (``contactlab.synthetic.rig``, plain chain) at the factors where an independent
generator showed them (conditions only):

- ``wave``: friction varying along the track, ``h0 (1 + a cos(2πx/L + φ))`` with a 0.6-2.3 %
  and L 20-180 µm (ac = 4e4 /m: the stroke's half-width A = ac·A / ac, 8-110 µm here), fs
  1-10 kHz, 2-20 Hz, 8-20 cycles, ac·A 0.3-4.5; named ``power_law_microslip`` or nothing;
- ``spring``: a parallel spring of ``k_p = r h0/A`` (r 1-2.5), fs 1-2 kHz, 2-16 Hz, 5-20
  cycles, ac·A 1.5-4.5; named ``position_friction`` or ``stribeck``;
- ``stick``: a breakaway b 0.05-0.1 of h0 at d_c 5-15 µm, fs 10 kHz, 30-50 Hz, 35 cycles,
  ac·A 3-4.2; named ``channel_delay``;
- ``lead``: the reverse, a force leading the displacement by 0.05-0.3 ms at the factors of
  ``stick`` (the size at ``--mults`` is the bound's, the sign negative).

Per (case, seed): the clean twin is diagnosed (its names are false alarms; the bound it
states for the true effect), then the effect is hidden at its drawn size and, with
``--mults``, at multiples of the stated bound (fresh noise, same factors). x noise is given
as a share of the displacement's range (the rig's ``x_noise`` is a share of the amplitude).

    nice .venv/bin/python benches/eval_posfric.py --base 49400000 --n 4 --cases wave
"""

from __future__ import annotations

import argparse
import json
import math
import tempfile
import time
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

H0, AC = 40.0, 4.0e4

CASES: dict[str, dict[str, Any]] = {
    "wave": {"effect": "position_friction", "fs": (1000.0, 2000.0, 5000.0, 10000.0),
             "f": (2.0, 20.0), "cycles": (8, 20), "acA": (0.3, 4.5), "xn": (0.004, 0.012)},
    "spring": {"effect": "parallel_stiffness", "fs": (1000.0, 2000.0), "f": (2.0, 16.0),
               "cycles": (5, 20), "acA": (1.5, 4.5), "xn": (0.005, 0.014)},
    "stick": {"effect": "stick_slip", "fs": (10000.0,), "f": (30.0, 50.0),
              "cycles": (35, 35), "acA": (3.0, 4.2), "xn": (0.005, 0.01)},
    # the reverse of ``stick``: a force leading the displacement (τ < 0), which a breakaway
    # mimics, at the same factors
    "lead": {"effect": "channel_delay", "fs": (10000.0,), "f": (30.0, 50.0),
             "cycles": (35, 35), "acA": (3.0, 4.2), "xn": (0.005, 0.01)},
}  # fmt: skip
MAX_SAMPLES = 24_000
#: ``--aca lo,hi``: every case's ac·A drawn log-uniform from this range (None: the case's own)
ACA: tuple[float, float] | None = None


def factors(case: str, seed: int) -> dict[str, Any]:
    c = CASES[case]
    rng = np.random.default_rng([seed, list(CASES).index(case), 4949])
    f = math.exp(rng.uniform(math.log(c["f"][0]), math.log(c["f"][1])))
    fs = float(rng.choice(c["fs"]))
    cycles = int(rng.integers(c["cycles"][0], c["cycles"][1] + 1))
    fs = min(fs, MAX_SAMPLES * f / 5)
    cycles = max(5, min(cycles, int(MAX_SAMPLES * f / fs)))
    acA = math.exp(rng.uniform(math.log(c["acA"][0]), math.log(c["acA"][1])))
    fac = {
        "fs": fs, "f": round(f, 3), "cycles": cycles, "acA": round(acA, 3),
        "x_noise_range": round(float(rng.uniform(*c["xn"])), 4),
        "F_noise": round(float(rng.uniform(0.005, 0.012)), 4),
        "x_drift": float(rng.uniform(-0.003, 0.003)),
        "ramp_cycles": round(float(rng.uniform(0.0, 1.0)), 3),
        # the effect's own draws (always drawn, so that every case keeps its stream)
        "eps": float(rng.uniform(0.006, 0.023)), "L": float(rng.uniform(20e-6, 180e-6)),
        "phi": float(rng.uniform(0.0, 2 * math.pi)), "r": float(rng.uniform(1.0, 2.5)),
        "b": float(rng.uniform(0.05, 0.1)), "d_c": float(rng.uniform(5e-6, 15e-6)),
    }  # fmt: skip
    if case == "lead":
        fac["tau"] = -float(rng.uniform(0.05e-3, 0.3e-3))
    if ACA is not None:  # ``--aca``: ac·A from this range instead (its own stream)
        r2 = np.random.default_rng([seed, list(CASES).index(case), 4950])
        fac["acA"] = round(math.exp(r2.uniform(math.log(ACA[0]), math.log(ACA[1]))), 3)
    if case == "wave":  # the contact's curvature too: waves of 0.1-20 half-widths
        fac["ac"] = round(math.exp(rng.uniform(math.log(1.0e4), math.log(8.0e4))), 1)
    return fac


def params(case: str, fac: dict[str, Any], size: float | None = None) -> dict[str, Any]:
    """The rig's effect at its drawn size, or at ``size`` in the diagnosis's parameter."""
    A = fac["acA"] / fac.get("ac", AC)
    if case == "wave":
        eps = fac["eps"] if size is None else size
        return {"position_friction": {"eps": eps, "L": fac["L"], "phi": fac["phi"]}}
    if case == "spring":
        return {"parallel_stiffness": {"k_p": fac["r"] * H0 / A if size is None else size}}
    if case == "lead":
        return {"channel_delay": {"tau": fac["tau"] if size is None else -abs(size)}}
    return {"stick_slip": {"b": fac["b"] if size is None else size, "d_c": fac["d_c"]}}


def record(effects: dict, fac: dict[str, Any], seed: int):
    import contactlab
    from contactlab.synthetic.rig import rig_recording

    rec = rig_recording(
        effects, "tangential", seed=seed, fs=fac["fs"], f=fac["f"], cycles=fac["cycles"],
        acA=fac["acA"], h0=H0, ac=fac.get("ac", AC), x_noise=2.0 * fac["x_noise_range"],
        F_noise=fac["F_noise"], x_drift=fac["x_drift"], ramp_cycles=fac["ramp_cycles"],
    )  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp:
        return contactlab.read_recording(str(rec.to_csv(Path(tmp) / "r.csv")))


def summary(rep: Any, effect: str) -> dict[str, Any]:
    nd = {x.effect: x for x in rep.not_detected}
    un = rep.unexplained
    gains = {}
    for st in rep.steps:
        for v in st.candidates:
            if v.name not in gains and np.isfinite(v.gain):
                gains[v.name] = [round(float(v.gain), 4), bool(v.accepted), (v.reason or "")[:120]]
    return {
        "named": list(rep.effect_names),
        "flagged": bool(un is not None and un.flagged),
        "bound": None if effect not in nd else nd[effect].detectable_above,
        "reason": "" if effect not in nd else (nd[effect].reason or "")[:160],
        "gains": gains,
    }


def without(names: tuple[str, ...]) -> None:
    """Take off this helper's rules (the "before" of a before/after on one tree): ``short``
    the position friction's short waves in its start, ``lead`` a leading force's yielding to
    a breakaway."""
    if "lead" in names:
        from contactlab.diagnose.effects import registry

        cls = type(registry("tangential")["channel_delay"])
        if "yields_to_tried" in cls.__dict__:
            delattr(cls, "yields_to_tried")
    if "short" in names:
        import contactlab.diagnose.effects.tangential.position_friction as pf

        pf.SHORT_WAVES = False


def run_job(case: str, seed: int, mults: tuple[float, ...], drawn: bool) -> dict[str, Any]:
    import warnings

    import contactlab

    warnings.simplefilter("ignore")
    effect = CASES[case]["effect"]
    fac = factors(case, seed)
    t0 = time.process_time()
    out: dict[str, Any] = {"case": case, "seed": seed, "factors": fac, "runs": []}
    out["clean"] = summary(contactlab.diagnose(record({}, fac, seed), model="tangential"), effect)
    bound = out["clean"]["bound"]
    sizes: list[tuple[str, float | None]] = [("drawn", None)] if drawn else []
    if bound is not None and np.isfinite(bound):
        sizes += [(f"{m:g}x", m * bound) for m in mults]
    for k, (label, size) in enumerate(sizes):
        p = params(case, fac, size)
        r = contactlab.diagnose(record(p, fac, seed + 7919 * (1 + k)), model="tangential")
        run = {"label": label, "params": p, **summary(r, effect)}
        run["size"] = float(next(iter(next(iter(p.values())).values())))
        run["over_bound"] = None if not bound else run["size"] / bound
        out["runs"].append(run)
    out["cpu"] = time.process_time() - t0
    return json.loads(json.dumps(out, default=float))


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", type=int, required=True)
    ap.add_argument("--n", type=int, default=4)
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--mults", default="", help="multiples of the clean twin's stated bound")
    ap.add_argument("--no-drawn", action="store_true", help="skip the drawn size")
    ap.add_argument("--jobs", type=int, default=1, help="(one process: kept for the brief)")
    ap.add_argument("--without", default="", help="short,lead: these rules off")
    ap.add_argument("--aca", default=None, help="lo,hi: ac·A drawn from this range instead")
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args(argv)
    if a.aca:
        global ACA
        lo, hi = (float(v) for v in a.aca.split(","))
        ACA = (lo, hi)
    without(tuple(w for w in a.without.split(",") if w))
    mults = tuple(float(m) for m in a.mults.split(",") if m)
    rows = []
    for case in a.cases.split(","):
        effect = CASES[case]["effect"]
        for i in range(a.n):
            r = run_job(case, a.base + i, mults, not a.no_drawn)
            rows.append(r)
            f = r["factors"]
            print(f"{case} {r['seed']} ac {f.get('ac', AC):.3g} L {1e6 * f['L']:.0f}um "
                  f"fs {f['fs']:g} f {f['f']:.3g} cyc {f['cycles']} "
                  f"acA {f['acA']:.2f} xn {100 * f['x_noise_range']:.2f}% Fn "
                  f"{100 * f['F_noise']:.2f}% | clean {r['clean']['named']} flag "
                  f"{r['clean']['flagged']} bound {r['clean']['bound']} "
                  f"{r['clean']['reason'][:80]} cpu {r['cpu']:.0f}", flush=True)  # fmt: skip
            for run in r["runs"]:
                g = {k: v[0] for k, v in run["gains"].items()}
                top = sorted(g.items(), key=lambda kv: -kv[1])[:5]
                print(f"    {run['label']}: {run['params']} ({run['over_bound'] or 0:.2g}x) -> "
                      f"{run['named']} flag {run['flagged']} own {g.get(effect)} top {top}",
                      flush=True)  # fmt: skip
            if a.out:
                a.out.write_text(json.dumps(rows, indent=1))
    tally: dict[tuple[str, str, bool], list[str]] = defaultdict(list)
    for r in rows:
        eff = CASES[r["case"]]["effect"]
        for run in r["runs"]:
            above = run["over_bound"] is not None and run["over_bound"] >= 1
            nm = run["named"]
            v = "exact" if nm == [eff] else ("+".join(nm) if nm else "nothing")
            tally[(r["case"], run["label"], above)].append(v)
    print("\n| case | run | above bound | n | exact | named instead |\n|---|---|---|---|---|---|")
    for (case, lab, above), v in sorted(tally.items()):
        other = defaultdict(int)
        for x in v:
            if x != "exact":
                other[x] += 1
        oth = ", ".join(f"{k}×{n}" for k, n in sorted(other.items()))
        print(f"| {case} | {lab} | {above} | {len(v)} | {v.count('exact')} | {oth} |")
    quiet = sum(not r["clean"]["named"] and not r["clean"]["flagged"] for r in rows)
    named = sum(bool(r["clean"]["named"]) for r in rows)
    print(f"\nclean twins: quiet {quiet}/{len(rows)}, named {named}/{len(rows)}")


if __name__ == "__main__":
    main()
