"""A force leading the displacement is not named over a breakaway on the input's noise alone
(issue 29, helper posfric): a rig breakaway of 8 % of h0 (50 Hz, fs 10 kHz, x noise 0.9 %
of the range) was named ``channel_delay`` (τ = -0.16 ms) by a held-out lead of 0.106 σ²
that the input's noise gives a delay over a breakaway."""

from __future__ import annotations

import tempfile
import warnings
from pathlib import Path
from types import SimpleNamespace

import pytest

from contactlab.diagnose.effects import registry


def _hook(tau, gain, rival_gain, budget=0.33, accepted=True, rival="stick_slip"):
    delay = registry("tangential")["channel_delay"]
    v = SimpleNamespace(name="channel_delay", gain=gain, accepted=True, reason="accepted")
    rv = SimpleNamespace(name=rival, gain=rival_gain, accepted=accepted, reason="accepted")
    d = SimpleNamespace(extra={"input_noise_budget": budget})
    return delay.yields_to_tried({"tau": tau}, v, None, {rival: (rv, None)}, None, d)


def test_leading_force_yields_within_the_noise_share():
    why = _hook(-1.6e-4, 0.717, 0.611)
    assert why is not None and "breakaway" in why


@pytest.mark.parametrize(
    "kw",
    [
        {"tau": 1.6e-4, "gain": 0.717, "rival_gain": 0.611},  # a lagging force: no breakaway
        {"tau": -1.6e-4, "gain": 0.9, "rival_gain": 0.611},  # a lead beyond 0.75 of 0.33
        {"tau": -1.6e-4, "gain": 0.717, "rival_gain": 0.611, "accepted": False},
        {"tau": -1.6e-4, "gain": 0.717, "rival_gain": 0.611, "budget": 0.0},
        {"tau": -1.6e-4, "gain": 0.717, "rival_gain": 0.611, "rival": "viscous_damping"},
    ],
)
def test_delay_stands_otherwise(kw):
    assert _hook(**kw) is None


@pytest.mark.slow
def test_rig_breakaway_is_not_named_a_delay():
    import contactlab
    from contactlab.synthetic.rig import rig_recording

    warnings.simplefilter("ignore")
    rec = rig_recording(
        {"stick_slip": {"b": 0.08, "d_c": 10e-6}}, "tangential", seed=49400200, fs=10000.0,
        f=50.0, cycles=35, acA=3.7, h0=40.0, ac=4e4, x_noise=0.018, F_noise=0.009,
        ramp_cycles=0.5,
    )  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp:
        r = contactlab.read_recording(str(rec.to_csv(Path(tmp) / "r.csv")))
    rep = contactlab.diagnose(r, model="tangential")
    assert "channel_delay" not in rep.effect_names
    assert "stick_slip" in rep.effect_names
