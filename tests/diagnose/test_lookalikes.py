"""A speed-strengthening Stribeck term yields to a mass or a series compliance accepted
beside it; the bounds of force drift and position friction carry their calibration margin."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from contactlab.diagnose.effects import registry
from contactlab.diagnose.effects.tangential.stribeck import LOOKALIKE_SHARE


@settings(max_examples=60, deadline=None)
@given(
    s=st.floats(-0.5, 1.0),
    own=st.floats(0.01, 100.0),
    share=st.floats(0.0, 2.0),
    rival=st.sampled_from(["inertia", "series_compliance", "viscous_damping"]),
)
def test_only_a_strengthening_term_yields_to_a_mass_or_a_compliance(s, own, share, rival):
    eff = registry("tangential")["stribeck"]
    why = eff.yields_to({"s": s, "v_s": 0.01}, {"stribeck": own, rival: share * own}, own)
    expect = s < 0 and rival != "viscous_damping" and share >= LOOKALIKE_SHARE
    assert bool(why) == expect
    if why:
        assert rival in why


def test_an_unfitted_rival_does_not_count():
    eff = registry("tangential")["stribeck"]
    assert eff.yields_to({"s": -0.2}, {"inertia": np.nan}, 1.0) is None


def test_the_calibrated_margins():
    from types import SimpleNamespace

    from contactlab.diagnose.power import power_margin

    fam = SimpleNamespace(kind="tangential")
    assert power_margin(fam, "force_drift") == 1.3
    assert power_margin(fam, "position_friction") == 1.2
    assert power_margin(fam, "stribeck") == 1.0


def test_the_margin_widens_the_stated_bound(monkeypatch):
    import contactlab
    from contactlab.diagnose.power import stated_power
    from contactlab.synthetic.diagnosis import hidden_effect_recording

    rep = contactlab.diagnose(hidden_effect_recording([], seed=3), max_effects=0)
    wide = {b.effect: b.detectable_above for b in stated_power(rep, seed=5)}
    cls = type(registry("tangential")["position_friction"])
    monkeypatch.setattr(cls, "power_margin", 1.0)
    bare = {b.effect: b.detectable_above for b in stated_power(rep, seed=5)}
    assert wide["position_friction"] / bare["position_friction"] == pytest.approx(1.2, rel=1e-9)
    assert wide["stribeck"] == bare["stribeck"]
