"""contactlab.tangential: reversals, averaging, Masing fits, identifiability, derived values."""

from __future__ import annotations

import json
import math
import warnings

import matplotlib

matplotlib.use("Agg")

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from contactlab import ContactLabWarning, InputError, Masing, loop_area
from contactlab.io import Recording, read_recording, write_recording
from contactlab.report.tangential import plot_loop, plot_residuals
from contactlab.synthetic.tangential import synthetic_recording
from contactlab.tangential import analyze_tangential, average_loop, find_reversals
from contactlab.tangential.model import area_ratio, initial_guess, steady_loop_force
from contactlab.tangential.preprocess import monotone_path

H0, AC, A = 20.0, 1e5, 10e-6  # aluminium-like: ac·A = 1, h0 and ac both identifiable


def _quiet(**kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ContactLabWarning)
        return analyze_tangential(**kw)


def _z(res, name, truth):
    p = res.fit.params[name]
    return (p.value - truth) / p.stderr


# -- reversals -------------------------------------------------------------------------------


@settings(max_examples=30, deadline=None)
@given(
    cycles=st.integers(2, 8),
    amp=st.floats(1e-7, 1e-3),
    offset=st.floats(-1e-3, 1e-3),
    rel_noise=st.floats(0.0, 0.1),
    seed=st.integers(0, 1000),
)
def test_reversals_count_ignores_noise(cycles, amp, offset, rel_noise, seed):
    rng = np.random.default_rng(seed)
    n = 200 * cycles + 50  # a quarter cycle more: the last valley is confirmed
    ph = np.arange(n) / 200
    x = offset + amp * np.sin(2 * np.pi * ph) + rel_noise * amp * rng.standard_normal(n)
    rev = find_reversals(x, ph)
    assert rev.peaks.size == cycles
    assert rev.valleys.size == cycles
    # refined instants near the true ones (sine peaks at k + 1/4, valleys at k + 3/4)
    # (timing jitter: noise / slope at the band edge, a few times over)
    tol = 0.002 + 0.5 * rel_noise
    np.testing.assert_allclose(rev.peak_times, np.arange(cycles) + 0.25, atol=tol)
    np.testing.assert_allclose(rev.valley_times, np.arange(cycles) + 0.75, atol=tol)
    assert np.all(np.diff(rev.turns) > 0)


def test_raw_sign_changes_would_overcount():
    # The reason for the hysteresis band: noise makes hundreds of sign changes of dx.
    rng = np.random.default_rng(0)
    x = np.sin(np.linspace(0, 6.5 * np.pi, 3000)) + 0.02 * rng.standard_normal(3000)
    raw = np.sum(np.diff(np.sign(np.diff(x))) != 0)
    rev = find_reversals(x)
    assert raw > 100
    assert rev.peaks.size + rev.valleys.size == 6


def test_no_motion_raises():
    with pytest.raises(InputError, match="does not move"):
        find_reversals(np.ones(100))


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 10_000), n=st.integers(10, 200))
def test_monotone_path_is_monotone_between_turns(seed, n):
    rng = np.random.default_rng(seed)
    x = np.cumsum(rng.standard_normal(n))
    turns = np.sort(rng.choice(np.arange(1, n - 1), size=min(3, n - 2), replace=False))
    y = monotone_path(x, turns)
    edges = np.r_[0, turns, n]
    for a, b in itertools.pairwise(edges):
        d = np.diff(y[a:b])
        assert np.all(d >= -1e-12) or np.all(d <= 1e-12)
        # isotonic regression preserves the mean of each stretch
        assert np.mean(y[a:b]) == pytest.approx(np.mean(x[a:b]), abs=1e-9)


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 10_000),
    n=st.integers(1, 300),
    k=st.integers(0, 6),
    ties=st.booleans(),
)
def test_monotone_path_is_scipys_isotonic_regression(seed, n, k, ties):
    """The Rust projection gives SciPy's numbers (ties pooled, both directions, turns at the
    ends and repeated)."""
    from fold_reference import monotone_path_scipy

    rng = np.random.default_rng(seed)
    x = np.cumsum(rng.standard_normal(n))
    if ties:  # runs of equal values (a quantised sensor)
        x = np.round(x)
    turns = np.sort(rng.integers(0, n + 1, size=k))
    np.testing.assert_allclose(
        monotone_path(x, turns), monotone_path_scipy(x, turns), rtol=1e-14, atol=1e-14
    )


