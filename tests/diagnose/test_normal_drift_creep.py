"""A displacement sensor's straight drift is neither creep nor a loss; a creep that settles
in a fraction of a second is creep (issue 29, docs/effects.md §2).

A straight drift of 2 % of δ's range on a single-tone record that starts from rest was named
``hysteretic_damping`` (the frequency-domain solve's start-up draws a slow trend) or
``creep_drift`` (τc twice the record); a creep of τc 0.3 s under a 2 Hz drive was refused as
settling within one excitation period.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import contactlab
from contactlab.diagnose._family import Prepared
from contactlab.diagnose.candidates_normal import NormalFamily, kelvin_voigt_exact
from contactlab.diagnose.effects.normal.creep_drift import CREEP_MAX_DURATIONS

F, FS, CYCLES = 2.0, 1000.0, 20
K, PSI, P0, PA = 1.3e12, 0.1, 5e5, 3.5e5


def _record(seed: int, drift_frac: float = 0.0, creep: float = 0.0, tau_c: float = 0.3):
    """Kelvin-Voigt joint whose pressure amplitude rises from rest, 1 % noise on p and 1.5 %
    on δ (of range), a straight drift of ``drift_frac`` of δ's range over the record and a
    settling of ``creep`` times the amplitude with time constant ``tau_c``."""
    t = np.arange(int(CYCLES * FS / F)) / FS
    om = 2 * np.pi * F
    pd = PA * (1 - np.exp(-t * F * 3)) * np.sin(om * t)
    d = kelvin_voigt_exact(t, pd, K, PSI, om)
    rng = np.random.default_rng(seed)
    p = P0 + pd + rng.normal(0, 0.01 * np.ptp(pd), t.size)
    dd = d + rng.normal(0, 0.015 * np.ptp(d), t.size) + drift_frac * np.ptp(d) * t / t[-1]
    dd = dd - creep * (PA / K) * np.expm1(-t / tau_c)
    return t, p, dd


def _diagnose(t, p, d):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return contactlab.diagnose({"t": t, "p": p, "delta": d}, "normal")


def _prepared(t, p, d):
    pr = Prepared.build(t, p, d, errors_in_input=False)
    NormalFamily().prepare(pr)
    return pr


def test_a_straight_sensor_drift_names_nothing():
    r = _diagnose(*_record(2, drift_frac=0.02))
    assert r.effect_names == []
    assert not r.to_dict()["unexplained"]["flagged"]


def test_a_creep_settling_within_one_period_is_named():
    t, p, d = _record(1, creep=0.15, tau_c=0.3)  # 0.6 of the 0.5 s period
    r = _diagnose(t, p, d)
    assert r.effect_names == ["creep_drift"]
    fitted = r.to_dict()["effects"][0]["parameters"]["tau_c"]
    assert fitted == pytest.approx(0.3, rel=0.2)


def test_hysteretic_damping_is_not_identifiable_at_one_frequency():
    fam = NormalFamily()
    pr = _prepared(*_record(0))
    why = fam.implausible("hysteretic_damping", {"k": K, "psi": PSI, "p0": P0, "eta": 0.02}, pr)
    assert why is not None and "one frequency" in why


def test_creep_must_settle_within_the_record():
    fam = NormalFamily()
    pr = _prepared(*_record(0))
    base = {"k": K, "psi": PSI, "p0": P0, "D": 1e-8}
    dur = pr.duration
    assert fam.implausible("creep_drift", {**base, "tau_c": 0.5 * dur}, pr) is None
    slow = fam.implausible("creep_drift", {**base, "tau_c": 1.5 * CREEP_MAX_DURATIONS * dur}, pr)
    assert slow is not None and "does not settle" in slow
    # a quarter of the 0.5 s period is the fastest creep told from a start-up step
    assert fam.implausible("creep_drift", {**base, "tau_c": 0.2}, pr) is None
    assert fam.implausible("creep_drift", {**base, "tau_c": 0.1}, pr) is not None
