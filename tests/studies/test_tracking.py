"""contactlab.track: per-cycle kernel against a plain-Python reference, windows, streamed vs
whole-signal analysis, chunking invariance, normal recordings, real data."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import contactlab
from contactlab import InputError
from contactlab.io import Recording, write_recording
from contactlab.studies.cycles import CycleState, block_cycles
from contactlab.studies.tracking import parse_every, track
from contactlab.synthetic.normal import synthetic_recording as normal_recording
from contactlab.synthetic.tangential import synthetic_recording
from contactlab.tangential import analyze_tangential

DATA = Path(__file__).resolve().parents[2].parent / "shared" / "data"


def _reference(t, x, F, drive, lo, hi):
    """Per-sample loop: Schmitt-trigger upward crossings, then each cycle's polygon area by
    the shoelace formula (clockwise loops dissipate: ∮F dx = -signed area)."""
    level, ups = 0, []
    for i, v in enumerate(drive):
        new = 1 if v >= hi else -1 if v <= lo else level
        if new == 1 and level == -1:
            ups.append(i)
        level = new
    out = []
    for a, b in itertools.pairwise(ups):
        xs, fs = x[a : b + 1], F[a : b + 1]
        area = 0.5 * float(np.sum(xs * np.roll(fs, -1) - np.roll(xs, -1) * fs))
        seg = slice(a, b)
        out.append((t[a], t[b], -area, 0.5 * np.ptp(x[seg]), 0.5 * (F[seg].max() + F[seg].min())))
    return ups, out


def _signal(n=3000, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) / 500.0
    x = 20e-6 * np.sin(2 * np.pi * 3.3 * t + rng.uniform(0, 6)) + 1e-6 * rng.standard_normal(n)
    F = contactlab.Masing(40.0, 4e4).force(x) + 0.3 * rng.standard_normal(n)
    return t, x, F


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10_000), cuts=st.lists(st.integers(1, 2999), max_size=6))
def test_cycle_kernel_matches_reference_under_any_chunking(seed, cuts):
    t, x, F = _signal(seed=seed)
    lo, hi = -5e-6, 5e-6
    ups, ref = _reference(t, x, F, x, lo, hi)
    s = CycleState()
    got = {k: [] for k in ("crossings", "start", "end", "energy", "amplitude", "offset")}
    edges = [0, *sorted(set(cuts)), t.size]
    for a, b in itertools.pairwise(edges):
        c = block_cycles(t[a:b], x[a:b], F[a:b], x[a:b], a, s, levels=(lo, hi))
        for k in got:
            got[k].append(getattr(c, k))
    cat = {k: np.concatenate(v) for k, v in got.items()}
    assert cat["crossings"].tolist() == ups
    ref_a = np.array(ref)
    assert cat["energy"].size == len(ref) > 10
    np.testing.assert_allclose(cat["start"], ref_a[:, 0])
    np.testing.assert_allclose(cat["end"], ref_a[:, 1])
    np.testing.assert_allclose(cat["energy"], ref_a[:, 2], rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(cat["amplitude"], ref_a[:, 3], rtol=1e-12)
    np.testing.assert_allclose(cat["offset"], ref_a[:, 4], rtol=1e-12, atol=1e-12)


def test_cycle_energy_equals_masing_closed_form():
    m = contactlab.Masing(h0=40.0, ac=4e4)
    t = np.linspace(0, 20, 40_001)
    x = 20e-6 * np.sin(2 * np.pi * t)
    c = block_cycles(t, x, m.force(x), x, 0, CycleState())
    # the first upward crossing follows the first fall below the band: 19 crossings, 18 cycles
    assert c.energy.size == 18 and c.crossings[0] == 2081
    # every one a steady symmetric loop: the closed-form energy
    np.testing.assert_allclose(c.energy, m.loop_energy(20e-6), rtol=2e-5)
    np.testing.assert_allclose(c.amplitude, 20e-6, rtol=1e-6)


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("100cycles", ("cycles", 100.0)),
        ("10s", ("time", 10.0)),
        ("500 ms", ("time", 0.5)),
        ("2min", ("time", 120.0)),
        (50, ("cycles", 50.0)),
    ],
)
def test_parse_every(text, expected):
    assert parse_every(text) == expected


@pytest.mark.parametrize("bad", ["", "2cycles", "3.5cycles", "10 kg", "fast", "-3s", None])
def test_parse_every_rejects(bad):
    with pytest.raises(InputError, match="every"):
        parse_every(bad)


@pytest.fixture(scope="module")
def long_rec():
    # fresh seed (not one used while writing the code), noise on both channels, drift off
    return synthetic_recording(
        h0=35.0,
        ac=6e4,
        amplitude=15e-6,
        n_cycles=40,
        fs=1500.0,
        frequency=2.0,
        noise=0.02,
        seed=9117,
    )


def test_windows_of_cycles_and_seconds(long_rec):
    r = track(long_rec, every="8cycles")
    spans = [row["cycle_end"] - row["cycle_start"] for row in r.rows]
    assert spans[:-1] == [8] * (len(spans) - 1) and 2 <= spans[-1] <= 8
    assert r.cycles["energy"].size == r.rows[-1]["cycle_end"]
    assert sum(row["n_samples"] for row in r.rows) == len(long_rec)
    rt = track(long_rec, every="4s")  # 2 Hz: cut at the first crossing 4 s after the start
    starts = rt.column("t_start")
    assert len(rt.rows) >= 4
    assert np.all(np.diff(starts) >= 4.0) and np.all(np.diff(starts) < 4.0 + 0.5 + 1e-9)
    assert sum(row["n_samples"] for row in rt.rows) == len(long_rec)
    assert r.units["h0"] == "N" and r.units["t_mid"] == "s"


def test_streamed_agrees_with_whole_signal_within_errors(long_rec, tmp_path):
    """The Done-when test of issue 9: the same recording, whole vs streamed (file read in
    small chunks, windows of 10 cycles pooled)."""
    p = tmp_path / "long.h5"
    write_recording(p, long_rec)
    whole = analyze_tangential(long_rec, warn=False).to_dict()
    streamed = track(p, every="10cycles", chunk_size=4096).combined()
    for q in (
        "h0",
        "ac",
        "h0_ac",
        "energy_per_cycle",
        "energy_per_cycle_numeric",
        "equivalent_damping",
        "k_global",
        "amplitude",
    ):
        err = np.hypot(whole[f"{q}_stderr"], streamed[f"{q}_stderr"])
        assert abs(whole[q] - streamed[q]) < 3 * err, (q, whole[q], streamed[q], err)
    # and both near the truth
    assert abs(streamed["h0"] - 35.0) < 4 * streamed["h0_stderr"]


def test_chunk_size_does_not_change_the_result(long_rec, tmp_path):
    p = tmp_path / "long.csv"
    write_recording(p, long_rec)
    a = track(p, every="10cycles", chunk_size=777)
    b = track(long_rec, every="10cycles")
    assert [r["cycle_end"] for r in a.rows] == [r["cycle_end"] for r in b.rows]
    np.testing.assert_allclose(a.column("h0"), b.column("h0"), rtol=1e-9)
    np.testing.assert_allclose(a.cycles["energy"], b.cycles["energy"], rtol=1e-9)


def test_window_too_long_is_refused(long_rec):
    with pytest.raises(InputError, match="max_window"):
        track(long_rec, every="30cycles", max_window=5000)


def test_too_short_for_a_window():
    rec = synthetic_recording(h0=35.0, ac=6e4, amplitude=15e-6, n_cycles=1, fs=500.0, seed=4)
    with pytest.raises(InputError, match="complete cycle"):
        track(rec, every="3cycles")


def test_normal_recording_tracks_loop_quantities():
    import contactlab.normal as cn

    t, p, d = normal_recording(p0=0.5e6, pa=0.4e6, omega=1.0, n_cycles=20, seed=5021)
    rec = Recording(t, {"p": p, "delta": d}, {"p": "Pa", "delta": "m"})
    r = track(rec, every="5cycles")
    whole = cn.analyze_loop(t, p, d)
    comb = r.combined()
    assert {"E_d", "psi", "k_tan", "k_sec", "poly_load_0"} <= set(r.quantities)
    assert r.units["k_tan"] == "Pa/m" and r.units["E_d"] == "J/m^2"
    whole_err = whole.E_d_cycle_std / np.sqrt(whole.n_cycles)
    assert abs(comb["E_d"] - whole.E_d) < 3 * np.hypot(comb["E_d_stderr"], whole_err)
    assert abs(comb["psi"] - whole.psi) < 4 * comb["psi_stderr"]
    # per-cycle energies: ∮ p dδ per cycle ≈ the loop analysis' E_d
    assert abs(np.median(r.cycles["energy"]) - whole.E_d) < 0.03 * whole.E_d


def test_real_friction_frame_data():
    """Measured loops (friction force from the frame's equation of motion, see the data's
    README): per-cycle energies equal the per-sample reference, are positive, and agree with
    the window analyses' loop areas."""
    f = DATA / "friction_frame" / "frame_disc450g.csv"
    if not f.exists():
        pytest.skip("../shared/data absent")
    raw = np.loadtxt(f, delimiter=",", skiprows=1)
    t, x, y = raw[:, 0], raw[:, 1] * 1e-3, raw[:, 2] * 1e-3
    dt = t[1] - t[0]
    xd, yd = np.gradient(x, dt), np.gradient(y, dt)
    F = 1191.0 * (y - x) + 0.6690 * (yd - xd) - 3.0799 * np.gradient(xd, dt)
    rec = Recording(t, {"x": x, "F": F}, {"x": "m", "F": "N"}, "frame_disc450g")
    a = track(rec, every="5cycles", chunk_size=100)
    assert len(a.rows) >= 1 and a.cycles["energy"].size >= 7
    # per-cycle energies: the per-sample reference with the trigger band the kernel used
    lo_d, hi_d = x.min(), x.max()
    c, h = 0.5 * (hi_d + lo_d), 0.25 * 0.5 * (hi_d - lo_d)
    _, ref = _reference(t, x, F, x, c - h, c + h)
    np.testing.assert_allclose(a.cycles["energy"], [r[2] for r in ref], rtol=1e-9)
    assert np.all(a.cycles["energy"] > 0)  # a passive joint dissipates
    # the window analyses' loop areas agree with the per-cycle ones
    ok = [r for r in a.rows if not r.get("error")]
    assert ok
    for r in ok:
        inside = (a.cycles["start"] >= r["t_start"]) & (a.cycles["end"] <= r["t_end"] + 0.01)
        e = abs(r["energy_per_cycle_numeric"])
        assert abs(np.mean(a.cycles["energy"][inside]) - e) < 0.05 * e


