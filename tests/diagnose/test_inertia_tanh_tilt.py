"""A backbone that is not the exponential Masing one tilts the plateaus as a mass would
(issue 29: a ``tanh`` backbone record at ac·A 4.7, 5 cycles, was named ``inertia`` and not
flagged as a misfit on an independent generator).

A Masing branch of ``h0 (1 - exp(-ac x))`` ends at the rate ``ac/2``; a ``tanh`` backbone's at
another rate, so with the tail's rate held at ``ac/2`` the plateau keeps a slope of the
tail's own (rig ``tanh_virgin`` records: t -25..-38 at the ac a Masing fit takes). A tail of
another rate with no slope fits those plateaus better than the Masing tail with a slope;
a mass's plateaus the other way round (:func:`tail_shape_ratio`).
"""

from __future__ import annotations

import numpy as np
import pytest

from contactlab.synthetic.rig import rig_recording

H0, AC = 40.0, 4.0e4
#: a rig record whose loops reach a plateau: ac·A 4, 12 Hz, 5 cycles from rest, 1 % noise
FAC = {"fs": 2000.0, "f": 12.0, "cycles": 5, "acA": 4.0, "x_noise": 0.01, "F_noise": 0.01}
#: the contact's ac a Masing fit takes on such a tanh record (fitted 49 000-53 000 on rig
#: tanh records at ac·A 2.6-5, tuning seeds 990200-990209)
AC_FIT = 1.3 * AC
STEADY = {-1: 0.01, 0: 0.02, **{c: 1.0 for c in range(1, FAC["cycles"])}}


def _prepared(effects: dict, seed: int, **over):
    from contactlab.diagnose._family import Prepared
    from contactlab.diagnose.candidates_tangential import TangentialFamily

    rec = rig_recording(effects, "tangential", seed=seed, **{**FAC, **over})
    d = Prepared.build(rec.t, rec.channels["x"], rec.channels["F"])
    TangentialFamily().prepare(d)
    return d


def _inertia():
    from contactlab.diagnose.effects import registry

    return registry("tangential")["inertia"]


@pytest.fixture(scope="module")
def tanh_record():
    return _prepared({"tanh_virgin": {}}, seed=31)


@pytest.fixture(scope="module")
def mass_record():
    """The same rig factors with a mass whose force is 6 % of the force amplitude."""
    A = FAC["acA"] / AC
    m = 0.06 * H0 * (1 - np.exp(-FAC["acA"])) / (A * (2 * np.pi * FAC["f"]) ** 2)
    return m, _prepared({"inertia": {"m": m}}, seed=31)


def test_a_tanh_tail_tilts_the_plateau_and_another_tail_explains_it(tanh_record):
    from contactlab.diagnose.effects.tangential.inertia import (
        SHAPE_RATIO,
        TILT_T,
        plateau_tilt,
        tail_shape_ratio,
    )

    k, se, n = plateau_tilt(tanh_record, AC_FIT)
    assert n >= 6 and k < -TILT_T * se  # the misfit's slope, as a mass's would be
    ratio, rate = tail_shape_ratio(tanh_record, AC_FIT)
    assert ratio > SHAPE_RATIO and rate > 0.5


def test_a_tanh_tilt_is_not_a_mass_and_the_reason_says_so(tanh_record):
    from contactlab.diagnose.effects.tangential.inertia import plateau_tilt

    eff = _inertia()
    k, _, _ = plateau_tilt(tanh_record, AC_FIT)
    p = {"m": -k / (2 * np.pi * FAC["f"]) ** 2, "h0": H0, "ac": AC_FIT}
    why = eff.gain_not_its_own(tanh_record, p, STEADY)
    assert why is not None and "a backbone of another shape than the Masing one" in why
    assert not eff.identified_apart(tanh_record, p)


def test_without_the_shape_check_the_tanh_tilt_reads_as_a_mass(tanh_record, monkeypatch):
    import contactlab.diagnose.effects.tangential.inertia as mod

    monkeypatch.setattr(mod, "SHAPE_CHECK", False)
    k, _, _ = mod.plateau_tilt(tanh_record, AC_FIT)
    p = {"m": -k / (2 * np.pi * FAC["f"]) ** 2, "h0": H0, "ac": AC_FIT}
    assert _inertia().gain_not_its_own(tanh_record, p, STEADY) is None
    assert _inertia().identified_apart(tanh_record, p)


def test_a_mass_tilt_is_the_better_explanation_and_stays_its_own(mass_record):
    from contactlab.diagnose.effects.tangential.inertia import SHAPE_RATIO, tail_shape_ratio

    m, d = mass_record
    ratio, _ = tail_shape_ratio(d, AC)
    assert ratio < SHAPE_RATIO
    eff = _inertia()
    p = {"m": m, "h0": H0, "ac": AC}
    assert eff.gain_not_its_own(d, p, STEADY) is None
    assert eff.identified_apart(d, p)
    assert f"squared residual ratio {ratio:.3g}" in eff.argument(d, p)
