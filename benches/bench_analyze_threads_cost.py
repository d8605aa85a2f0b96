"""What the helper threads of a streamed ``contactlab analyze`` cost in CPU, and where (issue 33
items 4 and 5): ``contactlab analyze FILE --json OUT`` as a new process with
``CONTACTLAB_ANALYZE_THREADS`` = each of ``--threads`` (default 0 and 2), interleaved round by
round, from the child's ``os.wait4`` usage: wall, CPU (user + system), user, system, minor
page faults (a fault on a transparent huge page counts once), peak RSS; medians of
``--rounds``. The JSON of every run is compared byte for byte with the first.

The system time is mostly the kernel zeroing memory the process touches for the first time
(``perf record -e cpu-clock``: ``clear_page_erms`` under ``preadv`` into the window arrays
and under the Rust passes writing fresh output arrays); it grows with the peak footprint
(more windows in flight with threads) and varies several-fold from run to run on a VM (the
host backing the pages). ``--baseline DIR`` also runs another tree's ``python/`` folder
(built, ``PYTHONPATH=DIR``) in the same rounds, as ``bench_analyze.py`` does.

Run: ``nice .venv/bin/python benches/bench_analyze_threads_cost.py [--recording FILE |
--samples 3e7] [--rounds 7] [--threads 0 2] [--baseline DIR]``.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benches"))

import bench_track  # noqa: E402

FIELDS = ("wall", "cpu", "user", "sys", "minflt", "rss_mb")


def run(recording: Path, out: Path, threads: int, tree: Path | None) -> tuple[float, ...]:
    env = dict(os.environ, CONTACTLAB_ANALYZE_THREADS=str(threads))
    if tree is not None:
        env["PYTHONPATH"] = str(tree)
    cmd = [sys.executable, "-m", "contactlab", "analyze", str(recording), "--json", str(out)]
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL)
    _pid, status, ru = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    if status != 0:
        raise SystemExit(f"{cmd} failed ({status})")
    return (
        wall,
        ru.ru_utime + ru.ru_stime,
        ru.ru_utime,
        ru.ru_stime,
        float(ru.ru_minflt),
        ru.ru_maxrss / 1024,
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--recording", type=Path, help="an HDF5 recording (else one is written)")
    ap.add_argument("--samples", type=float, default=3e7)
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--threads", type=int, nargs="+", default=[0, 2])
    ap.add_argument("--baseline", type=Path, help="another tree's python/ folder, run alike")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        recording = args.recording
        if recording is None:
            recording = folder / "recording.h5"
            bench_track.write_file(recording, int(args.samples))
        trees: list[tuple[str, Path | None]] = [("this tree", None)]
        if args.baseline is not None:
            trees.append(("baseline", args.baseline.resolve()))
        confs = [(label, tree, n) for label, tree in trees for n in args.threads]
        got: dict[tuple[str, int], list[tuple[float, ...]]] = {}
        digests: dict[tuple[str, int], set[str]] = {}
        for _ in range(args.rounds):
            for label, tree, n in confs:
                out = folder / f"out_{len(got)}.json"
                got.setdefault((label, n), []).append(run(recording, out, n, tree))
                digests.setdefault((label, n), set()).add(hashlib.md5(out.read_bytes()).hexdigest())
    print(
        f"`contactlab analyze --json` of {recording.name}; medians of {args.rounds} "
        f"interleaved rounds; load {os.getloadavg()[0]:.2f} after the runs"
    )
    print("| tree | threads | " + " | ".join(FIELDS) + " | JSON md5 |")
    print("|---|---|" + "---|" * len(FIELDS) + "---|")
    for (label, n), values in got.items():
        med = [statistics.median(c) for c in zip(*values, strict=True)]
        cells = " | ".join(
            f"{v:.0f}" if f == "minflt" else f"{v:.3f}" for f, v in zip(FIELDS, med, strict=True)
        )
        print(f"| {label} | {n} | {cells} | {', '.join(sorted(digests[(label, n)]))} |")


if __name__ == "__main__":
    main()
