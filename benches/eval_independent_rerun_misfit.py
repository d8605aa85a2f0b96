"""Re-diagnose the blind generator's misfit records (``*_virgin``) of earlier
``eval_independent`` runs on the current tree, and say whether names and flag are the same.

Usage (from the repository root): ``python benches/eval_independent_rerun_misfit.py LABEL ...``
with ``benches/results/eval_independent_<LABEL>.json`` present. Each record is regenerated
from its seed as ``eval_independent.job`` makes it and diagnosed by the command line.
"""

from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, "benches")
sys.path.insert(0, "benches/independent")

from generator import tangential_record

import eval_independent as E


def main(labels: list[str]) -> None:
    same = total = 0
    for lab in labels:
        runs = json.loads(Path(f"benches/results/eval_independent_{lab}.json").read_text())
        for r in runs:
            if r["kind"] != "tangential" or not r["label"].endswith("_virgin"):
                continue
            with tempfile.TemporaryDirectory() as tmp:
                path = Path(tmp) / "rec.csv"
                tangential_record(r["seed"], r["label"]).write_csv(path)
                s = E._summary(E.run_diagnose(path, "tangential")[0])
            was = (r["rec"]["named"], bool(r["rec"]["flagged"]))
            now = (s["named"], bool(s["flagged"]))
            total += 1
            same += was == now
            print(f"{lab} {r['label']:16s} {r['seed']} {was} -> {now}"
                  f"{'' if was == now else '  CHANGED'}", flush=True)  # fmt: skip
    print(f"same names and flag: {same}/{total}")


if __name__ == "__main__":
    main(sys.argv[1:])
