"""The rig simulator (contactlab.synthetic.rig) against closed forms and independent routes."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import signal

import contactlab
from contactlab.errors import InputError
from contactlab.synthetic.rig import (
    Virgin,
    butterworth,
    discretise,
    group_delay,
    load_cell,
    masing_force,
    play_operator,
    rig_recording,
    segalman_parameters,
)

H0, AC = 40.0, 4.0e4


def _cycle(A, n=20001, cycles=3):
    """Symmetric sine from rest; the last cycle's samples."""
    th = np.linspace(0.0, 2 * math.pi * cycles, cycles * (n - 1) + 1)
    x = A * np.sin(th)
    return x, slice(-n, None)


def _area(x, F):
    return float(np.sum(0.5 * (F[1:] + F[:-1]) * np.diff(x)))


@pytest.mark.parametrize("acA", [0.05, 0.7, 3.0, 12.0])
def test_masing_loop_energy_closed_form(acA):
    A = acA / AC
    x, last = _cycle(A)
    F, _ = masing_force(x, Virgin.exponential(H0, AC))
    E = _area(x[last], F[last])
    hm = H0 * (1 - math.exp(-AC * A))
    E_an = 8 * (H0 * (A - (1 - math.exp(-AC * A)) / AC) - A * hm / 2)
    assert E == pytest.approx(E_an, rel=2e-6)
    # the tips of the steady loop are ±f(A)
    assert F[last].max() == pytest.approx(hm, rel=1e-9)
    assert F[last].min() == pytest.approx(-hm, rel=1e-9)


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**31 - 1), st.integers(5, 400))
def test_masing_equals_package_operator_on_random_histories(seed, n):
    rng = np.random.default_rng(seed)
    x = np.cumsum(rng.standard_normal(n)) * 20e-6
    F, U = masing_force(x, Virgin.exponential(H0, AC))
    assert np.array_equal(U, x)
    F_pkg = contactlab.Masing(h0=H0, ac=AC).force(x)
    np.testing.assert_allclose(F, F_pkg, rtol=0, atol=1e-12 * H0)
    # odd symmetry
    Fm, _ = masing_force(-x, Virgin.exponential(H0, AC))
    np.testing.assert_allclose(Fm, -F, rtol=0, atol=1e-12 * H0)


def test_return_point_memory_and_extra_samples():
    # big half cycle, an inner loop, then past the inner loop's start
    pieces = [(0, 60e-6, 61), (60e-6, 10e-6, 51), (10e-6, 30e-6, 21)]
    x = np.concatenate([np.linspace(*p)[1 if i else 0 :] for i, p in enumerate(pieces)])
    i_start = x.size - 1  # at 30 µm before the inner loop
    inner = [(30e-6, 20e-6, 11), (20e-6, 30e-6, 11)]
    x = np.concatenate([x, *[np.linspace(*p)[1:] for p in inner]])
    i_back = x.size - 1  # back at 30 µm after it
    x = np.concatenate([x, np.linspace(30e-6, -60e-6, 91)[1:]])
    F, _ = masing_force(x, Virgin.exponential(H0, AC))
    assert F[i_back] == pytest.approx(F[i_start], abs=1e-12)
    # the descent to −60 µm rejoins the virgin curve (mirror of the largest excursion)
    assert F[-1] == pytest.approx(-H0 * (1 - math.exp(-AC * 60e-6)), rel=1e-12)
    # inserting samples on a monotone stretch changes nothing at the original ones
    xi = np.insert(x, 30, 0.5 * (x[29] + x[30]))
    Fi, _ = masing_force(xi, Virgin.exponential(H0, AC))
    np.testing.assert_allclose(np.delete(Fi, 30), F, rtol=0, atol=1e-12)


def test_non_masing_scaling_is_a_shifted_masing_loop():
    lam, A = 1.5, 2.0 / AC
    x, last = _cycle(A, n=4001, cycles=3)
    F, _ = masing_force(x, Virgin.exponential(H0, AC), lam=lam)
    f = Virgin.exponential(H0, AC)
    hm = float(f(np.array([A]))[0])
    D = lam * float(f(np.array([2 * A / lam]))[0])
    assert F[last].max() == pytest.approx(hm, rel=1e-9)
    assert F[last].min() == pytest.approx(hm - D, rel=1e-9)
    # closed after the first half cycle: cycles 2 and 3 are identical
    np.testing.assert_allclose(F[last], F[4000:8001], rtol=0, atol=1e-12)
    # every branch after the first is a Masing branch of (λ h0/2, 2 ac/λ) shifted by F_c
    Fc = hm - D / 2
    Fm, _ = masing_force(x, Virgin.exponential(lam * H0 / 2, 2 * AC / lam))
    np.testing.assert_allclose(F[last] - Fc, Fm[last], rtol=0, atol=1e-9 * H0)


