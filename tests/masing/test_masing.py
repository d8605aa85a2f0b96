"""Masing operator: Rust core against an independent Python reference, and the invariants of
PHYSICS.md §1 as hypothesis properties."""

from __future__ import annotations

import itertools
import pickle
import threading
import time

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

import contactlab
from contactlab import ContactLabError, InputError, Masing
from masing_reference import reference_energy, reference_force

H0, AC = 12.0, 3.0e4  # N, 1/m: steel-like, a loop of tens of µm is well curved


def walks(max_len=200):
    steps = st.lists(
        st.floats(-60e-6, 60e-6, allow_nan=False, allow_subnormal=False),
        min_size=1,
        max_size=max_len,
    )
    return steps.map(np.cumsum)


def close(a, b, rtol=1e-12):
    a, b = np.asarray(a), np.asarray(b)
    return np.all(np.abs(a - b) <= rtol * np.maximum(np.abs(b), H0 * 1e-3))


# -- against the independent reference -----------------------------------------------------------
@settings(max_examples=150, deadline=None)
@given(walks(), st.sampled_from([2.0, 1.5, 2.6]))
def test_rust_matches_python_reference(x, lam):
    got = Masing(H0, AC, scale=lam).force(x)
    ref = reference_force(x, H0, AC, lam)
    assert close(got, ref)


def test_random_signals_match_reference_long():
    rng = np.random.default_rng(3)
    for _ in range(5):
        x = np.cumsum(rng.normal(0, 8e-6, 3000)) + 1e-5 * np.sin(np.arange(3000) / 40)
        assert close(Masing(H0, AC).force(x), reference_force(x, H0, AC))


# -- analytic energy ---------------------------------------------------------------------------
@pytest.mark.parametrize("A", [1e-7, 3e-6, 2e-5, 1e-4, 1e-3])
def test_energy_formula_matches_branch_integration(A):
    m = Masing(H0, AC)
    hm = m.virgin(A)

    def gap(x):  # upper (loading from -A) minus lower (unloading from +A) branch
        return (-hm + 2 * m.virgin((x + A) / 2)) - (hm + 2 * m.virgin((x - A) / 2))

    numeric, _ = quad(gap, -A, A, epsabs=0, epsrel=1e-11)
    assert m.loop_energy(A) == pytest.approx(numeric, rel=1e-9)
    if A >= 3e-6:  # the printed form cancels catastrophically below that
        assert m.loop_energy(A) == pytest.approx(reference_energy(A, H0, AC), rel=1e-9)


def test_energy_limits_and_damping_shape():
    m = Masing(H0, AC)
    A = 1e-9
    assert m.loop_energy(A) == pytest.approx(2 / 3 * H0 * AC**2 * A**3, rel=1e-4)
    A = 1.0
    assert m.loop_energy(A) == pytest.approx(4 * H0 * A - 8 * H0 / AC, rel=1e-12)
    amps = np.geomspace(1e-8, 1e-2, 400)
    c = m.equivalent_damping(amps)
    k = int(np.argmax(c))
    assert 0 < k < amps.size - 1  # rises, peaks, falls
    assert c[-1] == pytest.approx(4 * H0 / (np.pi * amps[-1]), rel=2e-2)
    assert m.equivalent_damping(0.0) == 0.0


def test_loop_area_of_simulated_loop_equals_energy():
    m = Masing(H0, AC)
    A = 40e-6
    x = A * np.sin(np.linspace(0, 4 * np.pi, 40001))
    F = m.force(x)
    assert contactlab.loop_area(x[10000:30001], F[10000:30001]) == pytest.approx(
        m.loop_energy(A), rel=1e-6
    )
    # Offsets do not cost accuracy (shifted shoelace).
    a = contactlab.loop_area(x[10000:30001] + 1.0, F[10000:30001] + 1e6)
    assert a == pytest.approx(m.loop_energy(A), rel=1e-6)


def test_stiffness():
    m = Masing(H0, AC)
    assert m.local_stiffness(0.0) == pytest.approx(H0 * AC, rel=1e-15)
    assert m.global_stiffness(0.0) == pytest.approx(H0 * AC, rel=1e-15)
    x = np.array([1e-6, -2e-5, 1e-4])
    assert np.allclose(m.local_stiffness(x), H0 * AC * np.exp(-AC * np.abs(x)), rtol=1e-14)
    assert np.allclose(m.global_stiffness(x), m.virgin(x) / x, rtol=1e-14)
    # Numeric derivative of the virgin curve.
    h = 1e-9
    num = (m.virgin(2e-5 + h) - m.virgin(2e-5 - h)) / (2 * h)
    assert m.local_stiffness(2e-5) == pytest.approx(num, rel=1e-6)