# -- the one-pass window analysis (issue 9: per-window work in Rust) ----------------------

_WINDOW_CASES = {
    # fresh seeds; noise on both channels, drifts, another sampling rate, an inverted load
    # cell, and a gross-sliding loop (which takes the whole-window analysis)
    "pre-sliding": dict(h0=35.0, ac=6e4, amplitude=15e-6, n_cycles=12, fs=1500.0, frequency=2.0,
                        noise=0.02, seed=6803),
    "drifts": dict(h0=22.0, ac=9e4, amplitude=9e-6, n_cycles=10.3, fs=700.0, noise=0.03,
                   x_noise=0.01, drift=0.4, x_drift=2e-7, seed=6804),
    "transition": dict(h0=40.0, ac=1.2e5, amplitude=15e-6, n_cycles=8, fs=2500.0, noise=0.01,
                       seed=6805),
    "gross sliding": dict(h0=40.0, ac=4e5, amplitude=20e-6, n_cycles=8, fs=2000.0, noise=0.01,
                          seed=6806),
}  # fmt: skip


@pytest.mark.parametrize("case", sorted(_WINDOW_CASES))
@pytest.mark.parametrize("invert", [False, True])
def test_window_analysis_equals_the_whole_analysis(case, invert):
    """analyze_window (one fold, reused) gives analyze_tangential's numbers and verdicts."""
    from contactlab.tangential.window import analyze_window

    rec = synthetic_recording(**_WINDOW_CASES[case])
    if invert:
        rec = Recording(rec.t, {"x": rec["x"], "F": -rec["F"]}, rec.units, rec.source, {})
    a = analyze_tangential(rec, warn=False).to_dict()
    b = analyze_window(rec).to_dict()
    sign = -1 if invert else 1
    assert a["regime"] == b["regime"] and a["force_sign"] == b["force_sign"] == sign
    assert a["identifiable"]["h0"] == b["identifiable"]["h0"]
    # the same warnings; the orientation's names the loop area's error, which the window
    # estimates from the folded loop's spread instead of second differences
    assert [w[:40] for w in a["warnings"]] == [w[:40] for w in b["warnings"]]
    assert [w for w in a["warnings"] if "analysed -F" not in w] == [
        w for w in b["warnings"] if "analysed -F" not in w
    ]
    assert (
        abs(b["loop_area_recorded"] - a["loop_area_recorded"]) < 3 * a["loop_area_recorded_stderr"]
    )
    for q in (*contactlab.studies.tracking.TANGENTIAL_QUANTITIES, "force_drift", "x0"):
        for k in (q, f"{q}_stderr"):
            if a.get(k) is None:
                assert b.get(k) is None, k
            else:
                np.testing.assert_allclose(b[k], a[k], rtol=1e-9, atol=0, err_msg=k)
    if case == "gross sliding":
        assert b["stick_slip"] == a["stick_slip"]  # the whole-window analysis ran
    else:  # reversals counted, the stick search not run
        assert b["stick_slip"]["n_reversals"] == a["stick_slip"]["n_reversals"]
        assert b["stick_slip"]["reversals_with_stick"] is None
        assert set(b["stick_slip"]) == set(a["stick_slip"])


