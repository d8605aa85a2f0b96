"""Identification of 2-DOF structures with a joint (issue 10): parameters recovered against
the truth on fresh seeds.

Cases: a chain of two masses (m = 1, 0.5 kg; k = 4000, 2000 N/m; c = 2, 1 N s/m) with a
Jenkins joint between the masses (force at the outer mass), a Bouc-Wen joint from the inner
mass to the ground (force at the outer mass), a Masing joint from the outer mass to the
ground under base motion (masses given), and the same Jenkins structure fitted with masks of
free K and C entries. Multisine inputs started from rest (a start-up transient), 1 % noise on
the input and on every response channel, two sampling rates; ``--filter`` passes every
channel through the same first-order 80 Hz sensor low-pass. Prints, per case, the largest
relative error of the structure's and of the joint's parameters, the output error over the
noise and the time.

    python benches/eval_structure_mdof.py [--seeds 3] [--first 51000] [--filter]
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from scipy.signal import lfilter

from contactlab.structure import Structure, identify

M = np.diag([1.0, 0.5])
K = np.array([[6e3, -2e3], [-2e3, 2e3]])
C = np.array([[3.0, -1.0], [-1.0, 1.0]])
CHAIN = {"m0": 1.0, "m1": 0.5, "k0": 4e3, "k1": 2e3, "c0": 2.0, "c1": 1.0}
MASKS = {"K[0,0]": 6e3, "K[0,1]": -2e3, "K[1,1]": 2e3, "C[0,0]": 3.0, "C[0,1]": -1.0,
         "C[1,1]": 1.0, "M[0,0]": 1.0, "M[1,1]": 0.5}  # fmt: skip
CASES = {
    "jenkins 0-1, force": ("jenkins", (0, 1), "force", {"k": 1.5e3, "fs": 1.5},
                           {"kj": 1.5e3, "fs": 1.5}, None),
    "bouc_wen 0-ground, force": ("bouc_wen", (0, None), "force",
                                 {"alpha": 2e3, "beta": 1.0, "gamma": 300.0, "delta": -100.0,
                                  "nu": 1.0},
                                 {"alpha": 2e3, "gamma": 300.0, "delta": -100.0}, None),
    "masing 1-ground, base": ("masing", (1, None), "base", {"h0": 2.0, "ac": 1500.0},
                              {"h0": 2.0, "ac": 1500.0}, None),
    "jenkins 0-1, force, masks": ("jenkins", (0, 1), "force", {"k": 1.5e3, "fs": 1.5},
                                  {"kj": 1.5e3, "fs": 1.5}, "masks"),
}  # fmt: skip


def sensor(x: np.ndarray, dt: float, fc: float = 80.0) -> np.ndarray:
    a = np.exp(-2 * np.pi * fc * dt)
    return lfilter([1 - a], [1, -a], x, axis=0)


def record(case: str, seed: int, fs: float, filt: bool):
    joint, jd, exc, jp, _, _ = CASES[case]
    rng = np.random.default_rng(seed)
    n = int(3.0 * fs)
    t = np.arange(n) / fs
    u = sum(np.sin(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi)) for f in np.arange(3, 40, 0.5))
    u = u / np.std(u) * (6.0 if exc == "force" else 2e-3)
    s = Structure(M, C, K)
    s.add_joint(joint, jd[0], jd[1], **jp)
    if exc == "force":
        f = np.zeros((n, 2))
        f[:, 1] = u
        y = s.simulate(t, force=f, substeps=4).x
    else:
        y = s.simulate(t, base=u, substeps=4).x
    um = u + 0.01 * np.std(u) * rng.standard_normal(n)
    ym = y + 0.01 * np.std(y, axis=0) * rng.standard_normal(y.shape)
    if filt:
        um, ym = sensor(um, 1 / fs), sensor(ym, 1 / fs)
    return t, um, ym, 0.01 * float(np.sqrt(np.mean(np.var(y, axis=0))))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--first", type=int, default=51000)
    ap.add_argument("--filter", action="store_true")
    args = ap.parse_args()
    print(f"{'case':<28}{'fs':>6}{'seed':>7}{'struct err %':>14}{'joint err %':>13}"
          f"{'rms/noise':>11}{'time s':>8}")  # fmt: skip
    for case, (joint, jd, exc, _, jtruth, pattern) in CASES.items():
        for fs in (500.0, 1000.0):
            for seed in range(args.first, args.first + args.seeds):
                t, u, y, sigma = record(case, seed, fs, args.filter)
                kw = {"masks": {"K": np.ones((2, 2), bool)}} if pattern == "masks" else {}
                t0 = time.perf_counter()
                m = identify(t, u, y, joint=joint, excitation=exc, joint_dofs=jd,
                             input_dof=1 if exc == "force" else None,
                             mass=[1.0, 0.5] if exc == "base" else None, substeps=2,
                             start_samples=1500, **kw)  # fmt: skip
                el = time.perf_counter() - t0
                p = m.fit.params
                struct = MASKS if pattern == "masks" else CHAIN
                se = max(abs(p[k].value / v - 1) for k, v in struct.items() if k in p)
                je = max(abs(p[k].value / v - 1) for k, v in jtruth.items())
                print(f"{case:<28}{fs:>6.0f}{seed:>7}{100 * se:>14.2f}{100 * je:>13.2f}"
                      f"{m.rms / sigma:>11.2f}{el:>8.1f}")  # fmt: skip


if __name__ == "__main__":
    main()
