"""Clean tangential rig records under a measurement chain like the independent evaluation's
(issue 29, helper cleanfa, stop 48): Bessel anti-alias filters on both channels, 14-16 bit
ADC, mains hum on both channels (off a drive harmonic, or at twice the drive), sampling-clock
jitter, start from rest (no ramp). Diagnosed once per tree and cached with what the misfit
flag step saw (the arguments of :func:`contactlab.diagnose.misfit_null.simulated_null`), so
that the flag can be recomputed on the cached final model (``recompute``).

    nice .venv/bin/python benches/eval_clean_chain.py run 480000 40 --cache DIR
    .venv/bin/python benches/eval_clean_chain.py table --cache DIR
    .venv/bin/python benches/eval_clean_chain.py recompute [PATTERN] --cache DIR

(``recompute`` also reads ``benches/eval_misfit_short.py``'s cache: ``'short_*'``).

Seeds: 480000-480999 tuning (stop 48); report on fresh ones.
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
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

FS = (1000.0, 2000.0, 5000.0, 10000.0)
CYCLES = (8, 12, 20, 35, 50)
HUM = ("none", "off", "2f")


def factors(
    seed: int,
    hum: str | None = None,
    jitter: bool | None = None,
    xn: float | None = None,
    white: bool | None = None,
) -> dict[str, Any]:
    """The factors of one record, drawn from its seed (``hum``/``jitter`` forced if given,
    ``xn``: the x noise drawn from ``xn``-2 % instead of 0.5-2 %)."""
    rng = np.random.default_rng([seed, 4848])
    fs = float(rng.choice(FS))
    h = str(rng.choice(HUM)) if hum is None else hum
    if h == "2f":
        f = 25.0 * float(rng.uniform(0.995, 1.005))
        f = 25.0 if fs / f < 40 else f
    else:
        f = float(np.exp(rng.uniform(np.log(1.5), np.log(min(45.0, fs / 25.0)))))
    j = bool(rng.random() < 0.5) if jitter is None else jitter
    return {
        "fs": fs,
        "f": f,
        "cycles": int(rng.choice(CYCLES)),
        "acA": float(np.exp(rng.uniform(np.log(0.3), np.log(4.5)))),
        "x_noise": float(
            rng.uniform(0.005, 0.02) if xn is None else rng.uniform(xn, max(0.02, xn + 0.005))
        ),
        "F_noise": float(rng.uniform(0.005, 0.02)),
        "hum": h,
        "hum_x": float(rng.uniform(0.0, 0.004)) if h != "none" else 0.0,
        "hum_F": float(rng.uniform(0.0, 0.006)) if h != "none" else 0.0,
        "jitter": float(rng.uniform(0.0, 0.02)) / fs if j else 0.0,
        "bits": int(rng.integers(14, 17)),
        "white": bool(white),
    }


def record(seed: int, fx: dict[str, Any]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The rig record of ``fx``: clean, Bessel filters, start from rest; hum added on the
    sampled channels at its own amplitude per channel (fraction of the channel's amplitude).
    With ``fx["white"]`` the noise is white, added to the sampled channels after the chain
    (at the rig's noise fractions of each channel's amplitude), and the sample times are the
    nominal ones (the jittered instants unrecorded)."""
    from contactlab.synthetic.rig import rig_recording

    white = bool(fx.get("white"))
    rec = rig_recording(
        {}, "tangential", seed=seed, fs=fx["fs"], f=fx["f"], cycles=fx["cycles"],
        acA=fx["acA"], x_noise=0.0 if white else fx["x_noise"],
        F_noise=0.0 if white else fx["F_noise"], bits=fx["bits"],
        aa_kind="bessel", jitter=fx["jitter"], ramp_cycles=0.0,
    )  # fmt: skip
    t = np.asarray(rec.t, float)
    x = np.asarray(rec.channels["x"], float).copy()
    F = np.asarray(rec.channels["F"], float).copy()
    if white:
        t = np.arange(t.size) / fx["fs"]
        rng = np.random.default_rng([seed, 6060])
        x += rng.standard_normal(x.size) * fx["x_noise"] * 0.5 * float(np.ptp(x))
        F += rng.standard_normal(F.size) * fx["F_noise"] * 0.5 * float(np.ptp(F))
    if fx["hum"] != "none":
        rng = np.random.default_rng([seed, 5050])
        for s, a in ((x, fx["hum_x"]), (F, fx["hum_F"])):
            amp = 0.5 * float(np.ptp(s))
            s += a * amp * np.sin(2 * math.pi * 50.0 * t + rng.uniform(0, 2 * math.pi))
    return t, x, F


def get(seed: int, cache: str, **force: Any) -> dict[str, Any]:
    """One record's diagnosis (this tree), cached with what its flag step saw."""
    tag = "".join(f"_{k}{v}" for k, v in sorted(force.items()) if v is not None)
    path = f"{cache}/clean_{seed}{tag}.pkl"
    if os.path.exists(path):
        with open(path, "rb") as fh:
            return pickle.load(fh)
    import contactlab.diagnose.misfit_null as mn
    from contactlab.diagnose.workflow import diagnose

    fx = factors(seed, **force)
    rec = record(seed, fx)
    cap: dict[str, Any] = {}
    o1 = mn.simulated_null

    def h1(*a: Any, **k: Any) -> Any:
        cap["args"] = a
        cap["kw"] = k
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
    out = {
        "seed": seed, "tag": tag, "cpu": cpu, "named": list(rep.effect_names), "fac": fx,
        "flagged": bool(u is not None and u.flagged), "u": ud,
    }  # fmt: skip
    if "args" in cap:
        cap["args"][3].extra.pop("evaluations", None)
        out["args"] = cap["args"]
        out["kw"] = cap.get("kw", {})
    os.makedirs(cache, exist_ok=True)
    with open(path, "wb") as fh:
        pickle.dump(out, fh)
    return out


