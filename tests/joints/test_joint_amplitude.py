"""Amplitude-dependent stiffness and damping of joint laws, and laws fitted to them
(contactlab.joints.amplitude)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from contactlab.errors import InputError
from contactlab.joints import (
    Iwan,
    Jenkins,
    KelvinVoigt,
    Parallel,
    Segalman,
    Series,
    Sweep,
    equivalent_properties,
    fit_amplitude,
    fit_macroslip,
    fit_stepped_sine,
    macroslip_start,
)
from contactlab.joints.amplitude import simulated_cycle


def test_jenkins_closed_forms_against_a_simulated_cycle():
    law = Jenkins(k=1e4, fs=10.0)
    A = np.array([5e-4, 1.5e-3, 4e-3, 2e-2])
    cf = equivalent_properties(law, A)
    assert cf.method == "closed form"
    num = equivalent_properties(law, A, cycles=2, n_per_cycle=20000, simulate=True)
    assert num.method == "simulated cycles"
    np.testing.assert_allclose(cf.energy, np.where(A > 1e-3, 4 * 10 * (A - 1e-3), 0.0))
    np.testing.assert_allclose(num.energy, cf.energy, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(num.k_eq, cf.k_eq, rtol=1e-4)
    # Caughey's k_eq: k below slip, → 0 like 4 fs / (π A) ... (in-phase part) at large A
    assert cf.k_eq[0] == pytest.approx(1e4)
    np.testing.assert_allclose(cf.k_secant, np.minimum(1e4 * A, 10.0) / A)


@pytest.mark.parametrize("law", [Segalman(F_S=5.0, K_T=2e4, chi=-0.5, beta=0.3),
                                 Iwan(k=2e4, fs_max=5.0)])  # fmt: skip
def test_masing_quadrature_against_a_simulated_cycle(law):
    A = np.array([5e-5, 2e-4, 4e-4, 1e-3])
    cf = equivalent_properties(law, A)
    num = equivalent_properties(law, A, cycles=2, n_per_cycle=20000, simulate=True)
    np.testing.assert_allclose(cf.energy, num.energy, rtol=1e-5)
    np.testing.assert_allclose(cf.k_eq, num.k_eq, rtol=1e-5)


def test_segalman_small_amplitude_energy_power_law():
    law = Segalman(F_S=5.0, K_T=2e4, chi=-0.4, beta=0.2)
    A = np.array([1e-6, 1e-5])
    E = equivalent_properties(law, A).energy
    c = law.chi
    np.testing.assert_allclose(E, 4 * law.R * A ** (c + 3) / ((c + 2) * (c + 3)), rtol=1e-12)


def test_damping_needs_a_frequency_and_is_E_over_pi_omega_A2():
    law = Jenkins(k=1e4, fs=10.0)
    p = equivalent_properties(law, [2e-3], 5.0)
    assert p.c_eq[0] == pytest.approx(p.energy[0] / (math.pi * 2 * math.pi * 5.0 * 4e-6))
    assert np.isnan(equivalent_properties(law, [2e-3]).c_eq[0])


class _Flaky(Jenkins):
    """A Jenkins element whose evaluation fails beyond 1 mm (a stand-in for a law that
    cannot be integrated at some amplitude). Its own name keeps it off the closed forms (its
    cycles are simulated); its force is a plain Jenkins element's."""

    name = "flaky"  # not "jenkins": no closed form, the simulated-cycle route

    def spec(self):
        return ("jenkins", [self.k, self.fs], [])  # the core runs it as a Jenkins element

    def force(self, t, x, x0=0.0):
        if np.max(np.abs(x)) > 1e-3:
            raise InputError("flaky: cannot go beyond 1 mm")
        return Jenkins(k=self.k, fs=self.fs).force(t, x, x0)


def test_failures_are_reported_per_amplitude_never_raised():
    p = equivalent_properties(_Flaky(k=1e4, fs=5.0), [2e-4, 8e-4, 3e-3])
    assert list(p.failures) == [2]
    assert "beyond 1 mm" in p.failures[2]
    assert np.isnan(p.energy[2]) and np.isfinite(p.energy[:2]).all()
    A = np.array([6e-4, 8e-4, 9e-4, 2e-3])
    E = Jenkins(k=1e4, fs=5.0).loop_energy(A) if hasattr(Jenkins, "loop_energy") else (
        4 * 5.0 * (A - 5e-4))  # fmt: skip
    res = fit_amplitude(A, energy=E, law=_Flaky(k=1.2e4, fs=4.0), fixed=[])
    assert 3 in res.failures and "beyond 1 mm" in res.failures[3]
    assert np.isnan(res.predicted["energy"][3])