def test_monotone_path_refuses_non_finite_samples():
    with pytest.raises(InputError, match="x"):
        monotone_path(np.array([0.0, np.nan, 1.0]), np.array([1]))


# -- averaging -------------------------------------------------------------------------------


def test_average_loop_of_clean_signal_is_the_model_loop():
    model = Masing(H0, AC)
    rec = synthetic_recording(H0, AC, A, n_cycles=4.25, fs=400, noise=0.0, seed=0)
    loop = average_loop(rec["x"], rec["F"], rec.t, n_points=100)
    assert loop.n_cycles == 3
    assert loop.count.sum() == loop.cycle_end - loop.cycle_start
    # numeric area of the averaged loop vs the analytic energy (bins blunt the tips a little)
    assert loop_area(loop.x, loop.F) == pytest.approx(model.loop_energy(A), rel=2e-3)
    # noise-free: the only cycle-to-cycle scatter is where samples fall inside a bin, less
    # than one bin's step; the per-cycle loop areas agree
    assert np.nanmax(loop.F_std) < np.max(np.abs(np.diff(loop.F)))
    assert np.std(loop.scatter.energy) < 1e-3 * np.mean(loop.scatter.energy)
    np.testing.assert_allclose(loop.scatter.period, 1.0, atol=1e-9)


def test_average_loop_scatter_reflects_noise():
    rec = synthetic_recording(H0, AC, A, n_cycles=20.25, fs=200, noise=0.02, x_noise=0, seed=2)
    loop = average_loop(rec["x"], rec["F"], rec.t, n_points=50)
    sigma = rec.meta["truth"]["noise_F"]
    per_cycle = loop.count / loop.n_cycles  # samples of one cycle in each bin
    est = np.sqrt(np.mean(loop.F_std**2 * per_cycle))
    assert est == pytest.approx(sigma, rel=0.1)


def test_too_few_cycles_raises():
    rec = synthetic_recording(H0, AC, A, n_cycles=1.5, fs=200, seed=0)
    with pytest.raises(InputError, match="complete cycle"):
        analyze_tangential(rec)


# -- model and starting values ---------------------------------------------------------------


@settings(max_examples=40, deadline=None)
@given(z=st.floats(0.01, 30.0))
def test_initial_guess_inverts_the_area_ratio(z):
    model = Masing(H0, z / A)
    h0, ac = initial_guess(A, model.virgin(A), model.loop_energy(A))
    assert h0 == pytest.approx(H0, rel=1e-6)
    assert ac * A == pytest.approx(z, rel=1e-6)
    assert 0 < area_ratio(z) < 1


