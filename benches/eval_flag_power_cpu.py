"""The misfit flag's null, cheaper and with a second tier for small shape misfits (issue 29
item 3, stop 41): flags and CPU before and after, from one cached diagnosis per record.

The records are diagnosed once by ``benches/eval_flag_power.py run`` (its cache holds what
the flag step saw: the final model, the prepared record, the residual, the noise levels,
the phase bins' hand verdict, rivals and patches). This script recomputes the simulated
null and the calibrated decision on each cached record with the package found first on
``sys.path`` and prints one JSON line per record: the flag (calibrated decision or rivals
or patches), the statistics, and the null's CPU (best of ``--repeat``). Run it twice, with
``PYTHONPATH`` pointing at the start commit's package (before: ``git archive <commit>
python/contactlab | tar -x -C DIR`` and the built ``_core`` copied in) and at this tree
(after), then ``table`` the two outputs::

    nice .venv/bin/python benches/eval_flag_power.py run flagcal exp,rigclean 731000 30 --cache C
    PYTHONPATH=DIR/python nice .venv/bin/python benches/eval_flag_power_cpu.py run 'C/*' > b
    nice .venv/bin/python benches/eval_flag_power_cpu.py run 'C/*' > a
    .venv/bin/python benches/eval_flag_power_cpu.py table b a

BLAS threads: the CPU is measured as the process's CPU time, every thread counted.
"""

from __future__ import annotations

import argparse
import glob
import json
import pickle
import sys
import time
import warnings
from collections import defaultdict
from typing import Any

import numpy as np


def run(pattern: str, repeat: int) -> None:
    import contactlab.diagnose.misfit_null as mn

    for path in sorted(glob.glob(pattern)):
        with open(path, "rb") as fh:
            o = pickle.load(fh)
        f = o["fac"]
        row: dict[str, Any] = {
            "key": path.rsplit("/", 1)[-1][:-4], "gen": o["gen"], "kind": o["kind"],
            "seed": o["seed"], "xn": 100 * f["x_noise"], "acA": f["acA"], "cyc": f["cycles"],
            "fs": f["fs"], "named": o["named"], "rivals": o["rivals"], "patches": o["patches"],
        }  # fmt: skip
        if "args" not in o:  # the null did not run in the diagnosis: its flag stands
            row.update(flagged=bool(o["flagged"]), cal=None, cpu=None, samples=None)
            print(json.dumps(row), flush=True)
            continue
        fam, p, eff, d, r, so, sg = o["args"]
        for k in ("masing", "merged", "merged_span"):
            if isinstance(d.extra.get(k), dict):
                d.extra[k] = {}
        cpus, nd = [], None
        for _ in range(repeat):
            t0 = time.process_time()
            nd = mn.simulated_null(fam, p, eff, d, r, so, sg)
            cpus.append(time.process_time() - t0)
        cal = None if nd is None else mn.calibrated_flag(nd, hand_bins=o["hand_bins"])
        flagged = (
            bool(o["flagged"])
            if cal is None
            else bool(cal["flagged"] or o["rivals"] or o["patches"])
        )
        row.update(flagged=flagged, cal=cal, cpu=min(cpus), samples=int(d.y.size))
        print(json.dumps(row), flush=True)


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
    if k == "fs":
        return f"{r['fs'] / 1000:g} kHz"
    return r["kind"]


def table(before: str, after: str) -> None:
    def load(p: str) -> dict[str, dict[str, Any]]:
        with open(p) as fh:
            return {(r := json.loads(line))["key"]: r for line in fh if line.strip()}

    b, a = load(before), load(after)
    keys = sorted(set(b) & set(a))
    for k in keys:
        rb, ra = b[k], a[k]
        if rb["flagged"] != ra["flagged"]:
            c = ra["cal"] or {}
            print(f"changed {k}: xn {ra['xn']:.2f} acA {ra['acA']:.2f} cyc {ra['cyc']} named "
                  f"{ra['named']} {int(rb['flagged'])} -> {int(ra['flagged'])} by {c.get('by')} "
                  f"t {c.get('t')} gain {c.get('gain')}")  # fmt: skip
    print("\n| factor | level | n | flagged before | flagged after | nothing named or flagged, "
          "before | after |\n|---|---|---|---|---|---|---|")  # fmt: skip
    for fac in ("kind", "x noise %", "ac·A", "cycles", "fs"):
        g: dict[str, list[str]] = defaultdict(list)
        for k in keys:
            g[_band(a[k], fac)].append(k)
        for lvl in sorted(g):
            kk = g[lvl]
            fb = sum(b[k]["flagged"] for k in kk)
            fa = sum(a[k]["flagged"] for k in kk)
            ob = sum(not b[k]["named"] and not b[k]["flagged"] for k in kk)
            oa = sum(not a[k]["named"] and not a[k]["flagged"] for k in kk)
            print(f"| {fac} | {lvl} | {len(kk)} | {fb} | {fa} | {ob} | {oa} |")
    cp = [(b[k]["cpu"], a[k]["cpu"], a[k]["samples"]) for k in keys if b[k]["cpu"] and a[k]["cpu"]]
    if cp:
        cb, ca, n = (np.array(v, float) for v in zip(*cp, strict=True))
        long = n >= np.percentile(n, 75)
        print(f"\nnull CPU per record ({len(cp)} records): before median {np.median(cb):.3f} s "
              f"(max {cb.max():.3f}), after median {np.median(ca):.3f} s (max {ca.max():.3f}); "
              f"ratio after/before median {np.median(ca / cb):.3f}; longest quarter "
              f"({int(long.sum())} records, >= {int(np.percentile(n, 75))} samples): before "
              f"{np.median(cb[long]):.3f} s, after {np.median(ca[long]):.3f} s")  # fmt: skip


def main() -> None:
    warnings.simplefilter("ignore")
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("what", choices=("run", "table"))
    ap.add_argument("args", nargs="+")
    ap.add_argument("--repeat", type=int, default=2)
    a = ap.parse_args()
    if a.what == "run":
        run(a.args[0], a.repeat)
    else:
        table(a.args[0], a.args[1])


if __name__ == "__main__":
    main()
    sys.exit(0)
