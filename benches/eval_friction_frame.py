"""Base-excited frame rubbing on a wall (../shared/data/friction_frame/, Marino & Cicirello):
identify M, C, K and the joint together from the measured motion of the mass and the base
(M = 3.0799 kg given), and compare with the route that reconstructs the friction force from
the frame's equation of motion, F_f = K (y − x) + C (y' − x') − M x''.

For each recording and joint model: the fitted K, C, joint parameters, the RMS output error
on the training part (first 80 %) and on the held-out last 20 %, the joint's 95th-percentile
|force| and dissipated energy per second; for the reconstruction (with the authors' initial
K, C and with the identified K, C): 95th-percentile |F_f| and the energy ∮F_f d(x) per second.

    python benches/eval_friction_frame.py [joint ...]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from contactlab.structure import identify

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "friction_frame"
MASS = 3.0799


def reconstruct(t, x, y, k, c):
    xd = np.gradient(x, t, edge_order=2)
    xdd = np.gradient(xd, t, edge_order=2)
    yd = np.gradient(y, t, edge_order=2)
    return k * (y - x) + c * (yd - xd) - MASS * xdd


def main() -> None:
    joints = sys.argv[1:] or ["jenkins", "masing", "bouc_wen", "linear"]
    for f in sorted(DATA.glob("frame_disc*.csv")):
        d = np.loadtxt(f, delimiter=",", skiprows=1)
        t, x, y = d[:, 0], 1e-3 * d[:, 1], 1e-3 * d[:, 2]
        dur = t[-1] - t[0]
        ff = reconstruct(t, x, y, 1191.0, 0.6690)
        xd = np.gradient(x, t)
        print(f"{f.name}: reconstruction (K = 1191, C = 0.669): p95 |F_f| = "
              f"{np.percentile(np.abs(ff), 95):.3f} N, energy rate "
              f"{np.trapezoid(ff * xd, t) / dur:.4f} W")  # fmt: skip
        n = int(0.8 * t.size)
        for j in joints:
            m = identify(t[:n], y[:n], x[:n], joint=j, excitation="base", mass=MASS)
            r = m.simulate(t, base=y, x0=[m.x0], v0=[m.v0])
            e = r.x - x
            v = m.fit.values
            fj = r.joint_force.sum(axis=1) if r.joint_force.shape[1] else np.zeros_like(t)
            ej = r.joint_energy.sum(axis=1)[-1] / dur if r.joint_force.shape[1] else 0.0
            fr = reconstruct(t, x, y, v["k"], v["c"])
            print(f"  {j:9s} K={v['k']:8.1f} C={v['c']:6.3f} "
                  + " ".join(f"{k}={v[k]:.4g}" for k in v if k not in ("m", "c", "k", "x0",
                                                                        "v0"))
                  + f" | rms train {np.sqrt(np.mean(e[:n] ** 2)):.3e} m hold-out "
                  f"{np.sqrt(np.mean(e[n:] ** 2)):.3e} m | joint p95 "
                  f"{np.percentile(np.abs(fj), 95):.3f} N, {ej:.4f} W | reconstruction with "
                  f"these K, C: p95 {np.percentile(np.abs(fr), 95):.3f} N | {m.elapsed:.1f} s",
                  flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
