"""The displacement sensor's straight drift is carried by the normal-contact base model.

docs/effects.md §3: a slow drift of the displacement sensor belongs to the measurement chain,
not to the joint. Before the base carried it, a straight drift of 2 % of the displacement's
range on a record that starts from rest was named ``hysteretic_damping`` (the frequency-domain
solve draws a slow start-up) or ``creep_drift``.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import contactlab
from contactlab.diagnose._family import Prepared
from contactlab.diagnose.candidates_normal import NormalFamily, kelvin_voigt_exact

F, FS, CYCLES = 2.0, 1000.0, 20
K, PSI, P0, PA = 1.3e12, 0.1, 5e5, 3.5e5


def _record(seed: int, drift_frac: float, creep: float = 0.0):
    """Kelvin-Voigt joint whose pressure amplitude rises from rest, 1 % noise on p and 1.5 %
    on δ (of range), and a straight drift of ``drift_frac`` of δ's range over the record;
    ``creep``: a settling of that fraction of the amplitude with τ_c a quarter of the record."""
    t = np.arange(int(CYCLES * FS / F)) / FS
    om = 2 * np.pi * F
    pd = PA * (1 - np.exp(-t * F * 3)) * np.sin(om * t)
    d = kelvin_voigt_exact(t, pd, K, PSI, om)
    rng = np.random.default_rng(seed)
    p = P0 + pd + rng.normal(0, 0.01 * np.ptp(pd), t.size)
    drift = drift_frac * np.ptp(d)
    dd = d + rng.normal(0, 0.015 * np.ptp(d), t.size) + drift * t / t[-1]
    dd = dd - creep * (PA / K) * np.expm1(-t / (0.25 * t[-1]))
    return t, p, dd, drift


def _diagnose(t, p, d):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return contactlab.diagnose({"t": t, "p": p, "delta": d}, "normal")


def test_predict_adds_the_straight_drift_about_the_record_middle():
    t, p, d, _ = _record(0, 0.0)
    fam = NormalFamily()
    pr = Prepared.build(t, p, d, errors_in_input=False)
    fam.prepare(pr)
    base = {"k": K, "psi": PSI, "p0": P0}
    a = fam.predict({**base, "drift": 0.0}, (), pr)
    b = fam.predict({**base, "drift": 3e-9}, (), pr)
    line = 3e-9 * (t - 0.5 * (t[0] + t[-1])) / pr.duration
    np.testing.assert_allclose(b - a, line, rtol=0, atol=1e-15)
    # a parameter set without the drift (a model fitted before it existed) predicts as 0
    np.testing.assert_array_equal(fam.predict(base, (), pr), a)


@pytest.mark.parametrize("seed", [2])
def test_a_straight_sensor_drift_names_nothing_and_is_recovered(seed):
    t, p, d, drift = _record(seed, 0.02)
    r = _diagnose(t, p, d)
    assert r.effect_names == []
    assert not r.to_dict()["unexplained"]["flagged"]
    fitted = r.to_dict()["final_model"]["parameters"]["drift"]
    # over the record the line moves drift·(1 - 0) of the end-to-end change
    assert fitted == pytest.approx(drift, rel=0.1)


def test_creep_beside_a_sensor_drift_is_still_named():
    t, p, d, _ = _record(3, 0.02, creep=0.1)
    r = _diagnose(t, p, d)
    assert r.effect_names == ["creep_drift"]
