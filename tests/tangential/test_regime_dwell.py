"""A drive that dwells at its stroke ends is not stick-slip (issue 31: a tribometer stage
resting at both ends, position and force both still, was reported as "sticks at 99 of 99
reversals"): sticking is the position standing while the force changes."""

from __future__ import annotations

import numpy as np
import pytest

from contactlab import Masing, Recording
from contactlab.tangential import analyze_tangential


def _stroke(fs: float, f: float, cycles: int, amp: float, rest: float) -> np.ndarray:
    """A triangular stroke of amplitude ``amp`` that rests ``rest`` of each period at both
    ends (the stage stands; a rate-independent contact's force stands with it)."""
    n = round(fs / f)
    n_rest = round(rest * n / 2)
    n_move = n // 2 - n_rest
    up = np.linspace(-amp, amp, n_move, endpoint=False)
    down = np.linspace(amp, -amp, n_move, endpoint=False)
    period = np.r_[up, np.full(n_rest, amp), down, np.full(n_rest, -amp)]
    return np.tile(period, cycles)


def _record(x: np.ndarray, F: np.ndarray, fs: float, seed: int, name: str) -> Recording:
    rng = np.random.default_rng(seed)
    t = np.arange(x.size) / fs
    xr = np.ptp(x)
    xn = x + rng.normal(0, 0.002 * xr, x.size)
    Fn = F + rng.normal(0, 0.005 * np.ptp(F), F.size)
    return Recording(t, {"x": xn, "F": Fn}, {"x": "m", "F": "N"}, name)


@pytest.mark.parametrize("seed", [1, 2])
def test_dwell_at_the_stroke_ends_is_not_stick_slip(seed):
    fs, f, amp = 2000.0, 1.0, 200e-6
    x = _stroke(fs, f, 12, amp, rest=0.3)
    F = Masing(5.0, 2e5).force(x - x[0]) - Masing(5.0, 2e5).force(np.zeros(1))[0]
    res = analyze_tangential(_record(x, F, fs, seed, "dwell"), warn=False)
    d = res.to_dict()
    assert d["regime"] == "gross sliding", d["regime_reason"]
    assert "dwells at" in d["regime_reason"] and "not sticking" in d["regime_reason"]
    st = d["stick_slip"]
    assert st["reversals_with_dwell"] >= 0.8 * st["n_reversals"]
    assert st["reversals_with_stick"] == 0


def test_sticking_with_the_force_reversing_stays_stick_slip():
    """The same still stretches, but the force reverses while the position stands (the
    static friction holds the body until the drive's force breaks it away): stick-slip."""
    fs, f, amp = 2000.0, 1.0, 200e-6
    x = _stroke(fs, f, 12, amp, rest=0.3)
    F = Masing(5.0, 2e5).force(x - x[0]) - Masing(5.0, 2e5).force(np.zeros(1))[0]
    still = np.r_[False, np.diff(x) == 0]
    # while stuck, the force swings from one plateau towards the other (linear in time)
    Fs = F.copy()
    idx = np.flatnonzero(still)
    runs = np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1)
    for r in runs:
        if r.size < 10:
            continue
        start = Fs[r[0] - 1]
        Fs[r] = start * (1 - 1.6 * np.linspace(0, 1, r.size))
    res = analyze_tangential(_record(x, Fs, fs, 3, "stick"), warn=False)
    d = res.to_dict()
    assert d["regime"] == "stick-slip", d["regime_reason"]
    assert d["stick_slip"]["reversals_with_stick"] >= 0.8 * d["stick_slip"]["n_reversals"]
