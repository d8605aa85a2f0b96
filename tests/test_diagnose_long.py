"""Long records: decimation must not invent effects (issue 8/9).

The Masing model's memory holds the turning points it sees, i.e. the sampled extremes of the
displacement; between two samples the true extreme is up to ``A (1 - cos(π / s))`` higher (s
samples per cycle), and the branch that follows starts from the wrong point. At the rates a
rig records (hundreds of samples per cycle) this is far below the noise; a long record that
is decimated until its *dominant* (slowest) block keeps 64 samples per cycle left the fastest
block of the generator with 22 and a clean record was diagnosed with a channel delay of
-4e-5 s and a normal-load modulation. The factor is now set by the fastest cycles.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import contactlab
from contactlab.diagnose import hidden_effect_recording
from contactlab.diagnose._signal import find_cycles, shortest_period_samples
from contactlab.diagnose.workflow import MIN_SAMPLES_PER_CYCLE, reduce_long


def _two_tones(n1: int, n2: int, p1: float, p2: float) -> np.ndarray:
    """``n1`` cycles of period ``p1`` samples, then ``n2`` of period ``p2`` (phase-continuous)."""
    k = np.arange(round(n1 * p1) + round(n2 * p2))
    freq = np.where(k < round(n1 * p1), 1.0 / p1, 1.0 / p2)
    amp = np.where(k < round(n1 * p1), 1.0, 2.5)
    return amp * np.sin(2.0 * np.pi * np.cumsum(freq))


@settings(max_examples=25, deadline=None)
@given(
    p_fast=st.floats(40.0, 400.0),
    ratio=st.floats(1.3, 4.0),
    n_fast=st.integers(6, 30),
    noise=st.floats(0.0, 0.01),
    seed=st.integers(0, 2**31),
)
def test_shortest_period_is_the_fast_blocks(p_fast, ratio, n_fast, noise, seed):
    u = _two_tones(n_fast, 30, p_fast, ratio * p_fast)
    u = u + noise * np.random.default_rng(seed).normal(size=u.size)
    per = ratio * p_fast  # the slow block is the strong one
    got = shortest_period_samples(u, per)
    assert got == pytest.approx(p_fast, rel=0.05)


def test_shortest_period_of_one_tone_is_its_period():
    u = _two_tones(20, 20, 150.0, 150.0)
    assert shortest_period_samples(u, 150.0) == pytest.approx(150.0, rel=0.02)


def test_decimation_keeps_the_fastest_cycles_sampled():
    """Noise-free generator record of 5e5 samples: after reduce_long every half-cycle of the
    fastest block keeps MIN_SAMPLES_PER_CYCLE / 2 samples, and the discrete Masing model on
    the reduced displacement misses the reduced force by far less than the noise the
    generator would add (1 % of the force RMS, divided by √q by the decimation)."""
    rec = hidden_effect_recording(
        [], seed=3, cycles_per_block=150, samples_per_cycle=1000, noise=1e-12, input_noise=1e-15
    )
    t, x, F = rec.arrays()
    tr, xr, Fr, how = reduce_long(t, x, F)
    q = round((tr[1] - tr[0]) / (t[1] - t[0]))
    assert q > 1 and f"decimated by {q}" in how
    half = np.diff(find_cycles(xr).reversals)
    assert np.percentile(half, 10) >= MIN_SAMPLES_PER_CYCLE / 2 - 1
    bias = (Fr - contactlab.Masing(50.0, 5e4).force(xr))[50:-50]
    sigma = 0.01 * np.sqrt(np.mean(F**2)) / np.sqrt(q)
    assert np.sqrt(np.mean(bias**2)) < 0.15 * sigma


def test_long_clean_record_names_nothing():
    """The symptom: a clean 1e6-sample generator record at 1000 samples per cycle (default
    noise) was diagnosed with channel_delay and normal_load."""
    rec = hidden_effect_recording([], seed=23, cycles_per_block=307, samples_per_cycle=1000)
    report = contactlab.diagnose(rec, model="tangential")
    assert report.effect_names == []


def test_long_record_of_short_cycles_is_cut_not_decimated():
    """Fewer than MIN_SAMPLES_PER_CYCLE samples per cycle: no decimation, and the report
    counts the cycles kept (the factor was 0 and the sentence said "0 of 0 cycles")."""
    n = 40_000
    t = np.arange(n) / 1000.0
    x = 1e-5 * np.sin(2 * np.pi * t * 1000.0 / 20.0)  # 20 samples per cycle
    F = contactlab.Masing(50.0, 5e4).force(x)
    tr, _, _, how = reduce_long(t, x, F)
    assert tr.size == 24_000
    assert "decimated" not in how
    assert "first 1200 of 2000 excitation cycles" in how
