"""How much of a mass's force a Masing base refit absorbs on one drive frequency (issue 29).

On a sine ``m ẍ = -mω² x`` is a negative stiffness, and the Masing element's own stiffness and
curvature take most of it. Noise-free: ``x`` a sine from rest (a one-cycle linear ramp, then 5
steady cycles, 400 samples a cycle), ``F = Masing(h0, ac)(x) - mω² x`` with ``mω² A`` a
``--share`` of the steady force amplitude; ``h0``, ``ac`` and an offset refitted by least
squares on the steady cycles and on the whole record. Printed per ac·A: the mass's force RMS
and what the refit leaves of it (both in % of the force amplitude).

    .venv/bin/python benches/inertia_absorption.py --aca 0.5,0.9,1,2,3.4 --share 0.02
"""

from __future__ import annotations

import argparse

import numpy as np
from scipy.optimize import least_squares

from contactlab.masing import Masing

H0, AC = 40.0, 4.0e4


def absorbed(aca: float, share: float, steady_only: bool) -> tuple[float, float]:
    """The mass's force RMS and the refit's residual RMS, both over the force amplitude."""
    A = aca / AC
    t = np.linspace(0.0, 6.0, 6 * 400, endpoint=False)
    x = A * np.clip(t, 0.0, 1.0) * np.sin(2 * np.pi * t)
    steady = t >= 1.0
    base = Masing(H0, AC).force(x)
    amp = 0.5 * float(np.ptp(base[steady]))
    k = share * amp / A  # m ω²
    y = base - k * x
    sel = steady if steady_only else np.ones_like(steady)

    def res(p):
        return Masing(p[0], p[1]).force(x)[sel] + p[2] - y[sel]

    r = least_squares(res, [H0, AC, 0.0], x_scale=[H0, AC, 1.0])
    left = float(np.sqrt(np.mean(r.fun**2))) / amp
    return float(np.sqrt(np.mean((k * x[sel]) ** 2))) / amp, left


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--aca", default="0.5,0.9,1,2,3.4")
    ap.add_argument("--share", type=float, default=0.02)
    a = ap.parse_args()
    print("| ac·A | fit on | mass force RMS (% amp) | left after refit (% amp) | share left |")
    print("|---|---|---|---|---|")
    for aca in (float(v) for v in a.aca.split(",")):
        for steady_only in (True, False):
            tot, left = absorbed(aca, a.share, steady_only)
            where = "steady" if steady_only else "all"
            print(f"| {aca:g} | {where} | {100 * tot:.2f} | {100 * left:.3f} | {left / tot:.3f} |")


if __name__ == "__main__":
    main()
