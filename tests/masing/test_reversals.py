"""The Rust reversal detector, branch memory, anchored branch rule, multi-channel kernel and
output buffers against the pure-Python versions they replaced (tests/signal_reference.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.ndimage import uniform_filter1d

import contactlab
from contactlab import InputError
from contactlab.diagnose._signal import find_cycles
from contactlab.diagnose.scaled_masing import _scaled_force_python, memory, scaled_force
from contactlab.reversals import ReversalDetector, excursions
from contactlab.tangential.preprocess import find_reversals
from signal_reference import reversal_segments, schmitt_extrema, wiping_out_memory


def _signal(seed: int, n: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    k = np.arange(n)
    x = np.sin(2 * np.pi * k / rng.uniform(40, 300)) * rng.uniform(0.5, 2.0)
    x += rng.normal(0, rng.uniform(0.0, 0.4), n) + rng.uniform(-0.5, 0.5)
    if seed % 3 == 0:
        x = np.round(x, 1)  # repeated values: ties in the extremes
    return x


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10_000), n=st.integers(20, 3000), rel=st.floats(0.05, 0.9))
def test_find_reversals_equals_the_python_segments(seed, n, rel):
    x = _signal(seed, n)
    t = np.cumsum(np.random.default_rng(seed).uniform(0.5, 1.5, n))
    r = find_reversals(x, t, rel_threshold=rel)
    p, v, pt, vt, e = reversal_segments(x, t, r.centre, r.threshold)
    assert r.peaks.tolist() == p and r.valleys.tolist() == v and r.edges.tolist() == e
    assert r.peak_times.tolist() == pt and r.valley_times.tolist() == vt


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10_000), n=st.integers(20, 3000))
def test_find_cycles_equals_the_python_trigger(seed, n):
    us = _signal(seed, n)
    uc = us - uniform_filter1d(us, 50, mode="nearest")
    rev, ismax = schmitt_extrema(uc, us)
    ex = excursions(uc, 0.0, 0.2 * float(np.sqrt(np.mean(uc * uc))), value=us)
    ends = np.r_[ex.start[1:], n]
    got, got_max = [], []
    for a, b, s, i in zip(ex.start, ends, ex.sign, ex.extreme, strict=True):
        if b - a >= 2 and 0 < i < n - 1 and not (got_max and got_max[-1] == (s > 0)):
            got.append(int(i))
            got_max.append(bool(s > 0))
    assert got == rev and got_max == ismax
    # and through find_cycles itself
    c = find_cycles(_signal(seed, max(n, 200)), 120.0)
    assert np.all(np.diff(c.reversals) > 0)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10_000), n=st.integers(1, 2000))
def test_memory_equals_the_python_stack(seed, n):
    rng = np.random.default_rng(seed)
    x = np.cumsum(rng.normal(size=n))
    if seed % 2:
        x = np.round(x)  # exactly repeated extremes and zero steps
    mem = memory(x)
    a, t = wiping_out_memory(x)
    assert np.array_equal(mem.anchor, a) and np.array_equal(mem.target, t)


@pytest.mark.parametrize("lam", [1.4, 2.0, 2.6])
def test_anchored_rule_equals_python_scaled_force(lam):
    rng = np.random.default_rng(11)
    x = np.cumsum(rng.normal(size=5000)) * 2e-6
    mem = memory(x)
    for m in (
        contactlab.Masing(40.0, 4e4),
        contactlab.Masing.from_backbone(
            np.linspace(0, 2e-4, 60), contactlab.Masing(40.0, 4e4).virgin(np.linspace(0, 2e-4, 60))
        ),
    ):
        fast = scaled_force(m.virgin, lam, mem)
        slow = _scaled_force_python(m.virgin, lam, mem)
        assert np.max(np.abs(fast - slow)) <= 1e-12 * np.max(np.abs(slow))


def test_detector_streams_and_rejects_bad_input():
    x = _signal(5, 5000)
    whole = excursions(x, 0.0, 0.4)
    det = ReversalDetector(0.0, 0.4)
    parts = [det.push(x[a : a + 613]) for a in range(0, x.size, 613)]
    got = type(whole).concat([*parts, det.open()])
    for k in whole.__dataclass_fields__:
        assert np.array_equal(getattr(got, k), getattr(whole, k)), k
    assert det.count == x.size
    with pytest.raises(InputError, match="threshold"):
        ReversalDetector(0.0, 0.0)
    with pytest.raises(InputError, match=r"x\[2\] is not finite"):
        ReversalDetector(0.0, 1.0).push([0.0, 1.0, np.nan])
    with pytest.raises(InputError, match="value"):
        ReversalDetector(0.0, 1.0).push([0.0, 1.0], value=[1.0])


def test_force_many_and_out_buffers_equal_force():
    rng = np.random.default_rng(3)
    xs = [np.cumsum(rng.normal(size=n)) * 1e-6 for n in (10, 5000, 0, 777)]
    models = [contactlab.Masing(40.0, 4e4), contactlab.Masing(5.0, 1e5, scale=1.7)] * 2
    for threads in (1, 2, 3):
        got = contactlab.force_many(models, xs, threads=threads)
        for m, x, f in zip(models, xs, got, strict=True):
            assert np.array_equal(f, m.operator().push(x))
    buf = np.empty(5000)
    assert contactlab.Masing(40.0, 4e4).force(xs[1], out=buf) is buf
    assert np.array_equal(buf, models[0].force(xs[1]))
    with pytest.raises(InputError, match="out has 3 samples"):
        models[0].force(xs[1], out=np.empty(3))
    with pytest.raises(InputError, match="float64"):
        models[0].force(xs[1], out=np.empty(5000, dtype=np.float32))
    with pytest.raises(InputError, match="2 models but 4 signals"):
        contactlab.force_many(models[:2], xs)
    with pytest.raises(InputError, match="threads"):
        contactlab.force_many(models[0], xs, threads=0)


def test_force_many_reports_the_bad_channel_whatever_the_threads():
    # Channels run on worker threads (longest first): an error in any channel must still come
    # back as one typed error (the lowest-numbered bad channel's), no partial list.
    xs = [np.linspace(0, 1e-5, 300) * k for k in range(1, 6)]
    xs[3] = xs[3].copy()
    xs[3][7] = np.inf
    m = contactlab.Masing(40.0, 4e4)
    for threads in (1, 2, 4):
        with pytest.raises(InputError, match="not finite"):
            contactlab.force_many(m, xs, threads=threads)
    assert contactlab.force_many(m, [], threads=2) == []


def test_force_many_into_given_outputs_with_per_thread_stats():
    rng = np.random.default_rng(8)
    xs = [np.cumsum(rng.normal(size=n)) * 1e-6 for n in (3000, 10, 0, 2500, 40)]
    m = contactlab.Masing(40.0, 4e4)
    want = [m.operator().push(x) for x in xs]
    for threads in (1, 2, 3):
        outs = [np.full(x.size, np.nan) for x in xs]
        stats: list[dict] = []
        got = contactlab.force_many(m, xs, threads=threads, out=outs, stats=stats)
        assert all(g is o for g, o in zip(got, outs, strict=True))
        assert all(np.array_equal(g, w) for g, w in zip(got, want, strict=True))
        # one dict per worker; every channel run once; times ordered
        assert len(stats) == min(threads, len(xs))
        assert sum(s["jobs"] for s in stats) == len(xs)
        assert sum(s["samples"] for s in stats) == sum(x.size for x in xs)
        for s in stats:
            assert 0.0 <= s["start"] <= s["end"]
            # the per-thread CPU and run-queue times come from Linux's schedstat
            if Path("/proc/thread-self/schedstat").exists():
                assert s["cpu"] >= 0.0 and s["wait"] >= 0.0
            else:
                assert s["cpu"] is None and s["wait"] is None
    with pytest.raises(InputError, match="2 output arrays but 5 signals"):
        contactlab.force_many(m, xs, out=outs[:2])
    bad = list(outs)
    bad[3] = np.empty(7)
    with pytest.raises(InputError, match=r"out\[3\]: out has 7 samples"):
        contactlab.force_many(m, xs, out=bad)
    bad[3] = outs[0]  # the same array twice
    with pytest.raises(InputError, match=r"out\[3\]"):
        contactlab.force_many(m, xs, out=bad)
    bad[3] = xs[3]  # an output that is an input
    with pytest.raises(InputError, match=r"out\[3\]"):
        contactlab.force_many(m, xs, out=bad)
    with pytest.raises(InputError, match="stats must be a list"):
        contactlab.force_many(m, xs, stats={})


def test_phase_fold_equals_numpy_bincount_and_streams():
    from contactlab import _core
    from contactlab.tangential.preprocess import find_reversals, phase_knots, phase_of

    rng = np.random.default_rng(8)
    n = 20_000
    t = np.arange(n) * 1e-3
    x = np.sin(2 * np.pi * 3.3 * t) + rng.normal(0, 0.05, n)
    F = np.cos(2 * np.pi * 3.3 * t) + rng.normal(0, 0.05, n)
    rev = find_reversals(x, t)
    n_cyc, nb = rev.peaks.size - 1, 40
    ph, start, end = phase_of(t, rev)
    cyc = np.floor(ph).astype(np.int64)
    frac = ph - cyc
    b = np.minimum((frac * nb).astype(np.int64), nb - 1)
    kt, kp = phase_knots(rev)
    fold = _core.PhaseFold(nb, n_cyc)
    for a in range(0, n, 3001):  # chunk by chunk
        fold.push(t[a : a + 3001], x[a : a + 3001], F[a : a + 3001], a, kt, kp)
    s = fold.sums()
    assert np.array_equal(s.count, np.bincount(b, minlength=nb))
    assert np.array_equal(s.sum_x, np.bincount(b, x[start:end], nb))
    assert np.array_equal(s.sum_phase2, np.bincount(b, frac * frac, nb))
    flat = cyc * nb + b
    cf = np.bincount(flat, F[start:end], n_cyc * nb).reshape(n_cyc, nb)
    assert np.array_equal(s.cycle_F, cf)
    assert s.first[0] == start
    assert np.array_equal(s.first, start + np.searchsorted(cyc, np.arange(n_cyc)))
    with pytest.raises(InputError, match="knot_t"):
        fold.push(t, x, F, 0, kt[::-1].copy(), kp)


@settings(max_examples=60, deadline=None)
@given(
    n=st.integers(1 << 15, 1 << 17),
    kind=st.sampled_from(["noise", "sine", "ties", "half-flat", "constant", "spikes"]),
    seed=st.integers(0, 2**16),
)
def test_tail_percentiles_are_numpys(n, kind, seed):
    from contactlab.tangential.preprocess import tail_percentiles

    rng = np.random.default_rng(seed)
    x = {
        "noise": lambda: rng.standard_normal(n),
        "sine": lambda: np.sin(0.00628 * np.arange(n)) + 1e-3 * rng.standard_normal(n),
        "ties": lambda: np.round(rng.standard_normal(n), 1),
        "half-flat": lambda: np.r_[np.zeros(n // 2), rng.standard_normal(n - n // 2)],
        "constant": lambda: np.full(n, 2.5),
        "spikes": lambda: np.where(rng.random(n) < 0.02, 1e6, rng.standard_normal(n)),
    }[kind]()
    ref = np.percentile(x, [0.5, 99.5])
    got = tail_percentiles(x)
    np.testing.assert_allclose(got, ref, rtol=0, atol=4 * np.spacing(np.max(np.abs(x))))


@settings(max_examples=40, deadline=None)
@given(
    n=st.integers(1, 1 << 17),
    kind=st.sampled_from(["noise", "ties", "spikes", "signed-zeros"]),
    seed=st.integers(0, 2**16),
    fr=st.lists(st.floats(0, 1), min_size=1, max_size=5),
)
def test_order_stats_are_a_sorts(n, kind, seed, fr):
    """The Rust selection behind tail_percentiles: the values of a sort, exactly, for the
    ranks next to both ends (0.5 % and 99.5 %: from the tails) and anywhere else."""
    from contactlab import _core

    rng = np.random.default_rng(seed)
    x = {
        "noise": lambda: rng.standard_normal(n),
        "ties": lambda: np.round(rng.standard_normal(n), 1),
        "spikes": lambda: np.where(rng.random(n) < 0.02, 1e6, rng.standard_normal(n)),
        "signed-zeros": lambda: np.round(rng.standard_normal(n)) * 0.0,
    }[kind]()
    ranks = [0, n // 200, min(n // 200 + 1, n - 1), n - 1 - n // 200, n - 1]
    ranks += [int(f * (n - 1)) for f in fr]
    got = _core.order_stats(x, ranks)
    assert np.array_equal(got, np.sort(x)[ranks])
    with pytest.raises(InputError):
        _core.order_stats(x, [n])
