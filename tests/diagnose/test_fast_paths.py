"""The fast paths of a diagnosis give what the slow ones gave (issue 9): numpy filters against
scipy.signal / scipy.ndimage, the FFT frequency scan against one least-squares solve per
frequency, threaded candidate fits against a serial run, the reused Masing force against a
fresh one. Timings live in benches/bench_diagnose.py."""

from __future__ import annotations

import functools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import ndimage, signal

import contactlab
from contactlab.diagnose import _filters
from contactlab.diagnose._signal import modulation_gains
from contactlab.synthetic.diagnosis import hidden_effect_recording


def _walk(seed: int, n: int) -> np.ndarray:
    return np.cumsum(np.random.default_rng(seed).normal(size=n)) + 3.0


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(16, 3000),
    half=st.integers(2, 12),
    order=st.integers(1, 4),
    deriv=st.integers(0, 3),
    delta=st.floats(1e-4, 10.0),
)
def test_savgol_matches_scipy(seed, n, half, order, deriv, delta):
    w = 2 * half + 1
    if w > n or order >= w:
        return
    x = _walk(seed, n)
    a = signal.savgol_filter(x, w, order, deriv=deriv, delta=delta, mode="interp")
    b = _filters.savgol_filter(x, w, order, deriv=deriv, delta=delta, mode="interp")
    scale = max(float(np.max(np.abs(a))), 1e-300)
    assert np.max(np.abs(a - b)) <= 1e-11 * scale
    ca = signal.savgol_coeffs(w, order, deriv=deriv, delta=delta)
    cb = _filters.savgol_coeffs(w, order, deriv=deriv, delta=delta)
    assert np.allclose(ca, cb, rtol=1e-11, atol=1e-12 * max(np.max(np.abs(ca)), 1e-300))


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(16, 5000), q=st.integers(2, 45))
def test_decimate_matches_scipy(seed, n, q):
    x = _walk(seed, n)
    a = signal.decimate(x, q, ftype="fir", zero_phase=True)
    b = _filters.decimate(x, q, ftype="fir", zero_phase=True)
    assert a.shape == b.shape
    assert np.max(np.abs(a - b)) <= 1e-12 * np.max(np.abs(a))


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(2, 4000), size=st.integers(1, 600))
def test_hilbert_and_moving_mean_match_scipy(seed, n, size):
    x = _walk(seed, n)
    assert np.allclose(_filters.hilbert(x), signal.hilbert(x), rtol=0, atol=1e-12 * np.ptp(x))
    a = ndimage.uniform_filter1d(x, size, mode="nearest")
    b = _filters.uniform_filter1d(x, size, mode="nearest")
    assert np.max(np.abs(a - b)) <= 1e-10 * (np.ptp(x) + 1e-300)


def test_filters_refuse_what_they_do_not_implement():
    x = _walk(0, 100)
    with pytest.raises(ValueError, match="interp"):
        _filters.savgol_filter(x, 7, 3, mode="mirror")
    with pytest.raises(ValueError, match="odd"):
        _filters.savgol_coeffs(6, 3)
    with pytest.raises(ValueError, match="zero-phase FIR"):
        _filters.decimate(x, 3, ftype="iir")


@pytest.mark.parametrize("step_factor", [1.0, 1.0001])  # FFT route, and direct sums
def test_modulation_gains_match_least_squares(step_factor):
    rng = np.random.default_rng(11)
    n, dur = 3001, 12.0
    t = np.linspace(0.0, dur, n)
    h = 5.0 * np.sin(2 * np.pi * 1.3 * t) + rng.normal(size=n)
    r = 0.3 * h * np.cos(2 * np.pi * 0.77 * t + 0.4) + rng.normal(size=n)
    f_lo, step = 2.0 / dur, step_factor * 0.25 / dur
    count = 200
    g = modulation_gains(h, r, dur, f_lo, step, count)
    ref = []
    for f in f_lo + np.arange(count) * step:
        A = np.column_stack((h * np.cos(2 * np.pi * f * t), h * np.sin(2 * np.pi * f * t)))
        coef = np.linalg.lstsq(A, r, rcond=None)[0]
        ref.append(float(np.sum((A @ coef) ** 2)))
    assert np.max(np.abs(g - np.array(ref))) <= 1e-10 * max(ref)
    assert int(np.argmax(g)) == int(np.argmax(ref))
    # the strongest line is the hidden modulation at 0.77 Hz
    assert abs(f_lo + np.argmax(g) * step - 0.77) < 0.25 / dur