@settings(max_examples=200, deadline=None)
@given(
    pt=st.lists(st.floats(0, 10), max_size=8),
    vt=st.lists(st.floats(0, 10), max_size=8),
    ties=st.booleans(),
)
def test_phase_knots_vectorised_equals_the_loop(pt, vt, ties):
    from contactlab.tangential.preprocess import Reversals, phase_knots
    from fold_reference import phase_knots_loop

    p = np.sort(np.asarray(pt, dtype=float))
    v = np.sort(np.r_[vt, p[:2]] if ties else np.asarray(vt, dtype=float))
    e = np.empty(0, dtype=np.int64)
    rev = Reversals(e, e, p, v, 1.0, 0.0)
    for a, b in zip(phase_knots(rev), phase_knots_loop(rev), strict=True):
        np.testing.assert_array_equal(a, b)


def test_negated_loop_is_the_fold_of_minus_F():
    """The window analysis of an inverted load cell negates its one fold instead of folding
    -F again: bit for bit the same loop."""
    from contactlab.tangential.preprocess import average_loop, negated_loop

    rec = synthetic_recording(**_WINDOW_CASES["drifts"])
    a = negated_loop(average_loop(rec["x"], rec["F"], rec.t))
    b = average_loop(rec["x"], -rec["F"], rec.t)
    for k in ("x", "F", "count", "x_std", "F_std", "x_var", "t_mean"):
        np.testing.assert_array_equal(getattr(a, k), getattr(b, k), err_msg=k)
    for k in ("energy", "mean_force", "force_range", "amplitude", "mean_x"):
        np.testing.assert_array_equal(getattr(a.scatter, k), getattr(b.scatter, k), err_msg=k)
    for u, v in zip(a.sensitivity, b.sensitivity, strict=True):
        np.testing.assert_array_equal(u, v)