@pytest.mark.parametrize("chi", [-0.8, -0.47, -0.2])
def test_segalman_dissipation_power_law(chi):
    F_S, K_T, beta = H0, H0 * AC, 0.3
    phi_max, R, _S = segalman_parameters(F_S, K_T, chi, beta)
    v = Virgin.segalman(F_S, K_T, chi, beta)
    assert float(v(np.array([phi_max]))[0]) == pytest.approx(F_S, rel=1e-12)
    for A in (0.05 * phi_max, 0.5 * phi_max):
        x, last = _cycle(A, n=40001, cycles=2)
        F, _ = masing_force(x, v)
        D_an = 4 * R * A ** (chi + 3) / ((chi + 2) * (chi + 3))
        assert _area(x[last], F[last]) == pytest.approx(D_an, rel=1e-4)


def test_series_compliance_solves_the_series_equation():
    k_s = 0.5 * H0 * AC
    x, _ = _cycle(3.0 / AC, n=801, cycles=2)
    F, u = masing_force(x, Virgin.exponential(H0, AC), k_s=k_s)
    np.testing.assert_allclose(u + F / k_s, x, rtol=0, atol=1e-13 * np.max(np.abs(x)))
    F_contact, _ = masing_force(u, Virgin.exponential(H0, AC))
    np.testing.assert_allclose(F, F_contact, rtol=0, atol=1e-9 * H0)
    # the branch starts with the series slope 1/(1/(h0 ac) + 1/k_s)
    k_eff = 1 / (1 / (H0 * AC) + 1 / k_s)
    assert (F[2] - F[1]) / (x[2] - x[1]) == pytest.approx(k_eff, rel=2e-2)


def test_play_operator_dead_band():
    x, _ = _cycle(1.0, n=201, cycles=2)
    b = 0.2
    u = play_operator(x, b)
    assert np.all(np.abs(x - u) <= b + 1e-15)
    du = np.diff(u)
    # u moves only while the band is taken up, and never against x
    moving = np.abs(du) > 0
    assert np.all(np.abs(np.abs(x[1:] - u[1:])[moving] - b) < 1e-12)
    assert np.all(du * np.diff(x) >= 0)


def test_filters_against_their_analytic_responses():
    fc = 400.0
    dt = 1 / (40 * fc)
    t = np.arange(40000) * dt
    for ba, name in ((butterworth(fc), "aa"), (load_cell(1000.0, 0.05), "cell")):
        for f in (20.0, 120.0, 300.0):
            u = np.sin(2 * math.pi * f * t)
            b, a = discretise(ba, dt)
            y = signal.lfilter(b, a, u)
            m = t > t[-1] / 2
            X = np.column_stack([np.sin(2 * math.pi * f * t[m]), np.cos(2 * math.pi * f * t[m])])
            cs, cc = np.linalg.lstsq(X, y[m], rcond=None)[0]
            gain, phase = math.hypot(cs, cc), math.atan2(cc, cs)
            if name == "cell":  # closed form 1/(1 − r² + 2iζr)
                r = f / 1000.0
                H = 1 / complex(1 - r * r, 2 * 0.05 * r)
            else:  # Butterworth: |H| = 1/sqrt(1 + (f/fc)^8); phase from the poles
                poles = [
                    complex(
                        -math.sin((2 * k - 1) * math.pi / 8), math.cos((2 * k - 1) * math.pi / 8)
                    )
                    for k in range(1, 5)
                ]
                s = complex(0, f / fc)
                H = 1 / np.prod([s - p for p in poles]) * np.prod([-p for p in poles])
                assert abs(H) == pytest.approx(1 / math.sqrt(1 + (f / fc) ** 8), rel=1e-12)
            assert gain == pytest.approx(abs(H), rel=2e-3)
            assert phase == pytest.approx(np.angle(H), abs=2e-3)
    # low-frequency group delay: −dφ/dω at ω → 0
    for ba in (butterworth(fc), load_cell(1000.0, 0.05)):
        w = 2 * math.pi * 1e-3
        _, H = signal.freqs(*ba, worN=[w])
        assert group_delay(ba) == pytest.approx(-np.angle(H[0]) / w, rel=1e-6)


