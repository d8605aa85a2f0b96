"""The misfit flag (issue 29, item 3) on the measurement chain of ``benches/misfit_chain.py``,
over the factor ranges of the issue: clean records (exponential virgin curve, nothing to
flag) against virgin curves no candidate draws (tanh, rational, gamma) and a nameable
control (non-Masing branch scaling 1.3-1.6 applied from rest: to be named, not flagged).

Factors, drawn per record from its seed: fs 1, 2, 5 or 10 kHz; drive 1-50 Hz (at most
fs/20); 5-50 cycles; ac·A 0.5-5 (log-uniform); noise on both channels 0.5-2 % of the
range; the x sensor's noise coloured by an LVDT demodulator (2nd order) or an RC stage
(1st order) or white, always behind a 4th-order Bessel anti-alias filter; mains hum and
clock jitter on half of the records each; start from rest.

Seeds: 0-9999 were used for tuning (diagflag, stop 38); report on seeds from 20000.

Run (one process, ``nice``):
``nice .venv/bin/python benches/eval_misfit_flag.py --n 20 --misfits 20 --seed0 20000
--dump out.jsonl``; ``--table out.jsonl`` prints the tables of a dump (several dumps
side by side: before and after).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

MISFITS = ("tanh", "rational", "gamma")
KINDS = (*MISFITS, "nonmasing")


def factors(seed: int, kind: str) -> dict[str, Any]:
    """The factors of one record, drawn from its seed (the chain draws the rest)."""
    rng = np.random.default_rng([seed, 4242])
    fs = float(rng.choice((1000.0, 2000.0, 5000.0, 10000.0)))
    over = {
        "fs": fs,
        "f": min(float(np.exp(rng.uniform(0.0, np.log(50.0)))), fs / 20.0),
        "cycles": int(rng.integers(5, 51)),
        "acA": float(np.exp(rng.uniform(np.log(0.5), np.log(5.0)))),
        "x_noise": float(rng.uniform(0.005, 0.02)),
        "F_noise": float(rng.uniform(0.005, 0.02)),
    }
    chain = {
        "x_colour": str(rng.choice(("lvdt", "lp1", "white"))),
        "hum": bool(rng.random() < 0.5),
        "jitter": bool(rng.random() < 0.5),
        "scale": float(rng.uniform(1.3, 1.6)) if kind == "nonmasing" else 2.0,
    }
    return {"over": over, "chain": chain}


def run_one(seed: int, kind: str) -> dict[str, Any]:
    import warnings

    from contactlab.diagnose.workflow import diagnose
    from contactlab.errors import ContactLabError
    from misfit_chain import chain_record

    warnings.simplefilter("ignore")
    fx = factors(seed, kind)
    virgin = "exp" if kind in ("exp", "nonmasing") else kind
    rec, fac = chain_record(seed, virgin, **fx["chain"], **fx["over"])
    t0 = time.process_time()
    out: dict[str, Any] = {"seed": seed, "kind": kind, **fac}
    try:
        rep = diagnose(rec, model="tangential")
    except ContactLabError as exc:
        out.update(refused=str(exc)[:160], named=[], flagged=False)
    else:
        u = rep.unexplained
        ud = {} if u is None else u.to_dict()
        ud.pop("profile", None)
        out.update(
            refused=None,
            named=rep.effect_names,
            flagged=bool(u is not None and u.flagged),
            bins_flag=bool(u is not None and u.statistic > u.threshold),
            ratio=None if u is None else u.statistic / u.threshold,
            unexplained=ud,
            flag_route=rep.location.get("flag_route"),
        )
    out["cpu"] = time.process_time() - t0
    return out


def _band(name: str, r: dict[str, Any]) -> str:
    if name == "x noise %":
        x = 100 * r["x_noise"]
        return "0.5-1" if x < 1 else "1-1.5" if x < 1.5 else "1.5-2"
    if name == "ac·A":
        return "0.5-1" if r["acA"] < 1 else ("1-2.5" if r["acA"] < 2.5 else "2.5-5")
    if name == "cycles":
        return "5-20" if r["cycles"] <= 20 else "21-34" if r["cycles"] < 35 else "35-50"
    if name == "fs":
        return f"{r['fs']:g}"
    if name == "x colour":
        return str(r.get("x_colour"))
    return str(r["kind"])


def table(rs: list[dict[str, Any]], title: str) -> str:
    ok = [r for r in rs if r["refused"] is None]
    lines = [f"\n{title}: {len(ok)} diagnosed ({len(rs) - len(ok)} refused)"]
    lines.append(
        f"{'factor':<12}{'level':>10}{'n':>5}{'named':>7}{'flagged':>9}{'rate':>7}"
        f"{'w/o rivals':>12}"
    )
    for name in ("kind", "x colour", "x noise %", "ac·A", "cycles", "fs"):
        g: dict[str, list] = defaultdict(list)
        for r in ok:
            g[_band(name, r)].append(r)
        for lvl in sorted(g):
            k = sum(bool(r["named"]) for r in g[lvl])
            f = sum(r["flagged"] for r in g[lvl])
            f0 = sum(_without_rivals(r) for r in g[lvl])
            lines.append(
                f"{name:<12}{lvl:>10}{len(g[lvl]):>5}{k:>7}{f:>9}{100 * f / len(g[lvl]):>6.0f}%"
                f"{f0:>12}"
            )
    f = sum(r["flagged"] for r in ok)
    f0 = sum(_without_rivals(r) for r in ok)
    lines.append(f"all: flagged {f}/{len(ok)}; without the rival check {f0}/{len(ok)}")
    for r in ok:
        u = r.get("unexplained") or {}
        bb = u.get("backbone") or {}
        rv = ",".join(f"{x['effect']} {x['share']:.2f}" for x in u.get("rivals") or [])
        lines.append(
            f"  {r['seed']} {r['kind']}: named {r['named']} flag {int(r['flagged'])} "
            f"T/thr {_g(r.get('ratio'))} bb t {_g(bb.get('t'))} rivals [{rv}] "
            f"(fs {r['fs']:g} f {r['f']:.3g} cyc "
            f"{r['cycles']} xn {100 * r['x_noise']:.2g}% {r.get('x_colour')} Fn "
            f"{100 * r['F_noise']:.2g}% acA {r['acA']:.3g} cpu {r['cpu']:.0f})"
        )
    return "\n".join(lines)


def _without_rivals(r: dict[str, Any]) -> bool:
    """The flag as the tree before the rival check raised it: the rival check runs last and
    only adds ``rivals`` and sets ``flagged``, so the earlier flag is the phase bins' or the
    free-form virgin curve test's (the same run, the same record)."""
    u = r.get("unexplained") or {}
    if not u.get("rivals"):
        return bool(r["flagged"])
    return bool(r.get("bins_flag") or (u.get("backbone") or {}).get("flagged"))


