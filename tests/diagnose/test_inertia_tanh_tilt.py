"""A backbone that is not the exponential Masing one tilts the plateaus as a mass would
(issue 29: a ``tanh`` backbone record at ac·A 4.7, 5 cycles, was named ``inertia`` and not
flagged as a misfit on an independent generator).

A Masing branch of ``h0 (1 - exp(-ac x))`` ends at the rate ``ac/2``; a ``tanh`` backbone's at
another rate, so with the tail's rate held at ``ac/2`` the plateau keeps a slope of the
tail's own (on the rig's ``tanh_virgin`` records, tuning seeds 990200-990209: t -11..-45 at
the ac a Masing fit takes). With the rate free most of that slope is gone, but a mass's
``-mω² x`` is taken by a slightly faster tail on some records too, so the free rate is a
rule only with ``FREE_TAIL_CHECK`` (off by default) and otherwise stated in the argument.
"""

from __future__ import annotations

import numpy as np
import pytest

from contactlab.synthetic.rig import rig_recording

H0, AC = 40.0, 4.0e4
#: a rig record whose loops reach a plateau: ac·A 4, 12 Hz, 5 cycles from rest, 1 % noise
FAC = {"fs": 2000.0, "f": 12.0, "cycles": 5, "acA": 4.0, "x_noise": 0.01, "F_noise": 0.01}
#: the contact's ac a Masing fit takes on such a tanh record (fitted 49 000-53 000 on the rig
#: records of the tuning seeds above)
AC_FIT = 1.3 * AC


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


def test_a_tanh_backbone_tilts_the_plateau_with_the_masing_tail_only(tanh_record):
    """With the tail's rate free the slope keeps less than half of what it read with the
    Masing tail (a mass's -mω² keeps all of it, and a mass must reach half of it)."""
    from contactlab.diagnose.effects.tangential.inertia import (
        TILT_AGREE,
        TILT_T,
        plateau_tilt,
        plateau_tilt_free,
    )

    k, se, n = plateau_tilt(tanh_record, AC_FIT)
    assert n >= 6 and k < -TILT_T * se  # the misfit's slope, as a mass's would be
    kf, _, nf = plateau_tilt_free(tanh_record, AC_FIT)
    assert nf >= 6 and kf > TILT_AGREE * k


def test_with_the_free_tail_check_a_tanh_tilt_is_not_a_mass(tanh_record, monkeypatch):
    import contactlab.diagnose.effects.tangential.inertia as mod
    from contactlab.diagnose.effects.tangential.inertia import plateau_tilt

    monkeypatch.setattr(mod, "FREE_TAIL_CHECK", True)
    eff = _inertia()
    k, _, _ = plateau_tilt(tanh_record, AC_FIT)
    w2 = (2 * np.pi * FAC["f"]) ** 2
    p = {"m": -k / w2, "h0": H0, "ac": AC_FIT}
    steady = {-1: 0.01, 0: 0.02, **{c: 1.0 for c in range(1, FAC["cycles"])}}
    why = eff.gain_not_its_own(tanh_record, p, steady)
    assert why is not None and "another backbone's shape" in why
    assert not eff.identified_apart(tanh_record, p)


def test_a_mass_on_the_plateau_still_shows_with_the_tail_free(monkeypatch):
    """The same rig factors with a mass whose force is 6 % of the force amplitude instead of
    the tanh backbone: here the tilt holds with the tail's rate free, and the mass is its own
    with the check on; its argument gives both slopes."""
    import contactlab.diagnose.effects.tangential.inertia as mod
    from contactlab.diagnose.effects.tangential.inertia import (
        TILT_AGREE,
        TILT_T,
        plateau_tilt_free,
    )

    A = FAC["acA"] / AC
    w2 = (2 * np.pi * FAC["f"]) ** 2
    m = 0.06 * H0 * (1 - np.exp(-FAC["acA"])) / (A * w2)
    d = _prepared({"inertia": {"m": m}}, seed=31)
    kf, sef, nf = plateau_tilt_free(d, AC)
    assert nf >= 6 and kf < -TILT_T * sef and kf < -TILT_AGREE * m * w2
    eff = _inertia()
    steady = {-1: 0.01, 0: 0.02, **{c: 1.0 for c in range(1, FAC["cycles"])}}
    monkeypatch.setattr(mod, "FREE_TAIL_CHECK", True)
    assert eff.gain_not_its_own(d, {"m": m, "h0": H0, "ac": AC}, steady) is None
    text = eff.argument(d, {"m": m, "h0": H0, "ac": AC})
    assert f"{kf:.3g} ± {sef:.2g} N/m" in text and "such as a tanh" in text


def test_without_the_free_tail_check_the_tanh_tilt_reads_as_a_mass(tanh_record):
    """The default: on one amplitude the tilt cannot tell the two apart (the free rate takes
    a mass's slope as well), so the Masing tail's tilt decides, and a tanh passes it."""
    from contactlab.diagnose.effects.tangential.inertia import plateau_tilt

    k, _, _ = plateau_tilt(tanh_record, AC_FIT)
    w2 = (2 * np.pi * FAC["f"]) ** 2
    p = {"m": -k / w2, "h0": H0, "ac": AC_FIT}
    assert _inertia().identified_apart(tanh_record, p)