def test_parallel_candidates_give_the_serial_report(monkeypatch):
    rec = hidden_effect_recording(["stick_slip"], seed=4321, samples_per_cycle=60)
    monkeypatch.setenv("CONTACTLAB_DIAGNOSE_THREADS", "1")
    serial = contactlab.diagnose(rec, model="tangential", max_effects=1)
    monkeypatch.setenv("CONTACTLAB_DIAGNOSE_THREADS", "2")
    threaded = contactlab.diagnose(rec, model="tangential", max_effects=1)
    assert serial.to_json() == threaded.to_json()
    assert [v.to_dict() for v in serial.steps[0].candidates] == [
        v.to_dict() for v in threaded.steps[0].candidates
    ]


def test_reused_masing_force_is_the_fresh_one():
    """h0 times the kept unit-element force is Masing(h0, ac) to rounding, for any h0, and
    what predict hands out is the caller's to change."""
    from contactlab.diagnose._family import Prepared
    from contactlab.diagnose.candidates_tangential import TangentialFamily

    rec = hidden_effect_recording([], seed=77, samples_per_cycle=50)
    d = Prepared.build(rec.t, rec.data["x"], rec.data["F"])
    fam = TangentialFamily()
    fam.prepare(d)
    for h0 in (48.0, 0.013, 7.5e3):
        p = {"h0": h0, "ac": 4.6e4, "x0": 1e-7}
        fresh = contactlab.Masing(h0, 4.6e4).force(d.u)
        for _ in range(2):
            got = fam.predict(p, (), d)
            assert np.max(np.abs(got - fresh)) <= 1e-14 * h0
            got[:] = 0.0
        shifted = fam.predict(p, ("displacement_offset",), d)
        ref = contactlab.Masing(h0, 4.6e4).force(d.u - 1e-7)
        assert np.max(np.abs(shifted - ref)) <= 1e-14 * h0
        idx = np.arange(3, d.u.size, 7)
        for eff in [(), ("stick_slip", "stribeck"), ("position_friction", "force_drift")]:
            q = {**p, "s_b": 0.2, "ell": 3e-6, "s": 0.1, "v_s": 1e-3, "a1": 0.05, "b1": 0.0}
            q.update(L=2.5e-5, F1=0.3)
            assert np.array_equal(fam.predict(q, eff, d, at=idx), fam.predict(q, eff, d)[idx])
    with pytest.raises(contactlab.InputError, match="h0 must be finite"):
        fam.predict({"h0": 0.0, "ac": 4.6e4}, (), d)


def test_pmap_keeps_order_and_raises_the_first_error(monkeypatch):
    from contactlab.diagnose._parallel import pmap, workers

    monkeypatch.setenv("CONTACTLAB_DIAGNOSE_THREADS", "3")
    assert workers() == 3
    assert pmap(lambda i: i * i, list(range(40))) == [i * i for i in range(40)]

    def f(i: int) -> int:
        if i in (3, 7):
            raise ValueError(f"bad {i}")
        return i

    with pytest.raises(ValueError, match="bad 3"):
        pmap(f, list(range(10)))
    monkeypatch.setenv("CONTACTLAB_DIAGNOSE_THREADS", "0")  # not a count: the cores
    assert workers() >= 1


def test_threads_follow_the_load_now_not_the_lagging_average(monkeypatch):
    """The thread count takes the smaller of the 1-minute load average and the tasks
    runnable now: just after other work ended (average high, nothing running) a diagnosis
    uses the idle cores; under sustained load (both high) it runs serially."""
    import os

    from contactlab.diagnose import _parallel

    monkeypatch.delenv("CONTACTLAB_DIAGNOSE_THREADS", raising=False)
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0, 1}, raising=False)
    monkeypatch.setattr(os, "getloadavg", lambda: (1.7, 1.5, 1.2))
    monkeypatch.setattr(_parallel, "running_elsewhere", lambda: 0.0)
    assert _parallel.workers() == 2
    monkeypatch.setattr(_parallel, "running_elsewhere", lambda: 3.0)
    assert _parallel.workers() == 1
    monkeypatch.setattr(_parallel, "running_elsewhere", lambda: None)  # not Linux
    assert _parallel.workers() == 1
    monkeypatch.setattr(os, "getloadavg", lambda: (0.2, 0.5, 1.2))
    assert _parallel.workers() == 2
    monkeypatch.undo()
    now = _parallel.running_elsewhere()
    assert now is None or now >= 0.0


