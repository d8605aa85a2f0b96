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
from contactlab.studies._cycles import CycleState, block_cycles
from contactlab.studies.tracking import parse_every, track
from contactlab.tangential import analyze_tangential, synthetic_recording

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"


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

    t, p, d = cn.synthetic_recording(p0=0.5e6, pa=0.4e6, omega=1.0, n_cycles=20, seed=5021)
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
