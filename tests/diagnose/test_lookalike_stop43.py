"""Look-alikes named above the stated bound (issue 29, helper lookalike, stop 43): a
parallel spring is evaluated on the smoothed input (k_p times the sensor's white noise is
noise the data do not hold, and a noise-free 2f normal load won over it); a play's lead over
a delay counts only where the input's noise does not feed it, away from the turns.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from contactlab.diagnose._family import Prepared
from contactlab.diagnose.effects import registry
from contactlab.diagnose.effects._base import ForceContext
from contactlab.diagnose.effects.tangential._common import smoothed_velocity
from contactlab.diagnose.search import NOT_TOLD_APART, _mark_not_told_apart, paired_lead
from contactlab.diagnose.select import Verdict
from contactlab.masing import Masing

H0, AC, N_C, CYCLES = 10.0, 1e4, 200, 12
FS = 10_000.0
A = 2.5 / AC


def _sine(n: int = CYCLES * N_C) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(n) / FS
    return t, A * np.sin(2 * np.pi * np.arange(n) / N_C)


def _trial(pred: np.ndarray, *effects: str) -> SimpleNamespace:
    return SimpleNamespace(prediction=pred, heldout=np.ones(pred.size, bool), effects=effects)


def _v(name: str, gain: float) -> Verdict:
    return Verdict(name, 1.0, gain, 10.0, -50.0, True, "accepted")


@pytest.mark.parametrize("smooth", [True, False])
def test_a_spring_pulls_with_the_position_not_with_the_sensors_noise(smooth: bool):
    t, x = _sine()
    noise = 0.03 * A * np.random.default_rng(3).standard_normal(x.size)
    d = Prepared.build(t, x + noise, Masing(H0, AC).force(x))
    d.extra["u_noise"] = 0.03 * A
    spring = registry("tangential")["parallel_stiffness"]
    k_p = 1e5
    old = type(spring).smooth_input
    type(spring).smooth_input = smooth
    try:
        ctx = ForceContext(d, ("parallel_stiffness",), d.u, d.u, None)
        F = spring.apply(np.zeros(x.size), {"k_p": k_p}, ctx)
    finally:
        type(spring).smooth_input = old
    # the noise carried, as a share of the noise the prepared input itself holds
    left = float(np.std(F - k_p * x)) / (k_p * float(np.std(d.u - x)))
    if smooth:
        assert left < 0.7
        # the tilt itself is kept: the smoothing does not bend the sine
        assert np.corrcoef(F, x)[0, 1] > 0.999
    else:
        assert left == pytest.approx(1.0, rel=1e-6)


def _play_record(seed: int) -> tuple[Prepared, np.ndarray, np.ndarray, np.ndarray]:
    t, x = _sine()
    base = Masing(H0, AC).force(x)
    turn = np.exp(-(((np.arange(x.size) % (N_C // 2)) - N_C // 4) ** 2) / (2 * 40.0**2))
    sig = 0.3 * np.sign(np.cos(2 * np.pi * np.arange(x.size) / N_C)) * turn
    y = base + sig + 0.05 * np.random.default_rng(seed).standard_normal(x.size)
    d = Prepared.build(t, x, y)
    speed = np.abs(smoothed_velocity(d))
    fast = speed >= 0.5 * float(np.percentile(speed, 99.0))
    return d, base, sig, fast


@pytest.mark.parametrize(("same_fast", "tied"), [(True, True), (False, False)])
def test_a_plays_lead_only_at_the_turns_does_not_tell_it_from_a_delay(same_fast, tied):
    d, base, sig, fast = _play_record(4)
    d.extra["input_noise_budget"] = 1e-3  # too small to discount the lead
    current = _trial(base)
    best = (_v("backlash", 2.0), _trial(base + sig, "backlash"))
    # the delay: as good as the play away from the turns, or poorer there too
    other_pred = base + np.where(fast, sig, 0.2 * sig) if same_fast else base + 0.2 * sig
    other = (_v("channel_delay", 1.0), _trial(other_pred))
    assert paired_lead(d, current, best[1], other[1]) > 10.0  # every cycle: the play leads
    _mark_not_told_apart(best, {"backlash": best, "channel_delay": other}, st := SimpleNamespace(
        effects=(), current=current, where=[]), d, 3.0)  # fmt: skip
    assert ("channel_delay" in d.extra.get(NOT_TOLD_APART, {})) is tied
    assert bool(st.where) is tied


def test_only_a_play_is_judged_away_from_the_turns():
    d, base, sig, fast = _play_record(5)
    d.extra["input_noise_budget"] = 1e-3
    current = _trial(base)
    # a delay named over a play leads it at the turns only: its lead stands (the noise
    # does not feed a delay, so it has no samples to be judged on alone)
    best = (_v("channel_delay", 2.0), _trial(base + sig, "channel_delay"))
    other = (_v("backlash", 1.0), _trial(base + np.where(fast, sig, 0.2 * sig)))
    _mark_not_told_apart(best, {"channel_delay": best, "backlash": other}, SimpleNamespace(
        effects=(), current=current, where=[]), d, 3.0)  # fmt: skip
    assert "backlash" not in d.extra.get(NOT_TOLD_APART, {})


@pytest.mark.parametrize(("b_over_noise", "tied"), [(1.2, True), (4.0, False)])
def test_a_play_within_the_input_noise_is_not_told_from_a_delay(b_over_noise, tied):
    d, base, sig, _ = _play_record(6)
    d.extra["input_noise_budget"] = 1e-3
    d.extra["u_noise"] = 0.02 * A
    current = _trial(base)
    play = _trial(base + sig, "backlash")
    play.full = SimpleNamespace(params={"h0": H0, "ac": AC, "b": b_over_noise * 0.02 * A})
    best = (_v("backlash", 2.0), play)
    other = (_v("channel_delay", 1.0), _trial(base + 0.2 * sig))  # poorer everywhere
    _mark_not_told_apart(best, {"backlash": best, "channel_delay": other}, SimpleNamespace(
        effects=(), current=current, where=[]), d, 3.0)  # fmt: skip
    tie = d.extra.get(NOT_TOLD_APART, {}).get("channel_delay")
    assert (tie is not None) is tied
    if tied:
        assert "times the input noise" in tie["noise_sized"]


@pytest.mark.parametrize(("b_over_noise", "lead", "tied"), [(4.0, 0.99, True),
                                                           (1.2, 0.2, True),
                                                           (4.0, 0.2, False)])  # fmt: skip
def test_a_swap_without_telling_the_two_apart_withholds_the_bound(b_over_noise, lead, tied):
    from contactlab.diagnose.search import _mark_swapped_out

    d, base, sig, _ = _play_record(7)
    d.extra["u_noise"] = 0.02 * A
    old = _trial(base + lead * sig, "channel_delay")  # the model the play replaces
    new = _trial(base + sig, "backlash")
    new.full = SimpleNamespace(params={"h0": H0, "ac": AC, "b": b_over_noise * 0.02 * A})
    st = SimpleNamespace(effects=("backlash",), where=[])
    _mark_swapped_out("channel_delay", _v("backlash", 0.5), old, new, st, d, 3.0)
    tie = d.extra.get(NOT_TOLD_APART, {}).get("channel_delay")
    assert (tie is not None) is tied
    assert bool(st.where) is tied


@pytest.mark.parametrize("kind", ["tangential", "normal"])
def test_an_effect_named_and_then_displaced_gets_no_stated_bound(kind):
    from contactlab.diagnose.power import _withdrawn
    from contactlab.diagnose.search import StepwiseSearch

    d, _, _, _ = _play_record(8)
    me = SimpleNamespace(family=SimpleNamespace(kind=kind), d=d)
    StepwiseSearch._seen_and_dropped(me, "channel_delay", "named, then swapped out for backlash")
    why = _withdrawn("channel_delay", d, ("backlash",))
    assert bool(why) is (kind == "tangential")
    if why:
        assert "swapped out for backlash" in why
        # in the final model after all: its size is not asked for
        assert _withdrawn("channel_delay", d, ("channel_delay",)) == ""
