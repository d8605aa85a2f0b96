"""Long records: decimation must not invent effects (issue 8/9).

The Masing model's memory holds the turning points it sees, i.e. the sampled extremes of the
displacement; between two samples the true extreme is up to ``A (1 - cos(π / s))`` higher (s
samples per cycle), and the branch that follows starts from the wrong point. At the rates a
rig records (hundreds of samples per cycle) this is far below the noise; a long record that
is decimated until its *dominant* (slowest) block keeps 64 samples per cycle left the fastest
block of the generator with 22 and a clean record was diagnosed with a channel delay of
-4e-5 s and a normal-load modulation. The factor is now set by the fastest cycles (normal
records, :func:`reduce_long`).

A long tangential record is now kept every q-th sample over its whole length
(:func:`subsample_long`, q from the length) with the turning points between the kept samples
in the Masing memory (:class:`~contactlab.diagnose._signal.Knots`): the model at the kept
samples is the full-rate model, checked below for every effect of the library.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import contactlab
from contactlab.diagnose._signal import find_cycles, shortest_period_samples
from contactlab.diagnose.workflow import MIN_SAMPLES_PER_CYCLE, reduce_long
from contactlab.synthetic.diagnosis import hidden_effect_recording


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


# ---- whole-record diagnosis of long tangential records (kept samples + turning points) ----

from contactlab.diagnose._family import Prepared  # noqa: E402
from contactlab.diagnose._kept import RawInput, knots_at  # noqa: E402
from contactlab.diagnose._signal import dominant_period_samples  # noqa: E402
from contactlab.diagnose.candidates_tangential import CANDIDATES, TangentialFamily  # noqa: E402
from contactlab.diagnose.workflow import MAX_SAMPLES, subsample_long  # noqa: E402


@settings(max_examples=20, deadline=None)
@given(
    n=st.integers(2_000, 60_000),
    period=st.floats(30.0, 900.0),
    noise=st.floats(0.0, 0.05),
    seed=st.integers(0, 2**31),
)
def test_dominant_period_on_a_fast_length_is_the_plain_ffts(n, period, noise, seed):
    """Zero-padding to a fast FFT length moves the period by at most the plain FFT's own
    resolution (the spacing of its lines there, ``n/(k-1) - n/k``): a line between two
    bins may go to the other neighbour, never further; records of four cycles or more."""
    assume(n >= 4 * period)
    k = np.arange(n)
    u = np.sin(2 * np.pi * k / period) + noise * np.random.default_rng(seed).normal(size=n)
    spec = np.abs(np.fft.rfft((u - u.mean()) * np.hanning(n)))
    spec[0] = 0.0
    plain = n / int(np.argmax(spec))
    assert dominant_period_samples(u) == pytest.approx(plain, abs=plain**2 / (n - plain) + 1e-9)


@settings(max_examples=30, deadline=None)
@given(
    n=st.integers(300, 3_000),
    q=st.integers(2, 40),
    shift=st.floats(0.0, 1.0),
    seed=st.integers(0, 2**31),
)
def test_knots_give_the_full_rate_masing_force_at_the_kept_samples(n, q, shift, seed):
    """A random walk (many small inner loops) kept every q-th sample, also at positions
    shifted by a fraction of a sample interval: the Masing element over the kept samples with
    the knots merged in gives, at each kept position, the force of the element run over every
    raw sample with the kept (interpolated) points inserted in their places — rate
    independence: what lies between two turning points leaves no memory."""
    rng = np.random.default_rng(seed)
    u = np.cumsum(rng.normal(size=n)) * 1e-6
    raw, exact = RawInput.build(0.0, 1.0, u, u, u, np.array([], int), q, limit=n)
    assert exact
    pos = np.arange(0.0, n - 1.0, q) + shift
    pos = pos[pos <= n - 1]
    kn = knots_at(raw, pos)
    kept = np.interp(pos, np.arange(n), u)
    masing = contactlab.Masing(50.0, 2e5)
    got = masing.force(kn.merge(kept))[kn.grid]
    ins = np.searchsorted(np.arange(n), pos, side="left")  # before the raw sample >= pos
    ref = masing.force(np.insert(u, ins, kept))[ins + np.arange(pos.size)]
    assert np.allclose(got, ref, rtol=0, atol=1e-9)


@pytest.fixture(scope="module")
def kept_and_full():
    rec = hidden_effect_recording([], seed=11, cycles_per_block=100, samples_per_cycle=1000)
    t, x, F = rec.arrays()
    fam = TangentialFamily()
    d, how = subsample_long(t, x, F)
    full = Prepared.build(t, x, F)
    fam.prepare(d)
    full.extra.update({k: d.extra[k] for k in ("x_mid", "x_half")})
    return fam, d, full, how, F


_VALUES = {
    "x0": 2e-7, "C_s": 2e-7, "lam": 2.4, "alpha": 0.05, "beta": 0.05, "tau": 1.7e-3,
    "s_b": 0.3, "ell": 3e-6, "s": 0.1, "v_s": 1e-3, "a1": 0.03, "b1": 0.02, "L": 2.5e-5,
    "eps_c": 0.03, "eps_s": 0.02, "f_n": 3.3, "k_p": 1e5, "c": 10.0, "m": 0.5,
    "F0": 0.5, "F1": 0.5,
}  # fmt: skip


@pytest.mark.parametrize(
    "effects",
    [(), *((name,) for name in CANDIDATES),
     ("displacement_offset", "asymmetry", "stick_slip", "parameter_drift", "channel_delay")],
)  # fmt: skip
def test_kept_record_model_is_the_full_rate_model(kept_and_full, effects):
    """The model on the kept record agrees with the full-rate model at the kept samples far
    below the noise (bias² / σ² ≤ 1e-3, σ the generator's 1 % of the force RMS), for every
    effect of the library — the channel delay with its delay of 17 raw samples (0.4 of
    the kept interval) included; and at a subset of samples (``at``) it is the same."""
    fam, d, full, _, F = kept_and_full
    p = {"h0": 50.0, "ac": 5e4}
    for name in effects:
        p.update({s.name: _VALUES.get(s.name, s.null) for s in CANDIDATES[name].params})
    q = round(d.dt / full.dt)
    kept = fam.predict(p, effects, d)
    ref = fam.predict(p, effects, full)[::q][: kept.size]
    sigma = 0.01 * np.sqrt(np.mean(F**2))
    assert np.mean((kept - ref) ** 2) / sigma**2 <= 1e-3
    at = np.arange(3, kept.size, 7)
    assert np.array_equal(fam.predict(p, effects, d, at=at), kept[at])


def test_kept_record_spans_the_whole_recording(kept_and_full):
    """q from the record's length: at most MAX_SAMPLES kept, the held-out cycles over the
    whole recording, and the sentence says how."""
    _, d, full, how, _ = kept_and_full
    q = round(d.dt / full.dt)
    assert d.t.size <= MAX_SAMPLES and q == -(-full.t.size // MAX_SAMPLES)
    assert d.t[-1] >= full.t[-1] - q * full.dt
    labelled = d.t[d.cycles.cycle >= 0]
    assert labelled[0] - d.t[0] < 0.02 * d.duration and d.t[-1] - labelled[-1] < 0.02 * d.duration
    assert d.cycles.n_cycles == full.cycles.n_cycles
    assert f"kept one sample in {q} over its whole length" in how and "first" not in how


def test_kept_record_of_short_cycles_is_cut_and_says_so():
    """Cycles too short to keep MIN_KEPT_PER_CYCLE samples at the length's q: q is lowered
    (here to 1) and only the first MAX_SAMPLES samples are diagnosed, said in the sentence;
    the cycle cut at the end belongs to no fold."""
    n = 40_000
    t = np.arange(n) / 1000.0
    x = 1e-5 * np.sin(2 * np.pi * t * 1000.0 / 20.0)  # 20 samples per cycle
    F = contactlab.Masing(50.0, 5e4).force(x)
    d, how = subsample_long(t, x, F)
    assert d.t.size == MAX_SAMPLES and d.dt == pytest.approx(1e-3)
    assert "first 1200 of 2000 excitation cycles" in how
    assert "one sample in" not in how  # q = 1: nothing is thinned, the record is only cut
    assert d.cycles.cycle[-1] == -1


def test_too_many_extrema_keep_the_reversals_only():
    """An input whose local extrema exceed the limit (noise left in it) keeps the reversals
    (and the first sample) as turning points, and says it is not exact."""
    u = np.random.default_rng(5).normal(size=5_000)
    rev = np.array([100, 900, 2500])
    raw, exact = RawInput.build(0.0, 1.0, u, u, u, rev, 10, limit=100)
    assert not exact and raw.turns.tolist() == [0, 100, 900, 2500]
    raw, exact = RawInput.build(0.0, 1.0, u, u, u, rev, 10, limit=10_000)
    assert exact and raw.turns.size > 1_000 and set(rev) <= set(raw.turns.tolist())


def test_shifted_positions_by_strided_views_are_the_gathered_ones():
    """The delayed kept record's input (_kept._at_shift: positions k·q - s by strided views)
    is the linear interpolation at those positions (_kept._at, a gather), clipped ends too,
    for whole and fractional shifts of either sign."""
    from contactlab.diagnose._kept import _at, _at_shift

    rng = np.random.default_rng(84123)
    for _ in range(500):
        n = int(rng.integers(5, 300))
        q = int(rng.integers(1, 9))
        m = int(rng.integers(1, n // q + 2))
        s = float(rng.normal() * rng.choice([0.3, 3.0, 30.0, 300.0]))
        if rng.random() < 0.2:
            s = float(round(s))
        a, b = rng.normal(size=(2, n))
        pos = np.clip(np.arange(m) * float(q) - s, 0.0, n - 1.0)
        for ref, got in zip(_at(pos, n, a, b), _at_shift(q, s, m, n, a, b), strict=True):
            assert np.allclose(got, ref, rtol=0, atol=1e-12)