def test_window_analysis_force_sign_given_or_undecided():
    from contactlab.tangential.window import analyze_window

    rec = synthetic_recording(**_WINDOW_CASES["pre-sliding"])
    fixed = analyze_window(rec, force_sign=-1).to_dict()
    ref_fixed = analyze_tangential(rec, force_sign=-1, warn=False).to_dict()
    assert fixed["force_sign"] == ref_fixed["force_sign"] == -1
    assert "given by the user" in fixed["orientation_reason"]
    assert fixed["regime"] == ref_fixed["regime"]
    np.testing.assert_allclose(fixed["h0_ac"], ref_fixed["h0_ac"], rtol=1e-9)
    # a line (no dissipation): the area does not decide, the full orientation does
    line = Recording(rec.t, {"x": rec["x"], "F": 1e5 * rec["x"]}, rec.units, rec.source, {})
    with pytest.warns(contactlab.ContactLabWarning):
        ref = analyze_tangential(line).to_dict()
    got = analyze_window(line).to_dict()
    assert got["force_sign"] == ref["force_sign"] == 1
    assert got["orientation_reason"] == ref["orientation_reason"]


@pytest.mark.parametrize(
    ("channel", "index", "value", "message"),
    [
        ("x", 500, np.nan, r"x\[500\] is not finite"),
        ("F", 700, np.inf, r"F\[700\] is not finite"),
        ("t", 900, np.nan, r"t\[900\] is not finite"),
        ("t", 901, "dup", r"t\[901\] .* does not exceed"),
        ("x", 5, 1e200, "x reaches 1e\\+200 m at sample 5"),
    ],
)
def test_window_analysis_names_a_bad_sample(channel, index, value, message):
    """The window path scans x and F once (check_channel) and skips the conversions' second
    scan: a bad sample is still named (the messages the window path gave before)."""
    from contactlab.tangential.window import analyze_window

    rec = synthetic_recording(**_WINDOW_CASES["drifts"])
    t, x, F = rec.t.copy(), rec["x"].copy(), rec["F"].copy()
    a = {"t": t, "x": x, "F": F}[channel]
    a[index] = a[index - 1] if value == "dup" else value
    bad = Recording(t, {"x": x, "F": F}, rec.units, rec.source, {})
    with pytest.raises(InputError, match=message):
        analyze_window(bad)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10_000), n=st.integers(2, 400), k=st.integers(2, 12))
def test_period_means_is_numpy_cumsum_interp(seed, n, k):
    from contactlab import _core

    rng = np.random.default_rng(seed)
    t = np.cumsum(rng.uniform(0.01, 1.0, n))
    v = rng.standard_normal(n) * 10.0 ** rng.uniform(-6, 6)
    edges = np.sort(rng.uniform(t[0] - 0.5, t[-1] + 0.5, k))
    c = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))])
    with np.errstate(invalid="ignore", divide="ignore"):
        ref = np.diff(np.interp(edges, t, c)) / np.diff(edges)
    np.testing.assert_array_equal(_core.period_means(t, v, edges), ref)
    with pytest.raises(InputError, match="increasing"):
        _core.period_means(t[::-1].copy(), v, edges)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 10_000), cuts=st.lists(st.integers(0, 600), max_size=5))
