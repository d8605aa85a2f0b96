"""The misfit flag's null made honest (flagpower, stop 40, issue 29 items 1 and 3): before
and after from one diagnosis per record.

Each record is diagnosed once with this tree (its own flag is "after"); what the flag step
sees (the final model, the prepared record, the residual, the noise levels, the hand
threshold's verdict on the phase bins, rivals and patches) is cached, and the simulated
null and the calibrated decision are recomputed on it with stop 39's settings ("before":
``DENOISE = "harmonics"``, ``OUTPUT_NOISE = "estimate"``, ``MIN_GAIN = 0.05``) and with this
tree's. The named effects are the same in both (the flag step names nothing).

Generators (``benches/misfit_chain.py``, factors per seed):

- ``corner``: clean records where the blind generator's clean false flags sat: 35-50
  cycles, x noise 1.3-2 % of the range (white on half, else LVDT or RC coloured), ac·A
  2.5-5, fs 1/2/5/10 kHz, 1-50 Hz, hum and clock jitter on;
- ``misfit``: virgin curves no candidate draws (tanh, arctan, rational, gamma, bilinear,
  weibull, cubic), 5-50 cycles, ac·A 0.5-5 (log-uniform), x noise 0-2 %;
- ``flagcal``: the clean records of ``benches/eval_flag_calibration.py`` (``exp``: the
  misfit chain, ``rigclean``: the package's rig), x noise 0-2 %, ac·A 0.3-5.

Seeds below 750000 were used for tuning (700000-700045 corner, 710000-710002 misfit); the
report's seeds are 720000-, 750000-, 760000-, 770000-, 780000-, 790000-. One process::

    nice .venv/bin/python benches/eval_flag_power.py run corner exp 780000 6 --cache DIR
    nice .venv/bin/python benches/eval_flag_power.py table 'corner_exp_78*' --cache DIR
"""

from __future__ import annotations

import argparse
import glob
import math
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

BEFORE = {"DENOISE": "harmonics", "OUTPUT_NOISE": "estimate", "MIN_GAIN": 0.05}
AFTER = {"DENOISE": "lines", "OUTPUT_NOISE": "residual", "MIN_GAIN": 0.05}


def corner_record(seed: int, kind: str) -> tuple[Any, dict[str, Any]]:
    from misfit_chain import chain_record

    rng = np.random.default_rng([seed, 4242])
    fs = float(rng.choice((1000.0, 2000.0, 5000.0, 10000.0)))
    over = {
        "fs": fs, "f": min(float(np.exp(rng.uniform(0, np.log(50)))), fs / 20),
        "cycles": int(rng.integers(35, 51)), "acA": float(rng.uniform(2.5, 5)),
        "x_noise": float(rng.uniform(0.013, 0.02)), "F_noise": float(rng.uniform(0.005, 0.02)),
    }  # fmt: skip
    col = str(rng.choice(("white", "white", "lvdt", "lp1")))
    rec, fac = chain_record(seed, kind, x_colour=col, hum=True, jitter=True, **over)
    return rec, {**fac, "x_colour": col}


def misfit_record(seed: int, kind: str) -> tuple[Any, dict[str, Any]]:
    from misfit_chain import chain_record

    rng = np.random.default_rng([seed, 5151, sum(map(ord, kind))])
    fs = float(rng.choice((1000.0, 2000.0, 5000.0, 10000.0)))
    over = {
        "fs": fs, "f": min(float(np.exp(rng.uniform(0, np.log(50)))), fs / 20),
        "cycles": int(rng.integers(5, 51)),
        "acA": float(np.exp(rng.uniform(np.log(0.5), np.log(5.0)))),
        "x_noise": float(rng.uniform(0.0, 0.02)), "F_noise": float(rng.uniform(0.005, 0.02)),
    }  # fmt: skip
    col = str(rng.choice(("white", "lvdt", "lp1")))
    hum, jit = bool(rng.random() < 0.5), bool(rng.random() < 0.5)
    rec, fac = chain_record(seed, kind, x_colour=col, hum=hum, jitter=jit, **over)
    return rec, {**fac, "x_colour": col}


