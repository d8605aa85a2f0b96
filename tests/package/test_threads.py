"""Threads (issue 12): the kernels release the GIL, so a ThreadPoolExecutor over recordings
runs them in parallel. Models, fits and analyses used from several threads at once give
bit-for-bit the results of a serial run. What may be shared is listed in README.md
("Threads"): a Masing model yes, a MasingOperator (it carries state) no: one per thread.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np

import contactlab.normal as cn
from contactlab import Masing, least_squares_fit
from contactlab.synthetic.normal import synthetic_recording as normal_recording
from contactlab.synthetic.tangential import synthetic_recording
from contactlab.tangential import analyze_tangential

WORKERS = 4


def _recordings(n=6):
    return [
        synthetic_recording(
            h0=30.0 + 5 * i,
            ac=3e4 + 4e3 * i,
            amplitude=(15 + 2 * i) * 1e-6,
            n_cycles=4,
            fs=1200.0,
            noise=0.01,
            seed=100 + i,
        )
        for i in range(n)
    ]


def _summary(res):
    d = res.to_dict()
    return tuple(d[k] for k in ("h0", "ac", "h0_stderr", "ac_stderr", "energy_per_cycle"))


def test_tangential_analyses_in_a_thread_pool_equal_serial():
    recs = _recordings()
    serial = [_summary(analyze_tangential(r, warn=False)) for r in recs]
    with ThreadPoolExecutor(WORKERS) as ex:
        threaded = list(ex.map(lambda r: _summary(analyze_tangential(r, warn=False)), recs))
    assert threaded == serial  # bit for bit


def test_one_shared_model_many_threads_equal_serial():
    """A Masing model is immutable: its force/energy methods may be called concurrently."""
    m = Masing(h0=40.0, ac=4e4)
    xs = [a * 1e-6 * np.sin(np.linspace(0, 30 * np.pi, 200_001)) for a in (5, 10, 20, 40, 80)]
    serial = [m.force(x) for x in xs]
    with ThreadPoolExecutor(WORKERS) as ex:
        threaded = list(ex.map(m.force, xs * 2))
    for got, want in zip(threaded, serial * 2, strict=True):
        np.testing.assert_array_equal(got, want)


def test_operators_one_per_thread_stream_like_serial():
    """A MasingOperator carries the loop memory: one per recording (thread), chunked pushes
    equal to one pass."""
    m = Masing(h0=40.0, ac=4e4)
    rng = np.random.default_rng(3)
    xs = [np.cumsum(rng.standard_normal(50_000)) * 1e-7 for _ in range(6)]

    def stream(x):
        op = m.operator()
        return np.concatenate([op.push(c) for c in np.array_split(x, 7)])

    serial = [m.force(x) for x in xs]
    with ThreadPoolExecutor(WORKERS) as ex:
        threaded = list(ex.map(stream, xs))
    for got, want in zip(threaded, serial, strict=True):
        np.testing.assert_array_equal(got, want)


def test_fits_and_normal_loops_in_threads_equal_serial():
    x = np.linspace(0, 4, 80)

    def fit(seed):
        y = 3.0 * np.exp(-0.7 * x) + 0.02 * np.random.default_rng(seed).standard_normal(x.size)
        r = least_squares_fit(lambda v: v["a"] * np.exp(-v["k"] * x) - y, {"a": 1.0, "k": 1.0})
        return r.params["a"].value, r.params["k"].value, r.params["k"].stderr

    def loop(seed):
        t, p, d = normal_recording(p0=0.5e6, pa=0.4e6, omega=1.0, n_cycles=4, seed=seed)
        res = cn.analyze_loop(t, p, d)
        return res.psi, res.k_tan, res.k_sec

    seeds = list(range(20, 28))
    for fn in (fit, loop):
        serial = [fn(s) for s in seeds]
        with ThreadPoolExecutor(WORKERS) as ex:
            assert list(ex.map(fn, seeds)) == serial


def test_a_shared_operator_is_refused_with_a_contactlab_error():
    """Two threads pushing into one operator: the second is told to use its own (a clear
    ContactLabError, not PyO3's bare RuntimeError); what completes is still correct."""
    import threading

    from contactlab import ContactLabError

    m = Masing(h0=40.0, ac=4e4)
    op = m.operator()
    x = 20e-6 * np.sin(np.linspace(0, 400 * np.pi, 1_000_000))
    errors: list[BaseException] = []
    done: list[np.ndarray] = []

    def push():
        try:
            done.append(op.push(x))
        except BaseException as exc:
            errors.append(exc)

    threads = [threading.Thread(target=push) for _ in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert all(isinstance(e, ContactLabError) for e in errors), errors
    assert "one operator per thread" in str(errors[0]) if errors else True
    assert len(done) + len(errors) == 3
