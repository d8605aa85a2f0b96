"""Many channels on all cores: one core vs Rust threads inside one call vs Python threads and
processes over the GIL-free kernel, measured in the same run.

Eight channels of band-limited noise (1e6 samples each by default) through the Masing operator:

- serial: ``Masing.force`` channel after channel (one core);
- rust threads: ``contactlab.force_many(model, channels, threads=cores)``;
- python threads: a ``ThreadPoolExecutor`` calling ``Masing.force`` (the GIL is released in
  the kernel);
- python processes: a ``ProcessPoolExecutor`` (arrays pickled to the workers and back).

The modes run in turn, ``--repeat`` times, in a rotating order (so that a change of load hits
them alike). For each repeat the wall speed-up of a mode is serial / mode of that repeat; the
report gives its median over the repeats and the ratio of the best times (min / min). The
requirement is >= 1.9x on 2 cores.

The machine may be shared, so wall time alone says little. Each mode's CPU time is measured
too (this process's threads; for the process pool, each worker reports its own), giving:

- ``work``: CPU seconds of the mode / CPU seconds of serial (1.0: parallelism adds no work);
- ``busy``: CPU seconds / wall seconds of the mode (how many cores it actually had);
- ``cpu speed-up``: cores x serial CPU / mode CPU, the speed-up on idle cores if the work is
  spread evenly (what the wall speed-up tends to when nothing else runs).

The load average and ``uptime`` are printed before and after.
Run: ``.venv/bin/python benches/bench_parallel.py [--channels 8] [--n 1000000] [--repeat 9]``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import time
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

import numpy as np
from scipy import signal

import contactlab

MODEL = contactlab.Masing(40.0, 4.0e4)


def _force(x: np.ndarray) -> np.ndarray:
    return MODEL.force(x)


def _force_timed(x: np.ndarray) -> tuple[np.ndarray, float]:
    """In a worker process: the forces and the CPU seconds they took there."""
    c0 = time.process_time()
    f = MODEL.force(x)
    return f, time.process_time() - c0


def channels(k: int, n: int) -> list[np.ndarray]:
    rng = np.random.default_rng(3)
    sos = signal.butter(4, 1 / 25, output="sos")
    out = []
    for _ in range(k):
        v = signal.sosfilt(sos, rng.uniform(-0.5, 0.5, n))
        out.append(np.ascontiguousarray(v * 20e-6 / np.sqrt(np.mean(v**2))))
    return out


def uptime() -> str:
    try:
        return subprocess.run(["uptime"], capture_output=True, text=True, check=False).stdout
    except OSError:
        return "load average " + ", ".join(f"{a:.2f}" for a in os.getloadavg()) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--channels", type=int, default=8)
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=9)
    args = ap.parse_args()
    cores = os.cpu_count() or 1
    before = uptime()
    xs = channels(args.channels, args.n)
    ref = [_force(x) for x in xs]
    with ThreadPoolExecutor(cores) as tp, ProcessPoolExecutor(cores) as pp:
        list(pp.map(_force, xs[:cores]))  # start the workers outside the timing

        def processes() -> tuple[list[np.ndarray], float]:
            done = list(pp.map(_force_timed, xs))
            return [f for f, _ in done], sum(c for _, c in done)

        runs = {
            "serial (one core)": lambda: [_force(x) for x in xs],
            "rust threads": lambda: contactlab.force_many(MODEL, xs, threads=cores),
            "python threads": lambda: list(tp.map(_force, xs)),
            "python processes": processes,
        }
        names = list(runs)
        wall: dict[str, list[float]] = {k: [] for k in names}
        cpu: dict[str, list[float]] = {k: [] for k in names}
        for r in range(args.repeat):
            for name in names[r % len(names) :] + names[: r % len(names)]:
                t0, c0 = time.perf_counter(), time.process_time()
                out = runs[name]()
                dt, dc = time.perf_counter() - t0, time.process_time() - c0
                if isinstance(out, tuple):  # the pool's workers report their own CPU time
                    out, dc = out[0], dc + out[1]
                wall[name].append(dt)
                cpu[name].append(dc)
                assert all(np.array_equal(a, b) for a, b in zip(out, ref, strict=True)), name
                del out
    after = uptime()
    total = args.channels * args.n
    print(
        f"{args.channels} channels x {args.n:.0e} samples, {cores} cores, {args.repeat} "
        "interleaved repeats (rotating order)"
    )
    print(f"before: {before.strip()}\nafter:  {after.strip()}")
    s_wall, s_cpu = wall[names[0]], cpu[names[0]]
    print(
        f"{'mode':<19}{'Ms/s':>7}{'speed-up med':>14}{'min/min':>9}{'work':>7}{'busy':>7}"
        f"{'cpu speed-up':>14}"
    )
    for name in names:
        w, c = wall[name], cpu[name]
        med = statistics.median(a / b for a, b in zip(s_wall, w, strict=True))
        mm = min(s_wall) / min(w)
        work = statistics.median(c) / statistics.median(s_cpu)
        busy = statistics.median(a / b for a, b in zip(c, w, strict=True))
        cpu_up = cores * statistics.median(s_cpu) / statistics.median(c)
        if name == names[0]:
            cpu_up = 1.0
        print(
            f"{name:<19}{total / min(w) / 1e6:7.1f}{med:13.2f}x{mm:8.2f}x{work:7.2f}{busy:7.2f}"
            f"{cpu_up:13.2f}x"
        )


if __name__ == "__main__":
    main()