def hidden_record(seed: int, kind: str) -> tuple[Any, dict[str, Any]]:
    """A visible effect (``kind``) of the package's generator (``hidden_effect_recording``,
    start from rest): magnitude 4-10 % of the output's RMS, output noise 0.5-2 %, input noise
    0-2 % of max|x|, 1-50 Hz, 20-1500 samples per cycle, 2-8 cycles per block (three
    blocks); ``kind`` ``"exp"`` for a clean record."""
    from contactlab.synthetic.diagnosis import hidden_effect_recording

    rng = np.random.default_rng([seed, 6161, sum(map(ord, kind))])
    f0 = float(np.exp(rng.uniform(0.0, np.log(50.0))))
    fs = float(np.exp(rng.uniform(np.log(1000.0), np.log(10000.0))))
    fac = {
        "samples_per_cycle": int(max(20, min(fs / f0, 1500))),
        "cycles_per_block": int(rng.integers(2, 9)),
        "noise": float(rng.uniform(0.005, 0.02)),
        "input_noise": float(rng.uniform(0.0, 0.02)),
    }  # fmt: skip
    mag = float(rng.uniform(0.04, 0.10))
    eff = {} if kind == "exp" else {kind: mag}
    rec = hidden_effect_recording(eff, seed=seed, start="rest", f0=f0, **fac)
    out = {**fac, "magnitude": mag, "x_noise": fac["input_noise"], "acA": math.nan,
           "cycles": 3 * fac["cycles_per_block"]}  # fmt: skip
    return rec, out


def get(seed: int, kind: str, gen: str, cache: str) -> dict[str, Any]:
    """One record's diagnosis (this tree), cached with what its flag step saw."""
    path = f"{cache}/{gen}_{kind}_{seed}.pkl"
    if os.path.exists(path):
        with open(path, "rb") as fh:
            return pickle.load(fh)
    import contactlab.diagnose.misfit_null as mn
    from contactlab.diagnose.workflow import diagnose

    if gen == "corner":
        rec, fac = corner_record(seed, kind)
    elif gen == "misfit":
        rec, fac = misfit_record(seed, kind)
    elif gen == "hidden":
        rec, fac = hidden_record(seed, kind)
    else:
        from eval_flag_calibration import record

        rec, fac = record(seed, kind)
    cap: dict[str, Any] = {}
    o1, o2 = mn.simulated_null, mn.calibrated_flag

    def h1(*a: Any, **k: Any) -> Any:
        cap["args"] = a
        return o1(*a, **k)

    def h2(nd: Any, *a: Any, **k: Any) -> Any:
        cap["hand_bins"] = k.get("hand_bins", True)
        return o2(nd, *a, **k)

    mn.simulated_null, mn.calibrated_flag = h1, h2
    try:
        t0 = time.process_time()
        rep = diagnose(rec, model="tangential")
        cpu = time.process_time() - t0
    finally:
        mn.simulated_null, mn.calibrated_flag = o1, o2
    u = rep.unexplained
    ud = {} if u is None else u.to_dict()
    out = {
        "seed": seed, "kind": kind, "gen": gen, "cpu": cpu, "named": list(rep.effect_names),
        "fac": {k: v for k, v in fac.items() if isinstance(v, (int, float, str, bool))},
        "flagged": bool(u is not None and u.flagged), "rivals": bool(ud.get("rivals")),
        "patches": any(not q.get("swap") for q in ud.get("patches") or []),
        "swaps": [q["effects"][0] for q in ud.get("patches") or [] if q.get("swap")],
        "cal": ud.get("calibrated"),
    }  # fmt: skip
    if "args" in cap:
        cap["args"][3].extra.pop("evaluations", None)
        out["args"] = cap["args"]
        out["hand_bins"] = cap.get("hand_bins", True)
    os.makedirs(cache, exist_ok=True)
    with open(path, "wb") as fh:
        pickle.dump(out, fh)
    return out


