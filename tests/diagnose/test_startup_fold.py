"""The start-up (before the input's first maximum) is a held-out unit (issue 29).

A record from rest loads the contact along its virgin curve before the first maximum of x;
a displacement offset, a drift's first state and a mass on a shaker's start show mostly
there. The folds hold it out as a unit of its own (in the last fold, as cycle -1 would
be), and the stated power models the same units.
"""

from __future__ import annotations

import numpy as np
import pytest

import contactlab
from contactlab.diagnose import select
from contactlab.diagnose.power import stated_power
from contactlab.diagnose.select import fold_masks, heldout_unit, startup_mask, unit_fold
from contactlab.synthetic.diagnosis import hidden_effect_recording


@pytest.fixture(scope="module")
def report():
    rec = hidden_effect_recording([], seed=11, input_noise=0.005, noise=0.01)
    return contactlab.diagnose(rec, max_effects=0)


def test_the_startup_is_held_out_in_the_last_fold(report) -> None:
    d = report.prepared
    start = startup_mask(d)
    first = int(d.cycles.reversals[d.cycles.is_max][0])
    edge = int(np.ceil(select.STARTUP_EDGE * float(d.cycles.period_samples)))
    # every sample before the first maximum of x but the first ones (one-sided derivatives)
    assert 0 < edge < first and start.sum() == first - edge
    assert not start[:edge].any() and start[edge:first].all()
    unit = heldout_unit(d)
    assert np.all(unit[start] == 0)
    assert np.array_equal(unit[~start] >= 1, d.cycles.cycle[~start] >= 0)
    masks = fold_masks(d, 2)
    assert np.all(masks[1][start]) and not np.any(masks[0][start])
    for k, m in enumerate(masks):  # cycle c in fold c mod 2, as before
        cyc = d.cycles.cycle[m & ~start]
        assert np.all(cyc % 2 == k)
    tail = (d.cycles.cycle < 0) & ~start  # the incomplete last cycle: in no fold
    assert not np.any((masks[0] | masks[1])[tail])
    trial = report.trials[-1]
    assert np.all(trial.heldout[start])
    assert trial.cycle_mse.size == d.cycles.n_cycles + 1  # the start-up is a unit
    assert np.array_equal(unit_fold(np.array([-1, 0, 1, 2, 3]), 2), [-1, 1, 0, 1, 0])


def test_without_the_family_switch_the_startup_is_in_no_fold(report) -> None:
    d = report.prepared
    keep = d.extra["heldout_startup"]
    try:
        d.extra["heldout_startup"] = False
        assert not np.any(heldout_unit(d) == 0)
        held = fold_masks(d, 2)[0] | fold_masks(d, 2)[1]
        assert np.array_equal(held, d.cycles.cycle >= 0)
    finally:
        d.extra["heldout_startup"] = keep


def test_the_offset_bound_uses_the_startup(report) -> None:
    # most of a displacement offset's information lies on the virgin curve: with the
    # start-up held out the stated bound is lower than with it left out of the folds
    d = report.prepared

    def bound() -> float:
        b = {x.effect: x for x in stated_power(report, seed=3)}["displacement_offset"]
        assert b.detectable_above is not None, b.reason
        return float(b.detectable_above)

    with_start = bound()
    keep = d.extra["heldout_startup"]
    try:
        d.extra["heldout_startup"] = False
        without = bound()
    finally:
        d.extra["heldout_startup"] = keep
    assert with_start < 0.9 * without  # (0.83 on this record)


def test_a_record_cut_from_a_running_test_has_no_startup_unit() -> None:
    # from rest both channels start at the centre of the first cycles' range; a record cut
    # from a running test starts elsewhere on its loop, which the model from rest does not
    # hold: its start-up stays out of the folds (as the measured records of ../shared/data)
    from contactlab.diagnose._family import Prepared
    from contactlab.masing import Masing

    t = np.arange(6000) / 1000.0
    rng = np.random.default_rng(4)
    units = {}
    for label, lead in (("rest", 0.0), ("cut", 2.2)):
        x = 1e-3 * np.sin(2 * np.pi * 2.0 * t + lead) + rng.normal(0, 1e-5, t.size)
        full = np.r_[1e-3 * np.sin(2 * np.pi * 2.0 * np.arange(-2000, 0) / 1000.0 + lead), x]
        f = Masing(40.0, 4e3).force(full if label == "cut" else x)[-t.size :]
        d = Prepared.build(t, x, f + rng.normal(0, 0.2, t.size))
        d.extra["heldout_startup"] = True
        units[label] = heldout_unit(d)
    assert np.any(units["rest"] == 0)
    assert not np.any(units["cut"] == 0)
