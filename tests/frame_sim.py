"""An independent stick-slip reference for the friction-frame tests: a base-excited frame
(M x'' + C (x' - y') + K (x - y) + F_f = 0) with Coulomb friction (static ``Fs``, kinetic
``Fk``), integrated from rest with a small fixed step and sampled at ``fs``. Plain Python,
no contactlab code: it checks the reconstruction and the regime detection from outside.
"""

from __future__ import annotations

import numpy as np


def simulate_frame(*, M=3.08, K=1191.0, C=0.669, Fk=0.8, Fs=None, Y=1.8e-3, f=1.0, T=8.0,
                   dt=5e-5, fs=250.0):  # fmt: skip
    """Base-excited frame with Coulomb friction (static Fs, kinetic Fk), from rest."""
    Fs = Fk if Fs is None else Fs
    n = round(T / dt)
    step = round(1 / (fs * dt))
    w = 2 * np.pi * f
    x = v = 0.0
    stuck = True
    out_t, out_x, out_y, out_F = [], [], [], []
    for i in range(n):
        t = i * dt
        y, yd = Y * np.sin(w * t), Y * w * np.cos(w * t)
        drive = K * (y - x) + C * (yd - v)
        if stuck:
            if abs(drive) <= Fs:
                Ff, a = drive, 0.0
            else:
                stuck = False
                Ff = Fk * np.sign(drive)
                a = (drive - Ff) / M
        else:
            Ff = Fk * np.sign(v) if v != 0 else Fk * np.sign(drive)
            a = (drive - Ff) / M
        if i % step == 0:
            out_t.append(t)
            out_x.append(x)
            out_y.append(y)
            out_F.append(Ff)
        if not stuck:
            v_new = v + a * dt
            if v != 0 and np.sign(v_new) != np.sign(v):
                v_new = 0.0
                stuck = True
            x += 0.5 * (v + v_new) * dt
            v = v_new
    return tuple(np.asarray(c) for c in (out_t, out_x, out_y, out_F))
