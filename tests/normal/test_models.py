"""Kelvin-Voigt and nonlinear contact models (Konowalski 2009, eqs. 8-17) and the integrator."""

from __future__ import annotations

import numpy as np
import pytest

import contactlab
from contactlab.normal import KelvinVoigt, NonlinearContact, OdeResult
from contactlab.synthetic.normal import table2_model

A_T2 = np.array([1.32596e12, 1.59811e18, 2.92127e24, 2.87416e30])  # Table 2 k_s(δ), SI


def sine(n_cycles: int, per: int, w: float = 1.0, pa: float = 0.4e6):
    t = np.arange(n_cycles * per + 1) * (2 * np.pi / w / per)
    return t, pa * np.sin(w * t), pa * w * np.cos(w * t)


def test_kelvin_voigt_analytic_quantities_by_hand():
    kv = KelvinVoigt(1.206e12, 0.0887, 1.0)
    g = 0.0887 / (2 * np.pi)
    assert kv.h == pytest.approx(0.0887 * 1.206e12 / (2 * np.pi), rel=1e-15)
    # eq. 11 and eq. 14 give the same K; eq. 12 and eq. 15 the same φ.
    k11 = 0.4e6 / np.hypot(1.206e12, kv.h * 1.0)
    assert kv.amplitude(0.4e6) == pytest.approx(k11, rel=1e-14)
    assert kv.amplitude(0.4e6) == pytest.approx(0.4e6 / 1.206e12 / np.sqrt(1 + g * g), rel=1e-14)
    assert kv.phase == pytest.approx(np.arctan(kv.h / 1.206e12), rel=1e-14)
    e_pu = 0.5 * 1.206e12 * kv.amplitude(0.4e6) ** 2
    assert kv.loop_energy(0.4e6) / e_pu == pytest.approx(0.0887, rel=1e-13)
    a = kv.analytic(0.4e6)
    assert a["K"] == kv.amplitude(0.4e6) and a["phi"] == kv.phase and a["h"] == kv.h


@pytest.mark.parametrize("w", [1.0, 2 * np.pi * 10])
def test_kelvin_voigt_converges_to_the_analytic_steady_state(w):
    kv = KelvinVoigt(1.206e12, 0.0887, w)
    t, p, dp = sine(6, 512, w)
    res = kv.simulate(t, p, dpdt=dp, rtol=1e-10)
    assert res.success and res.status == 0
    d_ss, v_ss = kv.steady_state(t, 0.4e6)
    K = kv.amplitude(0.4e6)
    late = slice(2 * 512, None)
    assert np.max(np.abs(res.delta[late] - d_ss[late])) < 1e-8 * K
    assert np.max(np.abs(res.velocity[late] - v_ss[late])) < 1e-8 * K * w


def test_stable_and_accurate_at_256_samples_per_period():
    # The paper's sampling: 256 per period, ψ = 0.0887 (time constant 0.014 s vs Δt = 0.025 s).
    m = NonlinearContact(k_s_delta=A_T2, psi=0.0887, omega=1.0)
    t, p, _dp = sine(16, 256)
    ref = m.simulate(t, p, rtol=1e-13, atol=1e-22)
    for rtol in (1e-6, 1e-8):
        res = m.simulate(t, p, rtol=rtol)
        err = np.max(np.abs(res.delta - ref.delta)) / np.max(np.abs(ref.delta))
        assert err < 20 * rtol
        assert res.n_steps >= t.size - 1


def test_very_stiff_case_does_not_blow_up():
    # Time constant 1e-5 of the sample interval: explicit RK4 on this grid would diverge.
    m = NonlinearContact(k_s_delta=A_T2, psi=1e-6, omega=1.0)
    t, p, _ = sine(3, 64)
    res = m.simulate(t, p, delta0=1e-6)
    assert res.success
    eq = np.array([m.equilibrium(v) for v in p])
    assert np.max(np.abs(res.delta[8:] - eq[8:])) < 1e-3 * np.max(np.abs(eq))


