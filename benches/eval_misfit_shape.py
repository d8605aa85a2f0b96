"""The misfit flag where a named shape effect took up a virgin curve of another shape
(misfit, stop 43, issue 29 item 3): before and after from one diagnosis per record.

A tanh virgin curve named ``series_compliance`` alone, a rational one named
``parallel_stiffness`` alone: the named effect takes up most of the misfit and the flag's
tests on the final residual stay under their bounds. Each record is diagnosed once by this
tree and cached with what its flag step saw (``benches/eval_flag_power.py``'s cache, records
of ``benches/eval_flag_calibration.py``: ``gen`` ``flagcal``); the table prints the flag as
diagnosed and the pieces of the shape-effect check
(:func:`contactlab.diagnose.shape.swap_check`) recomputed on the cached final model.

Kinds: ``tanh``, ``rational``, ``gamma`` (misfit chain), ``exp`` (clean misfit chain),
``rigclean`` (clean rig), ``effect:series_compliance``, ``effect:parallel_stiffness``,
``effect:non_masing_scaling`` (nameable controls on the rig). ``--lead`` keeps only seeds
whose factors fall in the range of the lead's evidence (ac·A >= 1.5, x noise >= 0.5 %).

Seeds: 6000-6999 tuning (stop 43); fresh from 86000. One process, ``nice``::

    nice .venv/bin/python benches/eval_misfit_shape.py run tanh,rational,gamma 86000 8 \\
        --lead --cache DIR
    .venv/bin/python benches/eval_misfit_shape.py table 'flagcal_*_86*' --cache DIR
"""

from __future__ import annotations

import argparse
import glob
import pickle
import sys
import warnings
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))


def lead_range(seed: int) -> bool:
    """Whether the seed's factors fall where the lead's misfit records were unflagged."""
    from eval_flag_calibration import factors

    f = factors(seed)
    return f["acA"] >= 1.5 and f["x_noise"] >= 0.005


def recompute(o: dict[str, Any]) -> dict[str, Any] | None:
    """The swap check (:func:`contactlab.diagnose.shape.swap_check`) on the cached final
    model, and each named shape effect's share with one free-form column (None where the
    flag step did not run)."""
    from contactlab.diagnose.select import fit
    from contactlab.diagnose.shape import SWAP_EFFECTS, patch_share, swap_check

    if "args" not in o:
        return None
    fam, p, eff, d, r, _so, sg = o["args"]
    for k in ("masing", "merged", "merged_span"):
        if isinstance(d.extra.get(k), dict):
            d.extra[k] = {}
    sw = swap_check(fam, tuple(eff), d, p, fam.scales(d), r, sg)
    shares = []
    for e in eff:
        if e not in SWAP_EFFECTS:
            continue
        rest = tuple(x for x in eff if x != e)
        try:
            fr = fit(fam, rest, d, np.ones(d.y.size, bool), p, fam.scales(d))
        except Exception:  # a bench: no verdict on this one
            continue
        r0 = d.y - np.asarray(fam.predict(fr.params, rest, d), float)
        s1 = patch_share(d, r, r0, float(p["ac"]), sg, 1)
        if s1 is not None:
            shares.append(f"{e} gain {s1['gain_effects']:.1f} share {s1['share']:.3f}")
    return {"swap": bool(sw), "shares": shares}


def table(pattern: str, cache: str) -> None:
    rows = []
    for pat in pattern.split(","):
        for path in sorted(glob.glob(f"{cache}/{pat}.pkl")):
            with open(path, "rb") as fh:
                o = pickle.load(fh)
            got = recompute(o) or {}
            swap = bool(got.get("swap"))
            f = o["fac"]
            before = _before(o)
            after = bool(before or swap)
            rows.append({"kind": o["kind"], "before": before, "after": after, "swap": swap,
                         "named": bool(o["named"])})  # fmt: skip
            c = o.get("cal") or {}
            print(
                f"{o['kind']} {o['seed']} xn {100 * f['x_noise']:.2g} acA {f['acA']:.2f} "
                f"cyc {f['cycles']} named {o['named']} flag {int(before)} -> {int(after)} "
                f"(swap {int(swap)})"
                f" by {c.get('by')} t {_g(c.get('t'))}/{_g(c.get('t_threshold'))} gain "
                f"{_g(c.get('gain'))} T {_g(c.get('T'))}/{_g(c.get('T_threshold'))} "
                f"rivals {int(o['rivals'])} patches {int(o['patches'])} {got.get('shares')}"
            )
    print(
        "\n| kind | n | named | flagged before | flagged after | by the swap "
        "| nothing named or flagged before | after |\n|---|---|---|---|---|---|---|---|"
    )
    g: dict[str, list] = defaultdict(list)
    for r in rows:
        g[r["kind"]].append(r)
    for k in sorted(g):
        rr = g[k]
        print(
            f"| {k} | {len(rr)} | {sum(r['named'] for r in rr)} | "
            f"{sum(r['before'] for r in rr)} | {sum(r['after'] for r in rr)} | "
            f"{sum(r['swap'] for r in rr)} | "
            f"{sum(not r['named'] and not r['before'] for r in rr)} | "
            f"{sum(not r['named'] and not r['after'] for r in rr)} |"
        )


def _before(o: dict[str, Any]) -> bool:
    """The flag without the swap check (``patches`` counts no swap; a record cached while a
    lower gain floor after a named shape effect was tried counts without it)."""
    c = o.get("cal")
    if not c:
        return bool(o["flagged"])
    by = set(c.get("by") or ()) - {"backbone_after_shape"}
    return bool(o["rivals"] or o["patches"] or by)


def _g(v: Any) -> str:
    return "-" if v is None else (f"{v:.3g}" if isinstance(v, float) else str(v))


def main() -> None:
    warnings.simplefilter("ignore")
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("what", choices=("run", "table"))
    ap.add_argument("args", nargs="+")
    ap.add_argument("--cache", default="misfit_shape_cache")
    ap.add_argument("--lead", action="store_true", help="only seeds in the lead's range")
    ap.add_argument("--gen", default="flagcal", help="flagcal, or hidden (package generator)")
    a = ap.parse_args()
    if a.what == "table":
        table(a.args[0], a.cache)
        return
    from eval_flag_power import get

    kinds, seed0, n = a.args[0].split(","), int(a.args[1]), int(a.args[2])
    for kind in kinds:
        s, done = seed0, 0
        while done < n:
            if not a.lead or lead_range(s):
                o = get(s, kind, a.gen, a.cache)
                print(s, kind, "named", o["named"], "flagged", o["flagged"],
                      f"cpu {o['cpu']:.0f}", flush=True)  # fmt: skip
                done += 1
            s += 1


if __name__ == "__main__":
    main()