def test_determinism_and_independent_noise_streams():
    kw = {"fs": 2000.0, "f": 10.0, "cycles": 5, "acA": 1.5}
    a = rig_recording({"force_offset": {"F0": 1.0}}, seed=7, **kw)
    b = rig_recording({"force_offset": {"F0": 1.0}}, seed=7, **kw)
    c = rig_recording({"force_offset": {"F0": 1.0}}, seed=8, **kw)
    assert np.array_equal(a.x, b.x) and np.array_equal(a.F, b.F)
    assert not np.array_equal(a.F, c.F)
    clean = rig_recording(
        {"force_offset": {"F0": 1.0}}, seed=7, x_noise=0.0, F_noise=0.0, bits=None, **kw
    )
    noisy = rig_recording(
        {"force_offset": {"F0": 1.0}}, seed=7, x_noise=0.02, F_noise=0.01, bits=None, **kw
    )
    nx, nF = noisy.x - clean.x, noisy.F - clean.F
    assert np.std(nx) == pytest.approx(0.02 * noisy.truth["base"]["A"], rel=0.1)
    assert np.std(nF) == pytest.approx(noisy.truth["chain"]["noise_rms"]["F"], rel=0.1)
    assert abs(np.corrcoef(nx, nF)[0, 1]) < 0.1
    # starts from rest: first samples at zero displacement, force at the offset
    assert abs(clean.x[0]) < 1e-12 and clean.F[0] == pytest.approx(1.0, abs=1e-9)


def test_channel_delay_shifts_the_force_channel():
    kw = {
        "fs": 4000.0,
        "f": 10.0,
        "cycles": 4,
        "acA": 1.0,
        "x_noise": 0.0,
        "F_noise": 0.0,
        "bits": None,
    }
    base = rig_recording({}, seed=1, **kw)
    tau = 1.5e-3
    d = rig_recording({"channel_delay": {"tau": tau}}, seed=1, **kw)
    np.testing.assert_array_equal(d.x, base.x)
    ref = np.interp(d.t - tau, base.t, base.F)
    m = d.t > 0.05
    assert np.max(np.abs(d.F[m] - ref[m])) < 2e-3 * np.max(np.abs(base.F))


def test_normal_kelvin_voigt_steady_state_and_two_integrators():
    kw = {
        "kind": "normal",
        "fs": 2000.0,
        "f": 5.0,
        "cycles": 8,
        "x_noise": 0.0,
        "F_noise": 0.0,
        "bits": None,
    }
    r = rig_recording(**kw, seed=2)
    k, psi, f = 1.3e12, 0.0887, 5.0
    w = 2 * math.pi * f
    c = psi * k / (2 * math.pi * w)
    m = r.t > 0.8
    X = np.column_stack([np.sin(w * r.t[m]), np.cos(w * r.t[m]), np.ones(m.sum())])
    cd = np.linalg.lstsq(X, r.delta[m], rcond=None)[0]
    cp = np.linalg.lstsq(X, r.p[m], rcond=None)[0]
    amp = math.hypot(cd[0], cd[1]) / math.hypot(cp[0], cp[1])
    lag = math.atan2(-cd[1], cd[0]) - math.atan2(-cp[1], cp[0])
    assert amp == pytest.approx(1 / math.hypot(k, c * w), rel=1e-4)
    skew = r.truth["chain"]["channel_skew"]
    assert lag == pytest.approx(math.atan(c * w / k) + w * skew, abs=2e-5)
    # the implicit integrator (taken for nonlinear laws) agrees with the exact linear recurrence
    r2 = rig_recording(effects={"asymmetric_branches": {"a": 1e-12}}, **kw, seed=2)
    np.testing.assert_allclose(r2.delta, r.delta, rtol=0, atol=1e-5 * np.max(np.abs(r.delta)))


def test_bad_input_is_named():
    with pytest.raises(InputError, match="unknown effect 'wobble'"):
        rig_recording({"wobble": {}})
    with pytest.raises(InputError, match="no parameter 'tau'"):
        rig_recording({"force_offset": {"tau": 1.0}})
    with pytest.raises(InputError, match="fs >= 8 f"):
        rig_recording(fs=100.0, f=50.0)
    with pytest.raises(InputError, match="chi"):
        segalman_parameters(1.0, 1.0, 0.5, 0.0)