def test_a_binding_budget_stops_where_a_serial_run_stops(monkeypatch):
    """Candidates on threads spend the evaluation budget as a serial run does: the same
    candidates tried, the same ones left untested, the same sentence."""
    from contactlab.diagnose import search

    rec = hidden_effect_recording(["force_offset"], magnitude=0.05, seed=2)
    monkeypatch.setenv("CONTACTLAB_DIAGNOSE_THREADS", "1")
    full = contactlab.diagnose(rec, model="tangential", max_effects=1)
    assert not any("candidate search stopped" in w for w in full.where)
    # a budget that runs out in the middle of the first step's candidates (5 of 15 left
    # untested; 700 left 3 before the fits' quick tolerances and the load-frequency search,
    # and none since)
    monkeypatch.setattr(search, "MAX_EVALUATIONS", 400)
    serial = contactlab.diagnose(rec, model="tangential", max_effects=1)
    monkeypatch.setenv("CONTACTLAB_DIAGNOSE_THREADS", "2")
    threaded = contactlab.diagnose(rec, model="tangential", max_effects=1)
    reasons = [v.reason for v in serial.steps[0].candidates]
    untested = [r for r in reasons if r.startswith("not tested")]
    assert 0 < len(untested) < len(reasons)  # the budget binds part-way
    assert serial.to_json() == threaded.to_json()
    assert [v.to_dict() for v in serial.steps[0].candidates] == [
        v.to_dict() for v in threaded.steps[0].candidates
    ]
    assert serial.where == threaded.where


def test_evaluation_counter_counts_every_thread():
    from concurrent.futures import ThreadPoolExecutor

    from contactlab.diagnose._parallel import EvaluationCounter

    c = EvaluationCounter()

    def work(n: int) -> int:
        start = c.mine()
        for _ in range(n):
            c.tick()
        return c.mine() - start

    with ThreadPoolExecutor(4) as ex:
        got = list(ex.map(work, [1000] * 16))
    assert got == [1000] * 16 and c.total == 16_000


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(0, 3000), scale=st.floats(1e-9, 1e3))
def test_second_difference_noise_is_the_tangential_estimate(seed, n, scale):
    from contactlab.diagnose._signal import second_difference_var
    from contactlab.tangential.uncertainty import x_noise_var

    x = scale * _walk(seed, n)
    assert second_difference_var(x) == x_noise_var(x, None)


def test_one_verb_parser_is_the_full_parser_for_that_verb():
    """``contactlab VERB ...`` builds the parser of VERB only; every verb maps to the module
    that registers it, and parses as the full parser does."""
    from contactlab import cli

    full = cli.build_parser()
    verbs = next(a for a in full._actions if a.dest == "verb").choices
    assert set(verbs) == {cli._verb_module([v]) and v for v in verbs}
    for verb in verbs:
        mod = cli._verb_module([verb, "-x"])
        assert mod is not None
        only = cli.build_parser(mod)
        assert list(next(a for a in only._actions if a.dest == "verb").choices) == [verb]
    argv = ["diagnose", "rec.h5", "--model", "normal", "--p0", "0.5MPa", "--json", "o.json"]
    assert vars(cli.build_parser(cli._verb_module(argv)).parse_args(argv)) == vars(
        full.parse_args(argv)
    )
    assert cli._verb_module(["--help"]) is None
    assert cli._verb_module(["diagnos", "x"]) is None


