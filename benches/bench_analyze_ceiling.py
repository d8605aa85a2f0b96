"""How far streamed ``contactlab analyze`` could get toward 0.3 of the Masing kernel (issue
33 item 4) if parts of it cost nothing: measurement only, no result of these runs is used.

The bar (``bench_analyze.py``, ``speed_table.py``): ``contactlab analyze FILE --json OUT`` of
a long HDF5 recording at >= 0.3 of the Masing kernel's throughput in the same run. Where the
time goes was measured (``bench_analyze_parts.py``); this bench asks what each remaining block
is worth, by removing it in a child process and timing the rest, in the same interleaved
rounds as the kernel and the real command:

- ``analyze``: the command as a user runs it (new process; all cores, default helper
  threads), wall and CPU (user + system, ``os.wait4``);
- ``no window fit``: the same command with the per-window analysis after the fold
  (``contactlab.tangential.window._analyze``: the least-squares fits, covariances, lag,
  derived quantities) run for the first window only and its result reused for every later
  window: what a free fit would leave (the reading, the cycle tracker and every per-sample
  Rust kernel still run on every window);
- ``imports only``: a new process importing the modules a streamed tangential ``analyze``
  imports (numpy, h5py, contactlab's), and nothing else: the command's fixed start-up;
- ``warm track``: ``track`` of the file a second time in one process (imports done, memory
  already faulted in): the per-sample part alone.

Ratio = (samples / time) / (kernel samples / kernel time), by CPU and by wall; the bar is 0.3.
A row whose ratio stays under 0.3 says that removing that block alone cannot reach the bar.

Run: ``nice .venv/bin/python benches/bench_analyze_ceiling.py [--samples 1e7 3e7]
[--rounds 5]`` (about 1 CPU-minute at the defaults).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benches"))

import bench_track  # noqa: E402

#: the command line with the per-window analysis after the fold memoised (first window's)
NO_FIT = """
import sys
import contactlab.tangential.window as W
real, seen = W._analyze, []
def once(*a, **k):
    if not seen:
        seen.append(real(*a, **k))
    return seen[0]
W._analyze = once
from contactlab.cli import main
sys.exit(main(["analyze", sys.argv[1], "--json", sys.argv[2]]))
"""

#: the modules of a streamed tangential analyze, imported and nothing run
IMPORTS = """
import numpy, h5py
import contactlab.cli, contactlab.commands.analyze, contactlab.io.hdf5
import contactlab.studies.tracking, contactlab.studies.pooled, contactlab.tangential.window
"""

#: the second track of the file in one process: CPU seconds on stdout
WARM = """
import sys, time
from contactlab._malloc import keep_freed_memory
from contactlab.studies.tracking import track
keep_freed_memory()
track(sys.argv[1], "auto", kind="tangential", keep_documents=True, threads=0)
c0 = time.process_time()
track(sys.argv[1], "auto", kind="tangential", keep_documents=True, threads=0)
print(time.process_time() - c0)
"""


def run_child(cmd: list[str]) -> tuple[float, float, str]:
    """Wall and CPU (user + system of the process and its threads) of a child process."""
    t0 = time.perf_counter()
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
    assert p.stdout is not None
    out = p.stdout.read()
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"{cmd[:3]} failed with status {status}")
    return wall, usage.ru_utime + usage.ru_stime, out.decode()


def measure(path: Path, rounds: int, tmp: Path) -> dict[str, list[float]]:
    import h5py

    import contactlab

    with h5py.File(path, "r") as f:
        x = f["x"][:]
    m = contactlab.Masing(h0=bench_track.H0, ac=bench_track.AC)
    buf = np.empty_like(x)
    py = sys.executable
    out = str(tmp / "out.json")
    t: dict[str, list[float]] = {}

    def add(key: str, wall: float, cpu: float) -> None:
        t.setdefault(key, []).append(wall)
        t.setdefault(f"{key}_cpu", []).append(cpu)

    def kernel() -> None:
        t0, c0 = time.perf_counter(), time.thread_time()
        m.force(x, out=buf)
        add("kernel", time.perf_counter() - t0, time.thread_time() - c0)

    def analyze() -> None:
        w, c, _ = run_child([py, "-m", "contactlab", "analyze", str(path), "--json", out])
        add("analyze", w, c)

    def no_fit() -> None:
        w, c, _ = run_child([py, "-c", NO_FIT, str(path), out])
        add("no window fit", w, c)

    def imports() -> None:
        w, c, _ = run_child([py, "-c", IMPORTS])
        add("imports only", w, c)

    def warm() -> None:
        *_, text = run_child([py, "-c", WARM, str(path)])
        add("warm track", float("nan"), float(text.split()[-1]))

    steps = [kernel, analyze, no_fit, imports, warm]
    m.force(x, out=buf)  # warm-up
    for r in range(rounds):
        k = r % len(steps)
        for f in steps[k:] + steps[:k]:
            f()
    return t


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=float, nargs="+", default=[1e7, 3e7])
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args()
    print(
        f"load {', '.join(f'{a:.2f}' for a in os.getloadavg())}; {os.cpu_count()} CPUs; "
        f"medians of {args.rounds} interleaved rounds"
    )
    print("| samples | run | wall s | CPU s | ns/sample (CPU) | ratio to the kernel: wall, CPU |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory(prefix="contactlab-bench-ceiling-") as d:
        tmp = Path(d)
        for n in (int(s) for s in args.samples):
            path = tmp / f"t{n:.0e}.h5"
            bench_track.write_file(path, n)
            t = measure(path, args.rounds, tmp)
            path.unlink()
            med = {k: float(np.median(v)) for k, v in t.items()}
            kw, kc = med["kernel"], med["kernel_cpu"]
            for key in ("kernel", "analyze", "no window fit", "imports only", "warm track"):
                w, c = med[key], med[f"{key}_cpu"]
                ratio = "" if key == "imports only" else f"{kw / w:.2f}, {kc / c:.2f}"
                ratio = ratio.replace("nan", "-")
                print(f"| {n:.0e} | {key} | {w:.3f} | {c:.3f} | {c / n * 1e9:.1f} | {ratio} |")
            # the fixed part of a run and what 0.3 leaves for the samples
            fixed = med["analyze_cpu"] - med["warm track_cpu"]
            budget = kc / 0.3 - fixed
            print(
                f"| {n:.0e} | the command's fixed CPU (analyze - warm track) | | {fixed:.3f} | | "
                f"0.3 of the kernel leaves {budget:.3f} s CPU = {budget / n * 1e9:.1f} ns a "
                f"sample for the per-sample work (warm track: "
                f"{med['warm track_cpu'] / n * 1e9:.1f}) |"
            )


if __name__ == "__main__":
    main()
