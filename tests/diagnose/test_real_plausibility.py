"""Plausibility of what the diagnosis names on measured records (issue 29, item 5).

- :func:`~contactlab.diagnose.effects.tangential.stick_slip.turn_shape`: a dead band (the
  displacement crossing a gap with no force change near zero force) against an exponential
  Masing branch and one with a breakaway, on branches built in closed form;
- :func:`~contactlab.diagnose.effects.tangential.force_offset.rest_verdict`: the force at
  rest at a record's start checks a fitted sensor zero;
- the workflow withdraws a named effect the final fit does not support
  (:func:`contactlab.diagnose.workflow._unfounded`);
- on the friction damper's records in ../shared/data (skipped when absent): a dead band,
  and a record starting at rest whose force there contradicts a large sensor zero.
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from contactlab.diagnose._family import Prepared
from contactlab.diagnose.effects import registry
from contactlab.diagnose.effects.tangential.force_offset import rest_start, rest_verdict
from contactlab.diagnose.effects.tangential.stick_slip import (
    DEAD_BAND_SHARE,
    dead_band,
    turn_shape,
)

DATA = Path(__file__).resolve().parents[2].parent / "shared" / "data"
H0, A, AC = 10.0, 1e-3, 2e4  # ac·A = 20: gross sliding


def _branches(gap: float = 0.0, s_b: float = 0.0, ell: float = 1e-4, rest: int = 0):
    """A sine of 8 cycles (2 kHz, 1 Hz... scaled), the force built branch by branch in
    closed form from the last reversal at ``∓H0``: an exponential Masing branch, with a
    dead band of width ``gap`` where it crosses zero force, or a breakaway of ``s_b H0`` at
    the travel ``ell``; ``rest`` samples at rest before the motion."""
    n = 8 * 400
    t = np.arange(n + rest) / 2000.0
    ph = 2 * np.pi * np.arange(n) / 400.0
    x = np.r_[np.zeros(rest), -A * np.cos(ph) + A]  # from rest at 0, first turn at 2A
    F = np.zeros_like(x)
    s0 = np.log(2.0) / AC * 2.0  # exponential branch 2(1 - e^(-ac s/2)) = 1 crosses zero
    turn_x, direction, virgin = 0.0, 1.0, True
    for i in range(1, x.size):
        step = x[i] - x[i - 1]
        if step != 0 and np.sign(step) != direction:
            direction, turn_x, virgin = np.sign(step), x[i - 1], False
        if virgin:  # the first loading from rest at zero force
            F[i] = H0 * -np.expm1(-AC * x[i])
            continue
        s = abs(x[i] - turn_x)
        se = s if not gap else (s if s < s0 else (s0 if s < s0 + gap else s - gap))
        g = -H0 + 2 * H0 * -np.expm1(-AC * se / 2)
        g += s_b * H0 * (s / ell) * np.exp(1 - s / ell)
        F[i] = direction * g
    return t, x, F


def _prepared(t, x, F, u_noise=0.0):
    d = Prepared.build(t, x, F)
    d.extra["u_noise"] = u_noise
    return d


def test_turn_shape_tells_a_dead_band_from_a_breakaway_and_a_plain_branch():
    plain = turn_shape(_prepared(*_branches()))
    dead = turn_shape(_prepared(*_branches(gap=0.3 * A)))
    bump = turn_shape(_prepared(*_branches(s_b=0.4, ell=0.5 / AC)))
    assert plain is not None and dead is not None and bump is not None
    assert plain["share"] < 0.2  # exponential: 12.5 % in closed form, ~15 % sampled here
    assert bump["share"] < DEAD_BAND_SHARE  # a breakaway does not flatten the turn
    assert dead["share"] > DEAD_BAND_SHARE
    assert abs(dead["travel"] - 0.3 * A) < 0.1 * A  # the gap itself
    assert dead["level"] < 0.2 * H0  # near zero force
    assert dead_band(_prepared(*_branches(gap=0.3 * A))) is not None
    assert dead_band(_prepared(*_branches(s_b=0.4, ell=0.5 / AC))) is None


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**16), noise=st.floats(0.0, 0.02))
def test_turn_shape_of_a_plain_branch_stays_below_the_dead_band_bar_under_noise(seed, noise):
    """Force noise up to 2 % of the range does not make a dead band of a plain branch."""
    t, x, F = _branches()
    rng = np.random.default_rng(seed)
    F = F + rng.normal(0.0, noise * 2 * H0, F.size)
    shape = turn_shape(_prepared(t, x, F))
    assert shape is not None and shape["share"] < DEAD_BAND_SHARE


def test_stick_slip_is_refused_on_a_dead_band_and_kept_on_a_breakaway():
    eff = registry("tangential")["stick_slip"]
    p = {"h0": H0, "ac": AC, "s_b": 0.3, "ell": 0.5 / AC}
    ok, why = eff.plausible(_prepared(*_branches(gap=0.3 * A)), p)
    assert not ok and "dead band" in why
    ok, why = eff.plausible(_prepared(*_branches(s_b=0.3, ell=0.5 / AC)), p)
    assert ok and "no dead band" in why


def test_rest_start_and_the_sensor_zero():
    t, x, F = _branches(rest=100)
    d = _prepared(t, x, F - 2.0)  # a sensor zero of -2: read at rest
    rest = rest_start(d)
    assert rest is not None and rest[0] >= 90 and abs(rest[2] + 2.0) < 0.05 * H0
    ok, why = rest_verdict(d, -2.0)
    assert ok is True and "starts at rest" in why
    ok, why = rest_verdict(d, -5.0)  # the plateaus' shift is not the sensor's
    assert ok is False and "not at F0" in why
    eff = registry("tangential")["force_offset"]
    assert not eff.plausible(d, {"F0": -5.0, "h0": H0}).ok
    assert eff.plausible(d, {"F0": -2.0, "h0": H0}).ok
    # a record cut mid-stroke (no rest): the rest force cannot check F0
    t2, x2, F2 = _branches()
    cut = _prepared(t2[150:] - t2[150], x2[150:], F2[150:])
    assert rest_start(cut) is None
    ok, why = rest_verdict(cut, -5.0)
    assert ok is None and "does not start at rest" in why
    assert eff.plausible(cut, {"F0": -5.0, "h0": H0}).ok


def test_unfounded_picks_the_least_significant_named_effect():
    from contactlab.diagnose.candidates_tangential import TangentialFamily
    from contactlab.diagnose.workflow import _unfounded

    fam = TangentialFamily()
    d = _prepared(*_branches())
    full = SimpleNamespace(
        params={"h0": H0, "ac": AC, "F0": 0.5, "b": 2.6e-6},
        stderr={"h0": 0.1, "ac": 10.0, "F0": 0.01, "b": 2.4e-6},
    )
    state = SimpleNamespace(current=SimpleNamespace(full=full), added=["force_offset", "backlash"])
    name, why = _unfounded(fam, state, d)
    assert name == "backlash" and "not identifiable" in why
    full.stderr["b"] = 0.5e-6  # 5 standard errors: it stands
    assert _unfounded(fam, state, d) is None


def _damper(i: int):
    folder = DATA / "friction_damper"
    if not folder.is_dir():
        pytest.skip("../shared/data absent")
    x = np.load(folder / f"harmonic_test{i}_x.npy").ravel()
    F = np.load(folder / f"harmonic_test{i}_F.npy").ravel()
    return _prepared(np.arange(x.size) / 1024.0, x, F, u_noise=2.5e-6)


def test_damper_turns_hold_a_dead_band_and_its_rest_force_is_no_large_sensor_zero():
    """The README describes backlash dead bands near zero force: the turns show one (the
    displacement travels ~6 mm while the force changes by 10 % of its rise, ~40 % of the
    travel to 90 % of the rise), and the record starts at rest near -0.6 kN, which a
    fitted sensor zero of -2.2 kN (the old diagnosis's) contradicts."""
    d = _damper(0)
    shape = turn_shape(d)
    assert shape is not None and shape["share"] > DEAD_BAND_SHARE
    assert shape["level"] < 0.1 * 17e3
    ok, why = rest_verdict(d, -2241.0)
    assert ok is False, why


def test_stroke_levels_and_the_h0_check_say_why_with_figures():
    from contactlab.diagnose.paths import RegimeDecision, TangentialPath, stroke_levels

    t, x, F = _branches()
    d = _prepared(t, x, F + 3.0)  # both plateaus shifted by +3
    up, down = stroke_levels(d.u, d.y, d.cycles.reversals)
    assert abs(up - (H0 + 3.0)) < 0.02 * H0 and abs(down - (-H0 + 3.0)) < 0.02 * H0
    regime = RegimeDecision("gross sliding", "", "analyze", 1.1 * H0, 0.01, None,
                            {"h0_source": "analyze fit"})  # fmt: skip
    path = TangentialPath.__new__(TangentialPath)
    doc, text = path.check_final(
        regime, {"h0": H0}, ("asymmetry",), None, ((up, down), (0.9 * up, 0.9 * down))
    )
    assert doc is not None and not doc["within_tolerance"]
    assert abs(doc["stroke_half"]["ratio"] - 0.9) < 1e-12
    assert not doc["stroke_half"]["within_tolerance"]
    assert "no plateau" in text and "second half of each stroke" in text
    assert "does not redefine h0" in text
    doc, text = path.check_final(regime, {"h0": 1.08 * H0}, (), None, None)
    assert doc["within_tolerance"] and text is None and "stroke_half" not in doc


def test_unfounded_withdraws_an_effect_at_its_null_or_without_an_error():
    from contactlab.diagnose.candidates_tangential import TangentialFamily
    from contactlab.diagnose.workflow import _unfounded

    d = _prepared(*_branches())
    full = SimpleNamespace(
        params={"h0": H0, "ac": AC, "s_b": 2e-8, "ell": 1e-4},
        stderr={"h0": 0.1, "ac": 10.0, "s_b": np.inf, "ell": np.inf},
    )
    state = SimpleNamespace(current=SimpleNamespace(full=full), added=["stick_slip"])
    name, why = _unfounded(TangentialFamily(), state, d)
    assert name == "stick_slip" and "cannot be computed" in why


def test_plateau_trend_tells_a_drifting_zero_from_one_direction_changing():
    from contactlab.diagnose.effects.tangential.force_offset import drift_verdict, plateau_trend

    t, x, F = _branches()
    T = t[-1] - t[0]
    drift = _prepared(t, x, F + 2.0 * (t - t[0]) / T)  # the zero drifts by 2 N
    common, se, n = plateau_trend(drift)
    assert n >= 6 and abs(common - 2.0) < 0.3 and se < 0.3
    assert drift_verdict(drift, {"F1": 2.0})[0] is True
    assert drift_verdict(drift, {"F1": -2.0})[0] is False
    # the falling stroke's friction shrinks by 2 N (wear on one side): common change +1 N
    one_sided = _prepared(t, x, F + np.where(F < 0, 2.0 * (t - t[0]) / T, 0.0))
    common, _, _ = plateau_trend(one_sided)
    assert abs(common - 1.0) < 0.3
    ok, why = drift_verdict(one_sided, {"F1": -3.0})
    assert ok is False and "move together by" in why


def test_displacement_offset_is_refused_where_the_contact_would_be_loaded_at_rest():
    eff = registry("tangential")["displacement_offset"]
    d = _prepared(*_branches(rest=100))  # at rest at x = 0 with F = 0
    p = {"h0": H0, "ac": AC, "x0": 0.2 * A}  # M(-x0) = -H0 (1 - e^-4): -9.8 N at rest
    ok, why = eff.plausible(d, p)
    assert not ok and "starts at rest" in why
    assert eff.plausible(d, {**p, "x0": 1e-3 * A}).ok  # M(-x0) = -0.2 N: within the rule


def test_asymmetry_in_gross_sliding_is_told_from_an_offset_by_the_rest_force():
    eff = registry("tangential")["asymmetry"]
    p = {"h0": H0, "ac": AC, "alpha": -0.2}  # ac·A = 20: both plateaus shift by -2 N
    ok, why = eff.plausible(_prepared(*_branches(rest=100)), p)  # at rest F = 0
    assert ok and "is not the sensor's" in why
    t, x, F = _branches(rest=100)
    ok, why = eff.plausible(_prepared(t, x, F - 2.0), p)  # at rest F = -2 = α h0
    assert not ok and "force_offset stands for both" in why


def test_report_json_carries_withdrawn_and_refused_with_reasons():
    from contactlab.diagnose.result import DiagnosisReport

    rep = DiagnosisReport("tangential", [], [], [], 1.0, None, {})  # type: ignore[arg-type]
    rep.location = {"withdrawn_why": {"backlash": "not identifiable"}, "refused": {"a": "b"}}
    rep.final_model = SimpleNamespace(to_dict=lambda: {})
    doc = rep.to_dict()
    assert doc["withdrawn"] == {"backlash": "not identifiable"} and doc["refused"] == {"a": "b"}
