"""A named parallel stiffness over a virgin curve of another shape (issue 29, spring_shape):
the plateau-slope check (:func:`contactlab.diagnose.shape.slope_check`), before and after
from one diagnosis per record.

Records (factors per seed, the range of the issue's evidence): fs 1/2/5/10 kHz, drive 1-50
Hz (at most fs/20), 5-12 cycles, ac·A 1.6-4.5, x noise 0.8-1.9 % of the range, F noise
0.5-2 %:

- ``rational``, ``tanh``, ``exp``: the misfit chain (``benches/misfit_chain.py``), virgin
  curve ``h0 ac s/(1 + ac s)``, ``h0 tanh(ac s)`` or the exponential one (clean);
- ``spring``: the package's rig (``synthetic.rig``) with a parallel stiffness of
  ``k_p A`` = 0.10-0.35 of the plateau force; ``rigclean``: the same without it;
- ``series``: the rig with a compliance in series of 0.3-1.0 of the contact's initial
  one ``1/(h0 ac)`` (the tail check of a named series compliance,
  :func:`contactlab.diagnose.shape.tail_check`: ``tanh`` records against these).

Each record is diagnosed once by this tree and cached with what its flag step saw; "before"
is the flag without the slope and tail checks' entries (``patches`` with ``"slope"`` or
``"tail"``), "after" the
flag as diagnosed. ``quick`` prints the check's figures on a least-squares fit of the base
with a spring (no diagnosis): the tuning view. Seeds 100-115 tuned the check (quick);
report on fresh seeds. One process, ``nice``::

    nice .venv/bin/python benches/eval_spring_shape.py run rational,spring 300 6 --cache DIR
    .venv/bin/python benches/eval_spring_shape.py table 'rational_3*,spring_3*' --cache DIR
    nice .venv/bin/python benches/eval_spring_shape.py quick rational,spring 100 16
"""

from __future__ import annotations

import argparse
import glob
import os
import pickle
import sys
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))


def record(seed: int, kind: str) -> tuple[Any, dict[str, Any]]:
    """The recording ``(t, x, F)`` of one case and its factors."""
    rng = np.random.default_rng([seed, 99])
    fs = float(rng.choice((1000.0, 2000.0, 5000.0, 10000.0)))
    fac: dict[str, Any] = {
        "fs": fs,
        "f": min(float(np.exp(rng.uniform(0, np.log(50)))), fs / 20),
        "cycles": int(rng.integers(5, 13)),
        "acA": float(rng.uniform(1.6, 4.5)),
        "x_noise": float(rng.uniform(0.008, 0.019)),
        "F_noise": float(rng.uniform(0.005, 0.02)),
    }
    if kind in ("rational", "tanh", "exp"):
        from misfit_chain import chain_record

        col = str(rng.choice(("white", "lvdt", "lp1")))
        rec, _ = chain_record(seed, kind, x_colour=col, **fac)
        return rec, fac
    from contactlab.synthetic.rig import rig_recording

    m = float(rng.uniform(0.1, 0.35))
    h0, ac = 40.0, 4e4
    a = fac["acA"] / ac
    hm = h0 * (1 - np.exp(-fac["acA"]))
    eff = {} if kind == "rigclean" else {"parallel_stiffness": {"k_p": m * hm / a}}
    if kind == "series":  # a compliance of 0.3-1.0 of the contact's initial one, 1/(h0 ac)
        m = float(rng.uniform(0.3, 1.0))
        eff = {"series_compliance": {"k_s": h0 * ac / m}}
    fac["m"] = m if eff else 0.0
    r = rig_recording(
        eff, "tangential", seed=seed, fs=fac["fs"], f=fac["f"], cycles=fac["cycles"],
        acA=fac["acA"], x_noise=fac["x_noise"], F_noise=fac["F_noise"],
    )  # fmt: skip
    ch = r.channels
    return (np.asarray(r.t), np.asarray(ch["x"]), np.asarray(ch["F"])), fac


def get(seed: int, kind: str, cache: str) -> dict[str, Any]:
    """One record's diagnosis (this tree), cached with what its flag step saw."""
    path = f"{cache}/{kind}_{seed}.pkl"
    if os.path.exists(path):
        with open(path, "rb") as fh:
            return pickle.load(fh)
    import contactlab.diagnose.misfit_null as mn
    from contactlab.diagnose.workflow import diagnose

    rec, fac = record(seed, kind)
    cap: dict[str, Any] = {}
    o1 = mn.simulated_null

    def h1(*a: Any, **k: Any) -> Any:
        cap["args"] = a
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
    pats = ud.get("patches") or []
    slope = [q for q in pats if q.get("slope") or q.get("tail")]
    others = bool(ud.get("rivals")) or any(not (q.get("slope") or q.get("tail")) for q in pats)
    cal = ud.get("calibrated") or {}
    before = bool(
        u is not None and (others or (cal.get("flagged") if cal else u.statistic > u.threshold))
    )
    out = {
        "seed": seed, "kind": kind, "cpu": cpu, "named": list(rep.effect_names), "fac": fac,
        "flagged": bool(u is not None and u.flagged), "before": before, "slope": slope,
        "where": [w for w in rep.where if "slope" in w or "tail" in w],
    }  # fmt: skip
    if "args" in cap:
        cap["args"][3].extra.pop("evaluations", None)
        out["args"] = cap["args"][:4]
    os.makedirs(cache, exist_ok=True)
    with open(path, "wb") as fh:
        pickle.dump(out, fh)
    return out


