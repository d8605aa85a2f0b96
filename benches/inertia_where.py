"""Where the ideal test's information on a mass lies in time (issue 29, stop 52).

The ideal test of ``benches/eval_inertia_shaker.py`` (:func:`ideal_test`: noise-free ẍ, the
base h0, ac and an offset projected off, weights ``1/(σ_F² + k² σ_x²)``) on the noise-free
clean twin of one condition and drive; prints its noncentrality per kg² with no rival and
with each rival (a spring's x, a dashpot's ẋ, a delay's -Ḟ) projected off as well, the
cumulative share of it by 0.05, 0.25, 0.5, 1, 2 and 3 periods, and how far ẍ lies from
-ω² x per cycle.

    nice .venv/bin/python benches/inertia_where.py ramp0 b2 52400000
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))


def main(argv: list[str]) -> None:
    import eval_inertia_shaker as E
    from contactlab.synthetic.rig import Virgin, masing_force

    E.DRIVE, label, seed = argv[0], argv[1], int(argv[2])
    cond = next(c for c in E.CONDITIONS if c[0] == label)
    _, fs, f, cyc, xn, fn, _aca, _share = cond
    r0 = E.rig(cond, seed, 0.0, noise=False)
    x, F, dt = r0.x, r0.F, 1.0 / fs
    b = r0.truth["base"]
    h0, ac = b["h0"], b["ac"]
    sx, sF = xn * np.max(np.abs(x)), fn * np.max(np.abs(F))

    def base(p):
        return masing_force(x, Virgin.exponential(p[0], p[1]))[0] + p[2]

    p = np.array([h0, ac, 0.0])
    F0 = base(p)
    steps = (h0 * 1e-6, ac * 1e-6, h0 * 1e-6)
    J = np.column_stack([(base(p + np.eye(3)[i] * s) - F0) / s for i, s in enumerate(steps)])
    v = np.gradient(x, dt, edge_order=2)
    a = E.acc_of(x, dt)
    dF = np.gradient(F0, dt, edge_order=2)
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.where(np.abs(v) > 1e-12, dF / v, h0 * ac)
    k = np.clip(np.nan_to_num(k, nan=h0 * ac), 0, h0 * ac)
    sw = np.sqrt(1.0 / (sF**2 + (k * sx) ** 2))

    def perp(B, g):
        Q, _ = np.linalg.qr(B * sw[:, None])
        gw = g * sw
        return gw - Q @ (Q.T @ gw)

    per = round(fs / f)
    marks = (0.05, 0.25, 0.5, 1, 2, 3)
    for name, R in (("none", None), ("spring", x), ("dashpot", v), ("delay", -dF)):
        g = perp(J if R is None else np.column_stack([J, R]), a)
        tot = float(g @ g)
        c = np.cumsum(g * g) / tot
        shares = [f"{c[min(int(per * q), x.size - 1)]:.3f}" for q in marks]
        print(f"{name:8s} per kg² {tot:.4g}; share by {marks} periods: {shares}")
    w2 = (2 * np.pi * f) ** 2
    dev = a + w2 * (x - x[per:].mean())
    scale = w2 * np.max(np.abs(x))
    rms = [np.sqrt(np.mean(dev[i * per : (i + 1) * per] ** 2)) / scale for i in range(min(cyc, 8))]
    print("ẍ off -ω²x, RMS per cycle / ω²A:", [f"{v:.4f}" for v in rms])


if __name__ == "__main__":
    main(sys.argv[1:])