def test_steady_loop_is_the_rust_operator_loop():
    # the fit's model is the Rust operator itself: compare with a direct operator run
    model = Masing(H0, AC)
    n = 64
    ph = (np.arange(n) + 0.5) / n
    x = A * np.cos(2 * np.pi * ph)
    F = steady_loop_force(model, x, 0.0, A)
    path = np.r_[0.0, A, A, x[: n // 2], -A, x[n // 2 :]]
    direct = model.force(path)
    np.testing.assert_array_equal(F[: n // 2], direct[3 : 3 + n // 2])
    np.testing.assert_array_equal(F[n // 2 :], direct[4 + n // 2 :])
    # and the steady loop closes with the analytic energy
    assert loop_area(x, F) == pytest.approx(model.loop_energy(A), rel=2e-3)


# -- fits ------------------------------------------------------------------------------------


@pytest.mark.parametrize("on", ["averaged", "signal"])
def test_fit_recovers_parameters_with_offsets(on):
    rec = synthetic_recording(
        H0, AC, A, n_cycles=6, fs=500, noise=0.01, seed=11, offset=0.7, x_offset=4e-6
    )
    res = analyze_tangential(rec, on=on)
    assert res.fit.success
    assert res.identifiable
    for name, truth in [("h0", H0), ("ac", AC), ("offset", 0.7), ("x0", 4e-6)]:
        assert abs(_z(res, name, truth)) < 4, name
    assert abs(res.amplitude - A) < 4 * res.amplitude_stderr
    assert res.fit.redchi == pytest.approx(rec.meta["truth"]["noise_F"] ** 2, rel=0.3)


def test_virgin_history_fit_finds_the_rest_position():
    rec = synthetic_recording(
        H0, AC, A, n_cycles=3, fs=500, noise=0.01, x_noise=0.003, seed=5, x_offset=2e-6
    )
    res = analyze_tangential(rec, on="signal", history="virgin")
    assert abs(_z(res, "x0", 2e-6)) < 4
    assert abs(_z(res, "h0", H0)) < 4
    assert abs(_z(res, "ac", AC)) < 4


def test_uncertainty_is_honest_over_many_seeds():
    """~95 % of the 2σ intervals hold the truth (h0, ac, energy per cycle from the model and
    from the loop area, amplitude)."""
    n = 150
    hits = np.zeros(5)
    E = Masing(H0, AC).loop_energy(A)
    for seed in range(n):
        rec = synthetic_recording(H0, AC, A, n_cycles=3.25, fs=120, noise=0.02, seed=seed)
        res = analyze_tangential(rec, warn=False)
        e, de = res.derived["energy_per_cycle"]
        en, den = res.derived["energy_per_cycle_numeric"]
        hits += [
            abs(_z(res, "h0", H0)) <= 2,
            abs(_z(res, "ac", AC)) <= 2,
            abs(e - E) <= 2 * de,
            abs(res.amplitude - A) <= 2 * res.amplitude_stderr,
            abs(en - E) <= 2 * den,
        ]
    frac = hits / n
    assert np.all(frac >= 0.88), frac
    assert np.all(frac <= 0.99), frac


def test_signal_fit_uncertainty_is_honest():
    n = 60
    hits = 0
    for seed in range(n):
        rec = synthetic_recording(
            H0, AC, A, n_cycles=2.5, fs=100, noise=0.02, x_noise=0.003, seed=1000 + seed
        )
        res = analyze_tangential(rec, on="signal", warn=False)
        hits += abs(_z(res, "h0", H0)) <= 2
    assert 0.83 * n <= hits <= n  # 60 seeds: binomial 2σ band around 95 %


# -- identifiability and regimes -------------------------------------------------------------


def test_small_loop_reports_only_the_product():
    # the paper's steel case: amplitude << 1/ac, the loop is nearly a pure stiffness
    h0, ac, amp = 200.0, 2e4, 0.3e-6
    rec = synthetic_recording(h0, ac, amp, n_cycles=4, fs=400, noise=0.03, seed=3)
    with pytest.warns(ContactLabWarning, match="NOT separately identifiable"):
        res = analyze_tangential(rec)
    assert not res.identifiable
    d = res.to_dict()
    assert d["h0"] is None and d["ac"] is None
    assert d["identifiable"]["h0"] is False and d["identifiable"]["h0_ac"] is True
    k, dk = res.derived["h0_ac"]
    assert abs(k - h0 * ac) < 4 * dk
    assert dk / k < 0.01
    # the one-sided bounds hold the truth
    assert d["ac_upper_bound"] > ac
    assert d["h0_lower_bound"] < h0
    assert res.fit.params["h0"].identifiable is False
    assert "NOT IDENTIFIABLE" in res.fit.report()


def test_decision_follows_the_data_not_the_amplitude():
    # Same amplitude, same ac·A: clean data identify h0 and ac, noisy data do not.
    h0, ac, amp = 200.0, 2e4, 2e-6
    clean = synthetic_recording(h0, ac, amp, n_cycles=4, fs=400, noise=0.002, seed=1)
    noisy = synthetic_recording(h0, ac, amp, n_cycles=4, fs=400, noise=0.2, seed=1)
    assert _quiet(recording=clean).identifiable
    assert not _quiet(recording=noisy).identifiable


def test_gross_sliding_warns():
    rec = synthetic_recording(H0, AC, 80e-6, n_cycles=3, fs=400, noise=0.01, seed=0)
    with pytest.warns(ContactLabWarning, match="gross sliding"):
        res = analyze_tangential(rec)
    assert any("gross sliding" in w for w in res.warnings)


def test_pre_sliding_loop_does_not_warn():
    rec = synthetic_recording(H0, AC, A, n_cycles=3, fs=400, noise=0.01, seed=0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = analyze_tangential(rec)
    assert res.warnings == []


# -- derived quantities ----------------------------------------------------------------------


def test_derived_quantities_follow_the_paper_formulas():
    rec = synthetic_recording(H0, AC, A, n_cycles=4, fs=400, noise=0.01, seed=4)
    res = analyze_tangential(rec)
    m, amp = res.model, res.amplitude
    h0, ac = m.h0, m.ac
    E = 8 * (h0 * (amp - (1 - math.exp(-ac * amp)) / ac) - amp * h0 * (1 - math.exp(-ac * amp)) / 2)
    assert res.derived["energy_per_cycle"][0] == pytest.approx(E, rel=1e-9)
    assert res.derived["equivalent_damping"][0] == pytest.approx(E / (math.pi * amp**2), rel=1e-9)
    assert res.derived["k_local0"][0] == pytest.approx(h0 * ac, rel=1e-9)
    assert res.derived["k_local_amplitude"][0] == pytest.approx(
        h0 * ac * math.exp(-ac * amp), rel=1e-9
    )
    assert res.derived["k_global"][0] == pytest.approx(
        h0 * (1 - math.exp(-ac * amp)) / amp, rel=1e-9
    )
    # analytic and numerical energies agree within their combined errors
    e, de = res.derived["energy_per_cycle"]
    en, den = res.derived["energy_per_cycle_numeric"]
    assert abs(e - en) < 3 * math.hypot(de, den)


def test_to_dict_has_the_contract_keys_and_is_json():
    rec = synthetic_recording(H0, AC, A, n_cycles=3, fs=400, seed=0)
    d = analyze_tangential(rec).to_dict()
    keys = [
        "h0", "ac", "h0_stderr", "ac_stderr", "amplitude", "energy_per_cycle",
        "energy_per_cycle_numeric", "equivalent_damping", "k_local0", "k_global",
    ]  # fmt: skip
    for k in keys:
        assert d[k] is not None and math.isfinite(d[k]), k
    for k in ("energy_per_cycle", "equivalent_damping", "k_local0", "k_global", "amplitude"):
        assert d[f"{k}_stderr"] > 0
    assert d["units"]["h0"] == "N" and d["units"]["ac"] == "1/m"
    assert d["units"]["energy_per_cycle"] == "J" and d["units"]["k_global"] == "N/m"
    assert "identifiable" in d and "message" in d["identifiable"]
    json.loads(json.dumps(d, allow_nan=False))


# -- files end to end ------------------------------------------------------------------------


@pytest.mark.parametrize("ext", ["csv", "tdms", "h5", "mat"])
def test_round_trip_through_every_format(tmp_path, ext):
    rec = synthetic_recording(H0, AC, A, n_cycles=4, fs=400, noise=0.01, seed=21, offset=0.2)
    # a rig-like file: µm and ms for CSV
    p = tmp_path / f"run.{ext}"
    if ext == "csv":
        rows = np.column_stack([rec.t * 1e3, rec["x"] * 1e6, rec["F"]])
        p.write_text(
            "t [ms],x [um],F [N]\n" + "\n".join(",".join(repr(float(v)) for v in r) for r in rows)
        )
    else:
        write_recording(p, rec)
    back = read_recording(p)
    res = analyze_tangential(back)
    for name, truth in [("h0", H0), ("ac", AC), ("offset", 0.2)]:
        assert abs(_z(res, name, truth)) < 3, (ext, name)
    assert res.source == str(p)


# -- plots and bad input ---------------------------------------------------------------------


@pytest.mark.parametrize("on", ["averaged", "signal"])
def test_plots_return_axes(on):
    rec = synthetic_recording(H0, AC, A, n_cycles=3, fs=200, seed=0)
    res = analyze_tangential(rec, on=on)
    ax = plot_loop(res)
    assert ax.get_xlabel().startswith("displacement")
    ax2 = plot_residuals(res)
    assert len(ax2.lines) >= 1
    import matplotlib.pyplot as plt

    fig, axs = plt.subplots(1, 2)
    assert plot_loop(res, ax=axs[0]) is axs[0]
    assert plot_residuals(res, ax=axs[1]) is axs[1]
    plt.close(fig)


def test_plot_of_unidentifiable_fit_says_so():
    rec = synthetic_recording(200.0, 2e4, 0.3e-6, n_cycles=3, fs=200, noise=0.03, seed=3)
    res = _quiet(recording=rec)
    assert "not separable" in plot_loop(res).get_title()


def test_bad_input():
    rec = synthetic_recording(H0, AC, A, n_cycles=3, fs=200, seed=0)
    with pytest.raises(InputError, match="not both"):
        analyze_tangential(rec, x=rec["x"])
    with pytest.raises(InputError, match="on must be"):
        analyze_tangential(rec, on="loop")
    with pytest.raises(InputError, match="history"):
        analyze_tangential(rec, history="virgin")
    with pytest.raises(InputError, match="samples"):
        analyze_tangential(x=np.zeros(10), F=np.zeros(9))
    with pytest.raises(InputError, match=r"F\[3\]"):
        F = rec["F"].copy()
        F[3] = np.nan
        analyze_tangential(x=rec["x"], F=F, t=rec.t)
    with pytest.raises(InputError, match="no 'F'"):
        analyze_tangential(Recording(rec.t, {"x": rec["x"]}, {"x": "m"}))
    with pytest.raises(InputError, match="even"):
        analyze_tangential(rec, n_points=51)
    with pytest.raises(InputError):
        synthetic_recording(-1.0, AC, A)


def test_arrays_without_time_work():
    rec = synthetic_recording(H0, AC, A, n_cycles=3, fs=200, seed=0)
    res = analyze_tangential(x=rec["x"], F=rec["F"])
    assert abs(_z(res, "h0", H0)) < 4


def test_model_misfit_is_reported():
    # A loop from a different virgin curve (tanh-like): the exponential model cannot follow it,
    # and the analysis says so instead of quoting tiny errors silently.
    xp = np.linspace(0, 40e-6, 200)
    fp = 15 * np.tanh(xp / 8e-6) ** 0.7
    model = Masing.from_backbone(xp, fp)
    t = np.arange(2000) / 400
    x = 10e-6 * np.sin(2 * np.pi * t)
    F = model.force(x) + 0.01 * np.random.default_rng(0).standard_normal(x.size)
    rec = Recording(t, {"x": x, "F": F}, {"x": "m", "F": "N"})
    with pytest.warns(ContactLabWarning, match="misses systematic features"):
        analyze_tangential(rec)


def test_force_drift_is_removed():
    rec = synthetic_recording(H0, AC, A, n_cycles=10.25, fs=200, noise=0.02, drift=0.5, seed=8)
    res = analyze_tangential(rec)
    d, dd = res.derived["force_drift"]
    assert abs(d - 0.5) < 4 * dd
    assert abs(_z(res, "h0", H0)) < 3 and abs(_z(res, "ac", AC)) < 3
    raw = _quiet(recording=rec, detrend=False)
    assert raw.derived["force_drift"] == (0.0, 0.0)
    # left in, the drift opens the averaged loop: worse fit, h0 off by 3σ
    assert raw.fit.chisqr > 1.2 * res.fit.chisqr
    assert abs(_z(raw, "h0", H0)) > 2.5


def test_inverted_force_sign_is_detected():
    rec = synthetic_recording(H0, AC, A, n_cycles=4, fs=300, noise=0.01, seed=2)
    flipped = Recording(rec.t, {"x": rec["x"], "F": -rec["F"]}, {"x": "m", "F": "N"})
    with pytest.warns(ContactLabWarning, match="analysed -F"):
        res = analyze_tangential(flipped)
    assert res.meta["invert_force"] is True
    assert abs(_z(res, "h0", H0)) < 4
    straight = analyze_tangential(rec)
    assert res.fit.params["h0"].value == pytest.approx(straight.fit.params["h0"].value, rel=1e-6)


def test_triangle_wave_with_sharp_turns():
    # constant-speed drives turn sharply; the truth is made on a 32x finer grid so the contact
    # turns at the true extreme, between samples
    from scipy.signal import sawtooth

    rng = np.random.default_rng(4)
    fs = 173.3
    tf = np.arange(int(4.6 * fs * 32)) / (fs * 32)
    xf = A * sawtooth(2 * np.pi * (tf + 0.1), 0.5)
    Ff = Masing(H0, AC).force(xf)
    t, x = tf[::32], xf[::32] + 0.003 * A * rng.standard_normal(tf[::32].size)
    F = Ff[::32] + 0.25 * rng.standard_normal(t.size)
    rec = Recording(t, {"x": x, "F": F}, {"x": "m", "F": "N"})
    for on in ("averaged", "signal"):
        res = analyze_tangential(rec, on=on)
        assert abs(_z(res, "h0", H0)) < 3 and abs(_z(res, "ac", AC)) < 3, on
        assert abs(res.amplitude - A) < 3 * res.amplitude_stderr


def test_synthetic_sensor_imperfections():
    base = dict(h0=H0, ac=AC, amplitude=A, n_cycles=2, fs=1000, noise=0.0, x_noise=0.0, seed=1)
    clean = synthetic_recording(**base)
    np.testing.assert_array_equal(clean["F"], Masing(H0, AC).force(clean["x"]))
    q = synthetic_recording(**base, adc_bits=8)
    assert np.unique(q["F"]).size <= 2**8
    hum = synthetic_recording(**base, hum=0.5)
    spec = np.abs(np.fft.rfft(hum["F"] - clean["F"]))
    freqs = np.fft.rfftfreq(hum.t.size, 1 / 1000)
    assert freqs[np.argmax(spec)] == pytest.approx(50.0)
    drift = synthetic_recording(**base, drift=0.1, offset=1.0)
    np.testing.assert_allclose(drift["F"] - clean["F"], 1.0 + 0.1 * clean.t)
    assert synthetic_recording(**{**base, "seed": 7})["F"].tolist() == clean["F"].tolist()
    noisy1 = synthetic_recording(**{**base, "noise": 0.01, "seed": 3})
    noisy2 = synthetic_recording(**{**base, "noise": 0.01, "seed": 3})
    np.testing.assert_array_equal(noisy1["F"], noisy2["F"])


@settings(max_examples=15, deadline=None)
@given(
    h0=st.floats(1.0, 500.0),
    z=st.floats(0.005, 2.5),  # ac·A, from nearly linear to well into the curved regime
    amp=st.floats(1e-7, 1e-4),
    noise=st.floats(0.002, 0.05),
    seed=st.integers(0, 2**16),
)
def test_every_regime_is_reported_honestly(h0, z, amp, noise, seed):
    """Either h0 and ac are identified and hold the truth, or the analysis says they are not
    and the product h0·ac (always reported) holds the truth."""
    ac = z / amp
    rec = synthetic_recording(h0, ac, amp, n_cycles=3.25, fs=150, noise=noise, seed=seed)
    res = _quiet(recording=rec)
    k, dk = res.derived["h0_ac"]
    assert abs(k - h0 * ac) < 5 * dk
    if res.identifiable:
        # h0 = k0/ac: compare on a log scale, where the first-order error is symmetric
        p0, pa = res.fit.params["h0"], res.fit.params["ac"]
        assert abs(math.log(p0.value / h0)) < 5 * p0.rel_stderr
        assert abs(math.log(pa.value / ac)) < 5 * pa.rel_stderr
    else:
        d = res.to_dict()
        assert d["h0"] is None and d["ac"] is None
        # a (2σ, one-sided) bound is given, or none exists (null in JSON); the unidentified
        # ac still lies within its wide interval
        assert d["ac_upper_bound"] is None or d["ac_upper_bound"] > 0
        pa = res.fit.params["ac"]
        if pa.stderr is not None:
            assert ac < pa.value + 5 * pa.stderr


def test_displacement_drift_is_removed():
    rate = 0.03 * A  # m/s: the sensor's zero wanders 30 % of A over 10 s
    rec = synthetic_recording(H0, AC, A, n_cycles=10.25, fs=200, noise=0.02, x_drift=rate, seed=9)
    res = analyze_tangential(rec)
    d, dd = res.derived["displacement_drift"]
    assert abs(d - rate) < 4 * dd
    assert abs(_z(res, "h0", H0)) < 3 and abs(_z(res, "ac", AC)) < 3
    assert res.to_dict()["units"]["displacement_drift"] == "m/s"


@settings(max_examples=80, deadline=None)
@given(r=st.floats(0.0, 1.0), xtol=st.sampled_from([1e-10, 2e-12, 1e-6]))
def test_brentq_is_scipys_to_the_last_bit(r, xtol):
    """The start value's root finder (no SciPy import in a window's thread) gives SciPy's
    brentq root bit for bit, on the area-ratio equation it solves and on a cubic."""
    from scipy.optimize import brentq as scipy_brentq

    from contactlab.tangential.model import area_ratio, brentq

    lo, hi = 1e-3, 60.0
    r = area_ratio(lo) + r * (area_ratio(hi) - area_ratio(lo))
    if not area_ratio(lo) < r < area_ratio(hi):
        return
    f = lambda z: area_ratio(z) - r  # noqa: E731
    assert brentq(f, lo, hi, xtol=xtol) == scipy_brentq(f, lo, hi, xtol=xtol)
    g = lambda x: x**3 - 2 * x - 5 + r  # noqa: E731
    assert brentq(g, 2.0, 3.0) == scipy_brentq(g, 2.0, 3.0)


def test_brentq_refuses_an_unbracketed_root():
    from contactlab.tangential.model import brentq

    with pytest.raises(InputError, match="same sign"):
        brentq(lambda z: z * z + 1.0, -1.0, 1.0)


@settings(max_examples=100, deadline=None)
@given(
    v=st.lists(
        st.one_of(st.floats(0.0, 1e6), st.just(float("nan"))), min_size=1, max_size=30
    ).filter(lambda v: not all(math.isnan(a) for a in v))
)
def test_tip_nanmean_is_numpys_bit_for_bit(v):
    from contactlab.tangential.turns import nanmean

    a = np.asarray(v)
    assert nanmean(a) == float(np.nanmean(a))