def test_fit_amplitude_recovers_a_segalman_table():
    true = Segalman(F_S=8.0, K_T=5e4, chi=-0.45, beta=0.0)
    A = np.geomspace(2e-5, 2e-4, 10)
    f = 80.0
    c0 = 1.5
    c = c0 + equivalent_properties(true, A, f).c_eq
    res = fit_amplitude(A, damping=c, frequency=f, law="segalman", viscous=True)
    assert res.success
    assert res.rms_relative_error("c_eq") < 1e-6
    assert res.law.chi == pytest.approx(-0.45, abs=1e-4)
    assert res.result.params["c0"].value == pytest.approx(c0, rel=1e-4)
    # K_T is held (damping alone does not determine it) and the notes say why
    assert not res.result.params["K_T"].vary
    assert any("held" in n for n in res.result.notes)
    # the identified combination, R, is the true one
    assert res.law.R == pytest.approx(true.R, rel=1e-3)


def _sdof_sweeps(law, m, k, c0, amplitudes, freqs):
    """Exact first-harmonic responses of ``m ẍ + c0 ẋ + k x + law(x) = F`` held at each
    amplitude (response-controlled sweeps): F = |D| A, phase = -arg D."""
    sweeps = []
    for j, A in enumerate(amplitudes):
        p = equivalent_properties(law, [A])
        w = 2 * np.pi * freqs
        D = k - m * w**2 + p.k_eq[0] + 1j * (w * c0 + p.energy[0] / (np.pi * A**2))
        sweeps.append(Sweep(freqs.copy(), np.abs(D) * A, np.full(freqs.size, A), -np.angle(D),
                            f"s{j}"))  # fmt: skip
    return sweeps


def test_stepped_sine_fit_recovers_damping_and_backbone():
    true = Segalman(F_S=10.0, K_T=6e4, chi=-0.3, beta=0.0)
    m, k, c0 = 2.0, 4.4e5, 2.0
    amps = np.array([2e-5, 6e-5, 1.2e-4, 2.5e-4])
    freqs = np.linspace(66.0, 82.0, 65)
    sweeps = _sdof_sweeps(true, m, k, c0, amps, freqs)
    res = fit_stepped_sine(sweeps, law="segalman")
    assert res.success
    A = np.geomspace(2e-5, 2.5e-4, 6)
    bb = res.backbone(A)
    p = equivalent_properties(true, A)
    wn = np.sqrt((k + p.k_eq) / m)
    c_true = c0 + p.energy / (np.pi * wn * A**2)
    np.testing.assert_allclose(bb["c_eq"], c_true, rtol=1e-3)
    np.testing.assert_allclose(bb["f_n"], wn / (2 * np.pi), rtol=1e-5)
    assert res.modal["m"] == pytest.approx(m, rel=1e-3)
    # phase resonance of each exact sweep gives the damping there
    for s, a in zip(sweeps, amps, strict=True):
        pr = s.phase_resonance()
        pa = equivalent_properties(true, [a])
        wr = 2 * np.pi * pr["frequency"]
        assert pr["c_eq"] == pytest.approx(c0 + pa.energy[0] / (np.pi * wr * a**2), rel=2e-3)


def test_parallel_closed_form_against_a_simulated_cycle():
    law = Parallel(Segalman(F_S=3.0, K_T=2e4, chi=-0.2, beta=0.7), Jenkins(k=4e3, fs=0.6), k=100.0)
    A = np.array([2e-5, 2e-4, 4e-4])  # micro-slip, past the Jenkins' slip, past φmax
    p = equivalent_properties(law, A, 80.0)
    assert p.method == "closed form"
    # the virgin curves and the energies add up: each part alone, plus the spring
    s, j = (equivalent_properties(c, A, 80.0) for c in law.laws)
    np.testing.assert_allclose(p.energy, s.energy + j.energy, rtol=1e-12)
    # (Caughey's closed form for the Jenkins; the quadrature across its kink: 1e-6)
    np.testing.assert_allclose(p.k_eq, s.k_eq + j.k_eq + 100.0, rtol=1e-6)
    for i, a in enumerate(A):
        th, x, F = simulated_cycle(law, float(a), 80.0, n_per_cycle=8192)
        assert float(np.trapezoid(F, x)) == pytest.approx(p.energy[i], rel=1e-5)
        keq = float(np.trapezoid(F * np.sin(th), th)) / (math.pi * a)
        assert keq == pytest.approx(p.k_eq[i], rel=1e-5)
    # a viscous term makes it rate-dependent: simulated
    assert equivalent_properties(Parallel(law.laws[1], c=1.0), A, 80.0).method != "closed form"


