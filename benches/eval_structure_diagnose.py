"""Diagnosis on structures (issue 10): how often is the right effect named?

Base-excited frames with a Jenkins joint to the wall (tests/diagnose/test_diagnose_structure.py's
generator) with each missing effect (none, joint_damping, second_joint, base_coupling), on
fresh seeds, at two sampling rates (4 ms and 2 ms), started from rest (a start-up transient),
with 0.2 % noise on the base and the response channels, optionally both channels through the
same causal sensor filter (first-order low-pass at 25 Hz). The base model is identified on the
first 75 % of each record; :func:`contactlab.diagnose` names what it lacks. Prints the
confusion table and, with ``--frame``, the diagnosis of ../shared/data/friction_frame.

    python benches/eval_structure_diagnose.py [--seeds 3] [--filter] [--frame]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from scipy.signal import lfilter

import contactlab
from contactlab.structure import identify

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from test_structure_diagnose import MASS, frame_record

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "friction_frame"
EFFECTS = [None, "joint_damping", "second_joint", "base_coupling"]


def sensor(x: np.ndarray, dt: float, fc: float = 25.0) -> np.ndarray:
    a = np.exp(-2 * np.pi * fc * dt)
    return lfilter([1 - a], [1, -a], x, zi=[a * x[0]])[0]


def run(seeds: int, filt: bool) -> None:
    table: dict[str, dict[str, int]] = {}
    for dt, n in ((4e-3, 1500), (2e-3, 3000)):
        for effect in EFFECTS:
            for seed in range(seeds):
                s = 5000 + 100 * EFFECTS.index(effect) + seed + (0 if dt == 4e-3 else 50)
                t, u, y = frame_record(effect, s, n=n, dt=dt)
                if filt:
                    u, y = sensor(u, dt), sensor(y, dt)
                k = round(0.75 * n)
                t0 = time.perf_counter()
                m = identify(t[:k], u[:k], y[:k], joint="jenkins", excitation="base",
                             mass=MASS, substeps=2, start_samples=800)  # fmt: skip
                rep = contactlab.diagnose((t, u, y), base=m, max_effects=2)
                got = "+".join(rep.effects) or "none"
                want = effect or "none"
                table.setdefault(want, {})
                table[want][got] = table[want].get(got, 0) + 1
                print(f"dt={dt * 1e3:.0f} ms seed {s}: true {want:14s} named {got:28s} "
                      f"held-out {rep.steps[-1]['heldout_rms'] / rep.noise_rms:.2f} σ "
                      f"({time.perf_counter() - t0:.1f} s)", flush=True)  # fmt: skip
    print("\ntrue effect -> named (counts)")
    for want, row in table.items():
        print(f"  {want:14s} " + ", ".join(f"{g}: {c}" for g, c in sorted(row.items())))


def frame() -> None:
    for f in sorted(DATA.glob("frame_disc*.csv")):
        d = np.loadtxt(f, delimiter=",", skiprows=1)
        t, x, y = d[:, 0], 1e-3 * d[:, 1], 1e-3 * d[:, 2]
        n = round(0.75 * t.size)
        for joint in ("jenkins", "masing"):
            t0 = time.perf_counter()
            m = identify(t[:n], y[:n], x[:n], joint=joint, excitation="base", mass=3.0799,
                         substeps=2, start_samples=1000)  # fmt: skip
            rep = contactlab.diagnose((t, y, x), base=m, max_effects=2)
            print(f"\n{f.name}, {joint} base ({time.perf_counter() - t0:.0f} s)")
            print(rep.summary())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--filter", action="store_true", help="both channels through a sensor filter")
    ap.add_argument("--frame", action="store_true", help="also diagnose the measured frame")
    a = ap.parse_args()
    run(a.seeds, a.filter)
    if a.frame:
        if not DATA.exists():
            raise SystemExit(f"{DATA} absent")
        frame()


if __name__ == "__main__":
    main()
