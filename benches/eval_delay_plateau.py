"""Channel delays on plateau-dominated loops (issue 29, helper delay, stop 48): a force
channel lagging the displacement by τ 0.1-1 ms beyond identical anti-alias filters, at
ac·A 1.3-5 where the loop is mostly sliding plateau, on the package's rig simulator
(``contactlab.synthetic.rig``: white noise on both channels after the filters, a start
from rest, mains hum up to 0.3 %), and the rivals the diagnosis named instead (a 2f
``normal_load``, ``position_friction``, ``backlash``) and clean records over the same
factors, so that a fix for the delay can be checked not to take them. Kinds:

- ``delay``: τ 0.1-1 ms (at most 2 % of a period), fs 2, 5 or 10 kHz, f 3-40 Hz, 5-50
  cycles, ac·A 1.3-5, x noise 1-2 % of the range, F noise 0.8-2 % of the force amplitude;
- ``load``: a ``normal_load`` at 2f, ε 4-10 %, any phase; ``track``: ``position_friction``,
  ε 4-10 %, L 1-2 A; ``play``: ``backlash`` of half-width 1.5-5 % of A; ``clean``.

    nice .venv/bin/python benches/eval_delay_plateau.py --base 48100000 --n 8 --kinds delay
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

H0, AC = 40.0, 4.0e4
KINDS = {"delay": "channel_delay", "load": "normal_load", "track": "position_friction",
         "play": "backlash", "clean": None}  # fmt: skip


def factors(kind: str, seed: int) -> dict[str, Any]:
    rng = np.random.default_rng([seed, list(KINDS).index(kind), 4848])
    fs = float(rng.choice((2000.0, 5000.0, 10000.0)))
    f = math.exp(rng.uniform(math.log(3.0), math.log(40.0)))
    cycles = int(rng.integers(5, 51))
    cycles = max(5, min(cycles, int(30000 * f / fs)))
    return {
        "fs": fs, "f": round(f, 3), "cycles": cycles,
        "acA": round(float(rng.uniform(1.3, 5.0)), 3),
        "x_noise_range": round(float(rng.uniform(0.01, 0.02)), 4),
        "F_noise": round(float(rng.uniform(0.008, 0.02)), 4),
        "hum": round(float(rng.uniform(0.0, 0.003)), 5),
        "ramp_cycles": 0.0,
        "u": float(rng.uniform(0.0, 1.0)),
        "u2": float(rng.uniform(0.0, 1.0)),
        "phi": float(rng.uniform(0.0, 2 * math.pi)),
    }  # fmt: skip


def effect_params(kind: str, fac: dict[str, Any]) -> dict[str, dict[str, float]]:
    A = fac["acA"] / AC
    u, u2 = fac["u"], fac["u2"]
    if kind == "delay":
        return {"channel_delay": {"tau": min(1e-4 + 9e-4 * u, 0.02 / fac["f"])}}
    if kind == "load":
        return {"normal_load": {"eps": 0.04 + 0.06 * u, "f_n": 2.0 * fac["f"], "phi": fac["phi"]}}
    if kind == "track":
        return {"position_friction": {"eps": 0.04 + 0.06 * u, "L": (1.0 + u2) * 2 * A,
                                      "phi": fac["phi"]}}  # fmt: skip
    if kind == "play":
        return {"backlash": {"b": (0.015 + 0.035 * u) * A}}
    return {}


def run_job(job: tuple[str, int]) -> dict[str, Any]:
    import time
    import warnings

    import contactlab
    from contactlab.synthetic.rig import rig_recording

    warnings.simplefilter("ignore")
    kind, seed = job
    fac = factors(kind, seed)
    eff = effect_params(kind, fac)
    rec = rig_recording(
        eff, "tangential", seed=seed, fs=fac["fs"], f=fac["f"], cycles=fac["cycles"],
        acA=fac["acA"], h0=H0, ac=AC, x_noise=2.0 * fac["x_noise_range"],
        F_noise=fac["F_noise"], ramp_cycles=fac["ramp_cycles"], hum=fac["hum"], bits=16,
    )  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp:
        data = contactlab.read_recording(str(rec.to_csv(Path(tmp) / "r.csv")))
    t0 = time.process_time()
    rep = contactlab.diagnose(data, model="tangential")
    name = KINDS[kind]
    nd = {x.effect: x for x in rep.not_detected}
    steps = []
    for st in rep.steps:
        row = {v.name: [round(float(v.gain), 3), bool(v.accepted), (v.reason or "")[:200]]
               for v in st.candidates if np.isfinite(v.gain) and v.gain > 0}  # fmt: skip
        steps.append({"added": getattr(st, "added", None), "cands": row})
    un = rep.unexplained
    dl = nd.get("channel_delay")
    out = {
        "kind": kind, "seed": seed, "factors": fac, "truth": eff,
        "named": list(rep.effect_names), "flagged": bool(un is not None and un.flagged),
        "params": {e.name: dict(e.parameters) for e in rep.effects},
        "bound": None if name not in nd else nd[name].detectable_above,
        "delay_bound": None if dl is None else dl.detectable_above,
        "steps": steps, "where": [w[:400] for w in rep.where],
        "cpu": time.process_time() - t0,
    }  # fmt: skip
    return json.loads(json.dumps(out, default=float))


def verdict(r: dict[str, Any]) -> str:
    e = KINDS[r["kind"]]
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
    ap.add_argument("--seeds", default="", help="comma-separated offsets from --base")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument("--old", action="store_true", help="the load's delay rule off (before)")
    a = ap.parse_args(argv)
    if a.old:
        from contactlab.diagnose.effects.tangential.normal_load import NormalLoad

        NormalLoad.delay_check = False
    offs = [int(s) for s in a.seeds.split(",")] if a.seeds else list(range(a.n))
    jobs = [(k, a.base + i) for k in a.kinds.split(",") for i in offs]
    rows = []
    for r in map(run_job, jobs):
        rows.append(r)
        fac = r["factors"]
        tv = next(iter(r["truth"].values()), {})
        tv = {k: float(f"{v:.3g}") for k, v in tv.items()}
        db = r["delay_bound"]
        print(f"{r['kind']:6s} {r['seed']} fs {fac['fs']:.0f} f {fac['f']:.3g} "
              f"cyc {fac['cycles']} acA {fac['acA']:.2f} xn {100 * fac['x_noise_range']:.2f}% "
              f"Fn {100 * fac['F_noise']:.2f}% {tv} bound {r['bound']} dbound {db} -> "
              f"{r['named']} {r['params'].get('channel_delay', '')} flag {r['flagged']} "
              f"[{verdict(r)}] cpu {r['cpu']:.0f}", flush=True)  # fmt: skip
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
