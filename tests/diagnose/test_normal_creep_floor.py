"""The creep's share of the normal family's gain floor (issue 29, stop 52): a settling in
time, held to half of ``min_gain`` (``creep_drift.GAIN_FLOOR_SCALE``), its significance
across cycles, the drift test and the plausibility in full."""

from __future__ import annotations

import math
import warnings

import numpy as np

from contactlab.diagnose.candidates_normal import NormalFamily, kelvin_voigt
from contactlab.diagnose.effects.normal import creep_drift
from contactlab.diagnose.search import own_gain_floor


def test_creep_floor_is_half_the_families():
    fam = NormalFamily()
    assert creep_drift.GAIN_FLOOR_SCALE == 0.5
    assert own_gain_floor(fam, ("creep_drift",), 0.05) == 0.025
    # the shapes beyond the ellipse keep the whole floor
    assert own_gain_floor(fam, ("stiffness_nonlinearity",), 0.05) == 0.05
    assert own_gain_floor(fam, ("asymmetric_branches",), 0.05) == 0.05


def test_creep_at_the_ideal_size_is_named():
    """One tone from rest (fs 5 kHz, 10.5 Hz, 8 cycles, 1.6 % noise on p, 1.7 % on δ: a
    blind miss's conditions, ``benches/eval_normal_ideal.py --set blind52``, tuning seed
    52101008), a creep of D = -2.99 nm settling in τc 0.135 s: the ideal test's size
    (noncentrality 44.8 beyond the base and a channel delay). At the full floor it was not
    named (its gain below twice the floor, t below 3 across the 8 cycles)."""
    import contactlab

    fs, f, cycles, k, psi, p0 = 5000.0, 10.5, 8, 1.3e12, 0.2107544220346646, 5e5
    pa = 0.36 * p0
    n = round(cycles * fs / f)
    t = np.arange(n) / fs
    omega = 2 * math.pi * f
    pd = pa * np.sin(omega * t)
    d = kelvin_voigt(t, pd, k, psi, omega) - 2.9915937521790687e-09 * -np.expm1(
        -t / 0.13521538374015726
    )
    rng = np.random.default_rng(52101008)
    p = p0 + pd + rng.normal(0, 0.016 * np.ptp(p0 + pd), n)
    d = d + rng.normal(0, 0.017 * np.ptp(d), n)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rep = contactlab.diagnose({"t": t, "p": p, "delta": d}, "normal")
    assert rep.effect_names == ["creep_drift"]
