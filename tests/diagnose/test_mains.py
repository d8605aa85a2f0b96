"""Mains hum taken out of a tangential record's channels before the diagnosis (issue 29:
a delay fitted the phase between the two channels' lines and took the dashpot's share)."""

from __future__ import annotations

import numpy as np
import pytest

from contactlab.diagnose._mains import GUARD_BINS, remove_mains


def _record(f=3.0, fs=1000.0, cycles=16, hum=(0.01, 0.01), f_hum=50.0, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(int(cycles * fs / f)) / fs
    A = 1e-5
    x = A * np.sin(2 * np.pi * f * t)
    F = 40.0 * np.tanh(4e4 * x) + 300.0 * np.gradient(x, t)
    hx = hum[0] * A * np.sin(2 * np.pi * f_hum * t + 0.4)
    hF = hum[1] * 40.0 * np.sin(2 * np.pi * f_hum * t + 2.1)
    nx = rng.normal(0, 0.005 * A, t.size)
    nF = rng.normal(0, 0.005 * 40.0, t.size)
    return t, x + nx, F + nF, x + hx + nx, F + hF + nF, hx, hF


def test_a_hum_on_both_channels_is_taken_out_and_said():
    t, x0, F0, x, F, hx, hF = _record()
    u, y, note = remove_mains(t, x, F)
    assert note is not None and "50.00 Hz on x" in note and "on F" in note
    # what is left of the hum: a small fraction of it
    assert np.std(u - x0) < 0.05 * np.std(hx)
    assert np.std(y - F0) < 0.05 * np.std(hF)


def test_a_clean_record_is_left_as_recorded():
    t, x0, F0, *_ = _record()
    u, y, note = remove_mains(t, x0, F0)  # (u, y: the very arrays given)
    assert note is None and u is x0 and y is F0


@pytest.mark.parametrize("f", [10.0, 25.0, 50.0 / 3.0])
def test_a_line_on_a_drive_harmonic_is_left_alone(f):
    # the friction force's odd harmonics (and the hum) at 50 Hz cannot be told apart
    t, _, _, x, F, _, _ = _record(f=f)
    _, y, note = remove_mains(t, x, F)
    assert "on F" not in (note or "")
    np.testing.assert_array_equal(y, F)
    assert GUARD_BINS > 1


def test_sixty_hertz_is_found_too():
    t, _, F0, x, F, _, hF = _record(f=2.9, f_hum=60.0, hum=(0.0, 0.02))
    _, y, note = remove_mains(t, x, F)
    assert note is not None and "60.00 Hz on F" in note and "on x" not in note
    assert np.std(y - F0) < 0.05 * np.std(hF)


@pytest.mark.parametrize("seed", [0, 2])
def test_a_drive_in_blocks_keeps_its_own_content_near_the_mains(seed):
    # the package's three-block drive at 7.3 Hz has content at 50.3 and 60.3 Hz in one block
    # only: not a hum (a whole-record fit called it one before the steadiness check)
    from contactlab.synthetic.diagnosis import hidden_effect_recording

    r = hidden_effect_recording(
        {}, seed=seed, f0=7.3, start="rest", samples_per_cycle=300, noise=0.01, input_noise=0.01
    )
    t, x, F = (np.asarray(a) for a in (r.t, r.data["x"], r.data["F"]))
    assert remove_mains(t, x, F)[2] is None
    # the same record with a steady 1 % hum on the force at 60 Hz (50 Hz lies within 4 bins
    # of the 1.7 f block's 4th harmonic, 49.6 Hz: left alone): found and taken out
    hum = 0.01 * np.ptp(F) * np.sin(2 * np.pi * 60.0 * (t - t[0]) + 1.0)
    _, y, note = remove_mains(t, x, F + hum)
    assert note is not None and "on F" in note
    assert np.std(y - F) < 0.1 * np.std(hum)
