"""Where a streamed ``analyze`` spends its CPU, and whether a second thread can pay on this
machine (issue 33 item 4: ``analyze`` at 0.3 of the Masing kernel; why "all cores" gave no
wall-clock gain over one).

Two measurements, both in this process:

- ``--parts`` (default): :func:`contactlab.studies.tracking.track` of a long HDF5 recording
  (``bench_track.write_file``, the recording of ``bench_analyze.py``) as ``contactlab
  analyze`` runs it (``"auto"`` windows, window documents kept, the allocator settings of the
  command line), with every per-sample kernel of the chain wrapped: its CPU time (the calling
  thread's), ns a sample of the recording, its share of the process's CPU and the minor page
  faults it took (a part's figures exclude the wrapped parts it calls). The window's analysis
  after the fold (``tangential.window._analyze``: the fits, covariances, lag, in Python) is a
  part of its own, and so are the streamed window's detrending pass
  (``detrend_pair_scan_uniform_into``) and the reader's ``os.preadv`` calls (the copy from
  the page cache); what is left is the interpreter's other work (reversals' and knots'
  bookkeeping, windows, the reader's Python). The track runs as ``analyze --json`` runs it, without
  the per-cycle table (``track(cycles=False)``) where the tree under test has that.
  Run serially (``threads=0``) and with two helper threads (the
  command line's default on two CPUs): the difference of the process's CPU is what the
  threads cost.
- ``--scaling``: two threads of the same kernel at once against one after the other, for a
  compute-bound kernel (``Masing.force`` on a window in cache: 16 bytes a sample at
  ~8 ns) and a memory-bound one (``detrend_pair_scan_into``: 40 bytes a sample at ~3 ns).
  Both release the interpreter lock. ``speedup`` = the time of the two calls one after the
  other over the time of the two at once (2.0: two cores; ~1.0: the second thread gains
  nothing); ``CPU/wall`` how many CPUs the process got. On an idle machine this tells
  whether the two CPUs are two cores (both kernels near 2), share a core (the compute-bound
  kernel near 1.0-1.3) or share a memory path (only the memory-bound one near 1). Under
  load it measures the scheduler: Linux's autogroup shares CPU time between sessions, not
  threads, so a process's second thread gets nothing while other sessions keep both CPUs
  busy (``/proc/sys/kernel/sched_autogroup_enabled``).

Run: ``nice .venv/bin/python benches/bench_analyze_parts.py [--parts] [--scaling]
[--samples 3e7] [--rounds 3] [--threads 0 2]`` (``--threads 0``: the serial run only; another
tree's package with ``PYTHONPATH=<its python/ folder, built>``).
"""

from __future__ import annotations

import argparse
import os
import resource
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benches"))

import bench_track  # noqa: E402

#: the per-sample kernels of a streamed tangential analysis (reader and windows)
KERNELS = (
    "finite_min_max",
    "fill_time",
    "order_stats",
    "order_stats_trapezoids",
    "period_means_pair",
    "detrend_pair_scan_into",
    "detrend_pair_scan_uniform_into",
    "fold_window",
)


#: per thread, the CPU seconds and faults of the wrapped calls nested in the open ones
_NESTED = threading.local()


def _wrapped(f: Any, name: str, stats: dict[str, list[float]]) -> Any:
    """``f`` counting its calls, the calling thread's CPU seconds and minor faults, less
    those of wrapped calls made inside it (each part counted once)."""

    def run(*a: Any, **k: Any) -> Any:
        stack = _NESTED.__dict__.setdefault("stack", [])
        stack.append([0.0, 0])
        r0 = resource.getrusage(resource.RUSAGE_THREAD)
        c0 = time.thread_time()
        try:
            return f(*a, **k)
        finally:
            c = time.thread_time() - c0
            fl = resource.getrusage(resource.RUSAGE_THREAD).ru_minflt - r0.ru_minflt
            inner_c, inner_f = stack.pop()
            if stack:
                stack[-1][0] += c
                stack[-1][1] += fl
            s = stats.setdefault(name, [0, 0.0, 0])
            s[0] += 1
            s[1] += c - inner_c
            s[2] += fl - inner_f

    return run


def parts(path: Path, threads: int) -> tuple[dict[str, list[float]], float, float, int]:
    """Per-kernel [calls, CPU s, minor faults], the process's CPU and wall seconds and its
    minor faults over one ``track`` of ``path``."""
    import inspect

    from contactlab import _core
    from contactlab.reversals import ReversalDetector
    from contactlab.studies import tracking
    from contactlab.tangential import window

    stats: dict[str, list[float]] = {}
    # (a kernel the tree under test does not have is left out: A/B runs of an older build)
    saved: list[tuple[Any, str, Any]] = [
        (_core, k, getattr(_core, k)) for k in KERNELS if hasattr(_core, k)
    ]
    # the two stateful kernels: the reversal detector's pass (both of a window) and the
    # reader's cycle tracker (one pass a block, checks x and F finite too)
    saved += [
        (ReversalDetector, "push", ReversalDetector.push),
        (tracking, "block_cycles", tracking.block_cycles),
        # the window's analysis after the fold, in Python (fits, covariances, lag, derived
        # quantities; the Rust calls it makes are counted inside it)
        (window, "_analyze", window._analyze),
        # the reader's reads into the window's buffers (HDF5 read in place)
        (os, "preadv", os.preadv),
    ]
    for obj, k, f in saved:
        label = {
            "push": "ReversalDetector.push",
            "block_cycles": "CycleStream (block_cycles)",
            "_analyze": "window analysis in Python (_analyze)",
            "preadv": "os.preadv (the reader's reads)",
        }
        setattr(obj, k, _wrapped(f, label.get(k, k), stats))
    # as ``analyze --json`` runs it: without the per-cycle table where the tree can (the
    # crossings that cut the windows only; older trees compute the table)
    extra = {"cycles": False} if "cycles" in inspect.signature(tracking.track).parameters else {}
    try:
        r0 = resource.getrusage(resource.RUSAGE_SELF)
        t0, c0 = time.perf_counter(), time.process_time()
        tracking.track(
            path, "auto", kind="tangential", keep_documents=True, threads=threads, **extra
        )
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        r1 = resource.getrusage(resource.RUSAGE_SELF)
    finally:
        for obj, k, f in saved:
            setattr(obj, k, f)
    return stats, cpu, wall, r1.ru_minflt - r0.ru_minflt


