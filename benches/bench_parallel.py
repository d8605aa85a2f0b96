"""Many channels on all cores: one core vs Rust threads inside one call vs Python threads and
processes over the GIL-free kernel, measured in the same run (interleaved, best of repeats).

Eight channels of band-limited noise (1e6 samples each by default) through the Masing operator:

- serial: ``Masing.force`` channel after channel (one core);
- rust threads: ``contactlab.force_many(model, channels, threads=cores)``;
- python threads: a ``ThreadPoolExecutor`` calling ``Masing.force`` (the GIL is released in
  the kernel);
- python processes: a ``ProcessPoolExecutor`` (arrays pickled to the workers and back).

Prints each speed-up over serial; the requirement is >= 1.9x on 2 cores. For the in-process
modes it also prints the CPU time relative to serial (1.0 means no work added: on idle cores
the speed-up is then the thread count, less any imbalance). Unlike a ratio of two
single-core timings, this figure depends on what else the machine runs: the load average is
printed before and after (the run is only meaningful on an otherwise idle machine).
Run: ``.venv/bin/python benches/bench_parallel.py [--channels 8] [--n 1000000]``.
"""

from __future__ import annotations

import argparse
import os
import time
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

import numpy as np
from scipy import signal

import contactlab

MODEL = contactlab.Masing(40.0, 4.0e4)


def _force(x: np.ndarray) -> np.ndarray:
    return MODEL.force(x)


def channels(k: int, n: int) -> list[np.ndarray]:
    rng = np.random.default_rng(3)
    sos = signal.butter(4, 1 / 25, output="sos")
    out = []
    for _ in range(k):
        v = signal.sosfilt(sos, rng.uniform(-0.5, 0.5, n))
        out.append(np.ascontiguousarray(v * 20e-6 / np.sqrt(np.mean(v**2))))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--channels", type=int, default=8)
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    cores = os.cpu_count() or 1
    load_before = os.getloadavg()
    xs = channels(args.channels, args.n)
    ref = [_force(x) for x in xs]
    with ThreadPoolExecutor(cores) as tp, ProcessPoolExecutor(cores) as pp:
        list(pp.map(_force, xs[:cores]))  # start the workers outside the timing
        runs = {
            "serial (one core)": lambda: [_force(x) for x in xs],
            "rust threads": lambda: contactlab.force_many(MODEL, xs, threads=cores),
            "python threads": lambda: list(tp.map(_force, xs)),
            "python processes": lambda: list(pp.map(_force, xs)),
        }
        best = dict.fromkeys(runs, np.inf)
        cpu = dict.fromkeys(runs, np.inf)
        for _ in range(args.repeat):
            for name, f in runs.items():
                t0, c0 = time.perf_counter(), time.process_time()
                out = f()
                best[name] = min(best[name], time.perf_counter() - t0)
                cpu[name] = min(cpu[name], time.process_time() - c0)
                assert all(np.array_equal(a, b) for a, b in zip(out, ref, strict=True)), name
                del out
    total = args.channels * args.n
    print(f"{args.channels} channels x {args.n:.0e} samples, {cores} cores, best of {args.repeat}")
    load = ", ".join(f"{a:.2f}" for a in load_before + os.getloadavg())
    print(f"load average (1, 5, 15 min) before and after: {load}")
    serial, serial_cpu = best["serial (one core)"], cpu["serial (one core)"]
    for name, t in best.items():
        # CPU seconds of this process (all its threads; the process pool's workers are not
        # counted): their ratio to serial is the work parallelism adds, whatever the load.
        extra = "" if "processes" in name else f"   CPU {cpu[name] / serial_cpu:5.2f}x serial"
        print(f"{name:<20}{total / t / 1e6:8.1f} Ms/s   speed-up {serial / t:5.2f}x{extra}")


if __name__ == "__main__":
    main()
