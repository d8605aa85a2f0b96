"""Rule 2's large-gain route of the normal family (stop 45): a held-out gain far above the
floor passes at a lower t across the held-out cycles
(:func:`contactlab.diagnose.select._strong_pass`,
:data:`contactlab.diagnose.candidates_normal.STRONG_GAIN`)."""

from __future__ import annotations

import warnings

import pytest

from contactlab.diagnose.candidates_normal import STRONG_GAIN, NormalFamily
from contactlab.diagnose.search import _strong_rule
from contactlab.diagnose.select import _strong_pass


def test_strong_pass_needs_both_the_gain_and_the_consistency():
    factor, zs = STRONG_GAIN
    floor = 0.05
    assert _strong_pass(factor * floor * 1.01, zs + 0.01, floor, STRONG_GAIN)
    assert not _strong_pass(factor * floor * 0.99, zs + 5.0, floor, STRONG_GAIN)
    assert not _strong_pass(factor * floor * 10.0, zs - 0.01, floor, STRONG_GAIN)
    assert not _strong_pass(1.0, 10.0, floor, None)
    assert not _strong_pass(1.0, 10.0, 0.0, STRONG_GAIN)


def test_strong_rule_is_the_normal_familys_only_and_never_above_z():
    class Other:
        pass

    assert _strong_rule(Other(), 3.0) is None
    factor, zs = _strong_rule(NormalFamily(), 3.0)
    assert (factor, zs) == (STRONG_GAIN[0], min(STRONG_GAIN[1], 3.0))
    assert _strong_rule(NormalFamily(), 1.0)[1] == pytest.approx(min(STRONG_GAIN[1], 1.0))
    assert 1.0 < STRONG_GAIN[1] < 3.0 and STRONG_GAIN[0] > 1.0
    fam = NormalFamily()
    for name in ("stiffness_nonlinearity", "creep_drift", "asymmetric_branches"):
        assert _strong_rule(fam, 3.0, (name,)) is not None
    for name in ("channel_delay", "hysteretic_damping"):  # opted out
        assert _strong_rule(fam, 3.0, (name,)) is None
        assert _strong_rule(fam, 3.0, ("creep_drift", name)) is None


def _creep_record(creep: bool):
    """11 cycles at 40 Hz sampled at 1 kHz (25 samples a cycle), 1.5 % displacement noise:
    a creep of 5.6 % of the pressure's displacement amplitude settling over half the record
    (its gain lies in the first and last cycles, so the per-cycle t stays below 3)."""
    import numpy as np

    from contactlab.synthetic.rig import rig_recording

    k, p0 = 1.3e12, 5e5
    pa = 0.5 * p0
    rng = np.random.default_rng(4)  # the draws of the probe that found the record
    rng.choice([20.0, 30.0, 40.0])
    rng.integers(6, 12)
    size = float(rng.uniform(0.03, 0.08)) * pa / k
    tc = float(rng.uniform(0.2, 0.5)) * 11 / 40.0
    eff = {"creep_drift": {"D": size, "tau_c": tc}} if creep else {}
    return rig_recording(eff, "normal", seed=4, fs=1000.0, f=40.0, cycles=11, k=k, psi=0.15,
                         p0=p0, pa=pa, x_noise=0.015, F_noise=0.01,
                         ramp_cycles=1.0)  # fmt: skip


def _names(r):
    import contactlab

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = contactlab.diagnose({"t": r.t, "p": r.channels["p"], "delta": r.channels["delta"]},
                                  "normal")  # fmt: skip
    return res.effect_names


@pytest.mark.slow
def test_a_creep_seen_in_a_few_cycles_is_named_by_the_large_gain_route(monkeypatch):
    """The creep is named; without the route (rule 2 at t > 3 only) it is not, and the
    clean twin names nothing."""
    r = _creep_record(True)
    assert _names(r) == ["creep_drift"]
    assert _names(_creep_record(False)) == []
    monkeypatch.setattr(NormalFamily, "strong_gain", None)
    assert _names(r) == []
