"""Short windows of a rig-like normal recording as the audit wrote it (1 % noise on both
channels, sensor offsets and a slow drift, time printed to 10 significant digits).

Three things made ψ and E_d of its 5-cycle track windows high and E_d's error unreliable:

- the drift, folded into every cycle, is a sawtooth that shortened the range of δ: ψ +0.15 %,
  E_d +0.09 % on the noiseless record;
- the time axis printed to 10 digits jitters by ~1e-5 of a step at 250 s: the record was taken
  for irregularly sampled, interpolated onto the median of the rounded steps and lost its
  last sample; and cycles had to start at the fundamental's upward crossing, so a window cut
  a few samples before it lost a whole cycle (3 of 5 cycles analysed instead of 4);
- E_d's error was the jackknife over those 3-4 cycles (2-3 degrees of freedom): it scattered
  so much that (E_d - truth)² / error² averaged 6.8 over windows where 1 is right.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from contactlab.normal import analyze_loop
from contactlab.synthetic.normal import synthetic_recording

SPC = 500  # samples per cycle


@pytest.fixture(scope="module")
def exact():
    return synthetic_recording(n_cycles=40, samples_per_cycle=SPC, noise=0, seed=0)


def _printed(t):
    """Times as ``np.savetxt(fmt="%.10g")`` writes them."""
    return np.array([float(f"{v:.10g}") for v in t])


def test_time_printed_to_ten_digits_is_not_resampled(exact):
    t, p, d = exact
    s = slice(20 * SPC, 26 * SPC)
    tw = t[s] + 200.0  # far from 0: the printed times round to 1e-7 s, 8e-6 of a step
    ref = analyze_loop(tw, p[s], d[s])
    got = analyze_loop(_printed(tw), p[s], d[s])
    assert not got.resampled
    assert got.n_cycles == ref.n_cycles
    assert got.E_d == pytest.approx(ref.E_d, rel=1e-6)
    assert got.psi == pytest.approx(ref.psi, rel=1e-6)
    assert got.omega == pytest.approx(ref.omega, rel=1e-7)


def test_irregular_sampling_far_from_zero_is_still_resampled(exact):
    t, p, d = exact
    s = slice(0, 6 * SPC)
    tj = t[s] + 1e9  # a clock reading: 10 digits would be whole seconds there
    tj[1:-1] += 0.05 * (t[1] - t[0]) * np.sin(np.arange(1, tj.size - 1))
    assert analyze_loop(tj, p[s], d[s]).resampled


@pytest.mark.parametrize("early", [1, 20, 123])
def test_window_cut_before_the_crossing_keeps_all_its_cycles(exact, early):
    t, p, d = exact
    a = 10 * SPC  # the record starts at an upward crossing of p
    at = analyze_loop(t[a : a + 6 * SPC], p[a : a + 6 * SPC], d[a : a + 6 * SPC])
    s = slice(a - early, a - early + 6 * SPC)  # the same 6 cycles' length, cut earlier
    got = analyze_loop(t[s], p[s], d[s])
    assert got.n_cycles + got.n_discarded == 6
    # the averaged cycle still starts at the fundamental's upward crossing
    assert got.cycle_p[0] == pytest.approx(at.cycle_p[0], abs=1e-6 * at.pa)
    assert got.cycle_p[SPC // 4] > 0.99 * got.pa
    for q in ("E_d", "psi", "psi_kv", "k_tan", "delta_max", "delta_min"):
        assert getattr(got, q) == pytest.approx(getattr(at, q), rel=1e-6), q


def test_drift_of_both_channels_leaves_the_loop_alone(exact):
    t, p, d = exact
    s = slice(5 * SPC, 10 * SPC)
    ref = analyze_loop(t[s], p[s], d[s])
    tt = t[s]
    # the audit's drift: 50 Pa/s on p (0.08 % of pa a cycle), 2e-10 m/s on δ (0.2 % of its
    # range a cycle), on top of sensor offsets
    got = analyze_loop(tt, p[s] + 2e3 + 50 * tt, d[s] + 0.05e-6 + 2e-10 * tt)
    for q in ("E_d", "psi", "psi_kv", "delta_max", "delta_min", "pa"):
        assert getattr(got, q) == pytest.approx(getattr(ref, q), rel=2e-5), q


def _rig_windows(exact, seeds, cycles=5):
    """5-cycle windows of the exact record with the audit's sensors: 1 % noise (of the
    peak-to-peak) on both channels, offsets and drift, time printed to 10 digits."""
    t, p, d = exact
    tp = _printed(t + 100.0)
    n = cycles * SPC
    out = []
    for seed in seeds:
        rng = np.random.default_rng(seed)
        pn = p + rng.normal(0, 0.01 * np.ptp(p), p.size) + 2e3 + 50 * t
        dn = d + rng.normal(0, 0.01 * np.ptp(d), d.size) + 0.05e-6 + 2e-10 * t
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            for i in range(p.size // n):
                # cut 7 samples before the crossing, as track cuts at noisy crossings
                a = max(i * n - 7, 0)
                out.append(analyze_loop(tp[a : a + n], pn[a : a + n], dn[a : a + n]))
    return out


def test_energy_error_of_rig_windows_is_right_window_by_window(exact):
    truth = analyze_loop(*exact)
    res = _rig_windows(exact, (51, 52, 53, 54))
    e = np.array([r.E_d for r in res])
    se = np.array([r.E_d_cycle_std / np.sqrt(r.n_cycles) for r in res])
    z2 = float(np.mean(((e - truth.E_d) / se) ** 2))
    # 32 windows: the mean of z² is known to about ±25 %; the 2-3 cycle jackknife read 4-14
    assert 0.6 < z2 < 1.6, z2
    ratio = float(np.std(e, ddof=1) / np.sqrt(np.mean(se**2)))
    assert 0.7 < ratio < 1.4, ratio


def test_psi_and_energy_of_rig_windows_are_unbiased(exact):
    truth = analyze_loop(*exact)
    res = _rig_windows(exact, (61, 62, 63, 64, 65, 66))
    for q in ("psi", "E_d"):
        v = np.array([getattr(r, q) for r in res])
        m, err = float(v.mean()), float(v.std(ddof=1) / np.sqrt(v.size))
        assert abs(m - getattr(truth, q)) < 3 * err, (q, m / getattr(truth, q) - 1, err)
    # every window of 5 whole cycles analyses 4 of them (one start-up cycle dropped)
    assert all(r.n_cycles == 4 for r in res[1:])
