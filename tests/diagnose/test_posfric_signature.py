"""A track's wave is kept where its part odd about the stroke's middle, which no virgin curve
draws, gains across held-out cycles beyond a free-form virgin curve (issue 29, stop 52:
``misfit.beyond_virgin``, ``workflow.signature_beyond_virgin``); a virgin curve of another
shape, point-symmetric, shows no such signature."""

from __future__ import annotations

import numpy as np

from contactlab.diagnose._family import Prepared
from contactlab.diagnose.candidates_tangential import TangentialFamily
from contactlab.diagnose.misfit import beyond_virgin
from contactlab.diagnose.scaled_masing import memory, scaled_force
from contactlab.diagnose.workflow import signature_beyond_virgin
from contactlab.masing import Masing

H0, AC = 40.0, 4.0e4
EFF = ("position_friction",)


def _prepared(F_of_x, seed: int = 5220):
    """A single-amplitude record from rest (1 kHz, 10 Hz, 24 cycles, ac·A 2), with the force
    ``F_of_x(x)`` and white noise of 0.5 % of the range on the force."""
    rng = np.random.default_rng(seed)
    fs, f, cyc = 1000.0, 10.0, 24
    A = 2.0 / AC
    t = np.arange(int((cyc + 1.25) * fs / f) + 1) / fs
    ramp = np.where(t < 1 / f, 0.5 * (1 - np.cos(np.pi * t * f)), 1.0)
    x = A * ramp * np.sin(2 * np.pi * f * t)
    F = F_of_x(x)
    F = F + rng.normal(0.0, 0.005 * np.ptp(F), F.size)
    fam = TangentialFamily()
    d = Prepared.build(t, x, F)
    fam.prepare(d)
    return fam, d


def _params(fam, d, a1: float, b1: float):
    half = float(d.extra["x_half"])
    return {**fam.initial_base(d), "h0": H0, "ac": AC, "a1": a1, "b1": b1, "L": 1.5 * half}


def _wave(x, d_mid: float, half: float, a1: float, b1: float):
    ph = 2 * np.pi * (x - d_mid) / (1.5 * half)
    return 1 + a1 * np.cos(ph) + b1 * np.sin(ph)


def test_the_odd_part_of_a_wave_is_its_signature_and_a_tanh_curve_has_none() -> None:
    A = 2.0 / AC
    # a wave odd about the middle (b1: sin): kept
    fam, d = _prepared(lambda x: Masing(H0, AC).force(x) * _wave(x, 0.0, A, 0.0, 0.03))
    p = _params(fam, d, 0.0, 0.03)
    got = signature_beyond_virgin(fam, "position_friction", d, p, EFF, 3.0)
    assert got is not None and "virgin curve" in got
    # a tanh virgin curve (point-symmetric, no wave in it): the wave fitted to it, even or
    # odd, shows no signature beyond a free-form virgin curve
    fam, d = _prepared(lambda x: scaled_force(lambda s: H0 * np.tanh(AC * s), 2.0, memory(x)))
    for a1, b1 in ((0.03, 0.0), (0.0, 0.03), (0.02, -0.02)):
        p = _params(fam, d, a1, b1)
        assert signature_beyond_virgin(fam, "position_friction", d, p, EFF, 3.0) is None


def test_beyond_virgin_sees_no_point_symmetric_change() -> None:
    """A change of the virgin curve as the residual: the wave's even direction gains nothing
    held out beyond the free-form curve; its odd direction added to the residual does."""
    _, d = _prepared(lambda x: Masing(H0, AC).force(x), seed=5221)
    u = d.u
    half = float(d.extra["x_half"])
    ph = 2 * np.pi * (u - d.extra["x_mid"]) / (1.5 * half)
    m = Masing(H0, AC).force(u)
    J = np.column_stack([m * np.cos(ph), m * np.sin(ph)])
    sym = 2.0 * (Masing(1.0, 0.5 * AC).force(u) - Masing(1.0, 2.0 * AC).force(u))
    noise = np.random.default_rng(3).normal(0.0, 0.2, u.size)
    quiet = beyond_virgin(d, sym + noise, J, AC)
    assert quiet is not None and quiet["t"] < 3.0
    loud = beyond_virgin(d, sym + noise + 0.03 * J[:, 1], J, AC)
    assert loud is not None and loud["t"] > 3.0 and loud["gain"] > 0


def test_no_signature_where_the_free_form_curve_cannot_bend() -> None:
    """A base saturated over the stroke (a stick-slip frame's ac·A of 1e10) leaves the
    free-form virgin curve only plateaus: the test does not answer there."""
    _, d = _prepared(lambda x: Masing(H0, AC).force(x) * _wave(x, 0.0, 2.0 / AC, 0.0, 0.03))
    u = d.u
    J = np.column_stack(
        [np.cos(u / float(d.extra["x_half"])), np.sin(u / float(d.extra["x_half"]))]
    )
    assert beyond_virgin(d, 0.03 * J[:, 1], J, AC) is not None
    assert beyond_virgin(d, 0.03 * J[:, 1], J, 1e6 * AC) is None
