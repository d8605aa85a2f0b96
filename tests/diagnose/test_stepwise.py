"""Stepwise selection (backward elimination), the normal creep's start-up rule and the
parameter errors under residual autocorrelation (issue 8)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import contactlab
from contactlab.diagnose._family import Prepared
from contactlab.diagnose.candidates_normal import CREEP_MIN_PERIODS, NormalFamily
from contactlab.diagnose.select import correlation_time, stderr_inflation
from contactlab.synthetic.diagnosis import hidden_effect_recording


def _ar1(phi: float, n: int, rng: np.random.Generator) -> np.ndarray:
    e = rng.normal(size=n)
    r = np.empty(n)
    r[0] = e[0] / np.sqrt(1 - phi * phi)
    for i in range(1, n):
        r[i] = phi * r[i - 1] + e[i]
    return r


def test_inflation_of_a_mean_under_ar1_matches_the_closed_form():
    """The error of a mean of AR(1) samples is √((1+φ)/(1-φ)) times the independent one
    (closed form); white residuals are left alone."""
    rng = np.random.default_rng(5)
    n = 20_000
    jac = np.ones((n, 1))
    for phi, lo, hi in ((0.0, 1.0, 1.15), (0.8, 0.8, 1.2), (0.95, 0.7, 1.3)):
        want = np.sqrt((1 + phi) / (1 - phi))
        got = float(stderr_inflation(jac, _ar1(phi, n, rng), lag=400)[0])
        assert lo * want <= got <= hi * want, (phi, got, want)
        tau = correlation_time(_ar1(phi, n, rng), 400)
        assert tau == pytest.approx((1 + phi) / (1 - phi), rel=0.3)


@settings(max_examples=30, deadline=None)
@given(
    n=st.integers(20, 400),
    k=st.integers(1, 4),
    lag=st.integers(0, 60),
    seed=st.integers(0, 2**31 - 1),
)
def test_inflation_is_finite_and_never_narrows(n, k, lag, seed):
    rng = np.random.default_rng(seed)
    jac = rng.normal(size=(n, k))
    jac[:, 0] = 0.0 if seed % 7 == 0 else jac[:, 0]  # a parameter the data do not touch
    r = rng.normal(size=n) * (seed % 5)  # also all-zero residuals
    f = stderr_inflation(jac, r, lag)
    assert f.shape == (k,) and np.all(np.isfinite(f)) and np.all(f >= 1.0)


def test_creep_settling_within_a_period_is_a_start_up_transient():
    t = np.arange(2400) / 200.0
    p = 5e5 + 1e5 * np.sin(2 * np.pi * t)
    d = Prepared.build(t, p, p / 1.3e12)
    fam = NormalFamily()
    fam.prepare(d)
    period = d.cycles.period_samples * d.dt
    fast = {"D": 1e-9, "tau_c": 0.2 * CREEP_MIN_PERIODS * period}
    why = fam.implausible("creep_drift", fast, d)
    assert why is not None and "start-up" in why
    assert fam.implausible("creep_drift", {"D": 1e-9, "tau_c": 3.0 * period}, d) is None


def test_filtered_branch_scale_names_the_skew_and_the_scale():
    """Behind anti-alias filters at 0.3 / 0.6 of Nyquist a non-Masing branch scale (from
    rest at the turning points, docs/effects.md) and the filters' skew (a negative delay:
    the displacement's filter is the slower) are both named. (Before the branch scale
    followed the actual turning points, the forward search named stick-slip first and the
    backward step dropped it; that step is tested in tests/diagnose/test_search.py.)"""
    rec = hidden_effect_recording(
        ["non_masing_scaling"], magnitude=0.05, noise=0.005, input_noise=0.002,
        samples_per_cycle=200, anti_alias=(0.3, 0.6), bits=16, seed=92000,
    )  # fmt: skip
    rep = contactlab.diagnose(
        rec, candidates=["non_masing_scaling", "stick_slip", "channel_delay", "force_offset"]
    )
    assert sorted(rep.effect_names) == ["channel_delay", "non_masing_scaling"]
    assert rep.final_model.params["tau"] < 0


@settings(max_examples=8, deadline=None)
@given(
    s_b=st.floats(0.05, 0.5),
    ell_ac=st.floats(3.0, 30.0),
    h0=st.floats(0.1, 50.0),
)
def test_model_breakaway_matches_the_full_branch_peak(s_b, ell_ac, h0):
    """In gross sliding (ac·A = 200) every branch starts from -h0, so the breakaway force
    read off the simulated model at the reversals equals the peak of a full branch of the
    breakaway term (breakaway_force, a grid maximum of the closed form)."""
    from contactlab.diagnose.candidates_tangential import TangentialFamily, breakaway_force

    t = np.arange(4000) / 400.0
    x = 1e-3 * np.sin(2 * np.pi * t)
    ac = 200.0 / 1e-3
    d = Prepared.build(t, x, np.zeros_like(x))
    fam = TangentialFamily()
    fam.prepare(d)
    p = {"h0": h0, "ac": ac, "s_b": s_b, "ell": ell_ac / ac}
    got = fam.model_breakaway(p, ("stick_slip",), d)
    want = breakaway_force(h0, ac, s_b, ell_ac / ac)
    assert got == pytest.approx(want, rel=2e-3)
    # without the term, the model's force near the reversal is the plateau h0
    assert fam.model_breakaway(p, (), d) == pytest.approx(h0, rel=1e-3)


def test_swap_step_label_and_json():
    from contactlab.diagnose.workflow import Step

    s = Step("stribeck", 1.0, 2.0, 0.1, removed="parallel_stiffness")
    assert s.label == "parallel_stiffness ⇄ stribeck"
    assert s.to_dict()["added"] == "stribeck" and s.to_dict()["removed"] == "parallel_stiffness"
    assert Step(None, 1.0, 2.0, 0.1, removed="x").label == "- x"
    assert Step("x", 1.0, 2.0, 0.1).label == "+ x"


def test_swap_move_reaches_an_effect_never_tried_because_the_set_filled():
    """Behind anti-alias filters at 0.3 / 0.6 of Nyquist, Stribeck friction first looks like
    parallel stiffness + a breakaway after each reversal. With the channel delay among the
    candidates the truth (stribeck and the filters' skew) is named, by whichever route the
    search takes. Without it and with max_effects = 2 reached, the swap move replaces a
    named effect by a candidate not in the model: the parallel stiffness by stribeck (the
    Gaussian Stribeck of docs/effects.md predicts the held-out cycles better in its place),
    listed as "out ⇄ in". Stribeck and the breakaway then both reshape the friction between
    reversals, and the parsimony rule keeps them together only if each is significant after
    the other (the breakaway here also stands for the filters' skew, which no candidate of
    this list can name): a sentence says which one stays."""
    rec = hidden_effect_recording(
        ["stribeck"], magnitude=0.05, noise=0.005, input_noise=0.002,
        samples_per_cycle=200, anti_alias=(0.3, 0.6), bits=16, seed=92010,
    )  # fmt: skip
    rep = contactlab.diagnose(
        rec,
        candidates=["parallel_stiffness", "stick_slip", "non_masing_scaling", "stribeck",
                    "channel_delay"],
    )  # fmt: skip
    assert sorted(rep.effect_names) == ["channel_delay", "stribeck"]
    full = contactlab.diagnose(
        rec, candidates=["parallel_stiffness", "stick_slip", "non_masing_scaling", "stribeck"],
        max_effects=2,
    )  # fmt: skip
    # (since stop 51 the breakaway also acts on the first loading from rest and the start-up
    # is held out: the breakaway alone no longer fills the set at step 2, and the pair move
    # takes stribeck in together with it in place of the stiffness, "parallel_stiffness ⇄
    # stribeck + stick_slip"; the set-filled swap itself is tested in this file's other tests
    # only where they reach it)
    swaps = [s for s in full.steps if s.removed is not None and s.added is not None]
    assert [s.removed for s in swaps] == ["parallel_stiffness"]
    assert swaps[0].added in ("stribeck", "stribeck + stick_slip")
    said = ("swap: parallel_stiffness replaced by stribeck", "pair: stribeck and stick_slip")
    assert any(w.startswith(said) and "parallel_stiffness" in w for w in full.where)
    tried = [v for s in full.steps for v in s.candidates if "⇄" in v.name]
    assert any(v.name == f"parallel_stiffness ⇄ {swaps[0].added}" for v in tried)
    assert sorted(full.effect_names) == ["stick_slip", "stribeck"]
    assert "parallel_stiffness" not in full.effect_names
    assert any("friction along the branch" in w for w in full.where)


def test_pair_move_names_an_offset_and_a_drift_that_each_look_like_a_displacement_offset():
    """A force offset and a force drift (a ramp from 0) of 5 % of the force each: alone,
    neither fits (the ramp needs the offset to centre it; the offset alone misses the ramp),
    and a displacement offset, which moves the small-amplitude block's loop more than the
    others, wins the greedy first step. Nothing else passes after it, but the drift still
    gains several σ²: the pair move adds the offset and the drift together, each needed
    beside the other, and the backward step drops the displacement offset (seed not used in
    development; before the pair move the diagnosis named displacement_offset alone)."""
    rec = hidden_effect_recording(
        ["force_offset", "force_drift"], magnitude=0.05, noise=0.005, input_noise=0.002,
        samples_per_cycle=100, cycles_per_block=4, seed=93005,
    )  # fmt: skip
    rep = contactlab.diagnose(
        rec, candidates=["force_offset", "force_drift", "displacement_offset"]
    )
    assert sorted(rep.effect_names) == ["force_drift", "force_offset"]
    pair = [s for s in rep.steps if s.added is not None and " + " in s.added]
    assert pair and pair[0].label in (
        "+ force_drift + force_offset",
        "+ force_offset + force_drift",
    )
    assert pair[0].heldout_rms < 0.5 * rep.steps[1].heldout_rms
    assert any(w.startswith("pair: ") for w in rep.where)
    assert any(" + " in v.name and v.accepted for s in rep.steps for v in s.candidates)
    truth = rec.truth["effects"]
    fitted = {e.name: e for e in rep.effects}
    for name, par in (("force_offset", "F0"), ("force_drift", "F1")):
        want, got = truth[name][par], fitted[name].parameters[par]
        assert abs(got - want) < 0.15 * abs(want) + 4 * fitted[name].stderr[par], (name, got, want)
