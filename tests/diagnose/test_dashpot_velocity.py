"""The dashpot's velocity (a quintic over half a period), the long-window Savitzky-Golay
design it needs, and the takes-over anchor of a loop that never reaches its plateau
(issue 29: viscous damping named at its true size)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import savgol_coeffs as scipy_coeffs

from contactlab._filters import savgol_coeffs, savgol_filter
from contactlab.diagnose._family import Prepared
from contactlab.diagnose.candidates_tangential import TangentialFamily
from contactlab.diagnose.effects.tangential._common import smoothed_velocity
from contactlab.diagnose.effects.tangential.viscous_damping import dashpot_velocity
from contactlab.diagnose.search import _takes_over

FAM = TangentialFamily()


@pytest.mark.parametrize(("window", "order"), [(907, 5), (1501, 5), (601, 4), (2001, 3)])
def test_long_windows_pass_a_slow_sine_and_match_scipy(window, order):
    n_per = 4 * window  # a quarter of a period per window: the polynomial passes it
    t = np.arange(3 * n_per)
    x = np.sin(2 * np.pi * t / n_per)
    y = savgol_filter(x, window, order)
    mid = slice(window, t.size - window)
    assert np.max(np.abs(y[mid] - x[mid])) < 5e-3  # (the unscaled quintic kept 0.27 of it)
    # the coefficients reproduce every polynomial of the degree exactly (the defining
    # property; scipy's own unscaled design loses it at these windows too)
    pos = window // 2
    k = np.arange(-pos, pos + 1, dtype=float)[::-1] / pos  # (a convolution: reversed)
    rng = np.random.default_rng(window)
    coef = rng.normal(size=order + 1)
    poly = np.polynomial.Polynomial(coef)
    dt = 0.01
    for deriv in (0, 1):
        got = float(np.dot(savgol_coeffs(window, order, deriv, dt), poly(k)))
        want = poly.deriv(deriv)(0.0) / (pos * dt) ** deriv
        assert got == pytest.approx(want, rel=1e-7, abs=1e-9 * float(np.abs(coef).sum()))
    if order <= 3:  # short of the ill-conditioned range, scipy's design to rounding
        np.testing.assert_allclose(
            savgol_coeffs(window, order), scipy_coeffs(window, order, use="conv"), atol=1e-12
        )


def _noisy(x_noise=0.02, n_per=400, cycles=10, seed=2):
    rng = np.random.default_rng(seed)
    f, A = 5.0, 1e-5
    t = np.arange(cycles * n_per) / (n_per * f)
    ramp = 0.5 - 0.5 * np.cos(np.pi * np.clip(t * f, 0, 1))
    x = A * ramp * np.sin(2 * np.pi * f * t)
    v = np.gradient(x, t)
    d = Prepared.build(t, x + rng.normal(0.0, x_noise * A, t.size), 40.0 * np.tanh(4e4 * x))
    FAM.prepare(d)
    return d, v


def test_the_dashpot_velocity_carries_less_noise_and_no_loss_of_the_drive():
    d, v = _noisy()
    steady = d.cycles.cycle >= 1
    ref = float(np.sqrt(np.mean(v[steady] ** 2)))
    err_new = float(np.sqrt(np.mean((dashpot_velocity(d) - v)[steady] ** 2))) / ref
    err_old = float(np.sqrt(np.mean((smoothed_velocity(d) - v)[steady] ** 2))) / ref
    assert err_new < 0.5 * err_old
    # regression dilution: the slope of the true velocity on the regressor stays near 1
    vs = dashpot_velocity(d)[steady]
    slope = float(np.dot(vs, v[steady]) / np.dot(vs, vs))
    assert slope == pytest.approx(1.0, abs=0.01)


def test_the_dashpot_term_is_c_times_its_velocity():
    d, _ = _noisy()
    p = {"h0": 40.0, "ac": 4e4, "c": 300.0}
    diff = FAM.predict(p, ("viscous_damping",), d) - FAM.predict(p, (), d)
    np.testing.assert_allclose(diff, 300.0 * dashpot_velocity(d), atol=1e-9)


@pytest.mark.parametrize(("regime", "refused"), [("transition", False), ("gross sliding", True)])
def test_a_transition_is_anchored_at_its_initial_stiffness(regime, refused):
    # a dashpot's loop area read by the base as the way to gross sliding: the effect moves
    # h0 from 24 to 39 N at the same initial stiffness h0·ac
    base = {"h0": 24.0, "ac": 8.0e4}
    p = {"h0": 39.0, "ac": 24.0 * 8.0e4 / 39.0, "c": 1800.0}
    why = _takes_over(FAM, base, p, ("viscous_damping",), 1.0, regime=regime)
    assert (why is not None) is refused
    # the stiffness anchor still refuses a change of the initial stiffness
    q = {"h0": 39.0, "ac": 8.0e4, "c": 1800.0}
    assert _takes_over(FAM, base, q, ("viscous_damping",), 1.0, regime=regime) is not None
