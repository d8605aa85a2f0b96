"""Start-up and run-out transients of a tangential record (:mod:`contactlab.tangential.startup`):
a rig that ramps its stroke up over the first seconds had those cycles averaged in with the
steady ones without a word (audit: amplitude −0.12 %, energy −0.30 %)."""

from __future__ import annotations

import numpy as np
import pytest

import contactlab
from contactlab.tangential import analyze_tangential
from contactlab.tangential.startup import transient_cycles


def _record(seed: int, *, ramp_s: float = 0.0, runout_s: float = 0.0, n_cyc: int = 60,
            fs: float = 500.0, f0: float = 2.0, noise: float = 0.01):  # fmt: skip
    rng = np.random.default_rng(seed)
    t = np.arange(int(n_cyc * fs / f0)) / fs
    env = np.ones_like(t)
    if ramp_s:
        env = np.minimum(env, np.clip(t / ramp_s, 0, 1))
    if runout_s:
        env = np.minimum(env, np.clip((t[-1] - t) / runout_s, 0, 1))
    A = 20e-6
    x = A * env * np.sin(2 * np.pi * f0 * t)
    F = contactlab.Masing(40.0, 4e4).force(x)
    x = x + rng.normal(0, noise * 2 * A, t.size)
    F = F + rng.normal(0, noise * (F.max() - F.min()), t.size)
    return contactlab.Recording(t, {"x": x, "F": F}, {"x": "m", "F": "N"}, f"ramp{seed}")


def test_unit_cases():
    steady = np.full(30, 20e-6) + 1e-8 * np.sin(np.arange(30))
    t = np.arange(30) + 0.5
    assert transient_cycles(steady, t) is None
    a = steady.copy()
    a[:3] = [5e-6, 12e-6, 18e-6]
    a[-1] = 9e-6
    tr = transient_cycles(a, t, np.ones(30))
    assert (tr.lead, tr.trail, tr.n_cycles) == (3, 1, 30)
    assert tr.t_steady == (3.0, 29.0)
    assert tr.shift == pytest.approx(np.mean(a) / np.mean(a[3:-1]) - 1)
    assert "first 3 cycles" in tr.message() and "last 1 cycle " in tr.message()
    # one odd cycle in the middle is scatter, not a transient
    b = steady.copy()
    b[15] = 5e-6
    assert transient_cycles(b, t) is None
    # most of the record off: no steady state
    c = steady.copy()
    c[:16] = 10e-6
    assert transient_cycles(c, t) is None
    assert transient_cycles(steady[:5], t[:5]) is None
    # noise-free cycles that differ only by binning (1e-6 relative) are steady
    d = 20e-6 * (1 + 1e-6 * np.cos(np.arange(30)))
    d[0] *= 1 + 2e-6
    assert transient_cycles(d, t) is None


@pytest.mark.parametrize("seed", [7001, 7002, 7003])
def test_ramped_record_is_found(seed):
    rec = _record(seed, ramp_s=3.0)
    r = analyze_tangential(rec, warn=False)
    tr = transient_cycles(r.scatter.amplitude, r.scatter.time, r.scatter.period)
    assert tr is not None and tr.lead >= 1 and tr.trail == 0
    assert tr.t_steady[0] <= 3.0 + 1.0  # the ramp ends at 3 s; a cycle lasts 0.5 s
    assert tr.shift < 0


@pytest.mark.parametrize("seed", [7101, 7102, 7103, 7104, 7105])
def test_steady_noisy_records_are_not_flagged(seed):
    r = analyze_tangential(_record(seed), warn=False)
    assert transient_cycles(r.scatter.amplitude, r.scatter.time, r.scatter.period) is None


@pytest.mark.parametrize("seed", [7201, 7202])
def test_analysis_warns_of_a_ramp_and_says_where_to_cut(seed):
    rec = _record(seed, ramp_s=3.0, n_cyc=80)
    r = analyze_tangential(rec, warn=False)
    msg = [w for w in r.warnings if "start-up transient" in w]
    assert len(msg) == 1 and "cut the record to t = " in msg[0]
    # cutting where it says removes the warning
    t0 = float(msg[0].split("cut the record to t = ")[1].split(" ..")[0])
    keep = rec.t >= t0
    cut = contactlab.Recording(rec.t[keep], {"x": rec["x"][keep], "F": rec["F"][keep]},
                               dict(rec.units), "cut")  # fmt: skip
    r2 = analyze_tangential(cut, warn=False)
    assert not [w for w in r2.warnings if "transient" in w]


def test_run_out_is_named():
    r = analyze_tangential(_record(7301, runout_s=3.0, n_cyc=80), warn=False)
    assert any("run-out transient" in w and "the last" in w for w in r.warnings)