def test_loop_area_sensitivity_is_the_roll_formula(seed, cuts):
    from contactlab import _core

    rng = np.random.default_rng(seed)
    x, F = rng.standard_normal(600), rng.standard_normal(600)
    bounds = sorted({0, 600, *cuts})
    g_F, g_x = _core.loop_area_sensitivity(x, F, bounds)
    for k, (a, b) in enumerate(itertools.pairwise(bounds)):
        xs, Fs = x[a:b], F[a:b]
        ref_F = np.sum((0.5 * (np.roll(xs, 1) - np.roll(xs, -1))) ** 2)
        ref_x = np.sum((0.5 * (np.roll(Fs, -1) - np.roll(Fs, 1))) ** 2)
        np.testing.assert_allclose([g_F[k], g_x[k]], [ref_F, ref_x], rtol=1e-12, atol=1e-300)


def test_threads_give_the_serial_rows(long_rec):
    a = track(long_rec, every="6cycles", threads=0)
    b = track(long_rec, every="6cycles", threads=2)
    assert a.rows == b.rows
    np.testing.assert_array_equal(a.cycles["energy"], b.cycles["energy"])
    with pytest.raises(InputError, match="threads"):
        track(long_rec, every="6cycles", threads=-1)


def test_threads_read_on_when_a_younger_window_finishes_first(long_rec, monkeypatch):
    """On helper threads the reader waits for any window to finish, not the oldest: windows
    whose analysis times vary (a younger one done first) give the serial rows, the callbacks
    come in window order, and no more than threads + 2 windows are ever unfinished."""
    import threading
    import time

    from contactlab.studies import tracking

    real = tracking._tangential_window
    lock = threading.Lock()
    state = {"open": 0, "most": 0, "calls": 0}

    def slow(rec, opts, **kw):
        with lock:
            state["calls"] += 1
            k = state["calls"]
        try:
            time.sleep(0.03 if k % 3 == 1 else 0.0)  # every third window the slowest
            return real(rec, opts, **kw)
        finally:  # before the future is done (a done-callback would run after the reader
            with lock:  # may already have seen it done and submitted the next window)
                state["open"] -= 1

    from concurrent.futures import ThreadPoolExecutor

    submit = ThreadPoolExecutor.submit

    def counted(self, fn, *a, **k):
        with lock:
            state["open"] += 1
            state["most"] = max(state["most"], state["open"])
        return submit(self, fn, *a, **k)

    monkeypatch.setattr(tracking, "_tangential_window", slow)
    monkeypatch.setattr(ThreadPoolExecutor, "submit", counted)
    order = []
    b = track(long_rec, every="3cycles", threads=2, callback=lambda r: order.append(r["window"]))
    monkeypatch.undo()
    a = track(long_rec, every="3cycles", threads=0)
    assert a.rows == b.rows and len(b.rows) >= 8
    assert order == list(range(1, len(b.rows) + 1))
    assert state["most"] <= 4


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10_000), n_bins=st.integers(8, 60), n_cyc=st.integers(1, 9))
def test_fold_spread_is_the_numpy_spread(seed, n_bins, n_cyc):
    """PhaseFold.spread (Rust) against preprocess' numpy formulas, cells left empty included."""
    from contactlab import _core
    from fold_reference import dphase, spread

    rng = np.random.default_rng(seed)
    n = n_cyc * n_bins * 3
    t = np.sort(rng.uniform(0.0, n_cyc, n))
    t = t[np.r_[True, np.diff(t) > 0]]
    x, F = np.sin(2 * np.pi * t) + 0.1 * rng.standard_normal(t.size), rng.standard_normal(t.size)
    kt = np.linspace(0.0, n_cyc, n_cyc + 1)
    fold = _core.PhaseFold(n_bins, n_cyc)
    fold.push(t, x, F, 0, kt, kt.copy())
    s, got = fold.sums(), fold.spread()
    with np.errstate(invalid="ignore", divide="ignore"):
        cx, cF = s.cycle_x / s.cycle_count, s.cycle_F / s.cycle_count
        dphi = s.cycle_phase / s.cycle_count - s.sum_phase / s.count
        xm, Fm = s.sum_x / s.count, s.sum_F / s.count
        ref_x = spread(cx - dphase(xm, n_bins) * dphi)
        ref_F = spread(cF - dphase(Fm, n_bins) * dphi)
    np.testing.assert_allclose(got.x_std, ref_x, rtol=1e-12, atol=0)
    np.testing.assert_allclose(got.F_std, ref_F, rtol=1e-12, atol=0)
    with np.errstate(invalid="ignore"):
        full = np.isfinite(cx).any(axis=1)
        ref_a = np.full(n_cyc, np.nan)
        ref_a[full] = 0.5 * (np.nanmax(cx[full], axis=1) - np.nanmin(cx[full], axis=1))
    np.testing.assert_array_equal(got.amplitude, ref_a)
    lean = fold.sums(cells=False)
    assert lean.cycle_count is None and lean.cycle_x is None and lean.cycle_F is None
    assert lean.cycle_phase is None and np.array_equal(lean.sum_x, s.sum_x)


