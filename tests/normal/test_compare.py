"""Comparison with a measurement (Figs. 9-12), eq. 16 across tests, synthetic recordings."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest

import contactlab
from contactlab.normal import (
    KelvinVoigt,
    NonlinearContact,
    analyze_loop,
    compare,
    fit_pressure_stiffness,
)
from contactlab.normal.compare import measured_velocity
from contactlab.report.normal import (
    plot_comparison,
    plot_displacement,
    plot_loops,
    plot_phase_portrait,
    plot_velocity,
)
from contactlab.synthetic.normal import synthetic_recording


@pytest.fixture(scope="module")
def measured():
    return synthetic_recording(n_cycles=16, seed=7)


@pytest.fixture(scope="module")
def comparison(measured):
    t, p, d = measured
    res = analyze_loop(t, p, d)
    models = {
        "linear": KelvinVoigt.from_loop(res),
        "nonlinear": NonlinearContact.from_loop(res),
    }
    return compare(t, p, d, models)


def test_nonlinear_model_beats_linear_one(comparison):
    lin = comparison.metrics["linear"]
    nl = comparison.metrics["nonlinear"]
    assert nl["rms_delta"] < 0.2 * lin["rms_delta"]
    assert nl["peak_delta"] < lin["peak_delta"]
    assert abs(nl["loop_area_error"]) < 0.03
    # The nonlinear model's error is at the level of the 2 nm sensor noise.
    assert nl["rms_delta"] < 5e-9
    for key in (
        "rms_delta",
        "peak_delta",
        "rms_velocity",
        "peak_velocity",
        "loop_area_model",
        "loop_area_measured",
        "loop_area_error",
    ):
        assert np.isfinite(nl[key])
    assert comparison.n_cycles == 15
    assert "nonlinear" in comparison.table()
    assert set(comparison.to_dict()["metrics"]) == {"linear", "nonlinear"}


def test_measured_velocity_is_noise_robust():
    t = np.arange(8 * 256) * (2 * np.pi / 256)
    d = 0.3e-6 * np.sin(t)
    rng = np.random.default_rng(0)
    noisy = d + 2e-9 * rng.standard_normal(t.size)
    v = 0.3e-6 * np.cos(t)
    inner = slice(256, -256)
    for method in ("savgol", "spectral"):
        vm = measured_velocity(t, noisy, method=method, omega=1.0)
        assert np.sqrt(np.mean((vm[inner] - v[inner]) ** 2)) < 0.03 * 0.3e-6
    # A plain difference would not be.
    vd = np.gradient(noisy, t)
    assert np.sqrt(np.mean((vd[inner] - v[inner]) ** 2)) > 0.1 * 0.3e-6


def test_plots_accept_ax_and_return_figures(comparison):
    for fn in (plot_displacement, plot_velocity, plot_phase_portrait, plot_loops):
        fig = fn(comparison)
        assert isinstance(fig, matplotlib.figure.Figure)
        plt.close(fig)
        fig2, ax = plt.subplots()
        assert fn(comparison, ax=ax) is fig2
        assert ax.lines
        plt.close(fig2)
    fig = plot_comparison(comparison)
    assert len(fig.axes) == 4
    plt.close(fig)
    fig, axes = plt.subplots(2, 2)
    assert plot_comparison(comparison, ax=axes) is fig
    plt.close(fig)


def test_compare_rejects_bad_input(measured):
    t, p, d = measured
    kv = KelvinVoigt(1.2e12, 0.1, 1.0)
    with pytest.raises(contactlab.InputError, match="samples"):
        compare(t, p, d[:-1], kv)
    with pytest.raises(contactlab.InputError, match="two are needed"):
        compare(t[:300], p[:300], d[:300], kv)
    with pytest.raises(contactlab.InputError, match="simulate"):
        compare(t, p, d, object())


def test_fit_pressure_stiffness_across_p0():
    recs = [synthetic_recording(p0=p0, n_cycles=4, noise=None) for p0 in (1.5e6, 0.5e6, 1.0e6)]
    fit = fit_pressure_stiffness(recs)
    assert fit.b.shape == (3, 4)
    np.testing.assert_allclose(fit.p0, [0.5e6, 1.0e6, 1.5e6])
    # b4 = k_s at p = 0 is the centre curve's slope there: it grows with p0 (√p0 model).
    assert np.all(np.diff(fit.b[:, 3]) > 0)
    assert fit.b_display()[0, 3] == pytest.approx(1.326, abs=2e-3)
    # The cubic describes k_s along the centre curve closely.
    assert np.all(fit.rms < 5e-3 * fit.b[:, 3])
    np.testing.assert_allclose(fit.at(1.0e6), fit.b[1])
    np.testing.assert_allclose(fit.at(0.75e6), 0.5 * (fit.b[0] + fit.b[1]))
    with pytest.warns(contactlab.ContactLabWarning, match="outside"):
        fit.at(3e6)
    m = fit.model(1.0e6)
    t, p, _ = synthetic_recording(p0=1.0e6, n_cycles=2, noise=None)
    assert m.simulate(t, p).success
    d = fit.to_dict()
    assert d["units"]["p0"] == "Pa" and len(d["b"]) == 3
    assert "p0 [MPa]" in fit.table()


def test_fit_pressure_stiffness_by_hand():
    # Quadratic centre curve p = a1 δ + a2 δ², so k_s = a1 + a2 δ and, with δ(p) the root,
    # k_s(p) = (a1 + sqrt(a1² + 4 a2 p)) / 2 = a1 + (a2/a1) p - (a2²/a1³) p² + …
    a1, a2 = 1.3e12, 1.0e17
    t = np.arange(6 * 256) * (2 * np.pi / 256)
    p = 0.05e6 * np.sin(t)
    d = (-a1 + np.sqrt(a1**2 + 4 * a2 * p)) / (2 * a2)
    fit = fit_pressure_stiffness([(t, 0.5e6 + p, d)])
    _, b2, b3, b4 = fit.b[0]
    assert b4 == pytest.approx(a1, rel=1e-6)
    assert b3 == pytest.approx(a2 / a1, rel=1e-3)
    assert b2 == pytest.approx(-(a2**2) / a1**3, rel=5e-2)


def test_fit_pressure_stiffness_inputs():
    t, p, d = synthetic_recording(n_cycles=4, noise=None)
    f1 = fit_pressure_stiffness([{"t": t, "p": p, "delta": d}])
    f2 = fit_pressure_stiffness([analyze_loop(t, p, d)])
    np.testing.assert_allclose(f1.b, f2.b)
    with pytest.raises(contactlab.InputError, match="no tests"):
        fit_pressure_stiffness([])
    with pytest.raises(contactlab.InputError, match="each test"):
        fit_pressure_stiffness([42])
    with pytest.raises(contactlab.InputError, match="missing"):
        fit_pressure_stiffness([{"t": t, "p": p}])


def test_synthetic_recording_properties():
    t, p, d = synthetic_recording(n_cycles=8, seed=1)
    assert t.size == p.size == d.size == 8 * 256
    assert np.mean(p) == pytest.approx(0.5e6, rel=1e-3)
    _t2, _p2, d2 = synthetic_recording(n_cycles=8, seed=1)
    np.testing.assert_array_equal(d, d2)
    _, _, clean = synthetic_recording(n_cycles=8, noise=None)
    noise = d - clean
    assert 1e-9 < np.std(noise) < 4e-9
    _, _, lin = synthetic_recording(n_cycles=4, model="linear", noise=None)
    assert np.max(lin) == pytest.approx(-np.min(lin), rel=1e-3)  # symmetric ellipse
    _, _pr, dr = synthetic_recording(n_cycles=4, noise={"p": 100.0, "delta": 1e-9}, seed=2)
    assert np.all(np.isfinite(dr))
    _, _, dx = synthetic_recording(n_cycles=4, noise=0.01, seed=2)
    assert np.all(np.isfinite(dx))


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"pa": 0.6e6}, "separate"),
        ({"p0": -1.0}, "p0"),
        ({"n_cycles": 0}, "n_cycles"),
        ({"samples_per_cycle": 4}, "samples_per_cycle"),
        ({"model": "quadratic"}, "model"),
        ({"model": object()}, "simulate"),
        ({"noise": "loud"}, "noise"),
        ({"noise": {"x": 1.0}}, "unknown noise"),
        ({"noise": -0.1}, "noise"),
    ],
)
def test_synthetic_recording_bad_input(kwargs, match):
    with pytest.raises(contactlab.InputError, match=match):
        synthetic_recording(n_cycles=kwargs.pop("n_cycles", 2), **kwargs)
