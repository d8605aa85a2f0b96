"""A normal load off the drive's harmonics beats only the share of the input-noise budget
it can take (``NormalLoad.input_noise_share_at``, ``search._noise_floor`` with the fitted
parameters): a factor in time at a frequency no harmonic comes near cannot take what a noisy
input leaves locked to the cycle; at a harmonic it beats all of it, as before."""

from __future__ import annotations

import numpy as np
import pytest

from contactlab.diagnose._family import Prepared
from contactlab.diagnose.candidates_tangential import TangentialFamily
from contactlab.diagnose.effects import registry
from contactlab.diagnose.effects.tangential.normal_load import OFF_HARMONIC_SHARE
from contactlab.diagnose.search import _noise_floor
from contactlab.synthetic.diagnosis import hidden_effect_recording
from contactlab.synthetic.rig import rig_recording


@pytest.fixture(autouse=True)
def _off_harmonic_rules_on(monkeypatch):
    """The rules are off by default since stop 46 (``OFF_HARMONIC_RULES``); these tests
    measure them switched on."""
    from contactlab.diagnose.effects.tangential import normal_load

    monkeypatch.setattr(normal_load, "OFF_HARMONIC_RULES", True)


def _rig(seed: int = 4242, loads: tuple[float, ...] = ()) -> Prepared:
    """A rig record at 10 Hz; ``loads``: frequencies of 1.5 % loads it carries (the reduced
    floors apply only where the force shows the load: ``off_harmonic_evidence``)."""
    rec = rig_recording(
        {}, "tangential", seed=seed, fs=2000.0, f=10.0, cycles=20, acA=2.0,
        x_noise=0.01, F_noise=0.01,
    )  # fmt: skip
    if loads:
        t0 = rec.t - rec.t[0]
        g = 1.0 + sum(0.015 * np.cos(2 * np.pi * f * t0 + 0.3) for f in loads)
        d = Prepared.build(rec.t, rec.x, rec.F * g)
        TangentialFamily().prepare(d)
        return d
    d = Prepared.build(rec.t, rec.x, rec.F)
    TangentialFamily().prepare(d)
    return d


def test_a_load_at_a_harmonic_beats_the_whole_budget_off_it_almost_none() -> None:
    fam = TangentialFamily()
    eff = registry("tangential")["normal_load"]
    T = _rig().duration
    d = _rig(loads=(20.0 + 3.0 / T, 15.0, 15.0 + 0.25 / T))
    f = 1.0 / (d.cycles.period_samples * d.dt)
    assert eff.input_noise_share_at(d, {"f_n": 2.0 * f}) == 1.0
    assert eff.input_noise_share_at(d, {"f_n": 2.0 * f + 0.5 / T}) == 1.0  # one bin
    off = eff.input_noise_share_at(d, {"f_n": 2.0 * f + 3.0 / T})
    assert 0.0 <= off <= OFF_HARMONIC_SHARE
    # between harmonics: nothing of a cycle-locked pattern
    assert eff.input_noise_share_at(d, {"f_n": 1.5 * f}) < 0.01
    p = {"f_n": 1.5 * f + 0.25 / T}
    assert _noise_floor(fam, ("normal_load",), 0.4, d, p) < 0.4 * OFF_HARMONIC_SHARE + 1e-12
    assert _noise_floor(fam, ("normal_load",), 0.4, d, {"f_n": 3.0 * f}) == pytest.approx(0.4)
    # without the fitted parameters (the stated bound's floor), the whole budget
    assert _noise_floor(fam, ("normal_load",), 0.4) == pytest.approx(0.4)
    # a pair beats the larger of its shares
    assert _noise_floor(fam, ("normal_load", "viscous_damping"), 0.4, d, p) == pytest.approx(0.4)