def test_explicit_rk4_on_the_sample_grid_is_unstable_where_the_core_is_not():
    # δ' = r (p/k - δ); RK4 is stable for r Δt < 2.785. ψ = 0.05 at 256 samples/period:
    # r Δt = 2π ω Δt / ψ = 3.08.
    psi, k = 0.05, 1.3e12
    t, p, _ = sine(6, 256)
    r, dt = 2 * np.pi / psi, t[1] - t[0]
    y = np.zeros_like(t)
    pm = 0.5 * (p[1:] + p[:-1])
    for i in range(t.size - 1):
        f = lambda pp, yy: r * (pp / k - yy)  # noqa: E731
        k1 = f(p[i], y[i])
        k2 = f(pm[i], y[i] + 0.5 * dt * k1)
        k3 = f(pm[i], y[i] + 0.5 * dt * k2)
        k4 = f(p[i + 1], y[i] + dt * k3)
        y[i + 1] = y[i] + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    kv = KelvinVoigt(k, psi, 1.0)
    res = kv.simulate(t, p)
    K = kv.amplitude(0.4e6)
    assert np.max(np.abs(y[-256:])) > 10 * K  # RK4 has diverged
    assert np.max(np.abs(res.delta[-256:])) < 1.01 * K


def test_pressure_law_with_constant_stiffness_equals_kelvin_voigt():
    t, p, dp = sine(4, 256)
    kv = KelvinVoigt(1.3e12, 0.09, 1.0).simulate(t, p, dpdt=dp, rtol=1e-10)
    nl = NonlinearContact(b=[0.0, 0.0, 0.0, 1.3e12], psi=0.09, omega=1.0)
    res = nl.simulate(t, p, dpdt=dp, rtol=1e-10)
    np.testing.assert_allclose(res.delta, kv.delta, rtol=0, atol=1e-9 * np.abs(kv.delta).max())


def test_pressure_law_matches_delta_law_on_the_centre_curve():
    # k_s(p) fitted along the Table 2 centre curve reproduces the k_s(δ) model closely.
    from contactlab.normal import fit_pressure_stiffness
    from contactlab.synthetic.normal import synthetic_recording

    fit = fit_pressure_stiffness([synthetic_recording(n_cycles=4, noise=None)])
    m_p = fit.model(0.5e6)
    m_d = table2_model()
    t, p, dp = sine(4, 256)
    a = m_p.simulate(t, p, dpdt=dp, p0=0.0)
    b = m_d.simulate(t, p, dpdt=dp, p0=0.0)
    assert np.max(np.abs(a.delta - b.delta)) < 0.01 * np.ptp(b.delta)


def test_equilibrium_start_and_ode_result_fields():
    m = table2_model(p0=None)
    t, p, _ = sine(2, 128)
    p = p + 0.1e6  # starts off zero
    res = m.simulate(t, p)
    assert isinstance(res, OdeResult)
    assert res.delta[0] == pytest.approx(m.equilibrium(0.1e6), rel=1e-12)
    c = m.k_s(delta=res.delta[0])
    assert c * res.delta[0] == pytest.approx(0.1e6, rel=1e-10)
    assert res.y.shape == (1, t.size)
    assert res.nfev > res.n_steps >= t.size - 1 and res.njev == res.nlu
    assert "successfully" in res.message
    assert "OdeResult(success=True" in repr(res)


def test_linear_interpolation_and_p0_handling():
    m = NonlinearContact(k_s_delta=A_T2, psi=0.2, omega=1.0, p0=0.5e6)
    t, p, _ = sine(3, 256)
    a = m.simulate(t, p + 0.5e6, interp="linear")
    b = m.simulate(t, p, p0=0.0)
    assert a.success and b.success
    assert np.max(np.abs(a.delta - b.delta)) < 1e-3 * np.ptp(b.delta)


def test_failed_solve_reports_instead_of_raising():
    m = KelvinVoigt(1.2e12, 0.1, 1.0)
    t, p, _ = sine(2, 64)
    res = m.simulate(t, p, max_steps=20)
    assert not res.success and res.status == -1
    assert "Maximum number of steps" in res.message
    assert res.t.size == res.delta.size == res.velocity.size < t.size
    assert np.all(np.isfinite(res.delta))


def test_long_signal():
    m = table2_model(p0=None)
    t, p, dp = sine(2000, 256)  # 512 001 samples
    res = m.simulate(t, p, dpdt=dp)
    assert res.success and res.delta.size == t.size
    assert np.all(np.isfinite(res.delta))