def _g(v: Any) -> str:
    return "-" if v is None else (f"{v:.3g}" if isinstance(v, float) else str(v))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=20, help="clean records")
    ap.add_argument("--misfits", type=int, default=20, help="misfit and control records")
    ap.add_argument("--seed0", type=int, default=20000)
    ap.add_argument("--dump", default=None, help="append each record's result (JSON lines)")
    ap.add_argument("--table", nargs="*", default=None, help="print the tables of dumps")
    a = ap.parse_args()
    if a.table:
        for path in a.table:
            rs = [json.loads(line) for line in open(path)]
            print(f"===== {path}")
            print(table([r for r in rs if r["kind"] == "exp"], "clean"))
            print(table([r for r in rs if r["kind"] in MISFITS], "unnameable virgin curves"))
            print(table([r for r in rs if r["kind"] == "nonmasing"], "non-Masing (nameable)"))
        return
    done = set()
    if a.dump and Path(a.dump).exists():
        done = {(r["seed"], r["kind"]) for r in map(json.loads, open(a.dump))}
    jobs = [(a.seed0 + k, "exp") for k in range(a.n)]
    jobs += [(a.seed0 + 5000 + k, KINDS[k % len(KINDS)]) for k in range(a.misfits)]
    for seed, kind in jobs:
        if (seed, kind) in done:
            continue
        r = run_one(seed, kind)
        print(json.dumps({k: r.get(k) for k in ("seed", "kind", "named", "flagged", "cpu")}))
        if a.dump:
            with open(a.dump, "a") as fh:
                fh.write(json.dumps(r, default=str) + "\n")


if __name__ == "__main__":
    main()