@settings(max_examples=8, deadline=None)
@given(
    seed=st.integers(0, 10_000),
    offset=st.sampled_from([0.0, 1e3, -7e5]),
    spread=st.sampled_from([1e-6, 1e-3]),
)
def test_window_fold_spread_is_exact_on_the_cells(seed, offset, spread):
    """The fold's spread against exact rational arithmetic on the same cell means (the cell
    sums fold_phase gives, divided in double as both do) and slopes, on a large offset with a
    small variation (x around 1e3 varying by 1e-6): <= 1e-12 relative. (Welford's running
    mean rounded at the offset's scale: ~1e-7 here.)"""
    from fractions import Fraction

    from contactlab import _core

    rng = np.random.default_rng(seed)
    n_bins, n_cyc, per = 24, 12, 70
    t = np.arange(n_cyc * per + 40, dtype=float) * 1e-3 + rng.uniform(0, 1e-4)
    w = 2 * np.pi / (per * 1e-3)
    x = offset + spread * (np.sin(w * t) + 0.05 * rng.standard_normal(t.size))
    F = offset + spread * (np.cos(w * t + 0.3) + 0.05 * rng.standard_normal(t.size))
    kt = t[5] + per * 1e-3 * np.arange(n_cyc + 1) + 1e-4 * rng.uniform(size=n_cyc + 1)
    kp = np.arange(n_cyc + 1, dtype=float)
    wf = _core.fold_window(t, x, F, kt, kp, n_bins, n_cyc, kt)
    fold = _core.PhaseFold(n_bins, n_cyc)
    fold.push(t, x, F, 0, kt, kp)
    s = fold.sums()
    with np.errstate(invalid="ignore", divide="ignore"):
        cx, cF = s.cycle_x / s.cycle_count, s.cycle_F / s.cycle_count
        cp = s.cycle_phase / s.cycle_count
        xm, Fm = s.sum_x / s.count, s.sum_F / s.count
    for v, m, key in ((cx, xm, "x_std"), (cF, Fm, "F_std")):
        g = (np.roll(m, -1) - np.roll(m, 1)) * (n_bins / 2.0)
        # m - g·φ per cell, exactly (the constant g·mean(φ) of fold_spread does not change
        # the spread)
        exact = np.empty(v.shape, dtype=object)
        for (c, b), val in np.ndenumerate(v):
            ok = s.cycle_count[c, b] > 0
            exact[c, b] = Fraction(val) - Fraction(g[b]) * Fraction(cp[c, b]) if ok else None
        ref = []
        for b in range(n_bins):
            a = [e for e in exact[:, b] if e is not None]
            mean = sum(a) / len(a)
            ref.append(float(sum((e - mean) ** 2 for e in a) / (len(a) - 1)) ** 0.5)
        np.testing.assert_allclose(getattr(wf, key), ref, rtol=1e-12, atol=0)


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 10_000),
    n=st.integers(1, 300),
    exp=st.integers(-200, 200),
    slopes=st.tuples(st.floats(-1e6, 1e6), st.floats(-1e-3, 1e-3)),
)
def test_detrend_pair_is_numpys_expression_bit_for_bit(seed, n, exp, slopes):
    """The window's drift removal in one Rust pass equals numpy's ``v - s·(t - tm)``."""
    from contactlab import _core
    from fold_reference import detrended

    rng = np.random.default_rng(seed)
    t = np.cumsum(rng.uniform(1e-4, 1.0, n))
    tm = float(np.mean(t))
    F = rng.standard_normal(n) * 10.0**exp
    x = rng.standard_normal(n) * 1e-5
    a, b = _core.detrend_pair(t, tm, F, slopes[0], x, slopes[1])
    np.testing.assert_array_equal(a, detrended(F, t, tm, slopes[0]))
    np.testing.assert_array_equal(b, detrended(x, t, tm, slopes[1]))
    np.testing.assert_array_equal(a, F - slopes[0] * (t - tm))
    with pytest.raises(InputError):
        _core.detrend_pair(t, tm, F[: n - 1], 1.0, x, 1.0)
    # into numpy's arrays (what the window analysis uses): the same numbers
    oF, ox = np.full(n, np.nan), np.full(n, np.nan)
    _core.detrend_pair_into(t, tm, F, slopes[0], x, slopes[1], oF, ox)
    np.testing.assert_array_equal(oF, a)
    np.testing.assert_array_equal(ox, b)
    with pytest.raises(InputError):
        _core.detrend_pair_into(t, tm, F, 1.0, x, 1.0, oF[: n - 1], ox)