@pytest.mark.parametrize(
    ("make", "match"),
    [
        (lambda: KelvinVoigt(1e12, 0.0, 1.0), "psi"),
        (lambda: KelvinVoigt(1e12, -0.1, 1.0), "psi"),
        (lambda: KelvinVoigt(-1e12, 0.1, 1.0), "k"),
        (lambda: KelvinVoigt(1e12, 0.1, np.nan), "omega"),
        (lambda: NonlinearContact(k_s_delta=A_T2, psi=0.0, omega=1.0), "psi"),
        (lambda: NonlinearContact(psi=0.1, omega=1.0), "exactly one"),
        (
            lambda: NonlinearContact(k_s_delta=A_T2, b=[1, 2, 3, 4], psi=0.1, omega=1.0),
            "exactly one",
        ),
        (lambda: NonlinearContact(k_s_delta=A_T2, omega=1.0), "required"),
        (lambda: NonlinearContact(k_s_delta=[-1e12, 1e18], psi=0.1, omega=1.0), "a1"),
        (lambda: NonlinearContact(b=[0, 0, 1e6, -1.0], psi=0.1, omega=1.0), "b4"),
        (
            lambda: NonlinearContact(
                k_s_delta=[1e12, 1e19], psi=0.1, omega=1.0, delta_range=(-0.5e-6, 0.5e-6)
            ),
            "not positive",
        ),
    ],
)
def test_bad_models_raise(make, match):
    with pytest.raises(contactlab.InputError, match=match):
        make()


def test_bad_simulation_input_raises():
    m = KelvinVoigt(1.2e12, 0.1, 1.0)
    t, p, _ = sine(2, 64)
    with pytest.raises(contactlab.InputError, match="samples"):
        m.simulate(t, p[:-1])
    bad = p.copy()
    bad[7] = np.nan
    with pytest.raises(contactlab.InputError, match=r"p\[7\]"):
        m.simulate(t, bad)
    tt = t.copy()
    tt[5] = tt[4]
    with pytest.raises(contactlab.InputError, match="increasing"):
        m.simulate(tt, p)
    with pytest.raises(contactlab.InputError, match="interp"):
        m.simulate(t, p, interp="quadratic")
    with pytest.raises(contactlab.InputError, match="rtol"):
        m.simulate(t, p, rtol=0.0)


def test_stiffness_that_turns_negative_is_reported():
    # k_s(δ) = 1e12 + 5e18 δ vanishes at δ = -0.2 µm, inside the response.
    # There is no equilibrium below -0.2 MPa: δ runs into the singularity and the solve
    # stops with success=False and a message that says why.
    m = NonlinearContact(k_s_delta=[1e12, 5e18], psi=0.1, omega=1.0)
    t, p, _ = sine(2, 256)
    res = m.simulate(t, p)
    assert not res.success
    assert "not positive" in res.message
    assert np.all(np.isfinite(res.delta))
    mp = NonlinearContact(b=[0.0, 0.0, 4e6, 1e12], psi=0.1, omega=1.0)
    with pytest.raises(contactlab.InputError, match="k_s\\(p\\) is not positive at sample"):
        mp.simulate(t, p)


def test_extrapolation_and_separation_warn():
    m = NonlinearContact(k_s_delta=A_T2, psi=0.2, omega=1.0, delta_range=(-0.1e-6, 0.1e-6))
    t, p, _ = sine(2, 128)
    with pytest.warns(contactlab.ContactLabWarning, match="extrapolated"):
        m.simulate(t, p)
    kv = KelvinVoigt(1.2e12, 0.1, 1.0, p0=0.3e6)
    with pytest.warns(contactlab.ContactLabWarning, match="separate"):
        kv.simulate(t, p + 0.3e6)


def test_default_step_cap_ends_a_run_with_a_message(monkeypatch):
    # the default cap (per sample plus a base) is passed to the integrator: with a cap of 3
    # attempts the run stops with success False and says why, instead of running on
    from contactlab.normal import models

    t = np.linspace(0.0, 2 * np.pi, 400)
    kv = KelvinVoigt(1.3e12, 0.09, 1.0)
    assert kv.simulate(t, 0.4e6 * np.sin(t)).success  # the default suffices for a record
    monkeypatch.setattr(models, "AUTO_STEPS_PER_SAMPLE", 0)
    monkeypatch.setattr(models, "AUTO_STEPS_BASE", 3)
    r = kv.simulate(t, 0.4e6 * np.sin(t))
    assert not r.success and r.t.size < t.size and r.message
    assert kv.simulate(t, 0.4e6 * np.sin(t), max_steps=0).success  # 0: no cap, as before
