"""The bound stated for ``creep_drift`` (issue 29): stated at the log-middle of the
plausible settling times (stop 46; at the fastest, a quarter period, from stop 42 to 45 it
was the size of a start-up step, 10-40 times what a creep over the cycles is named at)."""

from __future__ import annotations

import warnings
from types import SimpleNamespace

import numpy as np
import pytest

from contactlab.diagnose.effects import registry
from contactlab.diagnose.effects.normal.creep_drift import CREEP_MAX_DURATIONS, CREEP_MIN_PERIODS


def test_power_shape_is_the_log_middle_of_the_plausible_settling():
    d = SimpleNamespace(cycles=SimpleNamespace(period_samples=250.0), dt=1e-3, duration=10.0)
    shape = registry("normal")["creep_drift"].power_shape(d, {})
    lo, hi = CREEP_MIN_PERIODS * 0.25, CREEP_MAX_DURATIONS * 10.0
    assert shape == {"tau_c": pytest.approx(np.sqrt(lo * hi))}


def _diagnose(t, p, d):
    import contactlab

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return contactlab.diagnose({"t": t, "p": p, "delta": d}, "normal")


@pytest.mark.slow
def test_creep_at_twice_the_stated_bound_is_named():
    """The bound tracks the detector: a creep of twice the stated ``D``, settling at the
    stated ``τc``, added to the clean record, is named (and the clean record names nothing);
    the note says the bound is stated at that ``τc``. Stated at a quarter period (stop 45)
    the bound on this record was 0.138 of the displacement's RMS, 7.4 times what it is now
    (0.0187)."""
    from contactlab.synthetic.rig import rig_recording

    r = rig_recording({}, "normal", seed=11, fs=1000.0, f=4.0, cycles=16, k=1.3e12,
                      psi=0.15, p0=5e5, pa=2.5e5, x_noise=0.01, F_noise=0.01,
                      ramp_cycles=1.0)  # fmt: skip
    t, p, d = r.t, r.channels["p"], r.channels["delta"]
    clean = _diagnose(t, p, d)
    assert list(clean.effect_names) == []
    b = next(x.to_dict() for x in clean.not_detected if x.to_dict()["effect"] == "creep_drift")
    assert b["relative_size"] < 0.1
    assert "log-middle" in b["note"]
    tc, size = b["at"]["tau_c"], 2.0 * b["detectable_above"]
    res = _diagnose(t, p, d + size * -np.expm1(-(t - t[0]) / tc))
    assert "creep_drift" in res.effect_names


def test_fast_creep_is_not_named():
    """A creep of 0.1 of the amplitude settling in 0.2 period (below the plausible range)
    is not named, and the bound's note says faster creeps need a larger ``D``."""
    import contactlab
    from contactlab.synthetic.rig import rig_recording

    k, p0 = 1.3e12, 5e5
    pa = 0.5 * p0
    size = 0.1 * pa / k
    r = rig_recording({"creep_drift": {"D": size, "tau_c": 0.05}}, "normal", seed=5,
                      fs=1000.0, f=4.0, cycles=12, k=k, psi=0.15, p0=p0, pa=pa,
                      x_noise=0.01, F_noise=0.01, ramp_cycles=1.0)  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = contactlab.diagnose({"t": r.t, "p": r.channels["p"], "delta": r.channels["delta"]},
                                  "normal")  # fmt: skip
    assert "creep_drift" not in res.effect_names
    b = next(x.to_dict() for x in res.not_detected if x.to_dict()["effect"] == "creep_drift")
    assert b["at"]["tau_c"] > CREEP_MIN_PERIODS / 4.0
    assert "settling faster" in b["note"]