# -- invariants (PHYSICS.md §1) ----------------------------------------------------------------
@settings(max_examples=80, deadline=None)
@given(walks(), st.floats(0.05, 0.95))
def test_return_point_memory(x, frac):
    m = Masing(H0, AC)
    op = m.operator()
    op.push(x)
    last = float(x[-1])
    a = last - 30e-6
    b = a + frac * (last - a)
    out = op.push([a, b, a])
    assert out[2] == pytest.approx(out[0], rel=1e-12, abs=1e-12 * H0)


@settings(max_examples=60, deadline=None)
@given(walks(), st.floats(-40e-6, 40e-6), st.floats(1e-6, 40e-6))
def test_congruency(x, lo, r):
    m = Masing(H0, AC)
    big = float(np.max(np.abs(x))) + 200e-6
    up = np.linspace(lo, lo + r, 501)[1:]  # leaves lo, ends at lo + r
    down = np.linspace(lo + r, lo, 501)[1:]  # leaves lo + r, ends at lo
    areas = []
    for pre in ([big, lo], [-big, lo + r]):
        op = m.operator()
        op.push(np.r_[x, pre])
        xs = np.r_[up, down] if pre[1] == lo else np.r_[down, up]
        areas.append(contactlab.loop_area(xs, op.push(xs)))
    assert areas[0] == pytest.approx(areas[1], rel=1e-9, abs=1e-20)
    assert abs(areas[0]) == pytest.approx(m.loop_energy(r / 2), rel=1e-4)


@settings(max_examples=80, deadline=None)
@given(walks())
def test_odd_symmetry(x):
    m = Masing(H0, AC)
    assert np.array_equal(m.force(-x), -m.force(x))


@settings(max_examples=80, deadline=None)
@given(walks(), st.lists(st.integers(0, 200), max_size=5))
def test_chunk_invariance_bit_for_bit(x, cuts):
    m = Masing(H0, AC)
    whole = m.force(x)
    op = m.operator()
    parts = [op.push(c) for c in np.split(x, sorted(set(cuts)))]
    assert np.array_equal(np.concatenate(parts), whole)


@settings(max_examples=60, deadline=None)
@given(walks(), st.integers(1, 4))
def test_monotone_refinement_and_rate_independence(x, k):
    m = Masing(H0, AC)
    base = m.force(x)
    prev = 0.0
    y, idx = [], []
    for v in x:
        for j in range(1, k):
            mid = prev + (v - prev) * j / k
            if (mid - prev) * (v - mid) > 0:
                y.append(mid)
        y.extend([v] * k)  # slower clock: repeated samples
        idx.append(len(y) - 1)
        prev = v
    assert np.array_equal(m.force(np.array(y))[idx], base)


@settings(max_examples=60, deadline=None)
@given(walks(100))
def test_cycle_energies_nonnegative_and_sum_to_work(x):
    m = Masing(H0, AC)
    A = float(np.max(np.abs(x))) + 10e-6
    sig = np.r_[A, 0.99 * x, -A, A]
    dense = np.concatenate([np.linspace(a, b, 300)[1:] for a, b in itertools.pairwise(sig)])
    dense = np.r_[sig[0], dense]
    F = m.force(dense)
    work = float(np.sum(0.5 * (F[1:] + F[:-1]) * np.diff(dense)))
    cyc = contactlab.cycle_energies(dense, m)
    assert np.all(cyc.energy >= 0)
    assert cyc.total_energy == pytest.approx(work, rel=5e-5, abs=1e-15)


def test_cycle_table_fields():
    m = Masing(H0, AC)
    x = np.r_[0, 50e-6, -10e-6, 20e-6, -10e-6, -50e-6, 50e-6] * 1.0
    cyc = contactlab.cycle_energies(x, m)
    inner = cyc.count == 1
    assert inner.sum() == 1
    assert cyc.range[inner][0] == pytest.approx(30e-6)
    assert cyc.mean[inner][0] == pytest.approx(5e-6)
    assert (cyc.start[inner][0], cyc.end[inner][0]) == (2, 4)
    assert cyc.energy[inner][0] == pytest.approx(m.loop_energy(15e-6))
    assert set(cyc.to_dict()) == {"range", "mean", "start", "end", "count", "energy"}


# -- streaming state, pickling, backbone ---------------------------------------------------------
def test_state_roundtrip_and_pickle():
    m = Masing(H0, AC)
    x = np.cumsum(np.random.default_rng(0).normal(0, 5e-6, 500))
    op = m.operator()
    op.push(x[:250])
    op2 = pickle.loads(pickle.dumps(op))
    assert np.array_equal(op2.push(x[250:]), m.force(x)[250:])
    op3 = m.operator()
    op3.state = op.state
    assert np.array_equal(op3.push(x[250:]), op.push(x[250:]))
    op.reset()
    assert np.array_equal(op.push(x), m.force(x))
    assert np.array_equal(m.force(x[250:], state=op2.state), m.force(x[250:], state=op2.state))
    m2 = pickle.loads(pickle.dumps(m))
    assert np.array_equal(m2.force(x), m.force(x))