def _why(o: dict[str, Any]) -> str:
    ud = o["u"]
    if not ud:
        return "no test"
    parts = list((ud.get("calibrated") or {}).get("by", []))
    if ud.get("rivals"):
        parts.append("rivals")
    parts += ["patch" for _ in ud.get("patches") or []]
    return "+".join(dict.fromkeys(parts)) or "-"


def _g(v: Any) -> str:
    return "n/a" if v is None else f"{v:.3g}"


def _load(cache: str) -> list[dict[str, Any]]:
    rows = []
    for p in sorted(glob.glob(f"{cache}/clean_*.pkl")):
        with open(p, "rb") as fh:
            rows.append(pickle.load(fh))
    return rows


def _line(o: dict[str, Any], cal: dict[str, Any], flagged: bool) -> str:
    f = o["fac"]
    return (
        f"{o['seed']:7d}{o['tag']:10s} fs {f['fs']:5.0f} f {f['f']:5.1f} cyc {f['cycles']:2d} "
        f"acA {f['acA']:4.2f} xn {100 * f['x_noise']:3.1f}% Fn {100 * f['F_noise']:3.1f}% "
        f"hum {f['hum']:4s} jit {int(f['jitter'] > 0)} bits {f['bits']} "
        f"flag {int(flagged)} by {'+'.join(cal.get('by', [])) or '-':18s} "
        f"t {_g(cal.get('t'))}/{_g(cal.get('t_threshold'))} "
        f"T {_g(cal.get('T'))}/{_g(cal.get('T_threshold'))} named {','.join(o['named']) or '-'}"
    )


def table(cache: str) -> None:
    rows = _load(cache)
    for o in rows:
        print(_line(o, o["u"].get("calibrated") or {}, o["flagged"]))
    q = sum(1 for o in rows if not o["named"] and not o["flagged"])
    nf = sum(1 for o in rows if o["flagged"])
    nn = sum(1 for o in rows if o["named"])
    ni = sum(1 for o in rows if "inertia" in o["named"])
    print(f"quiet {q}/{len(rows)} flagged {nf} named {nn} (inertia {ni})")


def recompute(cache: str, pattern: str = "clean_*") -> None:
    """The calibrated misfit decision recomputed with this tree's null on every cached
    record's final model (the other flag routes as cached), without and with the hum's
    directions (``misfit_null.HUM``: stop 48's before and after)."""
    import contactlab.diagnose.misfit_null as mn

    rows = []
    for p in sorted(glob.glob(f"{cache}/{pattern}.pkl")):
        with open(p, "rb") as fh:
            rows.append(pickle.load(fh))
    nf = {False: 0, True: 0}
    for o in rows:
        if "args" not in o:
            print(f"{o['seed']} (no null) flag {int(o['flagged'])}")
            for h in nf:
                nf[h] += int(o["flagged"])
            continue
        other = bool(o["u"].get("rivals") or o["u"].get("patches"))
        for hum in (False, True):
            mn.HUM = hum
            nd = mn.simulated_null(*o["args"], **o.get("kw", {}))
            u = o["u"]
            hand = u.get("statistic") is not None and u["statistic"] > u["threshold"]
            cal = {} if nd is None else mn.calibrated_flag(nd, hand_bins=bool(hand))
            fl = bool(cal.get("flagged")) or other
            nf[hum] += int(fl)
            if "fac" in o and "hum_x" in o["fac"]:
                head = _line(o, cal, fl)
            else:
                head = (
                    f"{o.get('kind', '')} {o['seed']} flag {int(fl)} by "
                    f"{'+'.join(cal.get('by', [])) or '-'} T {_g(cal.get('T'))}/"
                    f"{_g(cal.get('T_threshold'))} t {_g(cal.get('t'))}/"
                    f"{_g(cal.get('t_threshold'))}"
                )
            print(f"hum {int(hum)} {head}", flush=True)
    mn.HUM = True
    print(f"recomputed: flagged {nf[False]}/{len(rows)} before, {nf[True]}/{len(rows)} after")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("what", choices=("run", "table", "recompute"))
    ap.add_argument("args", nargs="*")
    ap.add_argument("--cache", default="clean_chain_cache")
    ap.add_argument("--hum", choices=HUM, default=None, help="force the hum case")
    ap.add_argument("--jitter", type=int, choices=(0, 1), default=None, help="force jitter")
    ap.add_argument(
        "--xn", type=float, default=None, help="x noise drawn from XN to max(0.02, XN + 0.005)"
    )
    ap.add_argument("--white", action="store_true", help="white noise after the chain")
    a = ap.parse_args()
    warnings.simplefilter("ignore")
    if a.what == "table":
        table(a.cache)
        return
    if a.what == "recompute":
        recompute(a.cache, *(a.args[:1]))
        return
    seed0, n = int(a.args[0]), int(a.args[1])
    force = {
        "hum": a.hum,
        "jitter": None if a.jitter is None else bool(a.jitter),
        "xn": a.xn,
        "white": True if a.white else None,
    }
    for seed in range(seed0, seed0 + n):
        o = get(seed, a.cache, **force)
        cal = o["u"].get("calibrated") or {}
        print(_line(o, cal, o["flagged"]) + f" cpu {o['cpu']:.0f}s", flush=True)


if __name__ == "__main__":
    main()
