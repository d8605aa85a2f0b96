"""A fit whose ``ac`` runs towards a straight line does not fail on a step onto ``ac = 0``.

The Masing element is defined for ``ac > 0`` only. On a short record whose backbone is far
from the exponential one (a gamma-shaped virgin curve, 5 cycles at 1 kHz, seed 474039 of
``benches/eval_misfit_short.py``) a candidate's fit drove ``ac`` to ~1e-4 of its scale, and a
central-difference step of the Jacobian, clipped to the bound of 0, made ``diagnose`` raise
"ac must be finite and > 0, got 0.0" on a valid record. The Jacobian now takes a one-sided
difference where the model refuses a step's end, as the Gauss-Newton polish already stopped
at such a step.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from contactlab.errors import InputError
from contactlab.fitting import Parameter, least_squares_fit

BENCHES = Path(__file__).resolve().parents[2] / "benches"


def test_jacobian_steps_off_a_refused_closed_bound() -> None:
    """A model that refuses its parameter at the closed bound (``a = 0``), fitted where the
    optimum lies within a Jacobian step of it: a one-sided difference, not an error."""
    x = np.linspace(0.0, 1.0, 40)
    y = 1e-9 * x + 1e-12 * np.sin(40 * x)
    calls = {"refused": 0}

    def model(p: dict[str, float]) -> np.ndarray:
        if not p["a"] > 0:
            calls["refused"] += 1
            raise InputError(f"a must be > 0, got {p['a']}")
        return p["a"] * x - y

    res = least_squares_fit(model, [Parameter("a", 1.0, min=0.0)])
    assert calls["refused"] >= 1  # the step to the bound was tried and refused
    assert np.isfinite(res.params["a"].value)
    assert abs(res.params["a"].value - 1e-9) < 1e-10


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
