"""The misfit flag on short records (stop 47, issue 29 item 3): virgin curves no candidate
draws (``rational``, ``gamma``, ``tanh``) and clean ones (``exp``) of ``benches/misfit_chain.py``
(and ``rigclean`` or ``effect:<name>``: the package's rig generator, clean or with one effect
of ``benches/eval_diagnose_rig.py``'s sizes)
at 5, 8 or 12 cycles, fs 1 or 2 kHz, noise 0.5-2 % of the range on both channels, ac·A
0.5-5 (log-uniform), drive 1-50 Hz (at most fs/20).

Each record is diagnosed once by this tree and cached with what its flag step saw (the
arguments of :func:`contactlab.diagnose.misfit_null.simulated_null`), so that a decision can be
recomputed on the cached final model. Seeds: 470000-470999 tuning (stop 47); report on fresh
seeds. One process, ``nice``::

    nice .venv/bin/python benches/eval_misfit_short.py run rational,gamma,tanh,exp 471000 12 \\
        --cache DIR
    .venv/bin/python benches/eval_misfit_short.py table 'short_*' --cache DIR
"""

from __future__ import annotations

import argparse
import glob
import os
import pickle
import sys
import time
import warnings
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

CYCLES = (5, 8, 12)


def factors(seed: int) -> dict[str, Any]:
    """The factors of one record, drawn from its seed."""
    rng = np.random.default_rng([seed, 4747])
    fs = float(rng.choice((1000.0, 2000.0)))
    return {
        "fs": fs,
        "cycles": int(rng.choice(CYCLES)),
        "acA": float(np.exp(rng.uniform(np.log(0.5), np.log(5.0)))),
        "x_noise": float(rng.uniform(0.005, 0.02)),
        "F_noise": float(rng.uniform(0.005, 0.02)),
        "f": min(float(np.exp(rng.uniform(0.0, np.log(50.0)))), fs / 20.0),
        "x_colour": str(rng.choice(("lvdt", "lp1", "white"))),
        "hum": bool(rng.random() < 0.5),
        "jitter": bool(rng.random() < 0.5),
    }


def record(seed: int, kind: str) -> tuple[Any, dict[str, Any]]:
    fx = factors(seed)
    if kind == "rigclean" or kind.startswith("effect:"):
        from contactlab.synthetic.rig import rig_recording
        from eval_diagnose_rig import chain_kwargs, rig_effect

        fac = {k: fx[k] for k in ("fs", "f", "cycles", "acA", "x_noise", "F_noise")}
        rng = np.random.default_rng(seed + 7919)
        effect = None if kind == "rigclean" else kind.split(":", 1)[1]
        eff = rig_effect(effect, "2f", fac, rng)
        rec = rig_recording(
            eff, "tangential", seed=seed, fs=fac["fs"], f=fac["f"], cycles=fac["cycles"],
            acA=fac["acA"], x_noise=fac["x_noise"], F_noise=fac["F_noise"],
            x_drift=float(rng.uniform(-0.003, 0.003)), bits=int(rng.integers(12, 17)),
            **chain_kwargs(seed, fac),
        )  # fmt: skip
        ch = rec.channels
        return (np.asarray(rec.t), np.asarray(ch["x"]), np.asarray(ch["F"])), fx
    from misfit_chain import chain_record

    over = {k: fx[k] for k in ("fs", "f", "cycles", "acA", "x_noise", "F_noise")}
    rec, fac = chain_record(
        seed, kind, x_colour=fx["x_colour"], hum=fx["hum"], jitter=fx["jitter"], **over
    )
    return rec, {**fx, **{k: v for k, v in fac.items() if k not in fx}}


