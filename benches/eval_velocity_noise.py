"""Velocity-like effects on a noisy displacement channel (issue 29, helper velocity_noise):
channel delays and viscous dampings at x noise 1-2 % of the range, and clean records at
0.5-2 %, on the package's rig simulator (``contactlab.synthetic.rig``, plain chain: white
x noise, Butterworth anti-alias filters, a start from rest).

The effect's size is set as a relative change of the force: the RMS of what it adds to the
clean twin's force (the same factors, no noise) over that force's RMS, ``--rel`` (drawn
log-uniformly in the range). A delay is kept within what the diagnosis calls plausible (2 %
of a period or 2 ms, at most 10 ms). Kinds:

- ``delay``: ac·A 0.8-5, 5-50 cycles, fs 5 or 10 kHz, x noise 1-2 %, relative change 3-8 %;
- ``viscous``: ac·A 0.4-1.2 (loops nearly elliptic), the rest as ``delay``, relative
  change 5-40 %;
- ``backlash``: a play of half-width 1-5 % of A (``--rel`` is that share here), ac·A 1.5-4,
  x noise 1-2 % (the reverse of the delay's confusion);
- ``clean``: ac·A 0.3-5, x noise 0.5-2 %.

Per record: the named set, the misfit flag, the bound stated for the true effect and the
held-out gains of the candidates at each step.

    nice .venv/bin/python benches/eval_velocity_noise.py --base 7100000 --n 6 --out /tmp/x.json
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

H0, AC = 40.0, 4.0e4
KINDS = {
    "delay": {"effect": "channel_delay", "acA": (0.8, 5.0), "xn": (0.01, 0.02),
              "rel": (0.03, 0.08)},
    "viscous": {"effect": "viscous_damping", "acA": (0.4, 1.2), "xn": (0.01, 0.02),
                "rel": (0.05, 0.4)},
    "backlash": {"effect": "backlash", "acA": (1.5, 4.0), "xn": (0.01, 0.02),
                 "rel": (0.01, 0.05)},
    "clean": {"effect": None, "acA": (0.3, 5.0), "xn": (0.005, 0.02), "rel": (0.0, 0.0)},
}  # fmt: skip


def _logu(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


def factors(kind: str, seed: int) -> dict[str, Any]:
    k = KINDS[kind]
    rng = np.random.default_rng([seed, list(KINDS).index(kind), 2929])
    fs = float(rng.choice((5000.0, 10000.0)))
    f = _logu(rng, 5.0, 50.0)
    cycles = int(rng.integers(5, 51))
    cycles = max(5, min(cycles, int(24000 * f / fs)))
    return {
        "fs": fs, "f": round(f, 3), "cycles": cycles,
        "acA": round(_logu(rng, *k["acA"]), 3),
        "x_noise_range": round(float(rng.uniform(*k["xn"])), 4),
        "F_noise": round(float(rng.uniform(0.005, 0.02)), 4),
        "x_drift": float(rng.uniform(-0.003, 0.003)),
        "ramp_cycles": round(float(rng.uniform(0.0, 1.0)), 3),
        "rel": round(_logu(rng, *k["rel"]), 4) if k["rel"][1] > 0 else 0.0,
    }  # fmt: skip


def simulate(effects: dict, fac: dict[str, Any], seed: int, noise: bool = True):
    from contactlab.synthetic.rig import rig_recording

    return rig_recording(
        effects, "tangential", seed=seed, fs=fac["fs"], f=fac["f"], cycles=fac["cycles"],
        acA=fac["acA"], h0=H0, ac=AC, x_noise=2.0 * fac["x_noise_range"] if noise else 0.0,
        F_noise=fac["F_noise"] if noise else 0.0, x_drift=fac["x_drift"] if noise else 0.0,
        ramp_cycles=fac["ramp_cycles"], bits=16 if noise else None,
    )  # fmt: skip


def effect_params(kind: str, fac: dict[str, Any], seed: int) -> dict[str, dict[str, float]]:
    """The true effect's parameters at the relative change ``fac["rel"]`` (linear in the
    size at these sizes: measured at a unit size on the noise-free twin)."""
    e = KINDS[kind]["effect"]
    if e is None:
        return {}
    if e == "backlash":
        return {e: {"b": fac["rel"] * fac["acA"] / AC}}
    clean = simulate({}, fac, seed, noise=False)
    rms = float(np.sqrt(np.mean(clean.F**2)))
    if e == "channel_delay":
        unit = 1e-4
        one = simulate({e: {"tau": unit}}, fac, seed, noise=False)
        ch = float(np.sqrt(np.mean((one.F - clean.F) ** 2))) / rms
        tau = fac["rel"] / ch * unit
        top = min(max(0.02 / fac["f"], 0.002), 0.010)
        return {e: {"tau": float(min(tau, 0.95 * top))}}
    unit = 1.0
    one = simulate({e: {"c": unit}}, fac, seed, noise=False)
    ch = float(np.sqrt(np.mean((one.F - clean.F) ** 2))) / rms
    return {e: {"c": float(fac["rel"] / ch * unit)}}


def without(names: tuple[str, ...]) -> None:
    """Take this helper's rules off (the "before" of a before/after on one tree):
    ``dashpot`` the dashpot's own lowering of the base
    (``ViscousDamping.max_base_lowering``), ``clip`` the element's turning points from the
    smoothed input (``_common.CLIP_TURNS``)."""
    from contactlab.diagnose.effects import registry
    from contactlab.diagnose.effects.tangential import _common

    reg = registry("tangential")
    vd = type(reg["viscous_damping"])
    if "dashpot" in names and "max_base_lowering" in vd.__dict__:
        delattr(vd, "max_base_lowering")
    if "clip" in names:
        _common.CLIP_TURNS = False


def run_job(job: tuple[str, int, tuple[str, ...]]) -> dict[str, Any]:
    import tempfile
    import time
    import warnings

    import contactlab

    warnings.simplefilter("ignore")
    kind, seed, off = job
    without(off)
    fac = factors(kind, seed)
    eff = effect_params(kind, fac, seed)
    rec = simulate(eff, fac, seed)
    with tempfile.TemporaryDirectory() as tmp:
        data = contactlab.read_recording(str(rec.to_csv(Path(tmp) / "r.csv")))
    t0 = time.process_time()
    rep = contactlab.diagnose(data, model="tangential")
    name = KINDS[kind]["effect"]
    nd = {x.effect: x for x in rep.not_detected}
    steps = []
    for st in rep.steps:
        row = {v.name: [round(float(v.gain), 3), bool(v.accepted), (v.reason or "")[:120]]
               for v in st.candidates if np.isfinite(v.gain) and v.gain > 0}  # fmt: skip
        steps.append({"added": getattr(st, "added", None), "cands": row})
    un = rep.unexplained
    out = {
        "kind": kind, "seed": seed, "factors": fac, "truth": eff,
        "named": list(rep.effect_names), "flagged": bool(un is not None and un.flagged),
        "params": {e.name: dict(e.parameters) for e in rep.effects},
        "bound": None if name not in nd else nd[name].detectable_above,
        "bound_reason": "" if name not in nd else (nd[name].reason or "")[:160],
        "steps": steps, "where": [w[:300] for w in rep.where],
        "cpu": time.process_time() - t0,
    }  # fmt: skip
    return json.loads(json.dumps(out, default=float))


def verdict(r: dict[str, Any]) -> str:
    e = KINDS[r["kind"]]["effect"]
    named = set(r["named"])
    if e is None:
        return "quiet" if not named and not r["flagged"] else ("named" if named else "flagged")
    if named == {e}:
        return "exact"
    if e in named:
        return "extra"
    return "other" if named else "nothing"


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", type=int, required=True)
    ap.add_argument("--n", type=int, default=4)
    ap.add_argument("--kinds", default=",".join(KINDS))
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--without", default="", help="dashpot,clip: this helper's rules off")
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args(argv)
    off = tuple(w for w in a.without.split(",") if w)
    jobs = [(k, a.base + i, off) for k in a.kinds.split(",") for i in range(a.n)]
    rows = []
    if a.jobs > 1:
        from concurrent.futures import ProcessPoolExecutor

        it = ProcessPoolExecutor(a.jobs).map(run_job, jobs)
    else:
        it = map(run_job, jobs)
    for r in it:
        rows.append(r)
        fac = r["factors"]
        tv = next(iter(r["truth"].values()), {})
        print(f"{r['kind']:8s} {r['seed']} fs {fac['fs']:.0f} f {fac['f']:.3g} "
              f"cyc {fac['cycles']} acA {fac['acA']:.2f} xn {100 * fac['x_noise_range']:.2f}% "
              f"rel {fac['rel']:.3f} {tv} bound {r['bound']} -> {r['named']} "
              f"flag {r['flagged']} [{verdict(r)}] cpu {r['cpu']:.0f}", flush=True)  # fmt: skip
        if a.out:
            a.out.write_text(json.dumps(rows, indent=1))
    by = defaultdict(list)
    for r in rows:
        by[r["kind"]].append(verdict(r))
    for k, v in by.items():
        print(f"{k}: " + ", ".join(f"{x} {v.count(x)}" for x in sorted(set(v))) + f" of {len(v)}")
    sys.stdout.flush()


if __name__ == "__main__":
    main()