def test_series_spring_closed_form_against_a_simulated_cycle():
    joint = Segalman(F_S=3.0, K_T=3e4, chi=-0.2, beta=0.3)
    law = Series(joint, KelvinVoigt(k=4e4))
    A = np.array([2e-5, 2e-4, 5e-4])  # micro-slip, near and past macro-slip
    p = equivalent_properties(law, A, 80.0)
    assert p.method == "closed form"
    # the split: the spring carries the joint's force, the joint dissipates at its share
    u = A - p.k_secant * A / 4e4
    np.testing.assert_allclose(joint.virgin(u), p.k_secant * A, rtol=1e-12)
    np.testing.assert_allclose(p.energy, joint.loop_energy(u), rtol=1e-12)
    q = equivalent_properties(law, A, 80.0, simulate=True, n_per_cycle=8192)
    np.testing.assert_allclose(p.energy, q.energy, rtol=1e-6)
    np.testing.assert_allclose(p.k_eq, q.k_eq, rtol=1e-6)
    # a viscous spring is rate-dependent: simulated
    assert equivalent_properties(Series(joint, KelvinVoigt(k=4e4, c=1.0)), A, 80.0).method != (
        "closed form"
    )


def test_fit_macroslip_recovers_segalman_with_a_dirac_share():
    # an independent table: Segalman's energy written out here (power law below φmax, the
    # Dirac share slipping beyond it), not the law's own loop_energy
    chi, beta, FS, KT = -0.3, 0.8, 4.0, 3e4
    true = Segalman(F_S=FS, K_T=KT, chi=chi, beta=beta)
    pm, R, S = true.phi_max, true.R, true.S
    A = np.geomspace(2e-5, 2.2 * pm, 14)
    E = np.where(A <= pm, 4 * R * A ** (chi + 3) / ((chi + 2) * (chi + 3)),
                 4 * R * (A * pm ** (chi + 2) / (chi + 2) - pm ** (chi + 3) / (chi + 3))
                 + 4 * S * pm * (A - pm))  # fmt: skip
    f, c0 = 80.0, 1.2
    c = c0 + E / (math.pi * 2 * math.pi * f * A**2)
    start, c0_start = macroslip_start(A, c, f)
    assert start.beta == pytest.approx(1.0) and -1 < start.chi <= 0 and c0_start > 0
    res = fit_macroslip(A, c, f)
    assert res.success
    assert res.rms_relative_error("c_eq") < 1e-6
    for n, v in (("F_S", FS), ("K_T", KT), ("chi", chi), ("beta", beta), ("c0", c0)):
        assert res.result.params[n].value == pytest.approx(v, rel=1e-3, abs=1e-4), n
        assert res.result.params[n].identifiable, n  # exact data: no residual, no stderr


def test_stepped_sine_law_stiffness_renamed_from_the_modes():
    law = Parallel(Segalman(F_S=10.0, K_T=6e4, chi=-0.3, beta=0.0), k=1e4)
    m, k, c0 = 2.0, 4.4e5, 2.0
    sweeps = _sdof_sweeps(law, m, k, c0, np.array([2e-5, 1.2e-4]), np.linspace(70.0, 80.0, 21))
    res = fit_stepped_sine(sweeps, law=law, fixed=["k", "c", "segalman.K_T", "segalman.beta"])
    assert "joint.k" in res.result.params and not res.result.params["joint.k"].vary
    assert res.law.k == 1e4
    assert res.modal["k"] == pytest.approx(k, rel=1e-4)
    assert res.law.laws[0].chi == pytest.approx(-0.3, abs=1e-4)
    assert np.all(np.isfinite(res.backbone([5e-5])["f_n"]))


def test_bad_input_is_named():
    law = Jenkins(k=1e4, fs=10.0)
    with pytest.raises(InputError, match="4 or more amplitudes"):
        fit_macroslip([1e-4, 2e-4, 3e-4], [1.0, 2.0, 3.0], 80.0)
    with pytest.raises(InputError, match="4 or more amplitudes"):
        macroslip_start([1e-4, 2e-4, 3e-4, 4e-4], [1.0, 2.0], 80.0)
    with pytest.raises(InputError, match="both"):
        fit_macroslip(np.geomspace(1e-5, 1e-4, 5), np.linspace(1, 2, 5), 80.0,
                      parallel_jenkins=True, series_spring=True)  # fmt: skip
    with pytest.raises(InputError, match=r"amplitude\[1\]"):
        equivalent_properties(law, [1e-3, -1e-3])
    with pytest.raises(InputError, match="needs the frequency"):
        fit_amplitude([1e-3, 2e-3], damping=[1.0, 2.0], law="segalman")
    with pytest.raises(InputError, match="3 values for 2 amplitudes"):
        fit_amplitude([1e-3, 2e-3], energy=[1.0, 2.0, 3.0])
    f = np.array([79.0, 80.0, 81.0])
    with pytest.raises(InputError, match="force has 2 points"):
        Sweep(f, np.ones(2), np.ones(3), -np.ones(3), "s")
    lead = Sweep(f, np.ones(3), np.ones(3) * 1e-4, np.array([0.2, 0.3, 0.4]), "lead")
    with pytest.raises(InputError, match="leads the force"):
        fit_stepped_sine([lead])
    assert simulated_cycle(law, 1e-3)[2].size == 1025
