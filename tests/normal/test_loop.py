"""Loop analysis (Konowalski 2009, eqs. 1-7) against hand-checkable values of its Table 2."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import contactlab
from contactlab.normal import TABLE2_MPA_UM, KelvinVoigt, analyze_loop
from contactlab.normal.paper import loop_poly_to_si
from contactlab.synthetic.normal import synthetic_recording

P = np.polynomial.polynomial


@pytest.fixture(scope="module")
def table2_loop():
    return synthetic_recording(model="table2", n_cycles=4, noise=None)


def test_round_trip_gives_table2_to_three_decimals(table2_loop):
    res = analyze_loop(*table2_loop)
    got = res.table2()
    for name in ("load", "centre", "unload"):
        np.testing.assert_allclose(got[name], TABLE2_MPA_UM[name], atol=5e-4, rtol=0)
        # Printed to 3 decimals, the rows are the paper's.
        assert [round(v, 3) for v in got[name]] == [round(v, 3) for v in TABLE2_MPA_UM[name]]
    assert res.degree == 4
    assert res.n_cycles == 3 and res.n_discarded == 1


def test_table2_derived_quantities_by_hand(table2_loop):
    res = analyze_loop(*table2_loop)
    centre = loop_poly_to_si(TABLE2_MPA_UM["centre"])
    load = loop_poly_to_si(TABLE2_MPA_UM["load"])
    unload = loop_poly_to_si(TABLE2_MPA_UM["unload"])
    # eq. 4: slope of the centre curve at p = 0 is its a1 = 1.32596 MPa/µm (not 1.206).
    assert res.k_tan == pytest.approx(1.32596e12, rel=1e-6)
    # eq. 5 and eq. 6.
    assert res.k_sec == pytest.approx(2 * res.pa / (res.delta_max - res.delta_min), rel=1e-12)
    # Table 2's centre row is the mean of the other two, rounded to 5 digits.
    np.testing.assert_allclose(res.k_s_delta, centre[1:], rtol=5e-6)
    # Energies under the centre curve (independent integration of the Table 2 polynomial).
    ic = P.polyint(centre)
    assert res.E_pu == pytest.approx(P.polyval(res.delta_max, ic), rel=1e-6)
    assert res.E_pd == pytest.approx(P.polyval(res.delta_min, ic), rel=1e-6)
    # The loop area from the samples agrees with the area between the curves.
    area = P.polyint(load - unload)
    e_curves = P.polyval(res.delta_max, area) - P.polyval(res.delta_min, area)
    assert res.E_d == pytest.approx(e_curves, rel=2e-3)
    assert res.psi == pytest.approx(2 * res.E_d / (res.E_pd + res.E_pu), rel=1e-12)
    assert res.psi_kv == pytest.approx(res.E_d / res.E_pu, rel=1e-12)
    # PHYSICS.md §2 caution: the loop does not give the paper's printed ψ = 0.0887.
    assert abs(res.psi - 0.0887) > 0.05 and abs(res.psi_kv - 0.0887) > 0.05
    # Asymmetry: the relief side reaches further than the loading side.
    assert -res.delta_min > res.delta_max > 0
    assert res.pa == pytest.approx(0.4e6, rel=1e-4)
    assert res.p0 == pytest.approx(0.5e6, rel=1e-12)


def test_to_dict_holds_the_contract_keys_and_is_json(table2_loop):
    d = analyze_loop(*table2_loop).to_dict()
    for key in (
        "E_d",
        "E_pu",
        "E_pd",
        "psi",
        "psi_kv",
        "k_tan",
        "k_sec",
        "poly_load",
        "poly_unload",
        "poly_centre",
        "delta_max",
        "delta_min",
        "omega",
        "frequency",
        "n_cycles",
        "cycle_scatter",
        "k_s_delta",
        "p0",
        "pa",
        "units",
    ):
        assert key in d, key
    assert d["units"]["E_d"] == "J/m^2" and d["units"]["k_tan"] == "Pa/m"
    json.dumps(d)
    json.dumps(analyze_loop(*table2_loop).to_dict(arrays=True))
    assert "ψ (eq. 7)" in analyze_loop(*table2_loop).report()


def test_frequency_estimate_and_sampling_rate_argument(table2_loop):
    t, p, d = table2_loop
    est = analyze_loop(t, p, d)
    assert est.omega == pytest.approx(1.0, rel=1e-9)
    assert est.frequency == pytest.approx(1 / (2 * np.pi), rel=1e-9)
    fs = 1 / (t[1] - t[0])
    by_rate = analyze_loop(fs, p, d, omega=1.0)
    np.testing.assert_allclose(by_rate.poly_centre, est.poly_centre, rtol=1e-9, atol=1e-3)


def test_non_integer_period_is_folded_by_interpolation():
    # 250.4 samples per cycle: cycles no longer start on samples.
    w = 2 * np.pi / (250.4 * 0.01)
    kv = KelvinVoigt(1.2e12, 0.1, w)
    t = np.arange(int(250.4 * 8)) * 0.01
    res = kv.simulate(t, 0.4e6 * np.sin(w * t), dpdt=0.4e6 * w * np.cos(w * t), rtol=1e-10)
    r = analyze_loop(t, 0.5e6 + 0.4e6 * np.sin(w * t), res.delta)
    assert r.omega == pytest.approx(w, rel=1e-7)
    assert r.psi_kv == pytest.approx(0.1, rel=1e-4)


def test_non_uniform_time_is_resampled(table2_loop):
    t, p, d = table2_loop
    tj = t.copy()
    tj[1:-1] += 1e-4 * (t[1] - t[0]) * np.sin(np.arange(1, t.size - 1))
    r = analyze_loop(tj, p, d)
    assert r.resampled
    assert r.k_tan == pytest.approx(1.32596e12, rel=1e-2)


@settings(max_examples=8, deadline=None)
@given(psi=st.floats(0.02, 0.6), k=st.floats(0.5e12, 4e12))
def test_kelvin_voigt_loop_gives_back_psi_and_stiffness(psi, k):
    kv = KelvinVoigt(k, psi, 1.0)
    t = np.arange(10 * 256 + 1) * (2 * np.pi / 256)
    res = kv.simulate(t, 0.4e6 * np.sin(t), dpdt=0.4e6 * np.cos(t), rtol=1e-10)
    r = analyze_loop(t, 0.5e6 + 0.4e6 * np.sin(t), res.delta, omega=1.0)
    # Ellipse: E_d / E_pu = ψ (eq. 3); symmetric, so eq. 7 gives the same.
    # (The centre curve is the mean of two degree-4 fits of the ellipse's halves, so it is
    # k δ only up to the fit of the square-root branches.)
    assert r.psi_kv == pytest.approx(psi, rel=1e-4)
    assert r.psi == pytest.approx(psi, rel=1e-4)
    assert r.E_d == pytest.approx(kv.loop_energy(0.4e6), rel=1e-6)
    assert r.k_sec == pytest.approx(0.4e6 / kv.amplitude(0.4e6), rel=1e-6)
    assert r.k_tan == pytest.approx(k, rel=1e-2)


def test_noisy_nonlinear_recording():
    t, p, d = synthetic_recording(seed=3)
    r = analyze_loop(t, p, d)
    assert r.n_cycles == 127 and r.n_discarded == 1
    assert r.samples_per_cycle == 256
    assert r.k_tan == pytest.approx(1.32596e12, rel=0.01)
    # Scatter of the cycles ≈ the 2 nm sensor noise.
    assert 1e-9 < r.cycle_scatter < 4e-9
    assert r.E_d_cycle_std < 0.2 * r.E_d


def test_dynamic_pressure_needs_p0(table2_loop):
    t, p, d = table2_loop
    with pytest.raises(contactlab.InputError, match="give the static pressure p0"):
        analyze_loop(t, p - 0.5e6, d)
    r = analyze_loop(t, p - 0.5e6, d, p0=0.5e6)
    assert r.p0 == 0.5e6


@pytest.mark.parametrize(
    ("args", "kwargs", "match"),
    [
        ((np.arange(10.0), np.ones(10), np.ones(9)), {}, "samples"),
        ((np.arange(10.0), np.ones(10), np.ones(10)), {}, "constant"),
        (
            (np.r_[0.0, 2.0, 1.0, np.arange(3.0, 20.0)], np.sin(np.arange(20.0)), np.ones(20)),
            {},
            "increasing",
        ),
        ((np.arange(10.0), np.r_[1.0, np.nan, np.ones(8)], np.ones(10)), {}, r"p\[1\]"),
        ((np.arange(10.0), np.ones(10), np.r_[np.ones(9), np.inf]), {}, r"delta\[9\]"),
    ],
)
def test_bad_input_raises_typed_errors(args, kwargs, match):
    with pytest.raises(contactlab.InputError, match=match):
        analyze_loop(*args, **kwargs)


def test_fewer_than_two_cycles_is_an_error():
    t = np.arange(300) * (2 * np.pi / 256)
    p = 0.5e6 + 0.4e6 * np.sin(t)
    with pytest.raises(contactlab.InputError, match="fewer than two whole cycles"):
        analyze_loop(t, p, 1e-7 * np.sin(t - 0.1), omega=1.0)


def test_pa_above_p0_is_an_error(table2_loop):
    t, p, d = table2_loop
    with pytest.raises(contactlab.InputError, match="separate"):
        analyze_loop(t, p, d, p0=0.3e6)


def test_degree_and_discard_validation(table2_loop):
    t, p, d = table2_loop
    with pytest.raises(contactlab.InputError, match="degree"):
        analyze_loop(t, p, d, degree=0)
    with pytest.raises(contactlab.InputError, match="leaves none"):
        analyze_loop(t, p, d, discard_cycles=10)
    r3 = analyze_loop(t, p, d, degree=3)
    assert len(r3.poly_centre) == 4


def test_errors_are_valueerrors_too(table2_loop):
    t, p, d = table2_loop
    with pytest.raises(ValueError):
        analyze_loop(t, p, d[:-1])
