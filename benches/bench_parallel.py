"""Many channels on all cores: one core vs Rust threads inside one call vs Python threads and
processes over the GIL-free kernel, measured in interleaved pairs in the same run.

Eight channels of band-limited noise (1e6 samples each by default) through the Masing operator.
Each parallel mode is paired with the serial run it is compared with (``Masing.force`` channel
after channel on one core), the two run back to back in alternating order, ``--repeat`` times,
the modes in a rotating order:

- rust threads: ``contactlab.force_many(model, channels, threads=cores)``, new output arrays
  (as serial ``Masing.force``): the channels that balancing needs are cut into pieces of 2^16
  samples after a comparisons-only pre-pass, and pieces and whole channels share one queue;
- rust threads, whole channels: the same with nothing split (a piece longer than any channel;
  the scheme before the pre-pass), out reused;
- rust threads, out reused: the same into output arrays given with ``out=`` (paired with serial
  ``Masing.force(x, out=buf)``): no fresh output pages, so the first-touch page clearing, which
  on this VM is sometimes ten times slower than usual, is out of both sides;
- python threads: a ``ThreadPoolExecutor`` calling ``Masing.force`` (GIL released in the
  kernel);
- python processes: a ``ProcessPoolExecutor`` (arrays pickled to the workers and back;
  ``--no-processes`` skips them).

A ``ceiling`` row is what the machine itself allows: the same kernel with no memory traffic and
nothing shared (``_core.force_repeat``: independent jobs, each the force of one 16384-sample
signal, in cache, computed over and over into the job's own buffer; as many samples in all as
the channels), one thread vs all cores, interleaved pairs likewise. A mode's speed-up divided by
the ceiling's (``of ceiling``, medians) is the part of the machine's scaling the code delivers;
what is left below the requirement beyond that is the machine's (a shared VM's cores slow each
other down: frequency, cache, memory).

A last row (``--long``, default 1e8 samples; 0 skips it) is ONE channel: ``force_many`` on one
thread vs on all cores, outputs reused, interleaved pairs likewise: the pre-pass and the pieces
alone carry the scaling there.

The allocator is set as the command-line interface sets it (``contactlab._malloc.
keep_freed_memory``: freed arrays of up to 32 MB stay in the process for reuse), on both sides of
every pair: with glibc's defaults each fresh 32 MB output is mapped anew and page-faulted, and on
this VM such faults sometimes cost ten times the usual (memory the host must back again), which
made the fresh-output modes' pairs scatter from 0.4x to 6x (``python threads`` reached a median
of 3x against 1.5-1.9x with the memory kept). ``--glibc-defaults`` leaves the allocator alone.

For each mode: the speed-up of each pair (serial wall / mode wall), their median, quartiles and
range (the spread of the paired ratios), and the ratio of the best times (min / min); the
requirement is >= 1.9x on 2 cores. ``prepass`` is the pre-pass's CPU as a share of the paired
serial run's CPU (what splitting costs: the wall speed-up cannot exceed cores / (1 + prepass)). CPU
time (this process's threads; the pool's workers report their own) gives ``work`` (mode CPU /
serial CPU of the pair: 1.0 when parallelism adds no work) and ``cpu speed-up`` (cores x serial CPU
/ mode CPU: what the wall speed-up tends to on idle cores with an even split). For the Rust threads
the core reports each worker's jobs, start, end, CPU and run-queue wait (``stats=``): ``imbal`` is
(last end - first end) / wall, ``start`` the latest thread start, ``wait`` the summed time the
workers were runnable without a CPU (other load), ``idle`` the part of the mode's wall x threads
during which its workers were not on a CPU. ``uptime`` is printed before and after.
Run: ``.venv/bin/python benches/bench_parallel.py [--channels 8] [--n 4000000] [--repeat 21]
[--long 1e8]``.
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
from contactlab import _core

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
    ap.add_argument("--repeat", type=int, default=21)
    ap.add_argument(
        "--long", type=float, default=1e8, help="samples of the one-channel row (0: none)"
    )
    ap.add_argument("--no-processes", action="store_true")
    ap.add_argument(
        "--glibc-defaults", action="store_true", help="leave the allocator's thresholds alone"
    )
    args = ap.parse_args()
    if not args.glibc_defaults:
        from contactlab._malloc import keep_freed_memory

        keep_freed_memory()
    cores = os.cpu_count() or 1
    before = uptime()
    xs = channels(args.channels, args.n)
    ref = [_force(x) for x in xs]
    bufs = [np.zeros(x.size) for x in xs]
    pbufs = [np.zeros(x.size) for x in xs]
    stats: dict[str, list[list[dict]]] = {}

    wbufs = [np.zeros(x.size) for x in xs]

    def rust(name: str, out: list[np.ndarray] | None) -> list[np.ndarray]:
        st: list[dict] = []
        res = contactlab.force_many(MODEL, xs, threads=cores, out=out, stats=st)
        stats.setdefault(name, []).append(st)
        return res

    def whole() -> list[np.ndarray]:
        # piece longer than any channel: every channel one job (nothing split)
        res, st = _core.force_many(
            [MODEL._core] * len(xs), xs, cores, wbufs, True, max(x.size for x in xs) + 1
        )
        keys = ("jobs", "samples", "start", "end", "cpu", "wait", "prepass", "prepass_cpu")
        rows = [{k: getattr(s, k) for k in keys} for s in st]
        stats.setdefault("rust threads, whole channels", []).append(rows)
        return res

    small = channels(1, 16384)[0]
    ceil_jobs = 64 * cores
    ceil_reps = max(1, round(args.channels * args.n / (ceil_jobs * small.size)))

    def ceiling(threads: int, name: str) -> None:
        st = _core.force_repeat(MODEL._core, small, ceil_jobs, ceil_reps, threads)
        keys = ("jobs", "start", "end", "cpu", "wait")
        stats.setdefault(name, []).append([{k: getattr(s, k) for k in keys} for s in st])

    long_x = channels(1, int(args.long)) if args.long >= 1 else []
    long_ref = [_force(x) for x in long_x]
    lbufs = [np.zeros(x.size) for x in long_x]
    lpbufs = [np.zeros(x.size) for x in long_x]

    def long_serial() -> list[np.ndarray]:
        st: list[dict] = []
        res = contactlab.force_many(MODEL, long_x, threads=1, out=lbufs, stats=st)
        stats.setdefault("one channel serial", []).append(st)
        return res

    def long_par() -> list[np.ndarray]:
        st: list[dict] = []
        res = contactlab.force_many(MODEL, long_x, threads=cores, out=lpbufs, stats=st)
        stats.setdefault("one channel", []).append(st)
        return res

    with ThreadPoolExecutor(cores) as tp, ProcessPoolExecutor(cores) as pp:
        list(pp.map(_force, xs[:cores]))  # start the workers outside the timing

        def processes() -> tuple[list[np.ndarray], float]:
            done = list(pp.map(_force_timed, xs))
            return [f for f, _ in done], sum(c for _, c in done)

        def serial() -> list[np.ndarray]:
            return [_force(x) for x in xs]

        def serial_reused() -> list[np.ndarray]:
            return [MODEL.force(x, out=b) for x, b in zip(xs, bufs, strict=True)]

        pairs = {
            "rust threads": (serial, lambda: rust("rust threads", None)),
            "rust threads, out reused": (
                serial_reused,
                lambda: rust("rust threads, out reused", pbufs),
            ),
            "rust threads, whole channels": (serial_reused, whole),
            "python threads": (serial, lambda: list(tp.map(_force, xs))),
            "ceiling (in cache)": (
                lambda: ceiling(1, "ceiling serial"),
                lambda: ceiling(cores, "ceiling (in cache)"),
            ),
        }
        if not args.no_processes:
            pairs["python processes"] = (serial, processes)
        if long_x:
            pairs[f"one channel of {args.long:.0e}"] = (long_serial, long_par)
        names = list(pairs)
        # per mode: [(serial wall, serial cpu, mode wall, mode cpu), ...]
        rec: dict[str, list[tuple[float, float, float, float]]] = {k: [] for k in names}

        def timed(f):
            t0, c0 = time.perf_counter(), time.process_time()
            out = f()
            dt, dc = time.perf_counter() - t0, time.process_time() - c0
            if out is None:  # the ceiling: nothing to compare
                return dt, dc
            if isinstance(out, tuple):  # the pool's workers report their own CPU time
                out, dc = out[0], dc + out[1]
            want = long_ref if len(out) == len(long_ref) and out[0].size != ref[0].size else ref
            assert all(np.array_equal(a, b) for a, b in zip(out, want, strict=True))
            return dt, dc

        for r in range(args.repeat):
            for k, name in enumerate(names[r % len(names) :] + names[: r % len(names)]):
                s_run, m_run = pairs[name]
                if (r + k) % 2 == 0:
                    sw, sc = timed(s_run)
                    mw, mc = timed(m_run)
                else:
                    mw, mc = timed(m_run)
                    sw, sc = timed(s_run)
                rec[name].append((sw, sc, mw, mc))
    after = uptime()
    print(
        f"{args.channels} channels x {args.n:.0e} samples, {cores} cores, {args.repeat} "
        "interleaved pairs per mode (rotating order, alternating within a pair)"
    )
    print(f"before: {before.strip()}\nafter:  {after.strip()}")
    print(
        "allocator: "
        + ("glibc defaults" if args.glibc_defaults else "freed memory kept (as the CLI)")
    )
    med = statistics.median
    print(
        f"{'mode':<29}{'Ms/s':>7}{'serial':>7}{'speed-up med':>13}{'q1-q3':>12}{'range':>12}"
        f"{'min/min':>8}{'work':>6}{'cpu speed-up':>13}{'prepass':>8}{'imbal':>7}"
        f"{'start ms':>9}{'wait ms':>8}{'idle':>6}"
    )
    ceil_up = (
        med(a[0] / a[2] for a in rec["ceiling (in cache)"]) if rec["ceiling (in cache)"] else None
    )
    for name in names:
        total = int(args.long) if name.startswith("one channel") else args.channels * args.n
        if name.startswith("ceiling"):
            total = ceil_jobs * ceil_reps * small.size
        sw, sc, mw, mc = (list(v) for v in zip(*rec[name], strict=True))
        ups = sorted(a / b for a, b in zip(sw, mw, strict=True))
        up = med(ups)
        q = statistics.quantiles(ups, n=4) if len(ups) > 1 else [up, up, up]
        mm = min(sw) / min(mw)
        work = med(b / a for a, b in zip(sc, mc, strict=True))
        cpu_up = cores / work
        key = "one channel" if name.startswith("one channel") else name
        pre = "-"
        if key in stats and all(s.get("prepass_cpu") is not None for st in stats[key] for s in st):
            shares = [
                sum(s["prepass_cpu"] for s in st) / c for st, c in zip(stats[key], sc, strict=True)
            ]
            pre = f"{med(shares):.3f}"
        line = (
            f"{name:<29}{total / min(mw) / 1e6:7.1f}{total / min(sw) / 1e6:7.1f}{up:12.2f}x"
            f"{q[0]:6.2f}-{q[2]:<5.2f}{ups[0]:6.2f}-{ups[-1]:<5.2f}"
            f"{mm:7.2f}x{work:6.2f}{cpu_up:12.2f}x{pre:>8}"
        )
        name = key
        if name in stats:
            imbal, start, wait, idle = [], [], [], []
            for st, wall in zip(stats[name], mw, strict=True):
                ends = [s["end"] for s in st]
                imbal.append((max(ends) - min(ends)) / wall)
                start.append(max(s["start"] for s in st) * 1e3)
                if all(s["cpu"] is not None for s in st):
                    wait.append(sum(s["wait"] for s in st) * 1e3)
                    idle.append(1.0 - sum(s["cpu"] for s in st) / (wall * len(st)))
            line += f"{med(imbal):7.3f}{med(start):9.2f}"
            line += f"{med(wait):8.1f}{med(idle):6.2f}" if wait else f"{'-':>8}{'-':>6}"
        print(line)
    if ceil_up:
        print("\nof ceiling (mode median / ceiling median, same run):")
        for name in names:
            if not name.startswith("ceiling"):
                up = med(a[0] / a[2] for a in rec[name])
                print(f"  {name:<29}{up / ceil_up:6.3f}  ({up:.2f}x of {ceil_up:.2f}x)")


if __name__ == "__main__":
    main()
