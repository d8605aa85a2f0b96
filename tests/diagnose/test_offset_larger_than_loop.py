"""A sensor zero larger than the loop it sits on is a force offset, not "no friction loop".

A pre-sliding loop (ac·A 0.39: ±1.6 N on h0 = 4.9 N) offset by -1.46 N from rest, with
1.95 % noise on x and 1.06 % on F, was refused: the Masing curve through the origin explains
0 % of the force's variance about its mean, and the check said "unrelated or swapped
channels". The same curve beside a constant explains it; the constant is the force offset.
"""

from __future__ import annotations

import numpy as np
import pytest

import contactlab
from contactlab.errors import InputError
from contactlab.masing import Masing

H0, F0 = 4.89, -1.456


def _record(offset: float, seed: int = 5):
    f, fs, n = 43.2, 2000.0, 35
    A = 1e-5
    t = np.arange(int(n * fs / f)) / fs
    x = A * np.minimum(1.0, t * f) * np.sin(2 * np.pi * f * t)  # from rest, one-cycle ramp
    F = Masing(H0, 0.387 / A).force(x) + offset
    rng = np.random.default_rng(seed)
    xm = x + rng.normal(0.0, 0.0195 * np.ptp(x), x.size)
    Fm = F + rng.normal(0.0, 0.0106 * np.ptp(F), F.size)
    return {"t": t, "x": xm, "F": Fm}


def test_an_offset_larger_than_the_loop_is_named_not_refused():
    rep = contactlab.diagnose(_record(F0))
    assert [e.name for e in rep.effects] == ["force_offset"]
    assert rep.effects[0].parameters["F0"] == pytest.approx(F0, abs=0.05)


def test_a_force_unrelated_to_the_displacement_is_still_refused():
    rec = _record(F0)
    rec["F"] = F0 + np.random.default_rng(2).normal(0.0, 1.0, rec["F"].size)
    with pytest.raises(InputError, match="force does not follow the displacement"):
        contactlab.diagnose(rec)
