"""A speed-strengthening Stribeck term (s < 0) yields to a dashpot tried at the same step
with at least DASHPOT_SHARE of its held-out gain, accepted or not (issue 29, stop 50: blind
dashpots below their stated bound named ``stribeck`` with ``stick_slip``, the two on their
reduced floors); a weakening term (s > 0), a dashpot behind it, or one refused as
implausible leave it standing."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from contactlab.diagnose.effects import registry
from contactlab.diagnose.effects.tangential.stribeck import DASHPOT_SHARE
from contactlab.diagnose.select import Verdict


def _case(s: float, dashpot_gain: float, reason: str = "held-out gain 0.4 σ² below 0.5 σ²"):
    n = 200
    d = SimpleNamespace(y=np.zeros(n), extra={})
    trial = SimpleNamespace(prediction=np.zeros(n), full=SimpleNamespace(params={}))
    v = Verdict("stribeck", 1.0, 1.0, 5.0, -20.0, True, "accepted")
    rv = Verdict("viscous_damping", 1.0, dashpot_gain, 4.0, -15.0, False, reason)
    p = {"h0": 40.0, "ac": 4e4, "s": s, "v_s": 0.01}
    return p, v, trial, {"viscous_damping": (rv, trial)}, d


def test_a_strengthening_term_yields_to_a_dashpot_below_its_floors():
    eff = registry("tangential")["stribeck"]
    p, v, cand, tried, d = _case(-0.04, DASHPOT_SHARE + 0.01)
    why = eff.yields_to_tried(p, v, cand, tried, cand, d)
    assert why and "viscous_damping" in why, why


@pytest.mark.parametrize(
    "s, gain, reason",
    [
        (0.1, 1.5, "held-out gain below"),  # a weakening term: a breakaway, not c ẋ
        (-0.04, DASHPOT_SHARE - 0.01, "held-out gain below"),  # the dashpot well behind
        (-0.04, 1.5, "implausible: it takes over the base model"),
    ],
)
def test_a_term_the_dashpot_does_not_draw_stands(s, gain, reason):
    eff = registry("tangential")["stribeck"]
    p, v, cand, tried, d = _case(s, gain, reason)
    assert eff.yields_to_tried(p, v, cand, tried, cand, d) is None
    assert eff.yields_to_tried(p, v, cand, {}, cand, d) is None
