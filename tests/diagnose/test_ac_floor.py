"""A fit whose ``ac`` runs towards a straight line never steps onto ``ac = 0``.

The Masing element is defined for ``ac > 0`` only. On a short record whose backbone is far
from the exponential one (a gamma-shaped virgin curve, 5 cycles at 1 kHz, seed 474039 of
``benches/eval_misfit_short.py``) a candidate's fit drove ``ac`` to ~1e-4 of its scale, and a
central-difference step of the Jacobian, clipped to the bound of 0, made ``diagnose`` raise
"ac must be finite and > 0, got 0.0" on a valid record.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from contactlab.diagnose.candidates_tangential import AC_MIN, BASE_PARAMS, TangentialFamily
from contactlab.masing import Masing

BENCHES = Path(__file__).resolve().parents[2] / "benches"


def test_ac_bounds_are_positive_and_valid_for_masing() -> None:
    ac = {p.name: p for p in BASE_PARAMS}["ac"]
    assert ac.lower > 0
    fam = TangentialFamily()
    fam.h0_band = (1.0, 2.0)  # the anchored base: its ac floor is still positive
    assert {p.name: p for p in fam.base_params}["ac"].lower >= AC_MIN > 0
    F = Masing(1.0, AC_MIN).force(np.linspace(0.0, 1e-3, 11))
    assert np.all(np.isfinite(F))


def test_short_gamma_record_is_diagnosed() -> None:
    sys.path.insert(0, str(BENCHES))
    try:
        from eval_misfit_short import record
    finally:
        sys.path.remove(str(BENCHES))
    from contactlab.diagnose.workflow import diagnose

    rec, fac = record(474039, "gamma")
    assert fac["virgin"] == "gamma" and fac["cycles"] == 5
    rep = diagnose(rec, model="tangential")  # raised InputError before
    assert isinstance(rep.effect_names, (list, tuple))
