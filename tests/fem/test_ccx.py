"""Checks that run CalculiX on exported joint characteristics (skipped without ``ccx``).

The figures asserted here are those the issue names: contact pressure–overclosure pairs on the
exported curve (≤ 1 % of range), compliance as the analytic series of blocks and joint, the
elastic-Coulomb loop energy equal to Jenkins' 4·F_s·(A − F_s/k) (≤ 2 %) with the Masing energy
reported beside it, and the beam frequency on the joint spring (≤ 0.5 %).
"""

from __future__ import annotations

import math

import pytest

import contactlab.normal as cn
from contactlab.fem.ccx import CCX_PACKAGE, ccx_version, find_ccx
from contactlab.fem.checks import check_dynamics, check_normal, check_tangential
from contactlab.synthetic.normal import synthetic_recording as normal_recording
from contactlab.synthetic.tangential import synthetic_recording
from contactlab.tangential import analyze_tangential

pytestmark = pytest.mark.skipif(
    find_ccx() is None, reason=f"ccx (CalculiX) not installed: apt-get install {CCX_PACKAGE}"
)


@pytest.fixture(scope="module")
def tangential() -> dict:
    # fresh seed, noisy, a different sampling rate from the unit tests
    rec = synthetic_recording(h0=25.0, ac=6e4, amplitude=40e-6, n_cycles=5, fs=800.0,
                              noise=0.02, seed=2101)  # fmt: skip
    return {**analyze_tangential(rec).to_dict(), "model": "tangential", "file": "sim.csv"}


def test_ccx_version() -> None:
    assert ccx_version().split(".")[0].isdigit()


@pytest.mark.parametrize("seed,p0,pa", [(2102, 0.5e6, 0.4e6), (2103, 1.0e6, 0.5e6)])
def test_normal_table_and_compliance(seed: int, p0: float, pa: float) -> None:
    t, p, delta = normal_recording(p0=p0, pa=pa, omega=1.0, n_cycles=4, seed=seed)
    res = {**cn.analyze_loop(t, p, delta).to_dict(), "model": "normal", "file": "sim.csv"}
    chk = check_normal(res)
    print(chk.report())
    assert chk.table_pressure_error <= 0.01
    assert chk.poly_error <= 0.01  # the table follows the fitted branch it came from
    assert chk.compliance_error <= 0.01
    assert 0.4 < chk.block_share < 0.6  # both terms of the series matter
    # the reported pairs span the table (the ramp reached its top)
    assert chk.pressure.max() == pytest.approx(0.98 * (p0 + pa) * 1e-6, rel=0.03)


def test_tangential_jenkins_energy(tangential: dict) -> None:
    chk = check_tangential(tangential, area=25e-4, normal_load=40.0)
    print(chk.report())
    assert len(chk.amplitudes) == 2 and max(chk.errors) <= 0.02
    # F_s = μW = h0 and k = λ·A_c = h0·ac whatever area and load were given
    assert chk.slip_force == pytest.approx(tangential["h0"], rel=1e-6)
    assert chk.stiffness == pytest.approx(tangential["h0_ac"], rel=1e-6)
    # the Masing energy differs from the bilinear law's and the report says so
    assert all(abs(m / f - 1) > 0.1 for m, f in zip(chk.energy_masing, chk.energy_fe,
                                                     strict=True))  # fmt: skip
    assert "E_Masing" in chk.report()
    # the FE loop is bilinear: its force saturates at ±F_s
    _, f = chk.loops[1]
    assert max(abs(f)) == pytest.approx(chk.slip_force, rel=1e-3)


def test_beam_frequency_on_joint_spring(tangential: dict) -> None:
    chk = check_dynamics(tangential, area=25e-4, normal_load=40.0, amplitude=30e-6,
                         frequency=50.0)  # fmt: skip
    print(chk.report())
    assert chk.error <= 0.005
    assert chk.reference.startswith("contactlab.structure")
    # the two references agree with each other (Hermite elements vs the closed form)
    assert chk.frequency_reference == pytest.approx(chk.frequency_closed_form, rel=1e-4)
    assert 0 < chk.damping_ratio < 1
    assert math.isfinite(chk.frequency_fe) and chk.frequency_fe > 0
