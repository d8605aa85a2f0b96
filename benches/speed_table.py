"""The speed table of issue 33 in one run: contactlab, the other tools, the limits, ratios.

Every row times contactlab and its reference in the same process, interleaved round by round
(A B A B …), and quotes medians over ``--rounds``; the machine is shared, so single times are
noise and the ratio of medians is the figure. Rows:

- ``loop_area`` of 1e6 / 1e7 samples against numpy's closed trapezoid (``0.5 Σ (F_i +
  F_{i+1}) (x_{i+1} - x_i)`` plus the closing edge), ``np.trapezoid`` (open) and
  ``np.copyto`` of the same array (a memory-bandwidth limit).
- per-cycle energies with the cycle bounds given (``contactlab.loop_areas``) against numpy
  (terms, then ``np.add.reduceat``, plus each cycle's closing edge).
- ``Masing(h0=1, ac=3).force(x, out=buf)`` on the anchor's signals (sine, band-limited,
  random walk) against ``../shared/bench/masing_anchor.rs`` (its ``masing_idx`` kernel),
  built here for generic x86-64 (``rustc -O``) into a driver kept running between our rounds
  (``benches/bench_masing.py``), each round's two calls on one CPU (taking turns), at least
  12 rounds; ratio: median of the per-round thread-CPU ratios, their spread and the ratio of
  the medians, of the fastest calls and of wall-clock time beside it.
- ``Masing.force(threads=2)`` with a competing busy process against one thread.
- ``contactlab analyze --json`` of a 1e7 / 3e7-sample HDF5 recording on the command line
  against the Masing kernel on the same samples (``benches/bench_analyze.py``).
- ``contactlab --help``, ``python -c 'import contactlab'`` and ``contactlab analyze`` to its
  first sample read and to its end, against ``python -c pass`` (wall and CPU time, a new
  process each: ``benches/bench_startup.py``).
- the normal-contact ODE against scipy ``odeint`` (LSODA) on the problem of
  ``benches/bench_normal.py`` when ``--ode`` is given (slow).

numba and OpenSees rows appear only when those are installed (they are not dependencies).
Run: ``.venv/bin/python benches/speed_table.py [--rounds 5] [--quick] [--only analyze ...]``
(``--only``: just those groups of rows, e.g. ``--only analyze`` for the streamed-analyze
rows; the groups are loop, masing, threads, analyze, startup and ode).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

import contactlab

ROOT = Path(__file__).resolve().parents[1]


def med(v: list[float]) -> float:
    return float(np.median(v))


def timed(f) -> float:
    t0 = time.perf_counter()
    f()
    return time.perf_counter() - t0


def interleave(fns: dict[str, object], rounds: int) -> dict[str, float]:
    """Median seconds of each callable, run in turn round by round (order rotating)."""
    times: dict[str, list[float]] = {k: [] for k in fns}
    keys = list(fns)
    for f in fns.values():
        f()  # warm-up: page faults, caches, lazy imports
    for r in range(rounds):
        for k in keys[r % len(keys) :] + keys[: r % len(keys)]:
            times[k].append(timed(fns[k]))
    return {k: med(v) for k, v in times.items()}


def closed_trapezoid(x: np.ndarray, f: np.ndarray) -> float:
    inner = 0.5 * np.dot(f[:-1] + f[1:], np.diff(x))
    return float(inner + 0.5 * (f[-1] + f[0]) * (x[0] - x[-1]))


def row(task: str, ours: str, other: str, ratio: float, note: str = "") -> None:
    print(f"| {task} | {ours} | {other} | {ratio:.2f} {note}|")


def loop_rows(rounds: int, sizes: list[int]) -> None:
    rng = np.random.default_rng(1)
    for n in sizes:
        t = np.arange(n) * (2 * np.pi / 1000)
        x = np.sin(t) + 1e-3 * rng.standard_normal(n)
        f = np.sin(t + 0.4) + 1e-3 * rng.standard_normal(n)
        buf = np.empty_like(x)
        r = interleave(
            {
                "cl": lambda x=x, f=f: contactlab.loop_area(x, f),
                "np": lambda x=x, f=f: closed_trapezoid(x, f),
                "trapz": lambda x=x, f=f: np.trapezoid(f, x),
                "copy": lambda x=x, buf=buf: np.copyto(buf, x),
            },
            rounds,
        )
        row(
            f"`loop_area`, {n:.0e}",
            f"{r['cl'] * 1e3:.1f} ms",
            f"numpy closed trapezoid {r['np'] * 1e3:.1f} ms; `np.trapezoid` "
            f"{r['trapz'] * 1e3:.1f} ms; `np.copyto` {r['copy'] * 1e3:.1f} ms",
            r["np"] / r["cl"],
            f"of numpy; {r['trapz'] / r['cl']:.2f} of np.trapezoid; "
            f"{r['cl'] / r['copy']:.1f}x the copy ",
        )
    n = sizes[0]
    t = np.arange(n) * (2 * np.pi / 1000)
    x = np.sin(t)
    f = np.sin(t + 0.4)
    bounds = np.arange(0, n + 1, 1000, dtype=np.int64)
    per_cycle = getattr(contactlab, "loop_areas", None)

    def numpy_cycles() -> np.ndarray:
        terms = 0.5 * (f[:-1] + f[1:]) * np.diff(x)
        a, b = bounds[:-1], bounds[1:]
        inner = np.add.reduceat(terms, a)
        # reduceat over [a, next a) includes the edge b-1 -> b; remove it, add the closing edge
        inner[:-1] -= terms[b[:-1] - 1]
        return inner + 0.5 * (f[b - 1] + f[a]) * (x[a] - x[b - 1])

    if per_cycle is None:
        from contactlab import _core

        def ours() -> np.ndarray:
            return _core.loop_areas(x, f, bounds)

        label = "`_core.loop_areas`"
    else:

        def ours() -> np.ndarray:
            return per_cycle(x, f, bounds)

        label = "`contactlab.loop_areas`"
    r = interleave({"cl": ours, "np": numpy_cycles}, rounds)
    err = np.max(np.abs(ours() - numpy_cycles()))
    row(
        f"per-cycle energies, bounds given, {n:.0e} ({label})",
        f"{r['cl'] * 1e3:.1f} ms",
        f"numpy {r['np'] * 1e3:.1f} ms (max diff {err:.1e})",
        r["np"] / r["cl"],
    )


def splitmix_uniform(seed: int, n: int) -> np.ndarray:
    with np.errstate(over="ignore"):
        i = np.arange(1, n + 1, dtype=np.uint64)
        z = np.uint64(seed) + i * np.uint64(0x9E3779B97F4A7C15)
        z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
        z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
        z ^= z >> np.uint64(31)
    u = (z >> np.uint64(11)).astype(np.float64) * (1.0 / 9007199254740992.0)
    return 2.0 * u - 1.0


def anchor_signal(kind: str, n: int) -> np.ndarray:
    from scipy.signal import lfilter

    if kind == "sine":
        return np.sin((2.0 * np.pi * (np.arange(n) % 1000)) / 1000.0)
    if kind == "bandlim":
        e = splitmix_uniform(1, n)
        r = 0.95
        a1, a2 = 2.0 * r * np.cos(2.0 * np.pi / 40.0), -(r * r)
        x = lfilter([0.06], [1.0, -a1, -a2], e)
        x[:2] = 0.0
        return x
    e = splitmix_uniform(2, n)
    e[0] = 0.0
    return lfilter([0.05], [1.0, -0.999], e)


def masing_rows(rounds: int, n: int) -> None:
    """``Masing(h0=1, ac=3).force(x, out=buf)`` against the anchor (``bench_masing.py``).

    The anchor's ``masing_idx`` built here for generic x86-64, kept running and called
    between our rounds on its own signals, each round's two calls pinned to the same CPU
    (taking turns); at least 12 rounds. The ratio is the median of the per-round thread-CPU
    ratios, with their spread (minimum, quartiles, maximum), the ratio of the CPU medians and
    that of the fastest calls beside it (the wall-clock ratio, which holds waiting for a core
    on a loaded machine, too).
    """
    sys.path.insert(0, str(ROOT / "benches"))
    import bench_masing

    k = max(rounds, 12)
    rows = bench_masing.measure(n, k)
    if rows is None:
        row(f"`Masing.force(x, out=buf)`, {n:.0e}", "n/a", "anchor absent", 0.0)
        return
    for r in rows:
        oc, ac, ow, aw = r["ours_cpu"], r["anchor_cpu"], r["ours_wall"], r["anchor_wall"]
        lo, q1, q3, hi = r["cpu_ratio_spread"]
        row(
            f"`Masing.force(x, out=buf)`, {n:.0e}, {r['signal']}",
            f"{n / oc / 1e6:.0f} M/s CPU ({oc / n * 1e9:.2f} ns/sample), "
            f"{n / ow / 1e6:.0f} M/s wall",
            f"anchor {n / ac / 1e6:.0f} M/s CPU ({ac / n * 1e9:.2f} ns/sample), "
            f"{n / aw / 1e6:.0f} M/s wall; {k} rounds, per-round ratios {lo:.2f} / "
            f"{q1:.2f}-{q3:.2f} / {hi:.2f} (min / quartiles / max); ratio of medians "
            f"{ac / oc:.2f}, of the fastest calls {r['cpu_ratio_min']:.2f}, wall {aw / ow:.2f}",
            r["cpu_ratio_paired"],
        )


def threads_row(rounds: int, n: int) -> None:
    x = anchor_signal("randwalk", n)
    m = contactlab.Masing(h0=1.0, ac=3.0)
    buf = np.empty(n)
    busy = subprocess.Popen([sys.executable, "-c", "while True: pass"])
    try:
        time.sleep(0.3)
        r = interleave(
            {
                "one": lambda: m.force(x, out=buf, threads=1),
                "two": lambda: m.force(x, out=buf, threads=2),
            },
            rounds,
        )
    finally:
        busy.kill()
        busy.wait()
    load = os.getloadavg()[0]
    row(
        f"`Masing.force(threads=2)`, {n:.0e} random walk, one busy competitor (load {load:.1f})",
        f"{r['two'] * 1e3:.0f} ms",
        f"one thread {r['one'] * 1e3:.0f} ms",
        r["one"] / r["two"],
        "of one thread ",
    )


def startup_rows(rounds: int) -> None:
    """``contactlab --help``, ``import contactlab`` and ``analyze`` up to its first sample
    read and to its end, each a new process, against ``python -c pass`` (bench_startup.py)."""
    sys.path.insert(0, str(ROOT / "benches"))
    import bench_startup

    for task, ours, other, ratio, note in bench_startup.table(max(rounds, 5)):
        row(f"{task} (new process)", ours, other, ratio, note + " ")


def analyze_rows(rounds: int, sizes: list[int]) -> None:
    """``contactlab analyze --json`` of long HDF5 recordings (command line) against the
    Masing kernel on the same samples (bench_analyze.py; the bar is 0.3 of the kernel)."""
    sys.path.insert(0, str(ROOT / "benches"))
    import bench_analyze

    for task, ours, other, ratio, note in bench_analyze.rows(sizes, max(3, rounds // 2)):
        row(task, ours, other, ratio, note + " ")


def ode_row(rounds: int) -> None:
    sys.path.insert(0, str(ROOT / "benches"))
    import bench_normal

    sys.argv = [sys.argv[0]]
    # 1e5 and 1e6 samples, clean and with 1 % noise on p; odeint on the first 1e5 samples
    # (scaled: its cost per sample is constant), contactlab at the matched accuracy.
    bench_normal.main(["--n", "1e5", "1e6", "--odeint-n", "1e5", "--rounds", str(rounds)])


def optional_tools() -> str:
    found = []
    for mod in ("numba", "openseespy"):
        try:
            __import__(mod)
            found.append(mod)
        except ImportError:
            pass
    return ", ".join(found) or "none"


#: the groups of rows ``--only`` selects, in the table's order (ode last: only on request)
GROUPS = ("loop", "masing", "threads", "analyze", "startup", "ode")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--quick", action="store_true", help="1e6-sample rows only")
    ap.add_argument("--ode", action="store_true", help="also the normal ODE against odeint")
    ap.add_argument(
        "--only",
        nargs="+",
        choices=GROUPS,
        help="only these groups of rows (e.g. --only analyze)",
    )
    args = ap.parse_args()
    only = set(args.only or GROUPS[:-1] + (("ode",) if args.ode else ()))
    big = 1_000_000 if args.quick else 10_000_000
    try:
        from contactlab import _core

        simd = _core.simd_level()
    except (ImportError, AttributeError):  # a build before the dispatch
        simd = "n/a (before runtime dispatch)"
    print(
        f"contactlab {contactlab.__version__}; SIMD level {simd}; load "
        f"{', '.join(f'{a:.2f}' for a in os.getloadavg())}; {os.cpu_count()} CPUs; medians of "
        f"{args.rounds} interleaved rounds; optional tools installed: {optional_tools()}"
    )
    print("| task | contactlab | the other tool / the limit | ratio |")
    print("|---|---|---|---|")
    if "loop" in only:
        loop_rows(args.rounds, sorted({1_000_000, big}))
    if "masing" in only:
        masing_rows(args.rounds, big)
    if "threads" in only:
        threads_row(args.rounds, big)
    if "analyze" in only:
        analyze_rows(args.rounds, [1_000_000] if args.quick else [10_000_000, 30_000_000])
    if "startup" in only:
        startup_rows(args.rounds)
    if "ode" in only:
        ode_row(args.rounds)


if __name__ == "__main__":
    main()
