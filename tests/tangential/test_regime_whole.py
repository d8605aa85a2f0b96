"""The whole-signal velocity and stick search in O(n) time and bounded memory (issue 9)
against the implementation they replaced (tests/regime_reference.py): the noise estimate, the
Lepski window, the velocity and every stick/breakaway output identical, and the pairwise
Lepski statistics equal to 1e-12 of their size (only the summation order changed). On
generator frames (Masing loops; Coulomb stick-slip frames from rest, with noise and sensor
filtering) and on the measured frame of ../shared/data/friction_frame."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import regime_reference as ref
from contactlab.synthetic.tangential import synthetic_recording
from contactlab.tangential import analyze_tangential, frame, frame_friction_force, regime
from frame_sim import simulate_frame

DATA = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "friction_frame"
M, C, K = 3.0799, 0.6690, 1191.0


def _reference(monkeypatch: pytest.MonkeyPatch) -> None:
    """Route the analysis through the old velocity and stick search."""
    monkeypatch.setattr(regime, "velocity", ref.velocity)
    monkeypatch.setattr(regime, "stick_slip", ref.stick_slip)


def _both(rec, monkeypatch: pytest.MonkeyPatch) -> tuple[dict, dict]:
    new = analyze_tangential(rec, warn=False).to_dict()
    with monkeypatch.context() as m:
        _reference(m)
        old = analyze_tangential(rec, warn=False).to_dict()
    return new, old


def _same_sticks(new: dict, old: dict) -> None:
    assert new["regime"] == old["regime"]
    assert new["stick_slip"] == old["stick_slip"]  # every key, exactly
    assert new == old


def _lepski_statistics(x: np.ndarray, dt: float) -> None:
    n = x.size
    top = min(401, max(7, n // 5))
    cands = sorted({w | 1 for w in np.geomspace(7, top, 16).astype(int) if w >= 7})
    if len(cands) < 2:
        return
    sq = frame.lepski_square_sums(x, cands, dt, block=997)  # many blocks, odd size
    ests = {w: frame.savgol_derivative(x, w, 2, dt) for w in cands}
    for i, w in enumerate(cands[1:], start=1):
        inner = slice(w // 2, n - w // 2)
        for j, wp in enumerate(cands[:i]):
            want = float(np.mean((ests[w][inner] - ests[wp][inner]) ** 2))
            got = sq[i, j] / (n - 2 * (w // 2))
            assert got == pytest.approx(want, rel=1e-12, abs=1e-12 * float(np.mean(ests[w] ** 2)))


def _check_velocity(x: np.ndarray, t: np.ndarray | None) -> None:
    dt = 1.0 if t is None else float(np.median(np.diff(t)))
    assert frame.difference_noise(x) == ref.difference_noise(x)
    v, thr, w = regime.velocity(t, x)
    v0, thr0, w0 = ref.velocity(t, x)
    assert w == w0 and thr == thr0
    assert np.array_equal(v, v0)
    _lepski_statistics(x, dt)


@pytest.mark.parametrize(
    ("seed", "fs", "Fs", "filt", "sigma"),
    [(1811, 250.0, 1.1, None, 4e-7), (1812, 500.0, 0.9, 60.0, 8e-7),
     (1813, 1000.0, 1.2, None, 0.0)],
)  # fmt: skip
def test_coulomb_frames_give_the_same_sticks(seed, fs, Fs, filt, sigma, monkeypatch):
    from scipy.signal import butter, lfilter

    rng = np.random.default_rng(seed)
    t, x, y, _ = simulate_frame(Fk=0.8, Fs=Fs, fs=fs)
    xm, ym = x + rng.normal(0, sigma, x.size), y + rng.normal(0, sigma, y.size)
    if filt is not None:
        b, a = butter(2, filt / (fs / 2))
        xm, ym = lfilter(b, a, xm), lfilter(b, a, ym)
    _check_velocity(xm, t)
    r = frame_friction_force(t, xm, ym, M=3.08, C=0.669, K=1191.0)
    with monkeypatch.context() as m:  # the force reconstruction uses the same two estimates
        m.setattr(frame, "difference_noise", ref.difference_noise)
        m.setattr(frame, "lepski_window", ref.lepski_window)
        r0 = frame_friction_force(t, xm, ym, M=3.08, C=0.669, K=1191.0)
    assert r.window == r0.window and np.array_equal(r.F, r0.F)
    new, old = _both(r.recording(), monkeypatch)
    assert new["regime"] == "stick-slip" and new["stick_slip"]["reversals_with_stick"] > 0
    _same_sticks(new, old)


@pytest.mark.parametrize(("z", "fs", "seed"), [(0.6, 2000.0, 1821), (4.0, 500.0, 1822)])
def test_masing_recordings_give_the_same_regime(z, fs, seed, monkeypatch):
    A = 20e-6
    rec = synthetic_recording(40.0, z / A, A, n_cycles=10, fs=fs, noise=0.01, seed=seed,
                              x_noise=0.002)  # fmt: skip
    _check_velocity(rec.data["x"], rec.t)
    _same_sticks(*_both(rec, monkeypatch))


@pytest.mark.parametrize("load", [250, 450])
def test_measured_frame_gives_the_same_sticks(load, monkeypatch):
    f = DATA / f"frame_disc{load}g.csv"
    if not f.is_file():
        pytest.skip(f"{f} absent: ../shared/data absent")
    d = np.loadtxt(f, delimiter=",", skiprows=1)
    t, x, y = d[:, 0], d[:, 1] * 1e-3, d[:, 2] * 1e-3
    _check_velocity(x, t)
    r = frame_friction_force(t, x, y, M, C, K)
    new, old = _both(r.recording(f.name), monkeypatch)
    assert new["stick_slip"]["reversals_with_stick"] > 0
    _same_sticks(new, old)


@settings(max_examples=25, deadline=None)
@given(
    n=st.integers(20, 3000),
    seed=st.integers(0, 2**32 - 1),
    scale=st.floats(1e-9, 1e3),
    smooth=st.floats(0.0, 1.0),
)
def test_noise_and_window_equal_the_reference_on_any_signal(n, seed, scale, smooth):
    """Any length (one block or many), any mix of a smooth wave and white noise."""
    rng = np.random.default_rng(seed)
    i = np.arange(n, dtype=float)
    wave = np.sin(2 * math.pi * i / max(n / 3, 7))
    x = scale * (smooth * wave + (1 - smooth) * rng.normal(size=n))
    assert frame.difference_noise(x) == ref.difference_noise(x)
    sx = frame.difference_noise(x)
    assert frame.lepski_window(x, 1e-3, sx) == ref.lepski_window(x, 1e-3, sx)
    _lepski_statistics(x, 1e-3)


def test_long_runs_are_the_runs_at_least_that_long():
    rng = np.random.default_rng(1830)
    mask = rng.random(5000) < 0.8
    for min_len in (1, 4, 9):
        want = [(int(a), int(b)) for a, b in ref._runs(mask) if b - a >= min_len]
        assert regime.long_runs(mask, min_len) == want
    assert regime.long_runs(np.zeros(0, bool), 4) == []
    assert regime.long_runs(np.ones(6, bool), 4) == [(0, 6)]
