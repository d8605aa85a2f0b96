"""One channel in pieces on several Rust threads (``contactlab_core::masing::split``): the
forces and the carried state are those of one thread bit for bit."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.signal import lfilter

import contactlab
from contactlab import InputError, _core


def _signals(n: int, seed: int) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(seed)
    return {
        "sine": 1e-5
        * np.sin(np.arange(n) * 2 * np.pi / 997)
        * (1 + 0.3 * np.sin(np.arange(n) * 1e-4)),
        "walk": np.cumsum(rng.normal(size=n)) * 1e-7,
        "noise": lfilter([1.0], [1.0, -0.95], rng.normal(size=n)) * 1e-6,
        # a grid walk: exact repeats of extremes and zero-length steps
        "grid": np.cumsum(rng.integers(-1, 2, size=n)) * 1e-7,
    }


def _bits(a: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(a).view(np.int64)


@pytest.mark.parametrize("kind", ["sine", "walk", "noise", "grid"])
def test_force_on_two_threads_equals_one_thread_bit_for_bit(kind):
    x = _signals(300_000, 61)[kind]
    for m in (contactlab.Masing(10.0, 2e5), contactlab.Masing(10.0, 2e5, scale=1.7)):
        one = m.force(x, threads=1)
        for threads in (2, 3):
            assert np.array_equal(_bits(m.force(x, threads=threads)), _bits(one))
        # from a carried state (a prefix), in place
        op = m.operator()
        op.push(x[:1234])
        out = np.empty(x.size - 1234)
        m.force(x[1234:], state=op.state, out=out, threads=2)
        assert np.array_equal(_bits(out), _bits(one[1234:]))
        # the operator's state after a split push is the serial one
        a, b = m.operator(), m.operator()
        a.push(x, threads=2)
        b.push(x)
        assert np.array_equal(_bits(a.state), _bits(b.state))


def test_force_many_splits_what_balancing_needs_and_reports_the_prepass():
    sig = _signals(400_000, 62)
    xs = [sig["walk"], sig["sine"][:150_000], sig["noise"][:5000], sig["grid"]]
    models = [
        contactlab.Masing(10.0, 2e5),
        contactlab.Masing(10.0, 2e5, scale=1.5),
        contactlab.Masing(10.0, 2e5),
        contactlab.Masing(10.0, 2e5),
    ]
    want = [m.force(x, threads=1) for m, x in zip(models, xs, strict=True)]
    stats: list[dict] = []
    got = contactlab.force_many(models, xs, threads=2, stats=stats)
    for g, w in zip(got, want, strict=True):
        assert np.array_equal(_bits(g), _bits(w))
    assert len(stats) == 2
    assert sum(s["samples"] for s in stats) == sum(x.size for x in xs)
    # the 150 000-sample channel is the shortest splittable one: its pre-pass ran
    assert sum(s["prepass"] for s in stats) > 0.0
    assert {"prepass", "prepass_cpu"} <= set(stats[0])
    one: list[dict] = []
    contactlab.force_many(models, xs, threads=1, stats=one)
    assert one[0]["prepass"] == 0.0 and one[0]["jobs"] == len(xs)


@settings(max_examples=40, deadline=None)
@given(
    steps=st.lists(
        st.sampled_from([-2.0, -1.0, 0.0, 1.0, 2.0, 7.0, -9.0]), min_size=1, max_size=600
    ),
    piece=st.integers(1, 50),
    threads=st.integers(2, 4),
    cut=st.integers(0, 100),
)
def test_tiny_pieces_equal_the_serial_kernel(steps, piece, threads, cut):
    # pieces of 1-50 samples put reversals on every kind of piece edge
    x = np.cumsum(steps) * 1e-6
    m = contactlab.Masing(10.0, 2e5)
    core = m._core.fresh()
    cut = min(cut, x.size)
    core.push(x[:cut])
    ser = core.fresh()
    ser.set_state(core.get_state())
    want = ser.push(x[cut:])
    got = core.push(x[cut:], None, threads, piece)
    assert np.array_equal(_bits(got), _bits(want))
    assert np.array_equal(_bits(core.get_state()), _bits(ser.get_state()))


def test_bad_input_on_the_split_path_is_a_clear_error():
    m = contactlab.Masing(10.0, 2e5)
    x = _signals(300_000, 63)["walk"]
    x[200_001] = np.nan
    with pytest.raises(InputError, match="200001"):
        m.force(x, threads=2)
    op = m.operator()
    with pytest.raises(InputError, match="threads"):
        op.push(x[:10], threads=0)
    with pytest.raises(InputError, match="threads"):
        m.force(x[:10], threads=True)
    # an overflowing force is named at its first sample, as on one thread
    tab = contactlab.Masing.from_backbone([0.0, 1.0], [0.0, 1.7e308])
    y = np.concatenate([np.tile([0.0, 1e-3], 100_000), [1.0, -0.99]])
    with pytest.raises(contactlab.ContactLabError) as one:
        tab.force(y, threads=1)
    with pytest.raises(contactlab.ContactLabError) as two:
        tab.force(y, threads=2)
    assert str(one.value) == str(two.value)
    assert "200001" in str(two.value)


def test_force_repeat_the_benchmarks_ceiling_runs_every_job_and_checks_its_input():
    """``_core.force_repeat`` (the in-cache ceiling of benches/bench_parallel.py): every job
    runs once whatever the threads, and a bad signal is an InputError naming the sample."""
    m = contactlab.Masing(40.0, 4.0e4)
    x = 20e-6 * np.sin(np.linspace(0.0, 12.0, 3000))
    for threads in (1, 2, 3):
        st = _core.force_repeat(m._core, x, 7, 3, threads)
        assert len(st) == min(threads, 7)
        assert sum(s.jobs for s in st) == 7
        assert all(0.0 <= s.start <= s.end for s in st)
    bad = x.copy()
    bad[17] = np.nan
    with pytest.raises(contactlab.InputError, match="17"):
        _core.force_repeat(m._core, bad, 2, 1, 2)
    with pytest.raises(contactlab.InputError, match="threads"):
        _core.force_repeat(m._core, x, 2, 1, 0)
