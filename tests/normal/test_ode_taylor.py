"""The normal-contact ODE's Taylor route (issue 33) against independent routes: scipy's
``solve_ivp`` (DOP853 at rtol 1e-12, on the same cubic-Hermite continuation of p) for the
nonlinear Table 2 model with 1 % noise on p, the closed-form Kelvin-Voigt response with its
start-up transient, and the RODAS4 route of the same core."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicHermiteSpline

from contactlab.errors import InputError
from contactlab.normal import KelvinVoigt, NonlinearContact

A_T2 = np.array([1.32596e12, 1.59811e18, 2.92127e24, 2.87416e30])
PSI, PA = 0.0887, 0.4e6


def noisy_record(periods: int, spc: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(periods * spc + 1) * (2 * np.pi / spc)
    rng = np.random.default_rng(seed)
    return t, PA * np.sin(t) + 0.01 * PA * rng.standard_normal(t.size)


def scipy_reference(t: np.ndarray, p: np.ndarray, delta0: float) -> np.ndarray:
    spl = CubicHermiteSpline(t, p, np.gradient(p, t, edge_order=2))
    r = 2 * np.pi / PSI

    def rhs(tt, y):
        k = np.polynomial.polynomial.polyval(y[0], A_T2)
        return [r * (spl(tt) / k - y[0])]

    # Steps stop at every sample (the continuation is only C1 there).
    out = [delta0]
    y = delta0
    for i in range(t.size - 1):
        sol = solve_ivp(rhs, (t[i], t[i + 1]), [y], method="DOP853", rtol=1e-12, atol=1e-22)
        y = float(sol.y[0, -1])
        out.append(y)
    return np.array(out)


@pytest.mark.parametrize("seed", [11, 12])
def test_noisy_nonlinear_matches_dop853(seed):
    t, p = noisy_record(2, 64, seed)  # coarse: 64 samples per period, r Δt = 6.9
    m = NonlinearContact(k_s_delta=A_T2, psi=PSI, omega=1.0)
    ref = scipy_reference(t, p, 0.0)
    scale = np.max(np.abs(ref))
    for rtol, bound in ((1e-10, 1e-9), (1e-7, 1e-6)):
        res = m.simulate(t, p, rtol=rtol, delta0=0.0)
        assert res.success
        assert res.njev == 0  # every interval by Taylor steps
        err = np.max(np.abs(res.delta - ref)) / scale
        assert err < bound, (rtol, err)


def test_kelvin_voigt_closed_form_with_transient():
    # p = pa sin ωt with exact slopes; the cubic continuation's own error is ~(ωΔt)^4/384.
    k, w = 1.206e12, 2.0
    kv = KelvinVoigt(k=k, psi=PSI, omega=w)
    t = np.arange(3 * 1024 + 1) * (2 * np.pi / w / 1024)
    p, dp = PA * np.sin(w * t), PA * w * np.cos(w * t)
    d0 = 0.2e-6
    res = kv.simulate(t, p, dpdt=dp, delta0=d0, rtol=1e-12)
    r = 2 * np.pi * w / PSI
    amp, phi = kv.amplitude(PA), kv.phase
    exact = amp * np.sin(w * t - phi) + (d0 + amp * np.sin(phi)) * np.exp(-r * t)
    assert np.max(np.abs(res.delta - exact)) < 1e-9 * amp
    v_exact = amp * w * np.cos(w * t - phi) - r * (d0 + amp * np.sin(phi)) * np.exp(-r * t)
    assert np.max(np.abs(res.velocity - v_exact)) < 1e-7 * np.max(np.abs(v_exact))


def test_auto_agrees_with_rodas4_and_takes_one_step_a_sample():
    t, p = noisy_record(4, 256, 3)
    m = NonlinearContact(k_s_delta=A_T2, psi=PSI, omega=1.0)
    a = m.simulate(t, p, rtol=1e-11, delta0=0.0)
    b = m.simulate(t, p, rtol=1e-11, delta0=0.0, method="rodas4")
    assert np.max(np.abs(a.delta - b.delta)) < 1e-9 * np.max(np.abs(b.delta))
    c = m.simulate(t, p, rtol=1e-7, delta0=0.0)
    assert c.n_steps <= 1.1 * (t.size - 1) and c.nfev > c.n_steps
    with pytest.raises(InputError, match="method"):
        m.simulate(t, p, method="rk45")


def test_stiff_interval_falls_back_to_rodas4():
    # ψ = 1e-6: r Δt ≈ 2.5e5 per interval, far past the Taylor sub-steps.
    kv = KelvinVoigt(k=1.0e12, psi=1e-6, omega=1.0)
    t = np.arange(257) * (2 * np.pi / 64)
    res = kv.simulate(t, PA * np.sin(t), delta0=0.0)
    assert res.success and res.njev > 0
    assert np.max(np.abs(res.delta[8:] - PA * np.sin(t[8:]) / 1.0e12)) < 1e-4 * PA / 1.0e12
