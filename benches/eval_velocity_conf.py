"""Velocity-like and turn-localised effects at x noise 1.5-2 % of the range (issue 29,
helper velocity_conf): channel delays, breakaways (``stick_slip``), plays and clean records
on the package's rig simulator (``contactlab.synthetic.rig``, plain chain: white x noise,
Butterworth anti-alias filters, a start from rest), at factors where a delay was named a
2f ``normal_load`` or a ``backlash``, a breakaway a ``normal_load`` + ``stribeck`` or a
``channel_delay``, and a clean record a ``backlash``. Kinds:

- ``delay``: ac·A 1.2-2.0, 12-50 cycles, fs 5 or 10 kHz, 15-32 Hz, τ 0.3-1.0 ms (within
  what the diagnosis calls plausible: 2 % of a period or 2 ms);
- ``stick``: ac·A 0.6-1.0, 35-50 cycles, fs 1 kHz, 10-16 Hz, b 0.04-0.09, d_c 0.1-0.3 A;
- ``backlash``: ac·A 1.5-4, a play of half-width 1-5 % of A, fs 5 or 10 kHz;
- ``clean``: ac·A 1-5, fs 5 or 10 kHz; ``clean_hi``: ac·A 4-4.6, fs 10 kHz (where a clean
  record was named a play of 1 µm).

x noise 1.5-2 % of the range, F noise 0.8-1.8 % of the force amplitude. Per record: the
named set, the misfit flag, the bound stated for the true effect, and the held-out gains
of the candidates at each step.

    nice .venv/bin/python benches/eval_velocity_conf.py --base 8100000 --n 6 --out /tmp/x.json
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
    "delay": {"effect": "channel_delay", "acA": (1.2, 2.0), "fs": (5000.0, 10000.0),
              "f": (15.0, 32.0), "cycles": (12, 50)},
    "stick": {"effect": "stick_slip", "acA": (0.6, 1.0), "fs": (1000.0,), "f": (10.0, 16.0),
              "cycles": (35, 50)},
    "backlash": {"effect": "backlash", "acA": (1.5, 4.0), "fs": (5000.0, 10000.0),
                 "f": (10.0, 40.0), "cycles": (8, 40)},
    "clean": {"effect": None, "acA": (1.0, 5.0), "fs": (5000.0, 10000.0), "f": (10.0, 40.0),
              "cycles": (8, 40)},
    "clean_hi": {"effect": None, "acA": (4.0, 4.6), "fs": (10000.0,), "f": (10.0, 40.0),
                 "cycles": (8, 40)},
}  # fmt: skip


def factors(kind: str, seed: int) -> dict[str, Any]:
    k = KINDS[kind]
    rng = np.random.default_rng([seed, list(KINDS).index(kind), 3131])
    fs = float(rng.choice(k["fs"]))
    f = math.exp(rng.uniform(math.log(k["f"][0]), math.log(k["f"][1])))
    cycles = int(rng.integers(k["cycles"][0], k["cycles"][1] + 1))
    cycles = max(5, min(cycles, int(24000 * f / fs)))
    return {
        "fs": fs, "f": round(f, 3), "cycles": cycles,
        "acA": round(float(rng.uniform(*k["acA"])), 3),
        "x_noise_range": round(float(rng.uniform(0.015, 0.02)), 4),
        "F_noise": round(float(rng.uniform(0.008, 0.018)), 4),
        "x_drift": float(rng.uniform(-0.003, 0.003)),
        "ramp_cycles": round(float(rng.uniform(0.0, 1.0)), 3),
        "size": float(rng.uniform(0.0, 1.0)),
        "size2": float(rng.uniform(0.0, 1.0)),
    }  # fmt: skip


def effect_params(kind: str, fac: dict[str, Any]) -> dict[str, dict[str, float]]:
    A = fac["acA"] / AC
    u, u2 = fac["size"], fac["size2"]
    if kind == "delay":
        top = max(0.02 / fac["f"], 0.002)
        return {"channel_delay": {"tau": min(3e-4 + 7e-4 * u, 0.95 * top)}}
    if kind == "stick":
        return {"stick_slip": {"b": 0.04 + 0.05 * u, "d_c": (0.1 + 0.2 * u2) * A}}
    if kind == "backlash":
        return {"backlash": {"b": (0.01 + 0.04 * u) * A}}
    return {}


def simulate(effects: dict, fac: dict[str, Any], seed: int):
    from contactlab.synthetic.rig import rig_recording

    return rig_recording(
        effects, "tangential", seed=seed, fs=fac["fs"], f=fac["f"], cycles=fac["cycles"],
        acA=fac["acA"], h0=H0, ac=AC, x_noise=2.0 * fac["x_noise_range"],
        F_noise=fac["F_noise"], x_drift=fac["x_drift"], ramp_cycles=fac["ramp_cycles"],
        bits=16,
    )  # fmt: skip


def run_job(job: tuple[str, int]) -> dict[str, Any]:
    import tempfile
    import time
    import warnings

    import contactlab

    warnings.simplefilter("ignore")
    kind, seed = job
    fac = factors(kind, seed)
    eff = effect_params(kind, fac)
    rec = simulate(eff, fac, seed)
    with tempfile.TemporaryDirectory() as tmp:
        data = contactlab.read_recording(str(rec.to_csv(Path(tmp) / "r.csv")))
    t0 = time.process_time()
    rep = contactlab.diagnose(data, model="tangential")
    name = KINDS[kind]["effect"]
    nd = {x.effect: x for x in rep.not_detected}
    steps = []
    for st in rep.steps:
        row = {v.name: [round(float(v.gain), 3), bool(v.accepted), (v.reason or "")[:160]]
               for v in st.candidates if np.isfinite(v.gain) and v.gain > 0}  # fmt: skip
        steps.append({"added": getattr(st, "added", None), "cands": row})
    un = rep.unexplained
    out = {
        "kind": kind, "seed": seed, "factors": fac, "truth": eff,
        "named": list(rep.effect_names), "flagged": bool(un is not None and un.flagged),
        "params": {e.name: dict(e.parameters) for e in rep.effects},
        "bound": None if name not in nd else nd[name].detectable_above,
        "bound_reason": "" if name not in nd else (nd[name].reason or "")[:200],
        "steps": steps, "where": [w[:400] for w in rep.where],
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
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args(argv)
    jobs = [(k, a.base + i) for k in a.kinds.split(",") for i in range(a.n)]
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
        tv = {k: float(f"{v:.3g}") for k, v in tv.items()}
        print(f"{r['kind']:8s} {r['seed']} fs {fac['fs']:.0f} f {fac['f']:.3g} "
              f"cyc {fac['cycles']} acA {fac['acA']:.2f} xn {100 * fac['x_noise_range']:.2f}% "
              f"{tv} bound {r['bound']} -> {r['named']} "
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