def test_cli_diagnose_imports_no_other_verb():
    """A diagnosis from the command line imports neither the studies, the report, the
    tangential analysis nor the generator (start-up time, issue 9)."""
    import subprocess
    import sys

    code = (
        "import sys\n"
        "from contactlab import cli\n"
        "cli.build_parser(cli._verb_module(['diagnose'])).parse_args(['diagnose', 'f.h5', "
        "'--model', 'tangential'])\n"
        "import contactlab.diagnose.workflow\n"
        "bad = [m for m in sys.modules if m.startswith(('contactlab.studies', "
        "'contactlab.report', 'contactlab.tangential', 'contactlab.synthetic', "
        "'matplotlib', 'pyarrow', 'scipy.signal', 'scipy.stats'))]\n"
        "print(bad)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


_ALL_TANGENTIAL = (
    "viscous_damping", "inertia", "parallel_stiffness", "force_offset", "force_drift",
    "displacement_offset", "asymmetry", "parameter_drift", "stribeck", "position_friction",
    "stick_slip", "normal_load",
)  # fmt: skip


@settings(max_examples=25, deadline=None)
@given(
    effects=st.lists(st.sampled_from(_ALL_TANGENTIAL), max_size=4, unique=True),
    tau_samples=st.one_of(st.just(0.0), st.floats(-40.0, 40.0)),
    stride=st.integers(1, 13),
    start=st.integers(0, 12),
    f_n=st.floats(0.1, 30.0),
)
def test_prediction_at_samples_is_the_full_one(effects, tau_samples, stride, start, f_n):
    """``predict(at=idx)`` (with a delay: the terms at the samples around each shifted time
    only; the load fluctuation's terms kept per f_n) equals the full prediction at ``idx``,
    bit for bit, also when called again (memos hit)."""
    from contactlab.diagnose.candidates_tangential import TangentialFamily

    d = _small_tangential()
    fam = TangentialFamily()
    p = {"h0": 48.0, "ac": 4.6e4, "x0": 1e-7, "c": 3.0, "m": 0.01, "k_p": 1e4, "F0": 0.5}
    p.update(F1=0.3, alpha=0.1, beta=0.05, s=0.1, v_s=1e-3, a1=0.05, b1=0.02, L=2.5e-5)
    p.update(s_b=0.2, ell=3e-6, eps_c=0.03, eps_s=-0.02, f_n=f_n)
    p["tau"] = tau_samples * d.dt
    eff = (*effects, "channel_delay")
    idx = np.arange(start, d.u.size, stride)
    for _ in range(2):
        for e in (tuple(effects), eff):
            full = fam.predict(p, e, d)
            assert np.array_equal(fam.predict(p, e, d, at=idx), full[idx])


@functools.cache
def _small_tangential():
    from contactlab.diagnose._family import Prepared
    from contactlab.diagnose.candidates_tangential import TangentialFamily

    rec = hidden_effect_recording([], seed=78, samples_per_cycle=40, cycles_per_block=3)
    d = Prepared.build(rec.t, rec.data["x"], rec.data["F"])
    TangentialFamily().prepare(d)
    return d


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(2, 1500),
    log_lam=st.floats(-4.0, 3.5),
    jitter=st.sampled_from([0.0, 1e-3]),
    noise=st.sampled_from([0.0, 0.02]),
)
def test_exact_kelvin_voigt_is_the_integrator_at_tight_tolerance(seed, n, log_lam, jitter, noise):
    """The exact first-order response (the normal base model a diagnosis fits) against the
    package's adaptive integrator at rtol 1e-11 — stiff (ωΔt/ψ up to 3000) and non-stiff
    steps, uneven sampling, noisy pressure — and the kept unit response ``(R - p0)/k``
    against a direct evaluation."""
    from contactlab.diagnose._family import Prepared
    from contactlab.diagnose.candidates_normal import _kelvin_voigt_fit, kelvin_voigt_exact
    from contactlab.normal import KelvinVoigt

    rng = np.random.default_rng(seed)
    fs, omega, k = 200.0, 2 * np.pi * 1.3, 1.3e12
    t = (np.arange(n) + jitter * rng.uniform(-1, 1, n)) / fs
    p = 3e5 * np.sin(omega * t) + 1e5 * np.sin(2.7 * omega * t + 1.0)
    p = p + noise * 3e5 * rng.standard_normal(n)
    psi = 2 * np.pi * omega / (10.0**log_lam * fs)  # a Δt = 10^log_lam
    if not 1e-6 <= psi <= 10.0:
        return
    ref = KelvinVoigt(k, psi, omega).simulate(t, p, rtol=1e-11).delta
    got = kelvin_voigt_exact(t, p, k, psi, omega)
    scale = float(np.max(np.abs(ref)))
    assert np.max(np.abs(got - ref)) <= 1e-8 * scale
    if n >= 16:
        p0 = 4e5
        d = Prepared(t, p + p0, p, 1.0 / fs, 7, p, p, None)  # type: ignore[arg-type]
        for _ in range(2):  # computed, then kept
            kept = _kelvin_voigt_fit(d, k, psi, p0, omega)
            assert np.max(np.abs(kept - got)) <= 1e-12 * scale


@settings(max_examples=30, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(8, 5000),
    nper=st.integers(2, 1100),
    fs=st.floats(1.0, 1e5),
)
def test_welch_matches_scipy(seed, n, nper, fs):
    from scipy.signal import welch

    nper = min(nper, n)
    x = np.random.default_rng(seed).normal(size=n) + np.linspace(0.0, 3.0, n)
    f0, p0 = welch(x, fs=fs, window="hann", nperseg=nper, detrend="linear")
    f1, p1 = _filters.welch(x, fs, nper)
    assert np.allclose(f1, f0, rtol=1e-12, atol=0.0)
    assert np.allclose(p1, p0, rtol=1e-9, atol=1e-12 * float(np.var(x)) / fs)


def test_normal_diagnosis_with_input_noise_imports_no_scipy_signal():
    """The input-noise spectrum of the normal family (Welch) is numpy's: a diagnosis run
    imports neither scipy.signal nor scipy.stats (half a second of a 1e6-sample run)."""
    import subprocess
    import sys

    code = (
        "import sys\n"
        "import numpy as np\n"
        "import contactlab\n"
        "rng = np.random.default_rng(5)\n"
        "t = np.arange(6000) / 200.0\n"
        "p = 5e5 + 2e5 * np.sin(2 * np.pi * t) + 1e3 * rng.normal(size=t.size)\n"
        "d = (p - 5e5) / 1.3e12 + 2e-10 * rng.normal(size=t.size)\n"
        "contactlab.diagnose((t, p, d), model='normal', max_effects=1)\n"
        "print([m for m in sys.modules if m.startswith(('scipy.signal', 'scipy.stats'))])\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip().splitlines()[-1] == "[]"