@pytest.mark.parametrize("every", ["3cycles", "7s", "auto"])
def test_windows_read_in_place_hold_their_samples(long_rec, tmp_path, monkeypatch, every):
    """Windows are views of the arrays the file is read into (HDF5 read from the file's bytes,
    the time axis made from the sampling interval): each holds exactly the samples of its
    span, whether short windows share an array or a long one outgrows it, and the rows are
    those of the same samples in memory."""
    import h5py

    from contactlab.studies import tracking

    dt = 1 / 1500.0
    n = len(long_rec)
    with h5py.File(p := tmp_path / "sampled.h5", "w") as f:
        f.create_dataset("x", data=long_rec["x"], chunks=(1000,))  # chunked
        f["F"] = long_rec["F"]  # contiguous
        f.attrs["dt"] = dt
    with h5py.File(p, "r") as f:  # both read from the file's bytes
        from contactlab.io.hdf5 import direct_read

        assert all(direct_read(f[k], p.stat().st_size) is not None for k in ("x", "F"))
    seen: list[tuple[int, np.ndarray, np.ndarray, np.ndarray]] = []
    analyse = tracking._tangential_window

    def spy(rec, options, keep_doc=False):
        rec = tracking._window_recording(rec)  # a sampled window's axis is made here
        seen.append((rec.meta["offset"], rec.t.copy(), rec["x"].copy(), rec["F"].copy()))
        return analyse(rec, options, keep_doc)

    monkeypatch.setattr(tracking, "_tangential_window", spy)
    r = track(p, every=every, chunk_size=700, threads=0)
    assert len(seen) == len(r.rows) >= 1
    for (a, t, x, F), row in zip(seen, r.rows, strict=True):
        assert row["n_samples"] == t.size == x.size == F.size
        assert t.tobytes() == (dt * np.arange(a, a + t.size, dtype=np.float64)).tobytes()
        assert x.tobytes() == long_rec["x"][a : a + x.size].tobytes()
        assert F.tobytes() == long_rec["F"][a : a + F.size].tobytes()
    same = Recording(
        dt * np.arange(n, dtype=np.float64),
        {"x": long_rec["x"], "F": long_rec["F"]},
        {"x": "m", "F": "N"},
    )
    m = track(same, every=every, chunk_size=700, threads=0)
    assert m.rows == r.rows
    for k in r.cycles:
        assert r.cycles[k].tobytes() == m.cycles[k].tobytes()


@pytest.mark.parametrize("segment", [300, 1 << 18])
def test_sampled_windows_carry_their_channels_ranges(long_rec, tmp_path, monkeypatch, segment):
    """A window of a checked, sampled file carries its channels' exact (min, max), made from
    the reader's blocks inside it and a scan of the blocks it cuts: the window analysis then
    does not scan x, F and t again; the rows are those of the same samples in memory."""
    import h5py

    from contactlab.studies import tracking

    monkeypatch.setattr(tracking, "CYCLE_SEGMENT", segment)
    with h5py.File(p := tmp_path / "sampled.h5", "w") as f:
        f.create_dataset("x", data=long_rec["x"], chunks=(1000,))
        f["F"] = long_rec["F"]
        f.attrs["dt"] = 1 / 1500.0
    seen = []
    analyse = tracking._tangential_window

    def spy(rec, options, keep_doc=False):
        seen.append((rec.scanned, rec.data["x"].copy(), rec.data["F"].copy()))
        return analyse(rec, options, keep_doc)

    monkeypatch.setattr(tracking, "_tangential_window", spy)
    r = track(p, every="3cycles", chunk_size=700, threads=0)
    monkeypatch.setattr(tracking, "_tangential_window", analyse)
    assert len(seen) == len(r.rows) >= 4
    for scanned, x, F in seen:
        assert scanned == {"x": (x.min(), x.max()), "F": (F.min(), F.max())}
    same = Recording(
        (1 / 1500.0) * np.arange(len(long_rec), dtype=np.float64),
        {"x": long_rec["x"], "F": long_rec["F"]},
        {"x": "m", "F": "N"},
    )
    assert track(same, every="3cycles", chunk_size=700, threads=0).rows == r.rows


