"""Detection under coloured input noise (issue 29, item 1), channel delay against backlash
(item 1's confusions) and hum next to a drive harmonic, on chains written here and on the
rig generator's sensor chain.

Sets (``--sets``, comma separated):

- ``clean``: nothing to name. Records alternate between three chains: the measurement chain
  of ``benches/misfit_chain.py`` (exponential virgin curve; LVDT demodulator low-pass and
  Bessel anti-alias filter on x, hum, jitter, ADC), the rig's sensor chain
  (:mod:`contactlab.synthetic.rig` with ``benches/eval_diagnose_rig.py``'s
  ``chain_kwargs``: LVDT low-pass, piezo or strain-gauge cell, Bessel, hum, jitter, drive
  harmonics) and the rig's plain chain (white x noise). Factors: fs 1-10 kHz, 5-50 cycles,
  x noise 0-2 % (of the range or amplitude), ac·A 0.3-5, start from rest. Anything named is
  a false alarm.
- ``effects``: one visible effect (``eval_diagnose_rig.rig_effect``'s sizes) on the rig's
  sensor chain; exact when exactly that effect is named.
- ``delay``: a channel delay of 0.3-1.5 ms (at most 2 % of the period) or a backlash of 5-15
  % of the amplitude, alternately, on the rig's sensor chain: which of the two is named.
- ``hum``: a clean rig record whose drive has a harmonic (2nd-4th) within 0.5-3.5 bins of 50
  Hz, with hum 0.3-1 % on both channels (and, every other record, a true normal load at 2f
  for the power): whether normal_load is named.

Seeds: ``--seed0`` (tuning 0-9999; report on fresh ones from 50 000). One record's result
per JSON line in ``--out``; the tables at the end give rates by set, effect and x-noise band.
Run: ``nice .venv/bin/python benches/eval_detect.py --sets clean --n 30 --seed0 50000``
(about 10 CPU-minutes at --jobs 1). Not part of the test suite.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

EFFECTS = (
    "channel_delay",
    "backlash",
    "viscous_damping",
    "parallel_stiffness",
    "force_offset",
    "force_drift",
    "asymmetry",
    "stribeck",
    "normal_load",
    "displacement_offset",
    "stick_slip",
    "non_masing_scaling",
)


def _rig(eff: dict[str, Any], seed: int, fac: dict[str, Any], sensors: bool, **more: Any) -> Any:
    import contactlab
    from contactlab.synthetic.rig import rig_recording
    from eval_diagnose_rig import chain_kwargs

    os.environ["CONTACTLAB_RIG_CHAIN"] = "sensors" if sensors else "plain"
    kw = chain_kwargs(seed, fac)
    kw.update(more)
    rng = np.random.default_rng(seed + 7919)
    rec = rig_recording(
        eff, "tangential", seed=seed, fs=fac["fs"], f=fac["f"], cycles=fac["cycles"],
        acA=fac["acA"], x_noise=fac["x_noise"], F_noise=fac["F_noise"],
        x_drift=float(rng.uniform(-0.003, 0.003)), bits=int(rng.integers(12, 17)), **kw,
    )  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp:
        path = rec.to_csv(Path(tmp) / "rec.csv")
        kw["channel_skew"] = rec.truth["chain"].get("channel_skew")
        return contactlab.read_recording(str(path)), kw


def _factors(rng: np.random.Generator) -> dict[str, Any]:
    from eval_diagnose_rig import draw_factors

    return draw_factors(rng, "tangential")


def make(set_: str, seed: int) -> tuple[Any, dict[str, Any]]:
    """A record of the set and what it holds."""
    rng = np.random.default_rng([seed, 31])
    fac = _factors(rng)
    info: dict[str, Any] = {"set": set_, "seed": seed, **fac}
    if set_ == "clean":
        chain = ("misfit", "sensors", "plain")[seed % 3]
        info["chain"] = chain
        if chain == "misfit":
            from misfit_chain import chain_record

            (t, x, F), f2 = chain_record(seed, "exp")
            info.update({k: f2[k] for k in ("fs", "f", "cycles", "acA", "x_noise", "F_noise")})
            return _plain_recording(t, x, F), info
        rec, kw = _rig({}, seed, fac, chain == "sensors")
        info["channel_skew"] = kw["channel_skew"]
        return rec, info
    if set_ == "effects":
        from eval_diagnose_rig import rig_effect

        e = EFFECTS[seed % len(EFFECTS)]
        variant = "2f" if rng.random() < 0.5 else "1.37f"
        eff = rig_effect(e, variant, fac, rng)
        info["effect"] = e
        info["truth"] = eff[e]
        rec, kw = _rig(eff, seed, fac, True)
        info["channel_skew"] = kw["channel_skew"]
        return rec, info
    if set_ == "delay":
        per = 1.0 / fac["f"]
        A = fac["acA"] / 4.0e4
        if seed % 2 == 0:
            tau = float(min(rng.uniform(3e-4, 1.5e-3), 0.02 * per))
            eff = {"channel_delay": {"tau": tau}}
            info["effect"] = "channel_delay"
        else:
            eff = {"backlash": {"b": float(rng.uniform(0.05, 0.15)) * A}}
            info["effect"] = "backlash"
        info["truth"] = eff[info["effect"]]
        rec, kw = _rig(eff, seed, fac, True)
        # the chain's own skew (the LVDT's lag, the anti-alias corners): the delay the
        # record holds is tau plus it
        info["channel_skew"] = kw["channel_skew"]
        return rec, info
    if set_ == "hum":
        k = int(rng.integers(2, 5))
        dur_cycles = fac["cycles"] + 1.0
        off = float(rng.uniform(0.5, 3.5)) * (1 if rng.random() < 0.5 else -1)
        # k f = 50 + off / duration, duration ≈ cycles / f  →  f = (50 + off f / cycles) / k
        f = 50.0 / (k - off / dur_cycles)
        fac["f"] = round(f, 4)
        fac["fs"] = max(fac["fs"], 25 * f * 1.0)
        fac["cycles"] = max(5, min(fac["cycles"], int(30000 * f / fac["fs"])))
        info.update(f=fac["f"], fs=fac["fs"], cycles=fac["cycles"], harmonic=k)
        eff: dict[str, Any] = {}
        if seed % 2 == 1:
            from eval_diagnose_rig import rig_effect

            eff = rig_effect("normal_load", "2f", fac, rng)
            info["effect"] = "normal_load"
            info["truth"] = eff["normal_load"]
        hum = float(rng.uniform(0.003, 0.01))
        info["hum"] = hum
        rec, _ = _rig(eff, seed, fac, False, hum=hum)
        return rec, info
    raise ValueError(set_)


def _plain_recording(t: np.ndarray, x: np.ndarray, F: np.ndarray) -> Any:
    import contactlab

    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / "rec.csv"
        np.savetxt(p, np.column_stack([t, x, F]), delimiter=",", header="t,x,F", comments="")
        return contactlab.read_recording(str(p))


def run_one(job: tuple[str, int]) -> dict[str, Any]:
    import warnings

    import contactlab

    warnings.simplefilter("ignore")
    set_, seed = job
    c0 = time.process_time()
    out: dict[str, Any] = {}
    try:
        rec, info = make(set_, seed)
        out.update(info)
        rep = contactlab.diagnose(rec, model="tangential")
        d = rep.to_dict()
        out["named"] = [e["name"] for e in d.get("effects", [])]
        out["params"] = {e["name"]: e.get("parameters", {}) for e in d.get("effects", [])}
        u = d.get("unexplained") or {}
        out["flagged"] = bool(isinstance(u, dict) and u.get("flagged"))
        eff = out.get("effect")
        if eff and eff not in out["named"]:
            nd = [x for x in d.get("not_detected", []) or [] if x.get("effect") == eff]
            if nd:
                out["bound"] = {k: nd[0].get(k) for k in ("parameter", "detectable_above")}
        out["error"] = None
    except Exception as exc:  # a failure is a result
        out.update(set=set_, seed=seed, named=[], error=f"{type(exc).__name__}: {exc}"[:200])
    out["cpu"] = time.process_time() - c0
    return json.loads(json.dumps(out, default=float))


def _band(x: float) -> str:
    for lo, hi in ((0, 0.005), (0.005, 0.01), (0.01, 0.015), (0.015, 0.0201)):
        if lo <= x < hi:
            return f"{100 * lo:g}-{100 * hi:.3g} %"
    return "?"


def tables(rs: list[dict[str, Any]]) -> str:
    lines = []
    by = defaultdict(list)
    for r in rs:
        by[r.get("set")].append(r)
    for set_, rr in by.items():
        lines.append(f"## {set_} ({len(rr)} records)")
        if set_ == "clean":
            named = [r for r in rr if r.get("named")]
            lines.append(f"named anything: {len(named)}/{len(rr)}; flagged "
                         f"{sum(bool(r.get('flagged')) for r in rr)}/{len(rr)}")  # fmt: skip
            for key, f in (("chain", lambda r: r.get("chain")),
                           ("x noise", lambda r: _band(r.get("x_noise", 0.0)))):  # fmt: skip
                g = defaultdict(list)
                for r in rr:
                    g[f(r)].append(r)
                for k in sorted(g, key=str):
                    n = sum(bool(r.get("named")) for r in g[k])
                    lines.append(f"- {key} {k}: named {n}/{len(g[k])}")
            for r in named:
                lines.append(
                    f"  - seed {r['seed']} {r.get('chain')} xn {r.get('x_noise')}: "
                    f"{r['named']} {r.get('params')} skew {r.get('channel_skew')}"
                )
        else:
            g = defaultdict(list)
            for r in rr:
                g[r.get("effect", "clean")].append(r)
            for e in sorted(g):
                rows = g[e]
                if e == "clean":
                    n = sum("normal_load" in r.get("named", []) for r in rows)
                    m = sum(bool(r.get("named")) for r in rows)
                    k = len(rows)
                    lines.append(f"- clean: normal_load named {n}/{k}; anything {m}/{k}")
                    continue
                exact = sum(r.get("named") == [e] for r in rows)
                has = sum(e in r.get("named", []) for r in rows)
                lines.append(f"- {e}: exact {exact}/{len(rows)}, named among others {has}")
                for r in rows:
                    if r.get("named") != [e]:
                        lines.append(f"  - seed {r['seed']} xn {r.get('x_noise')}: {r.get('named')}"
                                     f" truth {r.get('truth')} skew {r.get('channel_skew')}"
                                     f" bound {r.get('bound')} err {r.get('error')}")  # fmt: skip
            g2 = defaultdict(list)
            for r in rr:
                if r.get("effect"):
                    g2[_band(r.get("x_noise", 0.0))].append(r)
            for k in sorted(g2):
                ex = sum(r.get("named") == [r["effect"]] for r in g2[k])
                lines.append(f"- x noise {k}: exact {ex}/{len(g2[k])}")
        cpu = sum(r.get("cpu", 0.0) for r in rr)
        lines.append(f"(CPU {cpu:.0f} s)")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sets", default="clean")
    ap.add_argument("--n", type=int, default=12, help="records per set")
    ap.add_argument("--seed0", type=int, default=50000)
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument("--seeds", default=None, help="only these seeds (comma separated)")
    args = ap.parse_args()
    os.nice(5)
    rs = []
    fh = args.out.open("a") if args.out else None
    for set_ in args.sets.split(","):
        seeds = (
            [int(s) for s in args.seeds.split(",")]
            if args.seeds
            else range(args.seed0, args.seed0 + args.n)
        )
        for seed in seeds:
            r = run_one((set_, seed))
            rs.append(r)
            print(json.dumps({k: r.get(k) for k in ("set", "seed", "effect", "named", "x_noise",
                                                     "error", "cpu")}), flush=True)  # fmt: skip
            if fh:
                fh.write(json.dumps(r) + "\n")
                fh.flush()
    print(tables(rs))


if __name__ == "__main__":
    main()
