"""Structures with joints: the integrator against closed forms, energy balance, the Masing
joint against ``Masing.force``, modes, periodic steady state, persistence and bad input."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import contactlab
from contactlab.structure import Structure, iwan_uniform, modes


def _quasi_static(joint: str, amp: float, **params: float) -> tuple[Structure, object]:
    """A light mass tied to a slowly moving base by a stiff spring, the joint to ground: the
    joint is driven quasi-statically through 3 cycles of amplitude ~``amp``."""
    s = Structure(1e-3, 300.0, 1e7)  # the stiff tie overdamped (ζ = 1.5): no jitter
    s.add_joint(joint, 0, **params)
    t = np.linspace(0.0, 3.0, 6001)
    y = amp * np.sin(2 * np.pi * t)
    # fixed steps: the tie's mode (~1e5 rad/s) is far beyond the sample rate; the A-stable
    # trapezoidal rule steps over it smoothly, while error control leaves sub-sample jitter of
    # ~3e-4 relative at the turning points, enough to move a Masing loop's closure there
    yd = amp * 2 * np.pi * np.cos(2 * np.pi * t)
    return s, s.simulate(t, base=y, base_velocity=yd, substeps=1)


def test_linear_sdof_free_response_matches_closed_form():
    m, c, k, x0, v0 = 2.0, 4.0, 800.0, 1e-3, 0.02
    t = np.linspace(0, 2, 8001)
    r = Structure(m, c, k).simulate(t, x0=[x0], v0=[v0])
    wn, z = np.sqrt(k / m), c / (2 * np.sqrt(k * m))
    wd = wn * np.sqrt(1 - z * z)
    xe = np.exp(-z * wn * t) * (x0 * np.cos(wd * t) + (v0 + z * wn * x0) / wd * np.sin(wd * t))
    err = np.max(np.abs(r.x - xe)) / x0
    # Newmark's period error (ωh)²/12 over 6 periods: ~3e-5 relative here
    assert r.success and err < 5e-5, err


def test_linear_sdof_forced_steady_state_matches_closed_form():
    m, c, k, f0, w = 2.0, 4.0, 800.0, 3.0, 15.0
    t = np.linspace(0, 2 * np.pi / w, 401)[:-1]
    r = Structure(m, c, k).simulate(t, force=f0 * np.sin(w * t), periodic=True)
    H = 1.0 / (k - m * w * w + 1j * c * w)
    xe = np.imag(f0 * H * np.exp(1j * w * t))
    assert r.success
    assert np.max(np.abs(r.x - xe)) < 2e-3 * np.abs(f0 * H)


@pytest.mark.parametrize("fs,kj", [(1.0, 2e4), (0.3, 5e3)])
def test_jenkins_quasi_static_loop_energy(fs, kj):
    _s, r = _quasi_static("jenkins", 4 * fs / kj, k=kj, fs=fs)
    n = 2000  # one cycle per 2000 samples; use the last (steady) cycle
    x, e = r.x[-n - 1 :], r.joint_energy[-n - 1 :, 0]
    A = 0.5 * (x.max() - x.min())
    expected = 4 * fs * (A - fs / kj)
    assert abs((e[-1] - e[0]) - expected) < 1e-4 * expected


@given(h0=st.floats(5.0, 80.0), ac=st.floats(1e4, 1e5), scale=st.floats(1.5, 3.0))
@settings(max_examples=8, deadline=None)
def test_masing_joint_matches_masing_force(h0, ac, scale):
    amp = 2.0 / ac
    _s, r = _quasi_static("masing", amp, h0=h0, ac=ac, scale=scale)
    ref = contactlab.Masing(h0, ac, scale=scale).force(r.x)
    # the integrator also visits the reversal points between samples; at the sampled
    # turning points that shifts the remembered reversal by at most O(h²) in x
    assert np.max(np.abs(r.joint_force[:, 0] - ref)) < 1e-5 * h0


def _balance(s: Structure, r) -> float:
    ke = r.kinetic_energy(s.M)
    se = r.strain_energy(s.K)
    left = r.input_work
    right = ke - ke[0] + se - se[0] + r.damping_work + r.joint_work.sum(axis=1)
    return float(np.max(np.abs(left - right)) / np.max(np.abs(left)))


@pytest.mark.parametrize(
    "joint,params",
    [
        ("jenkins", {"k": 300.0, "fs": 1.0}),
        ("masing", {"h0": 2.0, "ac": 200.0}),
        ("iwan", iwan_uniform(300.0, 1.5, 10)),
        ("bouc_wen", {"alpha": 300.0, "beta": 1.0, "gamma": 20.0, "delta": -5.0, "nu": 1.3}),
        ("kelvin_voigt", {"k": 100.0, "c": 0.5}),
        ("normal", {"coeffs": [200.0, 0.0, 4e4]}),
    ],
)
def test_energy_balance_two_dofs(joint, params):
    s = Structure(np.diag([1.0, 0.5]), [[0.3, -0.1], [-0.1, 0.2]], [[900.0, -400], [-400, 400]])
    s.add_joint(joint, 1, 0, **params)
    s.add_joint("jenkins", 0, k=200.0, fs=0.8)
    t = np.linspace(0, 4, 4001)
    rng = np.random.default_rng(20251)
    f = np.zeros((t.size, 2))
    f[:, 1] = 6 * np.sin(2 * np.pi * 2.5 * t) + rng.normal(0, 1, t.size)
    r = s.simulate(t, force=f, x0=[0.002, -0.001])
    assert r.success
    assert _balance(s, r) < 1e-6
    # dissipation never decreases over a closed cycle and is never negative at the end
    assert r.joint_energy[-1, 1] > 0


def test_energy_balance_base_excitation():
    s = Structure(3.0, 0.7, 1200.0)
    s.add_joint("jenkins", 0, k=5e3, fs=1.0)
    t = np.linspace(0, 5, 2501)
    r = s.simulate(t, base=0.01 * np.sin(2 * np.pi * t))
    assert r.success and _balance(s, r) < 1e-6


def test_modes_two_dof_closed_form():
    m, k = 1.5, 1000.0
    s = Structure(np.diag([m, m]), np.zeros((2, 2)), [[2 * k, -k], [-k, k]])
    md = s.modes()
    w = np.sqrt(k / m * np.array([(3 - np.sqrt(5)) / 2, (3 + np.sqrt(5)) / 2]))
    np.testing.assert_allclose(md.frequency_hz, w / (2 * np.pi), rtol=1e-12)
    np.testing.assert_allclose(md.shapes.T @ s.M @ md.shapes, np.eye(2), atol=1e-12)
    # a joint adds its initial tangent stiffness; Rayleigh damping gives ζ = (a/ω + bω)/2
    s2 = Structure(np.diag([m, m]), 0.02 * np.array([[2 * k, -k], [-k, k]]), [[k, -k], [-k, k]])
    s2.add_joint("masing", 0, h0=10.0, ac=k / 10.0)
    md2 = s2.modes()
    np.testing.assert_allclose(md2.frequency_hz, w / (2 * np.pi), rtol=1e-12)
    np.testing.assert_allclose(md2.damping_ratio, 0.01 * w, rtol=1e-10)
    np.testing.assert_allclose(md2.state_damping_ratio, 0.01 * w, rtol=1e-8)
    assert modes(s2.M, *s2.linearised()[1:]).to_dict()["frequency_hz"] == md2.frequency_hz.tolist()


def test_save_load_round_trip(tmp_path):
    s = Structure(2.0, 1.0, 500.0)
    s.add_joint("iwan", 0, **iwan_uniform(100.0, 1.0, 5))
    s.add_joint("masing", 0, x_points=[0, 1e-3, 2e-3], f_points=[0, 0.8, 1.0])
    s.save(tmp_path / "s.json")
    s2 = Structure.load(tmp_path / "s.json")
    t = np.linspace(0, 1, 101)
    f = np.sin(20 * t)
    np.testing.assert_array_equal(s.simulate(t, force=f).x, s2.simulate(t, force=f).x)


@pytest.mark.parametrize(
    "call,match",
    [
        (lambda s: s.add_joint("spring", 0, k=1.0), "unknown joint kind"),
        (lambda s: s.add_joint("jenkins", 3, k=1.0, fs=1.0), "outside"),
        (lambda s: s.add_joint("jenkins", 0, k=-1.0, fs=1.0), "must be > 0"),
        (lambda s: s.add_joint("jenkins", 0, k=1.0), "needs parameter"),
        (lambda s: s.simulate([0, 1, 1], force=[0, 0, 0]), "strictly increasing"),
        (lambda s: s.simulate([0, 1, 2], force=[0, np.nan, 0]), "not finite"),
        (lambda s: s.simulate([0, 1, 2], force=[0, 0]), "shape"),
        (lambda s: s.simulate([0, 1, 2], base=[0, 0, 0], x0=[1, 2]), "x0"),
    ],
)
def test_bad_input_is_input_error(call, match):
    s = Structure(1.0, 0.1, 10.0)
    with pytest.raises(contactlab.InputError, match=match):
        call(s)


def test_non_square_and_singular_mass_rejected():
    with pytest.raises(contactlab.InputError, match="square"):
        Structure(np.ones((2, 3)), 0, 0)
    s = Structure(np.zeros((1, 1)), 0.0, 1.0)
    with pytest.raises(contactlab.InputError, match="singular"):
        s.simulate([0.0, 0.1], force=[0.0, 1.0])


def test_failed_integration_returns_partial_result():
    # A tolerance below rounding: Newton cannot meet it once the Bouc-Wen joint is loaded, so
    # the run stops with a failure status and returns what it computed.
    s = Structure(1.0, 0.1, 100.0)
    s.add_joint("bouc_wen", 0, alpha=100.0, beta=1.0, gamma=50.0, delta=10.0, nu=1.5)
    t = np.linspace(0, 1, 101)
    # (fixed steps: error control's inner solves may end on a quadratic-convergence bound)
    r = s.simulate(t, force=np.sin(10 * t), rtol=1e-30, substeps=1)
    assert not r.success and r.status == -1 and "t =" in r.message
    assert 1 <= r.t.size < t.size and r.x.shape == r.t.shape
    assert np.all(np.isfinite(r.x))


def test_amplitude_dependence_jenkins_closed_form():
    from contactlab.report.structure_plots import plot_amplitude_dependence
    from contactlab.structure.amplitude import amplitude_dependence

    m, c, k, kj, fs = 1.0, 0.5, 1000.0, 1000.0, 1.0
    s = Structure(m, c, k)
    s.add_joint("jenkins", 0, k=kj, fs=fs)
    ad = amplitude_dependence(s, [5e-4, 3e-3, 1e-1])
    A = ad.amplitude
    # stuck below fs/kj: linear with k + kj; slipping: loop energy 4 fs (A − fs/kj)
    assert ad.frequency_hz[0] == pytest.approx(np.sqrt((k + kj) / m) / (2 * np.pi), rel=1e-6)
    np.testing.assert_allclose(ad.energy[1:], 4 * fs * (A[1:] - fs / kj), rtol=1e-4)
    # first-harmonic stiffness of the Jenkins element (Caughey): with φ = arccos(1 − 2 fs/(kj A))
    phi = np.arccos(1 - 2 * fs / (kj * A[1:]))
    keq = kj / np.pi * (phi - 0.5 * np.sin(2 * phi))
    np.testing.assert_allclose(ad.k_eq[1:], keq, rtol=1e-3)
    assert ad.frequency_hz[-1] < ad.frequency_hz[1] < ad.frequency_hz[0]
    ax = plot_amplitude_dependence(ad)
    assert len(ax) == 2
