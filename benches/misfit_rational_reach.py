"""How far a rational virgin curve (``ac s / (1 + ac s)``) lies from what the diagnosis can
fit instead (stop 47, issue 29 item 3): the exponential Masing element alone, and with a
parallel stiffness. Noise-free, a sine drive from rest (a 1.5-cycle ramp), 5 cycles; the
RMS of the best least-squares fit's residual over the cycles after the ramp, as a
percentage of the force's range. A misfit flag cannot be asked to find a shape that lies
far below the record's noise (0.5-2 % of the range) once the named effect took it up::

    .venv/bin/python benches/misfit_rational_reach.py
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import least_squares

from contactlab.masing import Masing


def reach(acA: float, spring: bool) -> float:
    t = np.linspace(0.0, 5.0, 5000)
    u = acA * np.sin(2 * np.pi * t) * np.clip(t / 1.5, 0.0, 1.0)
    s = np.linspace(0.0, 40.0, 4001)
    F = Masing.from_backbone(s, s / (1.0 + s)).force(u)

    def res(p: np.ndarray) -> np.ndarray:
        k = p[2] if spring else 0.0
        return p[0] * Masing(1.0, p[1]).force(u) + k * u - F

    fit = least_squares(res, [1.0, 1.0, 0.1] if spring else [1.0, 1.0])
    keep = t > 1.5
    return float(100 * np.sqrt(np.mean(fit.fun[keep] ** 2)) / np.ptp(F[keep]))


if __name__ == "__main__":
    print("ac·A  exp alone  exp + parallel stiffness  (RMS, % of the force's range)")
    for acA in (0.7, 1.2, 1.5, 2.0, 3.2, 5.0):
        print(f"{acA:4.1f}  {reach(acA, False):9.2f}  {reach(acA, True):9.2f}")