def recompute(o: dict[str, Any]) -> dict[str, Any] | None:
    """The slope check's figures on the cached final model (None where no spring is named
    or the flag step did not run) and its verdict (``fails``: True, False or None)."""
    from contactlab.diagnose.effects.tangential.parallel_stiffness import (
        plateau_slopes,
        spring_slope_fails,
    )

    if "args" not in o:
        return None
    _fam, p, eff, d = o["args"]
    if "series_compliance" in eff:
        from contactlab.diagnose.effects.tangential.series_compliance import (
            plateau_tail,
            tail_fails,
        )

        s = plateau_tail(d, float(p["ac"]), float(p["C_s"]), float(p["h0"]))
        return {**s, "fails": tail_fails(s)}
    if "parallel_stiffness" not in eff:
        return None
    s = plateau_slopes(d, float(p["ac"]))
    return {**s, "fails": spring_slope_fails(s)}


def table(pattern: str, cache: str) -> None:
    """Per record and per kind: named, flagged before (without the slope check) and after
    (with it: the flag as diagnosed, or the check recomputed on the cached final model of
    a record diagnosed by a tree without it)."""
    from collections import defaultdict

    g: dict[str, list] = defaultdict(list)
    for pat in pattern.split(","):
        for path in sorted(glob.glob(f"{cache}/{pat}.pkl")):
            with open(path, "rb") as fh:
                o = pickle.load(fh)
            f = o["fac"]
            s = recompute(o)
            fig = ""
            if s is not None and "g" in s:
                fig = (
                    f" tail g {s['g']:.3g} t {s['t']:.2f} branches {s['branches']} "
                    f"fails {s['fails']}"
                )
            elif s is not None:
                fig = (
                    f" slopes near {s['k_near']:.3g} far {s['k_far']:.3g} t {s['t']:.2f} "
                    f"branches {s['branches']} fails {s['fails']}"
                )
            o["after"] = bool(o["flagged"] or (s is not None and s["fails"]))
            print(
                f"{o['kind']} {o['seed']} acA {f['acA']:.2f} xn {100 * f['x_noise']:.2g} "
                f"cyc {f['cycles']} fs {f['fs']:g} named {o['named']} flag "
                f"{int(o['before'])} -> {int(o['after'])}{fig} cpu {o['cpu']:.0f}"
            )
            g[o["kind"]].append(o)
    print(
        "\n| kind | n | named parallel_stiffness | named it alone | flagged before | after "
        "| nothing named or flagged before | after | named series_compliance | alone |"
        "\n|---|---|---|---|---|---|---|---|---|---|"
    )
    for k in sorted(g):
        rr = g[k]
        print(
            f"| {k} | {len(rr)} | {sum('parallel_stiffness' in r['named'] for r in rr)} | "
            f"{sum(r['named'] == ['parallel_stiffness'] for r in rr)} | "
            f"{sum(r['before'] for r in rr)} | {sum(r['after'] for r in rr)} | "
            f"{sum(not r['named'] and not r['before'] for r in rr)} | "
            f"{sum(not r['named'] and not r['after'] for r in rr)} | "
            f"{sum('series_compliance' in r['named'] for r in rr)} | "
            f"{sum(r['named'] == ['series_compliance'] for r in rr)} |"
        )


def quick(kinds: list[str], seed0: int, n: int) -> None:
    """The check's figures on a least-squares fit of the base with a spring (a grid of
    ``ac``; ``h0``, ``k_p`` and an offset linear): the tuning view, no diagnosis."""
    from contactlab.diagnose._family import Prepared
    from contactlab.diagnose.effects.tangential.parallel_stiffness import (
        plateau_slopes,
        spring_slope_fails,
    )
    from contactlab.masing import Masing

    for kind in kinds:
        for s in range(seed0, seed0 + n):
            (t, x, F), fac = record(s, kind)
            d = Prepared.build(t, x, F)
            half = float(np.ptp(d.u)) / 2
            best = None
            for aca in np.exp(np.linspace(np.log(0.3), np.log(12), 60)):
                ac = aca / half
                X = np.column_stack([Masing(1.0, ac).force(d.u), d.u, np.ones(d.u.size)])
                c, *_ = np.linalg.lstsq(X, d.y, rcond=None)
                ss = float(np.sum((d.y - X @ c) ** 2))
                if best is None or ss < best[0]:
                    best = (ss, ac, c)
            _, ac, c = best
            q = plateau_slopes(d, ac)
            print(
                f"{kind} {s} acA {fac['acA']:.2f} xn {100 * fac['x_noise']:.2g} cyc "
                f"{fac['cycles']} fs {fac['fs']:g} | fit acA {ac * half:.2f} k_p A/h0 "
                f"{c[1] * half / c[0]:.3f} | t {q['t']:.2f} far/near "
                f"{q['k_far'] / q['k_near']:.2f} branches {q['branches']} fails "
                f"{spring_slope_fails(q)}",
                flush=True,
            )


def main() -> None:
    warnings.simplefilter("ignore")
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("what", choices=("run", "table", "quick"))
    ap.add_argument("args", nargs="+")
    ap.add_argument("--cache", default="spring_shape_cache")
    ap.add_argument("--smooth", action="store_true", help="ParallelStiffness.smooth_input = True")
    a = ap.parse_args()
    if a.smooth:
        from contactlab.diagnose.effects.tangential.parallel_stiffness import ParallelStiffness

        ParallelStiffness.smooth_input = True
    if a.what == "table":
        table(a.args[0], a.cache)
        return
    kinds, seed0, n = a.args[0].split(","), int(a.args[1]), int(a.args[2])
    if a.what == "quick":
        quick(kinds, seed0, n)
        return
    for s in range(seed0, seed0 + n):
        for kind in kinds:
            o = get(s, kind, a.cache)
            print(s, kind, "named", o["named"], "flagged", o["before"], "->", o["flagged"],
                  f"cpu {o['cpu']:.0f}", flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