def test_sampled_window_makes_its_time_axis_when_analysed():
    """A window of a sampled recording waits for its helper thread without a time axis: the
    axis it then makes is fill_time's, bit for bit, as are the row's start and end times,
    and it survives pickling (process pools, Dask)."""
    import pickle

    from contactlab.studies import tracking

    rng = np.random.default_rng(4)
    x, F = rng.normal(size=1000), rng.normal(size=1000)
    t0, dt, start = 0.125, 1e-4, 123_456_789
    w = tracking._WindowSamples(
        {"x": x, "F": F}, {"x": "m", "F": "N"}, "f.h5", {"offset": start}, (t0, dt), start
    )
    want = t0 + dt * np.arange(start, start + 1000, dtype=np.float64)
    for win in (w, pickle.loads(pickle.dumps(w))):
        assert len(win) == 1000
        rec = tracking._window_recording(win)
        assert rec.t.tobytes() == want.tobytes()
        assert rec["x"].tobytes() == x.tobytes() and rec["F"].tobytes() == F.tobytes()
        assert rec.meta["offset"] == start and rec.units["x"] == "m" and rec.source == "f.h5"
        assert tracking._time_bounds(win) == (float(want[0]), float(want[-1]))
    assert tracking._window_recording(rec) is rec
    assert tracking._time_bounds(rec) == (float(want[0]), float(want[-1]))


def test_cycles_csv_as_the_csv_writer_wrote_it(long_rec):
    """The per-cycle CSV joined at C speed is byte for byte what csv.writer made of
    ``[i + 1, repr(float(v)), ...]``, NaN, inf and -0.0 included."""
    import csv
    import io

    from contactlab.studies.columns import CYCLE_UNITS

    res = track(long_rec, every="3cycles")

    def reference() -> str:
        names = list(res.cycles)
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(["cycle", *(f"{k} [{CYCLE_UNITS[res.kind][k]}]" for k in names)])
        cols = [res.cycles[k] for k in names]
        for i in range(cols[0].size):
            w.writerow([i + 1, *(repr(float(c[i])) for c in cols)])
        return buf.getvalue()

    assert res.cycles_csv() == reference()
    res.cycles["energy"][1] = np.nan
    res.cycles["amplitude"][2] = -np.inf
    res.cycles["offset"][0] = -0.0
    assert res.cycles_csv() == reference()
    for k in res.cycles:
        res.cycles[k] = res.cycles[k][:0]
    assert res.cycles_csv() == reference() == reference().splitlines()[0] + "\n"


@pytest.mark.parametrize("kind", ["tangential", "normal"])
def test_per_cycle_table_does_not_depend_on_the_chunk_size(tmp_path, kind):
    """The cycle trigger is judged on fixed global sample ranges (CYCLE_SEGMENT), so reading
    the same file in chunks of any length gives the same windows and per-cycle table, bit for
    bit (before, each chunk's own range set it: 2^18 against 2^20 chunks moved 735 of 1e5
    cycle starts)."""
    from contactlab.studies import tracking

    seg = 4096
    n = 5 * seg + 1234  # several segments and a partial one
    t = np.arange(n) / 2000.0
    rng = np.random.default_rng(11)
    amp = 1.0 + 0.4 * np.sin(2 * np.pi * 0.05 * t)  # the trigger band follows the amplitude
    drive = amp * np.sin(2 * np.pi * 3.1 * t) + 0.01 * rng.standard_normal(n)
    if kind == "tangential":
        rec = Recording(t, {"x": 20e-6 * drive, "F": 30.0 * np.tanh(2 * drive)},
                        {"x": "m", "F": "N"})  # fmt: skip
    else:
        p = 1e6 * (2.0 + drive)  # positive pressure
        rec = Recording(t, {"p": p, "delta": 1e-6 * (p / 1e6) ** 0.7}, {"p": "Pa", "delta": "m"})
    path = tmp_path / f"{kind}.h5"
    write_recording(path, rec)
    old = tracking.CYCLE_SEGMENT
    try:
        tracking.CYCLE_SEGMENT = seg
        runs = [
            track(path, every="4cycles", kind=kind, chunk_size=c, threads=0, keep_going=True)
            for c in (seg, 700, 3 * seg + 5, 10 * seg)
        ]
    finally:
        tracking.CYCLE_SEGMENT = old
    ref = runs[0]
    assert ref.cycles["energy"].size >= 20
    for r in runs[1:]:
        assert r.rows == ref.rows
        for k in ref.cycles:
            assert r.cycles[k].tobytes() == ref.cycles[k].tobytes(), k
