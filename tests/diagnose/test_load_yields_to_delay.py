"""A normal load locked to the drive at 2f yields to a channel delay accepted at the same
step with most of its held-out gain (issue 29, helper delay, stop 48): on plateau-dominated
loops a delay's shift of the force at both reversals of every cycle was named a 2f
``normal_load``."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from contactlab.diagnose.effects import registry
from contactlab.diagnose.effects.tangential.normal_load import DELAY_SHARE
from contactlab.diagnose.select import Verdict

LOAD = {"eps_c": 0.02, "eps_s": -0.02, "f_n": 40.0}


def _trial(pred: np.ndarray, tau: float | None = None) -> SimpleNamespace:
    full = SimpleNamespace(params={} if tau is None else {"tau": tau})
    return SimpleNamespace(prediction=pred, heldout=np.ones(pred.size, bool), full=full)


def _case(delay_gain: float, accepted: bool = True):
    rng = np.random.default_rng(0)
    n = 400
    d = SimpleNamespace(y=rng.standard_normal(n), extra={})
    current = _trial(np.zeros(n))
    load = _trial(0.1 * rng.standard_normal(n))
    delay = _trial(0.1 * rng.standard_normal(n), tau=4e-4)
    v = Verdict("normal_load", 1.0, 1.0, 10.0, -100.0, True, "accepted")
    why = "accepted" if accepted else "held-out gain below"
    rv = Verdict("channel_delay", 1.0, delay_gain, 10.0, -90.0, accepted, why)
    return d, current, load, v, {"channel_delay": (rv, delay)}


def test_a_load_yields_to_an_accepted_delay_with_most_of_its_gain():
    eff = registry("tangential")["normal_load"]
    d, current, load, v, tried = _case(delay_gain=DELAY_SHARE + 0.01)
    why = eff.yields_to_delay(LOAD, v, load, tried, current, d)
    assert why and "channel delay of 0.4 ms" in why


@pytest.mark.parametrize("gain, accepted", [(DELAY_SHARE - 0.01, True), (0.95, False)])
def test_a_load_well_ahead_of_the_delay_or_beside_a_refused_one_stands(gain, accepted):
    eff = registry("tangential")["normal_load"]
    d, current, load, v, tried = _case(delay_gain=gain, accepted=accepted)
    assert eff.yields_to_delay(LOAD, v, load, tried, current, d) is None
    assert eff.yields_to_delay(LOAD, v, load, {}, current, d) is None


@pytest.mark.slow
def test_a_rig_delay_on_a_plateau_loop_is_named_not_a_2f_load():
    """Rig, seed 48200011 of benches/eval_delay_plateau.py --kinds delay (0.60 ms at
    5.4 Hz, 6 cycles, ac·A 3.26, x noise 1.76 % of the range): with the rule off a 2f load
    was named (held-out gain 0.473 σ², the delay accepted at 0.456 σ²)."""
    import contactlab
    from contactlab.synthetic.rig import rig_recording

    rec = rig_recording(
        {"channel_delay": {"tau": 6.0071e-4}}, "tangential", seed=48200011, fs=10000.0,
        f=5.415, cycles=6, acA=3.258, h0=40.0, ac=4.0e4, x_noise=0.0352, F_noise=0.0154,
        ramp_cycles=0.0, hum=0.00182, bits=16,
    )  # fmt: skip
    rep = contactlab.diagnose((rec.t, rec.x, rec.F), model="tangential")
    assert "normal_load" not in rep.effect_names
    assert "channel_delay" in rep.effect_names


@pytest.mark.parametrize("tau", [-4e-4, 3e-3])
def test_a_load_does_not_yield_to_a_leading_force_or_a_delay_beyond_a_skew(tau):
    eff = registry("tangential")["normal_load"]
    d, current, load, v, tried = _case(delay_gain=0.95)
    tried["channel_delay"][1].full.params["tau"] = tau
    assert eff.yields_to_delay(LOAD, v, load, tried, current, d) is None