def decide(o: dict[str, Any], settings: dict[str, Any]) -> tuple[bool, Any, float]:
    """The flag with the null and decision of ``settings`` on the cached final model."""
    import contactlab.diagnose.misfit_null as mn

    if "args" not in o:
        return o["flagged"], None, 0.0
    fam, p, eff, d, r, so, sg = o["args"]
    for k in ("masing", "merged", "merged_span"):
        if isinstance(d.extra.get(k), dict):
            d.extra[k] = {}
    keep = {k: getattr(mn, k) for k in settings}
    for k, v in settings.items():
        setattr(mn, k, v)
    try:
        t0 = time.process_time()
        nd = mn.simulated_null(fam, p, eff, d, r, so, sg)
        cpu = time.process_time() - t0
        cal = None if nd is None else mn.calibrated_flag(nd, hand_bins=o["hand_bins"])
    finally:
        for k, v in keep.items():
            setattr(mn, k, v)
    if cal is None:
        return o["flagged"], None, cpu
    return bool(cal["flagged"] or o["rivals"] or o["patches"]), cal, cpu


def _band(r: dict[str, Any], k: str) -> str:
    if k == "x noise %":
        x = r["xn"]
        return "0-0.5" if x < 0.5 else "0.5-1" if x < 1 else "1-1.5" if x < 1.5 else "1.5-2"
    if k == "ac·A":
        a = r["acA"]
        return "0.3-0.5" if a < 0.5 else "0.5-1" if a < 1 else "1-2.5" if a < 2.5 else "2.5-5"
    if k == "cycles":
        c = r["cyc"]
        return "5-11" if c < 12 else "12-34" if c < 35 else "35-50"
    return r["kind"]


def table(pattern: str, cache: str) -> None:
    rows = []
    for pat in pattern.split(","):
        for path in sorted(glob.glob(f"{cache}/{pat}.pkl")):
            with open(path, "rb") as fh:
                o = pickle.load(fh)
            fb, _, cb = decide(o, BEFORE)
            fa, ca, cpa = decide(o, AFTER)
            f = o["fac"]
            rows.append({
                "kind": o["kind"], "before": fb, "after": fa, "xn": 100 * f["x_noise"],
                "acA": f["acA"], "cyc": f["cycles"], "cb": cb, "ca": cpa,
                "ok_b": not o["named"] and not fb, "ok_a": not o["named"] and not fa,
            })  # fmt: skip
            c = ca or {}
            print(f"{o['gen']} {o['kind']} {o['seed']} xn {100 * f['x_noise']:.2g} acA "
                  f"{f['acA']:.2f} cyc {f['cycles']} named {o['named']} before {int(fb)} "
                  f"after {int(fa)} t {c.get('t')}/{c.get('t_threshold')} gain {c.get('gain')} "
                  f"by {c.get('by')}")  # fmt: skip
    print("\n| factor | level | n | flagged before | flagged after | nothing named or flagged, "
          "before | after |\n|---|---|---|---|---|---|---|")  # fmt: skip
    for k in ("kind", "x noise %", "ac·A", "cycles"):
        g: dict[str, list] = defaultdict(list)
        for r in rows:
            g[_band(r, k)].append(r)
        for lvl in sorted(g):
            rr = g[lvl]
            print(f"| {k} | {lvl} | {len(rr)} | {sum(r['before'] for r in rr)} | "
                  f"{sum(r['after'] for r in rr)} | {sum(r['ok_b'] for r in rr)} | "
                  f"{sum(r['ok_a'] for r in rr)} |")  # fmt: skip
    if rows:
        ratio = np.median([r["ca"] / max(r["cb"], 1e-9) for r in rows])
        print(f"\nnull CPU per record: before median {np.median([r['cb'] for r in rows]):.2f} s, "
              f"after {np.median([r['ca'] for r in rows]):.2f} s (ratio {ratio:.2f})")  # fmt: skip


def main() -> None:
    warnings.simplefilter("ignore")
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("what", choices=("run", "table"))
    ap.add_argument("args", nargs="+")
    ap.add_argument("--cache", default="flag_power_cache")
    a = ap.parse_args()
    if a.what == "table":
        table(a.args[0], a.cache)
        return
    gen, kinds, seed0, n = a.args[0], a.args[1].split(","), int(a.args[2]), int(a.args[3])
    for kind in kinds:
        for s in range(seed0, seed0 + n):
            o = get(s, kind, gen, a.cache)
            print(s, kind, "named", o["named"], "flagged", o["flagged"], flush=True)


if __name__ == "__main__":
    main()
