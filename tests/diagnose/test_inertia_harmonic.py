"""The mass's ``ẍ`` from the drive's harmonics (issue 29, a shaker's drive): outside the
start-up the measured x is fitted by the harmonics of its fundamental and differentiated
analytically (``inertia.harmonic_acceleration``), so the regressor carries a fraction
``(2K + 2)/N`` of the input's noise instead of a local polynomial's share."""

from __future__ import annotations

import math
import types

import numpy as np
from scipy.signal import savgol_filter

from contactlab.diagnose.effects.tangential import inertia

FS, F, CYCLES = 2000.0, 10.0, 20


def _d(u: np.ndarray, f: float = F, noise: float = 1.0):
    t = np.arange(u.size) / FS
    return types.SimpleNamespace(
        u=u, udd=np.zeros(u.size), dt=1.0 / FS, t=t,
        extra={"u_noise": noise, "u_raw": u, "u_filter": 0},
        cycles=types.SimpleNamespace(
            period_samples=FS / f, cycle=np.floor(t * f).astype(int),
            reversals=np.arange(0, u.size, FS / f / 2).astype(int),
        ),
    )  # fmt: skip


def _shaker_like(seed: int, sx: float = 0.015):
    """A 10 Hz drive with odd harmonics (10 % and 3 % of it) and a start-up transient at
    6.3 Hz dying within 3 cycles, white noise ``sx`` of the amplitude on it; the noise-free
    ``ẍ`` beside it."""
    t = np.arange(round(CYCLES * FS / F)) / FS
    w, wn, s = 2 * math.pi * F, 2 * math.pi * 6.3, 12.0
    x = np.sin(w * t) + 0.1 * np.sin(3 * w * t + 0.4) + 0.03 * np.sin(5 * w * t + 1.0)
    acc = -(w**2) * (np.sin(w * t) + 0.9 * np.sin(3 * w * t + 0.4) + 0.75 * np.sin(5 * w * t + 1.0))
    x = x - 0.3 * np.exp(-s * t) * np.sin(wn * t)
    acc = acc - 0.3 * np.exp(-s * t) * (
        (s * s - wn * wn) * np.sin(wn * t) - 2 * s * wn * np.cos(wn * t)
    )
    noisy = x + np.random.default_rng(seed).normal(0.0, sx, x.size)
    return noisy, acc


def test_the_harmonics_read_the_drive_s_acceleration_far_better_than_a_local_polynomial():
    u, acc = _shaker_like(1)
    dt = 1.0 / FS
    local = savgol_filter(u, 31, 3, deriv=2, delta=dt)  # 15 % of the period, as before
    got = inertia.harmonic_acceleration(_d(u, noise=0.015), local)
    assert got is not None
    cyc = np.floor(np.arange(u.size) / FS * F).astype(int)
    steady = cyc >= 4
    rms = float(np.sqrt(np.mean(acc[steady] ** 2)))
    err_h = float(np.sqrt(np.mean((got - acc)[steady] ** 2))) / rms
    err_l = float(np.sqrt(np.mean((local - acc)[steady] ** 2))) / rms
    assert err_h < 0.02 and err_h < 0.2 * err_l
    # the first cycle (the start-up from rest) keeps the local polynomial's ẍ
    np.testing.assert_array_equal(got[cyc == 0], local[cyc == 0])


def test_a_drive_of_two_frequencies_is_left_to_the_local_polynomial():
    t = np.arange(round(CYCLES * FS / F)) / FS
    w = 2 * math.pi * F
    u = np.where(t < t[-1] / 2, np.sin(w * t), 0.7 * np.sin(1.7 * w * t))
    u = u + np.random.default_rng(2).normal(0.0, 0.015, u.size)
    local = savgol_filter(u, 31, 3, deriv=2, delta=1.0 / FS)
    assert inertia.harmonic_acceleration(_d(u, noise=0.015), local) is None


def test_a_pure_sine_keeps_the_local_polynomial():
    """No harmonic beyond the fundamental stands out: ẍ is -ω² x, which the base's own
    stiffness takes, and the single-frequency rules stay with the local ẍ."""
    t = np.arange(round(CYCLES * FS / F)) / FS
    u = np.sin(2 * math.pi * F * t) + np.random.default_rng(3).normal(0.0, 0.015, t.size)
    local = savgol_filter(u, 31, 3, deriv=2, delta=1.0 / FS)
    assert inertia.harmonic_acceleration(_d(u, noise=0.015), local) is None
    # ... while a 3rd harmonic of 2 % of it is read
    u3 = u + 0.02 * np.sin(3 * 2 * math.pi * F * t)
    assert inertia.harmonic_acceleration(_d(u3, noise=0.015), local) is not None
