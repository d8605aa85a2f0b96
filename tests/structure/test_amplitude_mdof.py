"""Amplitude dependence of each mode of a structure with joints (equivalent linearisation):
the single-DOF function on one DOF, and a 2-DOF structure's phase resonance (periodic
steady state of the time integration) at a few amplitudes."""

from __future__ import annotations

import matplotlib
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import contactlab
from contactlab.report.structure_plots import plot_modal_amplitude_dependence
from contactlab.structure import (
    Structure,
    modal_amplitude_dependence,
    phase_resonance,
)
from contactlab.structure.amplitude import amplitude_dependence

matplotlib.use("Agg")


def _two_dof(joint: str = "jenkins", between: bool = False) -> Structure:
    s = Structure(np.diag([1.0, 0.5]), [[3.0, -1.0], [-1.0, 1.0]], [[6e3, -2e3], [-2e3, 2e3]])
    if joint == "jenkins":
        s.add_joint("jenkins", 0, 1 if between else None, k=2e3, fs=1.0)
    else:
        s.add_joint("masing", 0, 1 if between else None, h0=1.5, ac=1500.0)
    return s


@settings(max_examples=6, deadline=None)
@given(
    m=st.floats(0.2, 5.0),
    k=st.floats(200.0, 5e3),
    kj=st.floats(100.0, 5e3),
    fs=st.floats(0.1, 5.0),
    c=st.floats(0.0, 5.0),
)
def test_one_dof_equals_the_single_dof_function(m, k, kj, fs, c):
    s = Structure(m, c, k)
    s.add_joint("jenkins", 0, k=kj, fs=fs)
    amps = np.geomspace(0.1, 10.0, 4) * fs / kj
    a = amplitude_dependence(s, amps)
    b = modal_amplitude_dependence(s, amps)
    np.testing.assert_allclose(b.frequency_hz, a.frequency_hz, rtol=1e-6)
    # the single-DOF function divides by the loop's own amplitude (the tie's, 1e-5 below)
    np.testing.assert_allclose(b.damping_ratio, a.damping_ratio, rtol=1e-4, atol=1e-12)
    np.testing.assert_allclose(b.k_eq[:, 0], a.k_eq, rtol=1e-4)


def test_limits_stuck_and_slipping():
    s = _two_dof()
    ad = modal_amplitude_dependence(s, [1e-6, 10.0], mode=0)
    K0 = s.K + np.diag([2e3, 0.0])
    w2 = np.sort(np.linalg.eigvals(np.linalg.solve(s.M, K0)).real)
    assert ad.frequency_hz[0] == pytest.approx(np.sqrt(w2[0]) / (2 * np.pi), rel=1e-9)
    w2s = np.sort(np.linalg.eigvals(np.linalg.solve(s.M, s.K)).real)
    assert ad.frequency_hz[1] == pytest.approx(np.sqrt(w2s[0]) / (2 * np.pi), rel=1e-3)
    # stuck: the viscous modal damping φᵀCφ/(2ω) of the linearised structure
    md = Structure(s.M, s.C, K0).modes()
    assert ad.damping_ratio[0] == pytest.approx(md.damping_ratio[0], rel=1e-9)
    assert abs(ad.energy[0, 0]) < 1e-20 and ad.energy[1, 0] > 0.0
    # the joint amplitude comes from the mode shape
    assert ad.joint_amplitude[1, 0] == pytest.approx(10.0 * abs(ad.shapes[1, 0]), rel=1e-12)


@pytest.mark.parametrize(
    "joint,between,mode,amp",
    [("jenkins", False, 0, 3e-3), ("jenkins", False, 1, 1e-3), ("masing", True, 0, 2e-3)],
)
def test_matches_phase_resonance_of_the_time_integration(joint, between, mode, amp):
    s = _two_dof(joint, between)
    pr = phase_resonance(s, amp, mode, samples_per_period=128, rel_tol=1e-5)
    ad = modal_amplitude_dependence(s, [pr.amplitude], mode=mode)
    assert pr.amplitude == pytest.approx(amp, rel=0.1)
    assert pr.frequency_hz == pytest.approx(ad.frequency_hz[0], rel=0.01)
    assert pr.damping_ratio == pytest.approx(ad.damping_ratio[0], rel=0.03)
    # the joint makes a difference here: not the stuck (linearised) values
    lin = modal_amplitude_dependence(s, [1e-7], mode=mode)
    assert ad.damping_ratio[0] > 1.3 * lin.damping_ratio[0]


def test_bad_input_and_plot():
    s = _two_dof()
    with pytest.raises(contactlab.InputError, match="mode"):
        modal_amplitude_dependence(s, [1e-3], mode=2)
    with pytest.raises(contactlab.InputError, match="> 0"):
        modal_amplitude_dependence(s, [0.0])
    kv = Structure(1.0, 0.0, 1e3)
    kv.add_joint("kelvin_voigt", 0, k=1.0, c=1.0)
    with pytest.raises(contactlab.InputError, match="Kelvin-Voigt"):
        modal_amplitude_dependence(kv, [1e-3])
    ads = [modal_amplitude_dependence(s, np.geomspace(1e-5, 1e-2, 5), mode=m) for m in (0, 1)]
    ax = plot_modal_amplitude_dependence(ads)
    assert len(ax[0].lines) == 2
    assert ads[0].to_dict()["units"]["amplitude"] == "m"
