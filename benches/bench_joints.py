"""Joint laws from Python (``law.force``: argument checks, the Rust kernel with the GIL
released) against the plain-Python reference (``contactlab.joints._reference``) in the same
run: samples per second by process CPU time (the machine may be shared; wall in brackets) and
the speed-up. The kernel runs on ``--n`` samples, the reference on ``--n-ref`` (it is ~1e4 times
slower); the forces of the common first ``--n-ref`` samples are compared.

Run: ``.venv/bin/python benches/bench_joints.py [--n 1000000] [--n-ref 20000]``.
The pure-Rust kernels against a plain Rust loop: ``cargo bench -p contactlab-core --bench
joints``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from contactlab.joints import (
    Backlash,
    BoucWen,
    Dahl,
    GeneralizedMaxwellSlip,
    Jenkins,
    KelvinVoigt,
    LuGre,
    MaxwellSlip,
    Segalman,
    Series,
)
from contactlab.joints import _reference as ref


def signal(n: int) -> tuple[np.ndarray, np.ndarray]:
    """5 Hz sine of slowly varying amplitude plus a random walk, at 10 kHz."""
    t = np.arange(n) * 1e-4
    rng = np.random.default_rng(0)
    x = 1e-3 * np.sin(2 * np.pi * 5 * t) * (1 + 0.5 * np.sin(2 * np.pi * 0.3 * t))
    return t, x + np.cumsum(rng.normal(0, 1e-7, n))


def timed(f, repeat: int) -> tuple[float, float]:
    """Best CPU and wall seconds of ``repeat`` calls."""
    cpu = wall = float("inf")
    for _ in range(repeat):
        c, w = time.process_time(), time.perf_counter()
        f()
        cpu, wall = min(cpu, time.process_time() - c), min(wall, time.perf_counter() - w)
    return cpu, wall


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--n-ref", type=int, default=20_000)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    t, x = signal(a.n)
    laws = [
        Dahl(1e4, 5.0),
        LuGre(1e6, 300.0, 10.0, 4.0, 5.0, 1e-3),
        MaxwellSlip(np.linspace(1e4, 2e4, 10), np.linspace(0.5, 5.0, 10)),
        Segalman(5.0, 1e4, -0.5, 0.2),
        BoucWen(1e4, 1e-3, 0.5, 0.5, 1.5),
        GeneralizedMaxwellSlip(np.full(10, 1e4), np.full(10, 0.1), 4.0, 5.0, 1e-3, 1e4),
        Series(KelvinVoigt(5e4), Jenkins(1e4, 5.0)),
        Backlash(2e-4, Jenkins(1e4, 5.0)),
    ]
    print(f"{'law':<14} {'kernel M/s':>11} {'(wall)':>8} {'reference k/s':>14} {'speed-up':>9} "
          f"{'max |dF| / max |F|':>19}")  # fmt: skip
    for law in laws:
        ck, wk = timed(lambda law=law: law.force(t, x), a.repeat)
        tr, xr = list(t[: a.n_ref]), list(x[: a.n_ref])
        c0 = time.process_time()
        fr = ref.run(law._ref(), tr, xr)[0]
        cr = time.process_time() - c0
        fk = law.force(t[: a.n_ref], x[: a.n_ref])
        err = np.abs(fk - np.asarray(fr)).max() / np.abs(fk).max()
        rate_k, rate_r = a.n / ck, a.n_ref / cr
        print(f"{law.name:<14} {rate_k / 1e6:>11.1f} {a.n / wk / 1e6:>8.1f} {rate_r / 1e3:>14.1f} "
              f"{rate_k / rate_r:>9.0f} {err:>19.1e}")  # fmt: skip


if __name__ == "__main__":
    main()
