"""Python-level throughput of the Masing operator on 1e7 samples.

For a sine, band-limited noise and a random walk that reverses every ~2 samples it reports the
throughput of ``Masing.force`` called from Python and of ``MasingOperator.push(x, out=buf)``
(no allocation), timed here in Python, interleaved, best of ``--repeat``; and a numpy ``exp``
pass over the same array as a same-run reference. The kernel's own speed against a plain
std-Rust loop of the same rules is ``cargo bench -p contactlab-core --bench masing``; the
parallel speed-up over channels is ``benches/bench_parallel.py``.
Run: ``.venv/bin/python benches/bench_masing.py [--n 10000000] [--repeat 15]``.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np
from scipy import signal

import contactlab


def signals(n: int) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(7)
    sos = signal.butter(4, 1 / 25, output="sos")  # cut-off at fs/50
    noise = signal.sosfilt(sos, rng.uniform(-0.5, 0.5, n))
    noise *= 20e-6 / np.sqrt(np.mean(noise**2))
    walk = np.cumsum(np.where(rng.integers(0, 2, n) == 0, 0.5e-6, -0.5e-6))
    return {
        "sine": 40e-6 * np.sin(np.arange(n) * (2 * np.pi / 1000)),
        "band_limited_noise": np.ascontiguousarray(noise),
        "random_walk": walk,
    }


def timed(f) -> float:
    t0 = time.perf_counter()
    result = f()
    dt = time.perf_counter() - t0
    del result  # freeing the output is not part of the call
    return dt


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--n", type=int, default=10_000_000)
    ap.add_argument("--repeat", type=int, default=15)
    args = ap.parse_args()
    n = args.n
    m = contactlab.Masing(40.0, 4.0e4)
    sig = signals(n)
    buf = np.empty(n)
    load = ", ".join(f"{a:.2f}" for a in os.getloadavg())
    print(f"n = {n:.0e} samples, best of {args.repeat} interleaved repeats; load {load}")
    print(f"{'signal':<20}{'force Ms/s':>12}{'push(out=) Ms/s':>17}{'numpy exp Ms/s':>16}")
    for name, x in sig.items():
        t_f = t_o = t_e = np.inf
        for _ in range(args.repeat):
            t_f = min(t_f, timed(lambda x=x: m.force(x)))
            t_o = min(t_o, timed(lambda x=x: m.operator().push(x, out=buf)))
            t_e = min(t_e, timed(lambda x=x: np.exp(-4.0e4 * x)))
        print(f"{name:<20}{n / t_f / 1e6:12.1f}{n / t_o / 1e6:17.1f}{n / t_e / 1e6:16.1f}")


if __name__ == "__main__":
    main()
