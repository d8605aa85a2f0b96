"""A drift of the friction force is tested across cycles, not against the input-noise
budget: a factor in time on the element's force cannot feed on the input's white noise."""

from __future__ import annotations

import numpy as np

import contactlab
from contactlab.diagnose.candidates_tangential import TangentialFamily
from contactlab.diagnose.search import _noise_floor
from contactlab.synthetic.rig import rig_recording


def test_only_input_blind_effects_skip_the_budget():
    fam = TangentialFamily()
    assert _noise_floor(fam, ("parameter_drift",), 0.3) == 0.0
    assert _noise_floor(fam, ("viscous_damping",), 0.3) == 0.3
    assert _noise_floor(fam, ("parameter_drift", "channel_delay"), 0.3) == 0.3


def test_a_drift_of_the_friction_force_is_named_at_two_percent_noise():
    """h0 grows by 6.4 % over 20 cycles (ac·A 0.83), noise 4 % of the amplitude on both
    channels, started abruptly from rest: the held-out gain, 0.12 σ² at t = 3.7 across the
    cycles, was refused below the 0.20 σ² input-noise floor."""
    T = 20 / 5.0
    rec = rig_recording(
        {"parameter_drift": {"beta": 0.064 / T}}, "tangential", seed=1, ramp_cycles=0.0,
        acA=0.83, f=5.0, fs=2000.0, cycles=20, x_noise=0.04, F_noise=0.04,
    )  # fmt: skip
    t, x, F = rec.t, rec.channels["x"], rec.channels["F"]
    rep = contactlab.diagnose((t, x, F), model="tangential")
    assert rep.effect_names == ["parameter_drift"]
    beta = rep.effects[0].parameters["beta"]
    assert abs(beta - 0.064) < 3 * rep.effects[0].stderr["beta"]
    assert np.isfinite(rep.effects[0].stderr["beta"])
