"""Errors in variables in the misfit test and its stated power (issue 29, items 1 and 3).

- :func:`contactlab.diagnose.misfit.eiv_bias`: the structure the input's noise alone leaves
  in a fitted Masing model's residual, simulated; taking it out lowers the phase-binned
  statistic of a clean record with 2 % input noise near gross sliding.
- :func:`contactlab.diagnose.misfit.detectable_rms`: the stated power; a phase-locked misfit
  of 1.5 times the bound is flagged nearly always, of half the bound seldom.
"""

from __future__ import annotations

import numpy as np

from contactlab.diagnose._family import Prepared
from contactlab.diagnose.misfit import (
    _branch_of,
    detectable_rms,
    eiv_bias,
    unexplained_structure,
)
from contactlab.diagnose.workflow import diagnose
from contactlab.masing import Masing

A = 1e-5


def _clean(acA: float, x_noise: float, seed: int, cycles: int = 20):
    fs, f0 = 2000.0, 5.0
    t = np.arange(round((cycles + 1.5) * fs / f0)) / fs
    x = A * np.sin(2 * np.pi * f0 * t) * np.minimum(t * f0, 1.0)
    F = Masing(50.0, acA / A).force(x)
    rng = np.random.default_rng(seed)
    xm = x + rng.normal(0.0, x_noise * np.ptp(x), x.size)
    Fm = F + rng.normal(0.0, 0.005 * np.ptp(F), F.size)
    return t, xm, Fm


def test_eiv_bias_takes_out_the_input_noise_structure():
    """Clean record, input noise 2 % of the range, ac·A 4: without a tolerance the phase
    bins see the noise's bias (turning points pushed outward); with the simulated bias taken
    out the statistic falls by more than half, and the report says it was simulated."""
    rep = diagnose(_clean(4.0, 0.02, 11), model="tangential")
    assert rep.effect_names == []
    u = rep.unexplained
    assert u is not None and u.eiv_bias_rms is not None and u.eiv_bias_rms > 0
    assert u.to_dict()["eiv_bias_rms"] == u.eiv_bias_rms
    fam, p, eff = rep.final_model.family, rep.final_model.params, rep.final_model.effects
    d = rep.prepared
    residual = d.y - fam.predict(p, eff, d)
    bias = eiv_bias(fam, p, eff, d)
    assert bias is not None and bias.shape == residual.shape
    raw = unexplained_structure(d, residual, rep.noise_rms)
    fixed = unexplained_structure(d, residual - bias, rep.noise_rms)
    assert raw is not None and fixed is not None
    assert fixed.statistic < 0.5 * raw.statistic, (raw.statistic, fixed.statistic)


def test_eiv_bias_none_without_input_noise():
    t, x, F = _clean(2.0, 0.0, 1, cycles=8)
    x = A * np.sin(2 * np.pi * 5.0 * t) * np.minimum(t * 5.0, 1.0)  # noise-free input
    rep = diagnose((t, x, F), model="tangential")
    assert rep.unexplained is not None and rep.unexplained.eiv_bias_rms is None
    m = rep.final_model
    assert eiv_bias(m.family, m.params, m.effects, rep.prepared) is None


def _sine_record(cycles: int) -> Prepared:
    t = np.arange(cycles * 200) / 200.0
    return Prepared.build(t, np.sin(2 * np.pi * t), np.zeros(t.size))


def test_stated_power_is_checked_by_simulation():
    """A phase-locked misfit (one sine period per branch, opposite on the two branches) of
    1.5 times the stated bound is flagged in at least 19 of 20 noise draws, of half the bound
    in at most 8; the bound grows in proportion to the noise."""
    d = _sine_record(30)
    rng = np.random.default_rng(5)
    u = unexplained_structure(d, rng.normal(0.0, 0.01, d.t.size), 0.01)
    assert u is not None and u.detectable_rms is not None
    a = u.detectable_rms
    assert "would be flagged" in u.sentence() and u.to_dict()["detectable_rms"] == a
    br = _branch_of(d)
    shape = np.sqrt(2.0) * np.sin(2 * np.pi * d.cycles.phase_in_branch)
    shape = np.where(br == 1, -shape, shape)
    hits = {}
    for k in (0.5, 1.5):
        hits[k] = sum(
            unexplained_structure(d, rng.normal(0.0, 0.01, d.t.size) + k * a * shape, 0.01).flagged
            for _ in range(20)
        )
    assert hits[1.5] >= 19 and hits[0.5] <= 8, hits
    u2 = unexplained_structure(d, rng.normal(0.0, 0.02, d.t.size), 0.02)
    assert u2 is not None and 1.6 < u2.detectable_rms / a < 2.5


def test_detectable_rms_grows_with_the_tolerance():
    se = np.full(20, 0.1)
    a0 = detectable_rms(se, np.zeros(20), 30, 40.0)
    a1 = detectable_rms(se, np.full(20, 0.2), 30, 40.0)
    assert a0 is not None and a1 is not None
    assert abs(a1 - a0 - 0.2) < 0.02  # the interval null adds its width
    assert detectable_rms(np.full(3, np.nan), np.zeros(3), 30, 40.0) is None


def test_series_compliance_absorbing_a_tanh_virgin_curve_is_not_named():
    """A tanh virgin curve (no candidate draws it) at ac·A 2, 20 cycles, input noise 0.5 %:
    series compliance takes up most of it, the structure left is flagged, so series
    compliance is withdrawn (its own signature test failed) and the report says why."""
    from contactlab.diagnose.scaled_masing import memory, scaled_force

    fs, f0, cycles = 2000.0, 5.0, 20
    t = np.arange(round((cycles + 1.5) * fs / f0)) / fs
    x = A * np.sin(2 * np.pi * f0 * t) * np.minimum(t * f0, 1.0)
    F = scaled_force(lambda s: 50.0 * np.tanh(2.0 / A * s), 2.0, memory(x))
    rng = np.random.default_rng(2)
    xm = x + rng.normal(0.0, 0.005 * np.ptp(x), x.size)
    Fm = F + rng.normal(0.0, 0.01 * np.ptp(F), F.size)
    rep = diagnose((t, xm, Fm), model="tangential")
    u = rep.unexplained
    assert u is not None and u.flagged
    assert "series_compliance" in u.absorbing and "series_compliance" not in rep.effect_names
    assert rep.location["withdrawn"] == list(u.absorbing)
    assert "is not named" in u.sentence() and u.to_dict()["absorbing"] == list(u.absorbing)
