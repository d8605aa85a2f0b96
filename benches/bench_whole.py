"""The whole-signal velocity and stick search of ``analyze --whole`` (issue 9): the O(n),
bounded-memory implementation against the one it replaced (tests/regime_reference.py), in the
same run, on the same long stick-slip recording.

The recording: a plate driven at 1 Hz that sticks at each reversal for a tenth of a period
(the displacement clipped flat there), 10 kHz, kinetic friction 0.8 N with a ramp while stuck,
noise 0.2 µm on x and 0.02 N on F. Each (implementation, size) runs in a child process, so its
peak RSS (``os.wait4``) is its own; both get the same arrays from the same seed. Prints wall
and CPU time, peak RSS, the ratios old/new, and whether the outputs (window, threshold,
velocity, every stick and breakaway force) agree.

Run: ``nice .venv/bin/python benches/bench_whole.py [--samples 1e6 1e7]``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
FS = 10_000.0


def recording(n: int, seed: int = 91):
    """(t, x, F, reversals) of the stick-slip plate described in the module docstring."""
    from contactlab.tangential.preprocess import find_reversals

    rng = np.random.default_rng(seed)
    t = np.arange(n) / FS
    s = np.sin(2 * np.pi * t)
    x = 1.6e-3 * np.clip(s / np.cos(0.1 * np.pi), -1.0, 1.0)  # flat for 0.1 period per turn
    stuck = np.abs(s) > np.cos(0.1 * np.pi)
    F = 0.8 * np.sign(np.cos(2 * np.pi * t))
    F[stuck] = 0.8 * np.sign(s[stuck]) * (1.6 - 0.8 * np.abs(np.cos(2 * np.pi * t[stuck])))
    x += rng.normal(0, 2e-7, n)
    F += rng.normal(0, 0.02, n)
    return t, x, F, find_reversals(x, t)


def child(impl: str, n: int) -> None:
    from contactlab.tangential import regime

    sys.path.insert(0, str(ROOT / "tests"))
    import regime_reference as ref

    velocity, stick_slip = (
        (ref.velocity, ref.stick_slip) if impl == "old" else (regime.velocity, regime.stick_slip)
    )
    t, x, F, rev = recording(n)
    c0, w0 = time.process_time(), time.perf_counter()
    v, thr, window = velocity(t, x)
    vel_wall, vel_cpu = time.perf_counter() - w0, time.process_time() - c0
    st = stick_slip(t, x, F, rev, v, thr, window)
    wall, cpu = time.perf_counter() - w0, time.process_time() - c0
    out = {"wall_s": wall, "cpu_s": cpu, "velocity_wall_s": vel_wall, "velocity_cpu_s": vel_cpu,
           "window": int(window), "threshold": thr,
           "v_digest": float(np.sum(v * np.arange(1, v.size + 1) % 7.0)),
           "sticks": st.to_dict() if st is not None else None,
           "breakaway": st.breakaway.tolist() if st is not None else []}  # fmt: skip
    print(json.dumps(out))


def run(impl: str, n: int) -> dict:
    cmd = [sys.executable, __file__, "--child", impl, str(n)]
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, text=True)
    assert p.stdout is not None
    text = p.stdout.read()
    _, status, usage = os.wait4(p.pid, 0)
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"{cmd} failed")
    d = json.loads(text)
    d["peak_rss_mb"] = usage.ru_maxrss / 1024.0
    return d


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--samples", type=float, nargs="+", default=[1e6, 1e7])
    ap.add_argument("--child", nargs=2, help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child:
        child(a.child[0], int(a.child[1]))
        return
    print("load:", os.getloadavg())
    for n in map(int, a.samples):
        new, old = run("new", n), run("old", n)
        same = all(new[k] == old[k] for k in ("window", "threshold", "v_digest", "sticks",
                                                   "breakaway"))  # fmt: skip
        print(f"n = {n:.0e}: sticks at {new['sticks']['reversals_with_stick']} of "
              f"{new['sticks']['n_reversals']} reversals; outputs identical: {same}")  # fmt: skip
        for name, d in (("old", old), ("new", new)):
            print(f"  {name}: wall {d['wall_s']:.2f} s, CPU {d['cpu_s']:.2f} s (velocity alone "
                  f"{d['velocity_wall_s']:.2f} s wall, {d['velocity_cpu_s']:.2f} s CPU; the rest: "
                  f"the per-stick breakaway search), peak RSS {d['peak_rss_mb']:.0f} MB (whole "
                  "child process)")  # fmt: skip
        print(f"  old/new: wall {old['wall_s'] / new['wall_s']:.2f}x, CPU "
              f"{old['cpu_s'] / new['cpu_s']:.2f}x (velocity alone "
              f"{old['velocity_cpu_s'] / new['velocity_cpu_s']:.2f}x CPU), peak RSS "
              f"{old['peak_rss_mb'] / new['peak_rss_mb']:.2f}x")  # fmt: skip
    print("load:", os.getloadavg())


if __name__ == "__main__":
    main()
