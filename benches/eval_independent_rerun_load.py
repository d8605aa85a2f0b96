"""Re-diagnose the blind generator's tangential records (and clean twins) of earlier
``eval_independent`` runs that named ``normal_load`` or carry one, on the current tree.

Usage (from the repository root): ``python benches/eval_independent_rerun_load.py LABEL ...``
with ``benches/results/eval_independent_<LABEL>.json`` present. Each record is regenerated
from its seed as ``eval_independent.job`` makes it and diagnosed by the command line.
"""

from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, "benches")
sys.path.insert(0, "benches/independent")

from generator import tangential_record

import eval_independent as E


def _flags(named: list, flagged: bool) -> str:
    return f"{named} F{int(bool(flagged))}"


def main(labels: list[str]) -> None:
    for lab in labels:
        runs = json.loads(Path(f"benches/results/eval_independent_{lab}.json").read_text())
        for r in runs:
            if r["kind"] != "tangential":
                continue
            tw = r.get("twin") or {}
            names = r["rec"]["named"] + tw.get("named", [])
            if "normal_load" not in names and r["label"] != "normal_load":
                continue
            seed = r["seed"]
            with tempfile.TemporaryDirectory() as tmp:
                tmp = Path(tmp)
                if r["label"].endswith("_virgin"):
                    rec, twin = tangential_record(seed, r["label"]), None
                else:
                    rng = np.random.default_rng(seed + 7919)
                    twin, rec, _ = E.make_pair("tangential", r["label"], seed, r["size_class"], rng)
                rec.write_csv(tmp / "rec.csv")
                s = E._summary(E.run_diagnose(tmp / "rec.csv", "tangential")[0])
                line = (
                    f"{lab[-5:]} {r['label']:20s} {seed} rec "
                    f"{_flags(r['rec']['named'], r['rec']['flagged'])} -> "
                    f"{_flags(s['named'], s['flagged'])}"
                )
                if twin is not None and "normal_load" in tw.get("named", []):
                    twin.write_csv(tmp / "tw.csv")
                    st = E._summary(E.run_diagnose(tmp / "tw.csv", "tangential")[0])
                    line += (
                        f" | twin {_flags(tw['named'], tw['flagged'])} -> "
                        f"{_flags(st['named'], st['flagged'])}"
                    )
                print(line, flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