def print_parts(n: int, rounds: int, threads_list: tuple[int, ...] = (0, 2)) -> None:
    from contactlab._malloc import keep_freed_memory

    keep_freed_memory()  # as the command line
    with tempfile.TemporaryDirectory(prefix="contactlab-bench-parts-") as d:
        path = Path(d) / "rec.h5"
        bench_track.write_file(path, n)
        parts(path, 0)  # warm: imports, the file in the page cache
        for threads in threads_list:
            runs = [parts(path, threads) for _ in range(rounds)]
            k = int(np.argsort([r[1] for r in runs])[len(runs) // 2])  # the median run by CPU
            stats, cpu, wall, faults = runs[k]
            print(
                f"\n### threads={threads}: {n:.0e} samples, median of {rounds} runs by CPU: "
                f"{cpu:.2f} s CPU ({cpu / n * 1e9:.1f} ns/sample), {wall:.2f} s wall, "
                f"{faults} minor faults; load {os.getloadavg()[0]:.1f}\n"
            )
            print("| part | calls | CPU s | ns/sample | share of CPU | minor faults |")
            print("|---|---|---|---|---|---|")
            total = 0.0
            for name, (calls, c, fl) in sorted(stats.items(), key=lambda kv: -kv[1][1]):
                total += c
                print(
                    f"| `{name}` | {int(calls)} | {c:.3f} | {c / n * 1e9:.2f} | "
                    f"{100 * c / cpu:.1f} % | {int(fl)} |"
                )
            rest = cpu - total
            print(
                f"| the rest (interpreter: reversals, knots, windows, bookkeeping) | | "
                f"{rest:.3f} | {rest / n * 1e9:.2f} | "
                f"{100 * rest / cpu:.1f} % | |"
            )


def _timed_pair(fn: Any, k0: int, k1: int) -> tuple[float, float, float, float]:
    """(wall, CPU) of fn(k0); fn(k1) one after the other, then of the two in threads."""
    t0, c0 = time.perf_counter(), time.process_time()
    fn(k0)
    fn(k1)
    w1, c1 = time.perf_counter() - t0, time.process_time() - c0
    ts = [threading.Thread(target=fn, args=(k,)) for k in (k0, k1)]
    t0, c0 = time.perf_counter(), time.process_time()
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    return w1, c1, time.perf_counter() - t0, time.process_time() - c0


def print_scaling(rounds: int) -> None:
    import contactlab
    from contactlab import _core

    n = 1 << 20
    rng = np.random.default_rng(7)
    xs = [np.cumsum(rng.standard_normal(n)) * 1e-7 for _ in range(2)]
    fs = [x * 4e5 + rng.standard_normal(n) for x in xs]
    t = np.arange(n) * 1e-4
    m = contactlab.Masing(h0=40.0, ac=4e4)
    bufs = [np.empty(n) for _ in range(4)]

    def masing(k: int) -> None:
        for _ in range(8):
            m.force(xs[k], out=bufs[k])

    def detrend(k: int) -> None:
        for _ in range(30):
            _core.detrend_pair_scan_into(
                t, 50.0, fs[k], 1e-3, xs[k], 1e-9, bufs[2 * k], bufs[2 * k + 1], []
            )

    auto = Path("/proc/sys/kernel/sched_autogroup_enabled")
    group = auto.read_text().strip() if auto.exists() else "n/a"
    print(
        f"\n### two threads at once against one after the other ({rounds} rounds, medians; "
        f"load {os.getloadavg()[0]:.1f}, {os.cpu_count()} CPUs, autogroup {group})\n"
    )
    head = "| kernel | one after the other: wall, CPU/wall | two at once: wall, CPU/wall |"
    print(head + " speedup |")
    print("|---|---|---|---|")
    for name, fn in (
        ("`Masing.force`, 2^20 samples x 8 (compute-bound)", masing),
        ("`detrend_pair_scan_into`, 2^20 samples x 30 (memory-bound)", detrend),
    ):
        fn(0)
        r = np.array([_timed_pair(fn, 0, 1) for _ in range(rounds)])
        w1, c1, w2, c2 = np.median(r, axis=0)
        print(f"| {name} | {w1:.3f} s, {c1 / w1:.2f} | {w2:.3f} s, {c2 / w2:.2f} | {w1 / w2:.2f} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--parts", action="store_true", help="CPU by kernel (the default)")
    ap.add_argument("--scaling", action="store_true", help="two threads against one")
    ap.add_argument("--samples", type=float, default=3e7)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--threads", type=int, nargs="+", default=[0, 2], help="runs of --parts")
    args = ap.parse_args()
    if args.scaling:
        print_scaling(args.rounds)
    if args.parts or not args.scaling:
        print_parts(int(args.samples), args.rounds, tuple(args.threads))


if __name__ == "__main__":
    main()
