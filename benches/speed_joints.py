"""Joint-law speed (issue 30), one run: the plain Rust loop of each law (written out in
``benches/joints.rs``: no checks, no trait), the Rust kernel (``Operator::push``) and the
Python call ``law.force(t, x)`` (argument checks, the kernel with the GIL released), all on
the same signal (written here, read by the Rust bench with ``--signal``): M samples/s by CPU
time, ratios to the plain loop, and the issue's targets (Dahl / LuGre >= 50, Maxwell-slip
with 10 elements >= 10, Iwan (Segalman) >= 20 M samples/s).

Run: ``.venv/bin/python benches/speed_joints.py [--n 2000000] [--repeat 7]`` (builds the
bench binary with ``cargo bench`` first: minutes on a loaded machine when not built yet).
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

from contactlab.joints import Dahl, LuGre, MaxwellSlip, Segalman

ROOT = Path(__file__).resolve().parents[1]

#: the laws of benches/joints.rs, with the same parameters: (row name, law, timed)
LAWS = [
    ("dahl", Dahl(1e4, 5.0, 1.0), False, 50.0),
    ("lugre", LuGre(1e6, 300.0, 10.0, 4.0, 5.0, 1e-3, 2.0), True, 50.0),
    ("maxwell_slip 10", MaxwellSlip(1e4 * (1 + 0.1 * np.arange(10)), 0.5 * (1 + np.arange(10))),
     False, 10.0),
    ("segalman (exact)", Segalman(5.0, 1e4, -0.5, 0.2), False, 20.0),
]  # fmt: skip


def signal(n: int) -> tuple[np.ndarray, np.ndarray]:
    """5 Hz sine of slowly varying amplitude plus a random walk, at 10 kHz."""
    t = np.arange(n) * 1e-4
    rng = np.random.default_rng(0)
    x = 1e-3 * np.sin(2 * np.pi * 5 * t) * (1 + 0.5 * np.sin(2 * np.pi * 0.3 * t))
    return t, x + np.cumsum(rng.uniform(-2e-7, 2e-7, n))


def rust_rows(path: str, repeat: int) -> dict[str, tuple[float, float]]:
    """``name -> (kernel, plain)`` M samples/s (CPU) from the Rust bench."""
    cmd = ["cargo", "bench", "-q", "-p", "contactlab-core", "--bench", "joints", "--",
           "--signal", path, "--repeat", str(repeat)]  # fmt: skip
    out = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, check=False,
                         env={**os.environ, "CARGO_TERM_COLOR": "never"})  # fmt: skip
    if out.returncode != 0:
        sys.exit(f"cargo bench failed:\n{out.stderr[-2000:]}")
    rows = {}
    for line in out.stdout.splitlines():
        for name, *_ in LAWS:
            if line.startswith(name + " ") and line[len(name) :].split():
                v = line[len(name) :].split()
                rows[name] = (float(v[0]), float(v[2]))
    return rows


def python_rate(law: object, t: np.ndarray, x: np.ndarray, timed: bool, repeat: int) -> float:
    cpu = []
    for _ in range(repeat):
        c = time.process_time()
        law.force(t if timed else None, x)  # type: ignore[attr-defined]
        cpu.append(time.process_time() - c)
    return x.size / float(np.median(cpu)) / 1e6


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=2_000_000)
    ap.add_argument("--repeat", type=int, default=7)
    a = ap.parse_args()
    t, x = signal(a.n)
    with tempfile.NamedTemporaryFile(suffix=".f64", delete=False) as fh:
        fh.write(np.concatenate([t, x]).astype("<f8").tobytes())
        path = fh.name
    try:
        rust = rust_rows(path, a.repeat)
    finally:
        os.unlink(path)
    print(f"{a.n} samples, median of {a.repeat}; M samples/s by process CPU time")
    print(f"{'law':<18} {'plain Rust':>10} {'kernel':>8} {'python':>8} {'kernel/plain':>13} "
          f"{'python/plain':>13} {'target':>7}  met (kernel, python)")  # fmt: skip
    for name, law, timed, target in LAWS:
        kern, plain = rust[name]
        py = python_rate(law, t, x, timed, a.repeat)
        print(f"{name:<18} {plain:10.1f} {kern:8.1f} {py:8.1f} {kern / plain:13.2f} "
              f"{py / plain:13.2f} {target:7.0f}  {kern >= target}, {py >= target}")  # fmt: skip


if __name__ == "__main__":
    main()
