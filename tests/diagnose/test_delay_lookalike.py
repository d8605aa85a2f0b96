"""A play yields to a channel delay within the input-noise budget; a delay's start takes the
base back from a delayed loop; a delay may move the base's anchor (issue 29)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from contactlab.diagnose.effects import registry


def _d(budget: float) -> SimpleNamespace:
    return SimpleNamespace(extra={"input_noise_budget": budget})


@settings(max_examples=80, deadline=None)
@given(
    own=st.floats(0.01, 100.0),
    lead=st.floats(-5.0, 5.0),
    budget=st.floats(0.0, 3.0),
)
def test_a_play_yields_to_a_delay_only_within_the_input_noise_budget(own, lead, budget):
    eff = registry("tangential")["backlash"]
    rival = own - lead
    why = eff.yields_to({"b": 1e-6}, {"backlash": own, "channel_delay": rival}, own, _d(budget))
    assert bool(why) == (budget > 0 and own - rival < budget)
    if why:
        assert "channel_delay" in why


def test_a_play_without_a_delay_or_a_budget_stands():
    eff = registry("tangential")["backlash"]
    assert eff.yields_to({"b": 1e-6}, {"backlash": 2.0}, 2.0, _d(1.0)) is None
    assert eff.yields_to({"b": 1e-6}, {"channel_delay": np.nan}, 2.0, _d(1.0)) is None
    assert eff.yields_to({"b": 1e-6}, {"channel_delay": 1.9}, 2.0, None) is None
    assert eff.yields_to({"b": 1e-6}, {"channel_delay": 1.9}, 2.0, _d(0.0)) is None


def test_a_delay_may_move_the_anchor_other_effects_may_not():
    from contactlab.diagnose.search import _takes_over

    fam = SimpleNamespace(kind="tangential")
    base = {"h0": 10.0, "ac": 1.0e5}
    moved = {"h0": 16.0, "ac": 1.0e5, "tau": 1e-3, "c": 1.0}
    assert _takes_over(fam, base, moved, ("channel_delay",)) is None
    assert "takes over" in _takes_over(fam, base, moved, ("viscous_damping",))
    assert "takes over" in _takes_over(fam, base, {**moved, "h0": 25.0}, ("channel_delay",))


def test_a_delay_that_thins_a_noisy_pre_sliding_loop_is_named_not_a_play():
    """A 1.5 ms lag of the force at 27 Hz, ac·A 1, x noise 1.3 % (the rig, start from rest,
    load cell, anti-alias filters, 14 bits): the delay, not a play."""
    import contactlab
    from contactlab.synthetic.rig import rig_recording

    rec = rig_recording({"channel_delay": {"tau": 1.5e-3}}, seed=4, fs=2000.0, f=26.7,
                        cycles=16, acA=1.0, x_noise=0.013, F_noise=0.008, bits=14)  # fmt: skip
    rep = contactlab.diagnose((rec.t, rec.x, rec.F), model="tangential",
                              candidates=["channel_delay", "backlash"])  # fmt: skip
    assert rep.effect_names == ["channel_delay"]
    tau = dict(rep.effects[0].parameters)["tau"]
    assert abs(tau - 1.5e-3) < 0.3e-3
