"""Physical invariants of the independent evaluation generator (benches/independent/)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

BENCH = Path(__file__).resolve().parents[2] / "benches" / "independent"
sys.path.insert(0, str(BENCH))

gen = pytest.importorskip("generator")
vis = pytest.importorskip("visibility")


def _energy_closed_form(h0: float, ac: float, A: float) -> float:
    hm = h0 * (1 - np.exp(-ac * A))
    return 8 * (h0 * (A - (1 - np.exp(-ac * A)) / ac) - A * hm / 2)


def _loop_area(x: np.ndarray, F: np.ndarray) -> float:
    return float(np.sum(0.5 * (F[1:] + F[:-1]) * np.diff(x)))


@pytest.mark.parametrize("acA", [0.3, 1.5, 5.0])
def test_plain_masing_matches_closed_form_energy_and_package(acA):
    import contactlab

    h0, A = 20.0, 10e-6
    ac = acA / A
    t = np.linspace(0.0, 3.0, 3001)
    x = A * np.sin(2 * np.pi * t)
    F = gen.masing_series(x, gen.virgin_function("exponential", h0, ac))
    last = t >= 2.0
    E = _loop_area(x[last], F[last])  # a passive joint: the loop integral is positive
    assert E == pytest.approx(_energy_closed_form(h0, ac, A), rel=2e-3)
    ref = contactlab.Masing(h0=h0, ac=ac).force(x)
    np.testing.assert_allclose(F, ref, rtol=0, atol=1e-9 * h0)


def test_inner_loop_returns_to_its_start():
    h0, ac = 5.0, 1e5
    f = gen.virgin_function("exponential", h0, ac)
    x = np.concatenate(
        [np.linspace(0, 20e-6, 50), np.linspace(20e-6, 5e-6, 30), np.linspace(5e-6, 12e-6, 20)]
    )
    x = np.concatenate([x, np.linspace(12e-6, 8e-6, 10), np.linspace(8e-6, 20e-6, 40), [25e-6]])
    F = gen.masing_series(x, f)
    # back at the first turning point (20 um) the force equals its value there, then virgin
    assert F[-2] == pytest.approx(F[49], rel=1e-12)
    assert F[-1] == pytest.approx(f(25e-6), rel=1e-12)


def _small_chain(seed: int, noise_x=None):
    import dataclasses

    rng = np.random.default_rng(seed)
    ch = gen.draw_chain(rng, fs=1000.0, cycles=8, noise_x=noise_x)
    return dataclasses.replace(ch, f=10.0, lvdt_fc=max(ch.lvdt_fc, 200.0), cond_fc=200.0)


@pytest.mark.parametrize("seed", [3, 4])
def test_clean_tangential_record_invariants(seed):
    ch = _small_chain(seed, noise_x=0.015)
    rec = gen.tangential_record(seed, "clean", chain=ch)
    T, ideal = rec.truth, rec.ideal
    # the virgin curve and every branch stay within +-h0
    assert np.max(np.abs(ideal["F"])) <= T["h0"] * (1 + 1e-12)
    # a passive joint dissipates: every full cycle's loop energy is positive
    x, F, t = ideal["x_true"], ideal["F"], ideal["t"]
    for k in range(2, ch.cycles - 1):
        sel = (t >= T["t_pre"] + k / ch.f) & (t < T["t_pre"] + (k + 1) / ch.f)
        assert _loop_area(x[sel], F[sel]) > 0
    # the record starts from rest
    assert abs(ideal["x_true"][0]) == 0.0 and abs(ideal["F"][0]) == 0.0
    # the noise on each channel is the requested fraction of its range (hum and ADC included)
    for meas, clean, frac, rng_ in (
        (rec.x, ideal["x_meas_clean"], ch.noise_x, T["range_x"]),
        (rec.y, ideal["F_meas_clean"], ch.noise_y, T["range_y"]),
    ):
        ratio = np.std(meas - clean) / (frac * rng_)
        assert 0.9 < ratio < 1.2
    # independent streams: the two channels' noise is uncorrelated
    ex = rec.x - ideal["x_meas_clean"]
    ey = rec.y - ideal["F_meas_clean"]
    assert abs(np.corrcoef(ex, ey)[0, 1]) < 0.1
    # the chain (sensor dynamics, calibrated skew, filters) barely changes the loop
    M = gen.masing_series(
        ideal["x_meas_clean"], gen.virgin_function("exponential", T["h0"], T["ac"])
    )
    assert np.sqrt(np.mean((M - ideal["F_meas_clean"]) ** 2)) < 0.1 * T["sigma_y"]


def test_clean_normal_record_matches_kelvin_voigt_closed_form():
    ch = _small_chain(5)
    rec = gen.normal_record(5, "clean", chain=ch)
    T, ideal = rec.truth, rec.ideal
    w = 2 * np.pi * T["f"]
    d = vis.kv_from_rest(ideal["t"], T["t_pre"], T["pa"], T["k"], T["c"], w)
    assert np.max(np.abs(d - ideal["delta"])) < 1e-5 * np.max(np.abs(d))
    # the loop p(delta) dissipates
    tt = ideal["t"] - T["t_pre"]
    sel = (tt >= 2.0 / T["f"]) & (tt <= 7.0 / T["f"])
    assert _loop_area(ideal["delta"][sel], ideal["p"][sel]) > 0


def test_effects_follow_their_definitions():
    t = np.linspace(0, 1, 2001)
    x = 10e-6 * np.sin(2 * np.pi * 2 * t)
    v = np.gradient(x, t)
    a = np.gradient(v, t)
    h0, ac = 3.0, 2e5
    _, M = gen.tangential_output(None, {}, t, x, v, a, h0, ac)
    _, F = gen.tangential_output("asymmetry", {"a": 0.2}, t, x, v, a, h0, ac)
    np.testing.assert_allclose(F, (1 + 0.2 * np.sign(M)) * M)
    _, F = gen.tangential_output("non_masing_scaling", {"lam": 2.0}, t, x, v, a, h0, ac)
    np.testing.assert_allclose(F, M, atol=1e-12)
    # series compliance: x = u + F/k_s holds at every sample
    k_s = 0.5 * h0 * ac
    F = gen.series_compliance_force(x, gen.virgin_function("exponential", h0, ac), k_s)
    u = x - F / k_s
    np.testing.assert_allclose(
        F, gen.masing_series(u, gen.virgin_function("exponential", h0, ac)), atol=1e-9 * h0
    )
