"""Series compliance: the base parameters it is equivalent to (the search's takeover check
compares these with the base fit), against the sheared backbone's own initial slope."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from contactlab.diagnose.effects import registry
from contactlab.diagnose.effects.tangential.series_compliance import series_backbone


@settings(max_examples=40, deadline=None)
@given(
    h0=st.floats(1.0, 1e4),
    ac=st.floats(1e2, 1e6),
    ratio=st.floats(0.05, 20.0),
)
def test_equivalent_stiffness_is_the_backbones_initial_slope(h0, ac, ratio):
    eff = registry("tangential")["series_compliance"]
    c = ratio / (h0 * ac)  # a compliance of 1/ratio times the contact's stiffness
    eq = eff.base_equivalent({"h0": h0, "ac": ac, "C_s": c})
    bx, bf = series_backbone(h0, ac, c, 1.0 / ac)
    slope = (bf[1] - bf[0]) / (bx[1] - bx[0])  # the sheared virgin curve's first chord
    assert h0 * eq["ac"] == pytest.approx(slope, rel=1e-3)
    assert "h0" not in eq  # the plateau stays


def test_no_compliance_is_the_base_itself():
    eff = registry("tangential")["series_compliance"]
    assert eff.base_equivalent({"h0": 40.0, "ac": 4e4, "C_s": 0.0}) == {"ac": 4e4}


def test_a_compliance_at_twice_its_bound_is_named():
    """Rig tuning seed 73005 of benches/eval_bound_power.py (10 of its 31 cycles): before
    the equivalent, the
    compliance's refit (h0·ac back at the truth, 1.6e6 N/m, from the base's 1.15e6) read
    as a base taken over, and power_law_microslip + position_friction were named."""
    import contactlab
    from contactlab.synthetic.rig import rig_recording

    rec = rig_recording(
        {"series_compliance": {"k_s": 1.0 / 2.92e-7}}, "tangential", seed=73005 + 2 * 7919,
        fs=1299.7, f=1.764, cycles=10, acA=1.982, x_noise=0.0088, F_noise=0.0079,
        x_drift=-0.00074, bits=16,
    )  # fmt: skip
    data = {"t": rec.t, "x": rec.channels["x"], "F": rec.channels["F"]}
    rep = contactlab.diagnose(data, model="tangential")
    assert rep.effect_names == ["series_compliance"]
    k_s = 1.0 / rep.final_model.params["C_s"]
    assert 0.5 < k_s * 2.92e-7 < 2.0


def test_no_compliance_is_promised_where_the_loops_never_reach_a_plateau():
    from types import SimpleNamespace

    eff = registry("tangential")["series_compliance"]
    d = SimpleNamespace(u=np.array([-1e-4, 1e-4]))  # A = 1e-4 m
    assert eff.not_separable(d, {"h0": 40.0, "ac": 2.0e4}) is None  # ac·A 2
    why = eff.not_separable(d, {"h0": 40.0, "ac": 1.2e4})  # ac·A 1.2
    assert why.startswith("not separable from a softer contact")
    assert "ac·A = 1.2 < 1.5" in why