def test_on_a_drive_in_blocks_the_whole_budget() -> None:
    """A drive in blocks of several frequencies has harmonics of each block's own: no
    exemption there."""
    eff = registry("tangential")["normal_load"]
    rec = hidden_effect_recording(
        [], seed=4243, cycles_per_block=6, samples_per_cycle=100, input_noise=0.01
    )
    t, x, F = rec.arrays()
    d = Prepared.build(t, x, F)
    TangentialFamily().prepare(d)
    f = 1.0 / (d.cycles.period_samples * d.dt)
    assert eff.input_noise_share_at(d, {"f_n": 1.5 * f}) is None
    fam = TangentialFamily()
    assert _noise_floor(fam, ("normal_load",), 0.4, d, {"f_n": 1.5 * f}) == pytest.approx(0.4)


def test_the_drive_frequency_is_read_from_the_reversals() -> None:
    """One cycle's length in samples is too coarse to call a third harmonic locked (0.75 %
    off over 50 cycles is a bin or more); the reversals over the record are not."""
    from contactlab.diagnose.effects.tangential.normal_load import drive_frequency, harmonic_offset

    d = _rig()
    assert drive_frequency(d) == pytest.approx(10.0, rel=2e-3)
    for k in (1, 2, 3, 5):
        assert harmonic_offset(d, 10.0 * k) < 0.3


def test_the_start_prefers_a_load_that_clears_its_floors_off_the_harmonics() -> None:
    """A residual with a larger pair at 2f (which must beat the whole budget) and a smaller
    one between harmonics (which beats a share of it): with a large budget the start is the
    latter; with none, the largest gain, as before."""
    fam = TangentialFamily()
    eff = registry("tangential")["normal_load"]
    f = 10.0
    f_off = 2.0 * f + 3.5 / _rig().duration
    d = _rig(loads=(f_off,))
    p = fam.initial_base(d)
    h = fam.predict(p, (), d)
    t = d.t - d.t[0]
    r = h * (0.05 * np.cos(2 * np.pi * 2 * f * t) + 0.03 * np.cos(2 * np.pi * f_off * t))
    sigma = float(np.std(r)) * 0.5
    d.extra["weight"] = None
    d.extra["gain_rules"] = {"min_gain": 0.05, "budget": 50.0, "sigma": sigma}
    start = eff.start(p, d, r, family=fam)
    assert abs(start["f_n"] - f_off) * d.duration < 0.5
    d.extra["gain_rules"] = {"min_gain": 0.05, "budget": 0.0, "sigma": sigma}
    start = eff.start(p, d, r, family=fam)
    assert abs(start["f_n"] - 2 * f) * d.duration < 0.5


def test_a_short_record_keeps_the_whole_budget() -> None:
    """Below MIN_OFF_CYCLES complete cycles a frequency bin is too wide to tell a load off
    the harmonics: the whole budget and ``min_gain``, as before."""
    from contactlab.diagnose.effects.tangential.normal_load import MIN_OFF_CYCLES

    rec = rig_recording(
        {}, "tangential", seed=4244, fs=2000.0, f=10.0, cycles=MIN_OFF_CYCLES - 3, acA=2.0,
        x_noise=0.01, F_noise=0.01,
    )  # fmt: skip
    d = Prepared.build(rec.t, rec.x, rec.F)
    TangentialFamily().prepare(d)
    eff = registry("tangential")["normal_load"]
    assert eff.input_noise_share_at(d, {"f_n": 15.0}) is None
    assert eff.gain_floor_scale_at(d, {"f_n": 15.0}) is None
    assert _noise_floor(TangentialFamily(), ("normal_load",), 0.4, d, {"f_n": 15.0}) == 0.4


def test_off_by_default_a_load_beats_the_whole_budget(monkeypatch) -> None:
    from contactlab.diagnose.effects.tangential import normal_load

    monkeypatch.setattr(normal_load, "OFF_HARMONIC_RULES", False)
    eff = registry("tangential")["normal_load"]
    d = _rig()
    f = 1.0 / (d.cycles.period_samples * d.dt)
    assert eff.input_noise_share_at(d, {"f_n": 2.0 * f + 3.5 / d.duration}) is None
    assert eff.gain_floor_scale_at(d, {"f_n": 2.0 * f + 3.5 / d.duration}) is None
