"""``force_highpass``: a piezo load cell's first-order high-pass (docs/effects.md).

Its filter against independent routes (scipy's first-order-hold discretisation through
``lfilter``; the analytic response of a sine switched on at rest), its plausibility rules,
and the diagnosis on the rig simulator's piezo chain (``F_highpass``), on the package
generator's own high-pass, on a real dashpot and on clean records."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import signal

import contactlab
from contactlab.diagnose._family import Prepared
from contactlab.diagnose.candidates_tangential import TangentialFamily
from contactlab.diagnose.effects import registry
from contactlab.diagnose.effects.tangential.force_highpass import MAX_CORNER_SHARE, highpass
from contactlab.synthetic.diagnosis import hidden_effect_recording
from contactlab.synthetic.rig import rig_recording

FAM = TangentialFamily()


@pytest.mark.parametrize("fc", [0.005, 0.08, 1.5])
def test_filter_matches_scipy_first_order_hold(fc):
    rng = np.random.default_rng(7)
    dt = 1 / 1500.0
    t = np.arange(9000) * dt
    F = np.cumsum(rng.standard_normal(t.size))
    F[0] = 0.0  # from rest: lfilter's zero state is a force of 0 before t[0]
    b, a, _ = signal.cont2discrete(([1.0, 0.0], [1.0, 2 * math.pi * fc]), dt, "foh")
    ref = signal.lfilter(np.ravel(b), np.ravel(a), F)
    np.testing.assert_allclose(highpass(F, t, fc), ref, atol=1e-10 * np.max(np.abs(F)))


def test_filter_follows_the_analytic_response_of_a_sine_on_an_uneven_axis():
    """``sin ωt`` from rest through ``s/(s + a)``: ``y = ω/(ω² + a²) (ω sin ωt + a cos ωt)
    - a ω/(ω² + a²) e^(-a t)``, on a jittered time axis over 600 time constants (several
    blocks of the closed form)."""
    rng = np.random.default_rng(3)
    fc, f = 4.0, 12.0
    a, w = 2 * math.pi * fc, 2 * math.pi * f
    errors = []
    for step in (8e-4, 4e-4):  # exact for a force linear between samples: error O(h²)
        t = np.cumsum(rng.uniform(0.5, 1.5, round(24 / step))) * step
        t -= t[0]
        y = highpass(np.sin(w * t), t, fc)
        exact = w / (w * w + a * a) * (w * np.sin(w * t) + a * np.cos(w * t)) - a * w / (
            w * w + a * a
        ) * np.exp(-a * t)
        assert a * t[-1] > 2 * 300.0  # several blocks
        assert np.max(np.abs(y - np.sin(w * t))) > 0.05  # (the filter did something)
        errors.append(float(np.max(np.abs(y - exact))))
    assert errors[0] < 5e-4
    assert errors[1] < errors[0] / 3


def test_zero_corner_is_the_identity_and_the_mean_is_lost():
    t = np.linspace(0, 200, 20001)
    F = 3.0 + np.sin(2 * np.pi * t)
    np.testing.assert_array_equal(highpass(F, t, 0.0), F)
    y = highpass(F, t, 0.1)  # 126 time constants: the constant has leaked away
    assert abs(np.mean(y[-5000:])) < 1e-3
    assert y[0] == F[0]


def test_candidate_is_the_filter_of_the_base_at_any_samples():
    rec = hidden_effect_recording([], noise=1e-12, seed=11)
    t, x, F = rec.arrays()
    d = Prepared.build(t, x, F)
    FAM.prepare(d)
    p = {"h0": 50.0, "ac": 5e4, "fc": 0.3}
    full = FAM.predict(p, ("force_highpass",), d)
    base = FAM.predict(p, (), d)
    np.testing.assert_allclose(full, highpass(base, d.t - d.t[0], 0.3), atol=1e-12)
    at = np.arange(5, t.size, 7)
    np.testing.assert_allclose(FAM.predict(p, ("force_highpass",), d, at), full[at], atol=1e-12)
    # the sensor's zero (offset, drift) is added after the filter, not leaked by it
    q = {**p, "F0": 2.0}
    both = FAM.predict(q, ("force_highpass", "force_offset"), d)
    np.testing.assert_allclose(both, full + 2.0, atol=1e-9)


def test_plausible_refuses_a_corner_near_the_drive_and_a_reconstructed_force():
    eff = registry("tangential")["force_highpass"]
    rec = hidden_effect_recording([], noise=0.01, seed=11)
    t, x, F = rec.arrays()
    d = Prepared.build(t, x, F)
    FAM.prepare(d)
    f = 1.0 / (d.cycles.period_samples * d.dt)
    ok, why = eff.plausible(d, {"h0": 50.0, "ac": 5e4, "fc": 0.05 * f})
    assert ok, why
    assert "time constant" in why
    ok, why = eff.plausible(d, {"h0": 50.0, "ac": 5e4, "fc": 1.5 * MAX_CORNER_SHARE * f})
    assert not ok and "drive" in why
    d.extra["meta"] = {"same_clock": True}
    ok, why = eff.plausible(d, {"h0": 50.0, "ac": 5e4, "fc": 0.05 * f})
    assert not ok and "load cell" in why


def _rig(seed, fc, f=2.4, cycles=14):
    rec = rig_recording(
        {}, "tangential", seed=seed, fs=3000.0, f=f, cycles=cycles, acA=0.5,
        x_noise=0.004, F_noise=0.01, F_highpass=fc,
    )  # fmt: skip
    return {"t": rec.t, "x": rec.x, "F": rec.F}


@pytest.mark.slow
def test_rig_piezo_high_pass_is_named_with_its_corner():
    """The rig's charge amplifier at 0.1 Hz on a 2.4 Hz drive (only non-ideal part of the
    chain): named, at its corner; without it nothing is named."""
    rep = contactlab.diagnose(_rig(4720001, 0.1), model="tangential")
    assert rep.effect_names == ["force_highpass"]
    assert rep.final_model.params["fc"] == pytest.approx(0.1, rel=0.15)
    clean = contactlab.diagnose(_rig(4720001, None), model="tangential")
    assert clean.effect_names == []


@pytest.mark.slow
def test_a_real_dashpot_is_not_taken_for_a_high_pass():
    rec = hidden_effect_recording(["viscous_damping"], magnitude=0.05, noise=0.01, seed=4720002)
    rep = contactlab.diagnose(rec, model="tangential")
    assert rep.effect_names == ["viscous_damping"]