def test_from_backbone_reproduces_exponential():
    m = Masing(H0, AC)
    u = np.linspace(0, 300e-6, 600)
    mb = Masing.from_backbone(u, m.virgin(u))
    x = np.cumsum(np.random.default_rng(1).normal(0, 8e-6, 2000))
    x = np.clip(x, -290e-6, 290e-6)
    assert np.allclose(mb.force(x), m.force(x), atol=1e-6 * H0)
    assert mb.loop_energy(50e-6) == pytest.approx(m.loop_energy(50e-6), rel=1e-5)
    assert mb.local_stiffness(20e-6) == pytest.approx(m.local_stiffness(20e-6), rel=1e-3)
    mb2 = pickle.loads(pickle.dumps(mb))
    assert np.array_equal(mb2.force(x), mb.force(x))


# -- bad input ---------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("args", "match"),
    [((-1, AC), "h0"), ((H0, 0), "ac"), ((H0, AC, -2), "scale"), ((H0, float("nan")), "ac")],
)
def test_bad_parameters(args, match):
    with pytest.raises(InputError, match=match):
        Masing(*args)


def test_bad_arrays():
    m = Masing(H0, AC)
    with pytest.raises(InputError, match=r"x\[2\]"):
        m.force([0.0, 1e-6, np.nan])
    with pytest.raises(InputError, match=r"x\[0\]"):
        m.force([np.inf])
    with pytest.raises(InputError, match="empty"):
        m.force([])
    with pytest.raises(InputError, match="1-D"):
        m.force(np.zeros((3, 2)))
    with pytest.raises(InputError):
        m.force(["a", "b"])
    with pytest.raises(InputError, match="F has"):
        contactlab.loop_area([0, 1, 2], [0, 1])
    with pytest.raises(InputError, match=r"F\[1\]"):
        contactlab.loop_area([0, 1, 2], [0, np.nan, 1])
    with pytest.raises(InputError):
        contactlab.cycle_energies([0, 1], "not a model")
    with pytest.raises(InputError, match="state"):
        m.operator().state = [0.0, 0.0, 5.0, 0.0]
    # int and float32 input is converted, not rejected
    assert np.array_equal(m.force(np.array([0, 1, -1])), m.force([0.0, 1.0, -1.0]))
    x32 = np.array([1e-6, -2e-6], dtype=np.float32)
    assert np.array_equal(m.force(x32), m.force(x32.astype(np.float64)))


@pytest.mark.parametrize(
    ("xp", "fp", "match"),
    [
        ([0.1, 0.2], [0.0, 1.0], "origin"),
        ([0.0, 0.2, 0.1], [0.0, 1.0, 2.0], "increasing"),
        ([0.0, 0.1, 0.2], [0.0, 1.0, 0.5], "monotone"),
        ([0.0, 0.1], [0.0, 1.0, 2.0], "points"),
        ([0.0], [0.0], "two points"),
        ([0.0, np.nan], [0.0, 1.0], "not finite"),
    ],
)
def test_bad_backbone(xp, fp, match):
    with pytest.raises(InputError, match=match):
        Masing.from_backbone(xp, fp)


def test_no_panic_reaches_python():
    # Hostile inputs across the API: every failure must be a ContactLabError, never a
    # PanicException (a BaseException that `except Exception` would miss).
    m = Masing(H0, AC)
    hostile = [
        lambda: m.force(np.full(10, np.nan)),
        lambda: m.operator().push(np.array([1e308, -1e308, np.inf])),
        lambda: setattr(m.operator(), "state", np.array([np.nan] * 7)),
        lambda: setattr(m.operator(), "state", np.array([0, 0, 1, 0, 1e-6, 1.0, 0.0, -2e-6])),
        lambda: Masing.from_backbone([0.0, 0.0], [0.0, 0.0]),
        lambda: contactlab.loop_area([], []),
    ]
    for f in hostile:
        try:
            f()
        except ContactLabError:
            pass
        except BaseException as exc:  # pragma: no cover - this is the failure being tested
            pytest.fail(f"{type(exc).__name__} escaped: {exc}")
    # Extreme but finite values are not errors.
    out = m.force(np.array([1e308, -1e308, 1e-300]))
    assert np.all(np.isfinite(out))


def test_gil_is_released_during_kernels():
    m = Masing(H0, AC)
    x = 40e-6 * np.sin(np.linspace(0, 2000 * np.pi, 4_000_000))
    ticks = []
    done = threading.Event()

    def work():
        m.force(x)
        done.set()

    t = threading.Thread(target=work)
    t0 = time.perf_counter()
    t.start()
    while not done.is_set():
        ticks.append(time.perf_counter())
        time.sleep(0.001)
    t.join()
    elapsed = time.perf_counter() - t0
    # With the GIL held, this thread could not tick while the kernel ran.
    assert len(ticks) >= 3 or elapsed < 0.005
