"""Before/after CPU of a streamed ``analyze``'s passes, part by part, in interleaved rounds
(issue 33 item 4: the window's passes fused; the bar is 0.3 of the Masing kernel).

Each round runs, for this tree and for ``--baseline DIR`` (another tree's ``python/``
folder, built: ``PYTHONPATH=DIR``), a new process that warms up (imports, the file in the
page cache, one serial track) and then runs :func:`contactlab.studies.tracking.track` of
the recording as ``analyze --json`` runs it, serially (``threads=0``), with every per-sample
kernel wrapped (``bench_analyze_parts.parts``: each part's CPU seconds on the calling
thread), and times the Masing kernel (``Masing.force(x, out=buf)`` over the recording's
displacement, the best of three) in the same process. The trees alternate round by round,
so a change of the machine's load falls on both. Medians over the rounds, per part:
CPU seconds, ns a sample, and after/before; the total's ratio of samples per CPU-second to
the kernel's samples per second (both on one thread). CPU seconds, not wall time: the
machine is shared, and a loaded CPU stretches wall time far more than CPU time.

Run: ``nice .venv/bin/python benches/bench_analyze_passes_ab.py --baseline DIR
[--samples 3e7] [--rounds 5] [--recording FILE]``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benches"))

#: run in each child: argv[1] the recording, argv[2] this benches folder
_CHILD = r"""
import json, sys, time
sys.path.insert(0, sys.argv[2])
import numpy as np
import h5py
import bench_track
from bench_analyze_parts import parts
from contactlab._malloc import keep_freed_memory
import contactlab
keep_freed_memory()
path = sys.argv[1]
parts(path, 0)  # warm
stats, cpu, wall, faults = parts(path, 0)
with h5py.File(path, "r") as f:
    x = np.asarray(f["x"][:])
buf = np.empty_like(x)
m = contactlab.Masing(h0=bench_track.H0, ac=bench_track.AC)
best = float("inf")
for _ in range(3):
    c0 = time.process_time()
    m.force(x, out=buf)
    best = min(best, time.process_time() - c0)
print(json.dumps({"parts": {k: v[1] for k, v in stats.items()}, "cpu": cpu, "wall": wall,
                  "kernel": best, "n": int(x.size)}))
"""


def run(tree: Path | None, path: Path) -> dict:
    env = dict(os.environ)
    if tree is not None:
        env["PYTHONPATH"] = str(tree)
    out = subprocess.run(
        [sys.executable, "-c", _CHILD, str(path), str(ROOT / "benches")],
        env=env,
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    return json.loads(out.strip().splitlines()[-1])


def report(runs: dict[str, list[dict]], names: list[str]) -> None:
    n = runs[names[0]][0]["n"]
    med = {
        k: {
            "cpu": float(np.median([r["cpu"] for r in v])),
            "kernel": float(np.median([r["kernel"] for r in v])),
            "parts": {
                p: float(np.median([r["parts"].get(p, 0.0) for r in v]))
                for p in sorted({p for r in v for p in r["parts"]})
            },
        }
        for k, v in runs.items()
    }
    for k in names:
        med[k]["parts"]["the rest (interpreter)"] = med[k]["cpu"] - sum(med[k]["parts"].values())
    all_parts = sorted(
        {p for k in names for p in med[k]["parts"]},
        key=lambda p: -med[names[-1]]["parts"].get(p, 0),
    )
    rounds = len(runs[names[0]])
    print(
        f"\n{n:.0e} samples, serial track as `analyze --json` runs it, medians of {rounds} "
        f"interleaved rounds by CPU; load {os.getloadavg()[0]:.1f}\n"
    )
    head = " | ".join(f"{k}: CPU s (ns/sample)" for k in names)
    print(f"| part | {head} | after/before |")
    print("|---|" + "---|" * len(names) + "---|")
    for p in [*all_parts, "total"]:
        vals = [med[k]["cpu"] if p == "total" else med[k]["parts"].get(p, 0.0) for k in names]
        cells = " | ".join(f"{v:.3f} ({v / n * 1e9:.2f})" for v in vals)
        ratio = f"{vals[-1] / vals[0]:.3f}" if vals[0] > 0 else "-"
        print(f"| {'**total**' if p == 'total' else f'`{p}`'} | {cells} | {ratio} |")
    for k in names:
        kern = n / med[k]["kernel"]
        ours = n / med[k]["cpu"]
        print(
            f"\n{k}: {ours / 1e6:.1f} M samples per CPU-s against the Masing kernel's "
            f"{kern / 1e6:.0f} M/s (same process): {ours / kern:.3f} of the kernel"
        )
    per_round = [runs[names[-1]][i]["cpu"] / runs[names[0]][i]["cpu"] for i in range(rounds)]
    print(
        f"\nafter/before total CPU by round: {' '.join(f'{v:.3f}' for v in per_round)} "
        f"(lower in {sum(v < 1 for v in per_round)} of {rounds})"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", type=Path, required=True)
    ap.add_argument("--samples", type=float, default=3e7)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--recording", type=Path)
    args = ap.parse_args()
    import bench_track

    with tempfile.TemporaryDirectory(prefix="contactlab-bench-ab-") as d:
        path = args.recording
        if path is None:
            path = Path(d) / "rec.h5"
            bench_track.write_file(path, int(args.samples))
        names = ["before", "after"]
        trees = {"before": args.baseline, "after": None}
        runs: dict[str, list[dict]] = {k: [] for k in names}
        for i in range(args.rounds):
            order = names if i % 2 == 0 else names[::-1]
            for k in order:
                runs[k].append(run(trees[k], path))
            print(
                f"round {i + 1}: " + ", ".join(f"{k} {runs[k][-1]['cpu']:.3f}" for k in names),
                flush=True,
            )
        report(runs, names)


if __name__ == "__main__":
    main()