def get(seed: int, kind: str, cache: str) -> dict[str, Any]:
    """One record's diagnosis (this tree), cached with what its flag step saw."""
    path = f"{cache}/short_{kind}_{seed}.pkl"
    if os.path.exists(path):
        with open(path, "rb") as fh:
            return pickle.load(fh)
    import contactlab.diagnose.misfit_null as mn
    from contactlab.diagnose.workflow import diagnose

    rec, fac = record(seed, kind)
    cap: dict[str, Any] = {}
    o1 = mn.simulated_null

    def h1(*a: Any, **k: Any) -> Any:
        cap.setdefault("args", a)  # the final model's (not the flag route's rechecks)
        return o1(*a, **k)

    mn.simulated_null = h1
    try:
        t0 = time.process_time()
        rep = diagnose(rec, model="tangential")
        cpu = time.process_time() - t0
    finally:
        mn.simulated_null = o1
    u = rep.unexplained
    ud = {} if u is None else u.to_dict()
    ud.pop("profile", None)
    out = {
        "seed": seed, "kind": kind, "cpu": cpu, "named": list(rep.effect_names),
        "fac": {k: v for k, v in fac.items() if isinstance(v, (int, float, str, bool))},
        "flagged": bool(u is not None and u.flagged), "u": ud,
        "withdrawn": list((rep.location or {}).get("withdrawn", [])),
        "flag_route": (rep.location or {}).get("flag_route"),
    }  # fmt: skip
    if "args" in cap:
        cap["args"][3].extra.pop("evaluations", None)
        out["args"] = cap["args"]
    os.makedirs(cache, exist_ok=True)
    with open(path, "wb") as fh:
        pickle.dump(out, fh)
    return out


def _period(seed: int) -> float:
    """Samples per drive period of a seed's record."""
    f = factors(seed)
    return f["fs"] / f["f"]


def _why(o: dict[str, Any]) -> str:
    ud = o["u"]
    if not ud:
        return "no test"
    parts = []
    cal = ud.get("calibrated") or {}
    parts += cal.get("by", [])
    if ud.get("rivals"):
        parts.append("rivals")
    for q in ud.get("patches") or []:
        parts.append(
            "swap" if q.get("swap") else "slope" if q.get("slope") else
            "tail" if q.get("tail") else "patch"
        )  # fmt: skip
    return "+".join(dict.fromkeys(parts)) or "-"


def table(pattern: str, cache: str) -> None:
    rows = []
    for pat in pattern.split(","):
        for p in sorted(glob.glob(f"{cache}/{pat}.pkl")):
            with open(p, "rb") as fh:
                rows.append(pickle.load(fh))
    by: dict[tuple[str, int], list[bool]] = defaultdict(list)
    for o in sorted(rows, key=lambda o: (o["kind"], o["seed"])):
        f = o["fac"]
        by[(o["kind"], f["cycles"])].append(o["flagged"])
        cal = o["u"].get("calibrated") or {}
        print(
            f"{o['kind']:9s} {o['seed']:7d} cyc {f['cycles']:2d} fs {f['fs']:5.0f} "
            f"acA {f['acA']:4.2f} xn {100 * f['x_noise']:3.1f}% Fn {100 * f['F_noise']:3.1f}% "
            f"flag {int(o['flagged'])} by {_why(o):14s} t {_g(cal.get('t'))}/"
            f"{_g(cal.get('t_threshold'))} T {_g(cal.get('T'))}/{_g(cal.get('T_threshold'))} "
            f"named {','.join(o['named']) or '-'}"
            + (f" withdrawn {','.join(o['withdrawn'])}" if o.get("withdrawn") else "")
        )
    print()
    tot: dict[str, list[bool]] = defaultdict(list)
    for (k, c), v in sorted(by.items()):
        tot[k] += v
        print(f"{k:9s} cycles {c:2d}: flagged {sum(v)}/{len(v)}")
    for k, v in sorted(tot.items()):
        print(f"{k:9s} all      : flagged {sum(v)}/{len(v)}")


def _g(v: Any) -> str:
    return "n/a" if v is None else f"{v:.3g}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("what", choices=("run", "table"))
    ap.add_argument("args", nargs="+")
    ap.add_argument("--cache", default="misfit_short_cache")
    ap.add_argument("--jobs", type=int, default=1, help="processes (1: this one)")
    ap.add_argument(
        "--few", type=float, default=None,
        help="only seeds with fewer samples per drive period than this (stop 47: 60)",
    )  # fmt: skip
    a = ap.parse_args()
    warnings.simplefilter("ignore")
    if a.what == "table":
        table(a.args[0], a.cache)
        return
    kinds, seed0, n = a.args[0].split(","), int(a.args[1]), int(a.args[2])
    seeds = range(seed0, seed0 + n)
    if a.few is not None:  # the first n seeds from seed0 with few samples per period
        seeds = [s for s in range(seed0, seed0 + 100 * n) if _period(s) < a.few][:n]
    for seed in seeds:
        for kind in kinds:
            o = get(seed, kind, a.cache)
            print(f"{kind} {seed} flag {int(o['flagged'])} cpu {o['cpu']:.0f}s "
                  f"named {o['named']}", flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
