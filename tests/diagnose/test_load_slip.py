"""A load fluctuating at twice the drive frequency and a breakaway in pre-sliding
(issue 29, helper loadslip).

- a 2f load in phase with the stroke (``1 - 2 (x/A)²``, the same on both strokes) is no
  longer refused as friction varying along the track: the held-out comparison decides, and
  the argument says what one amplitude cannot tell;
- a breakaway that is a large share of a pre-sliding branch's rise flattens the turn as a
  gap does: the dead-band test lets ``stick_slip`` stand when the fitted breakaway draws
  that flat stretch itself (:func:`drawn_by_breakaway`), and still refuses it on a gap.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from contactlab.diagnose._family import Prepared
from contactlab.diagnose.effects import registry
from contactlab.diagnose.effects.tangential.stick_slip import (
    DEAD_BAND_SHARE,
    breakaway_term,
    drawn_by_breakaway,
    turn_shape,
)
from contactlab.masing import Masing

H0, AC = 10.0, 1e4


def _record(acA: float, s_b: float = 0.0, ell: float = 0.1, gap: float = 0.0, cycles=8):
    """A sine from rest (400 samples a cycle); the force of Masing's rules with a breakaway
    ``s_b H0`` at the travel ``ell·A`` after each reversal (docs/effects.md), or, built
    branch by branch in closed form, a dead band of width ``gap·A`` where each branch
    crosses zero force (the displacement crossing a gap with no force change, as in a
    banded friction damper)."""
    A = acA / AC
    n = cycles * 400
    t = np.arange(n) / 2000.0
    x = A * np.sin(2 * np.pi * np.arange(n) / 400.0)
    F = Masing(H0, AC).force(x)
    rev = np.asarray(Prepared.build(t, x, F).cycles.reversals, int)
    if gap:
        fa = H0 * -np.expm1(-acA)  # the loop's tip force
        s0 = -2.0 / AC * np.log1p(-fa / (2 * H0))  # the branch crosses zero force there
        for a, b in zip(rev, np.r_[rev[1:], n], strict=True):
            s = np.abs(x[a:b] - x[a])
            se = np.where(s < s0, s, np.where(s < s0 + gap * A, s0, s - gap * A))
            sign = np.sign(x[min(a + 1, n - 1)] - x[a]) or 1.0
            F[a:b] = sign * (-fa + 2 * H0 * -np.expm1(-AC * se / 2))
    if s_b:
        F = breakaway_term(F, x, rev, s_b, ell * A, H0)
    return Prepared.build(t, x, F)


def test_a_large_breakaway_in_pre_sliding_reads_as_a_flat_turn_but_is_its_own():
    d = _record(0.35, s_b=0.2, ell=0.05)
    shape = turn_shape(d)
    assert shape is not None and shape["share"] >= DEAD_BAND_SHARE  # flat, as a gap
    p = {"h0": H0, "ac": AC, "s_b": 0.2, "ell": 0.05 * 0.35 / AC}
    assert drawn_by_breakaway(d, p)
    ok, why = registry("tangential")["stick_slip"].plausible(d, p)
    assert ok, why


def test_a_gap_is_still_a_dead_band_that_no_small_breakaway_draws():
    d = _record(3.0, gap=0.3)
    shape = turn_shape(d)
    assert shape is not None and shape["share"] >= DEAD_BAND_SHARE
    p = {"h0": H0, "ac": AC, "s_b": 0.1, "ell": 0.1 * 3.0 / AC}
    assert not drawn_by_breakaway(d, p)
    ok, why = registry("tangential")["stick_slip"].plausible(d, p)
    assert not ok and "dead band" in why
    assert not drawn_by_breakaway(d, {**p, "s_b": 0.0})  # no breakaway: nothing drawn


@settings(max_examples=12, deadline=None)
@given(phi=st.floats(0.0, 2 * np.pi), eps=st.floats(0.01, 0.25))
def test_a_2f_load_is_plausible_at_any_phase(phi, eps):
    """Every phase of a load at 2f is a load coupled to the motion; in phase with the stroke
    (nearly all of it the same on both strokes) the argument says one amplitude cannot
    tell it from a track wave."""
    d = _record(3.0)
    eff = registry("tangential")["normal_load"]
    f2 = 2.0 / (400 * d.dt)
    p = {"h0": H0, "ac": AC, "eps_c": eps * np.cos(phi), "eps_s": -eps * np.sin(phi), "f_n": f2}
    ok, why = eff.plausible(d, p)
    assert ok, why
    text = eff.argument(d, p)
    assert "harmonic 2" in text
    if np.sin(phi) ** 2 < 0.2:
        assert "cannot tell" in text


def _in_phase(d, eps=0.1, phi=0.0):
    f2 = 2.0 / (400 * d.dt)
    return {"h0": H0, "ac": AC, "eps_c": eps * np.cos(phi), "eps_s": -eps * np.sin(phi), "f_n": f2}


def test_an_in_phase_load_yields_to_an_accepted_stribeck_term_only():
    d = _record(3.0)
    eff = registry("tangential")["normal_load"]
    p = _in_phase(d)
    assert eff.yields_to(p, {"stribeck": 0.9}, 1.0, d)  # a parabola in the speed: Stribeck
    assert eff.yields_to(p, {"stribeck": 0.5}, 1.0, d) is None  # far below the load's gain
    assert eff.yields_to(p, {"position_friction": 0.99}, 1.0, d) is None
    assert eff.yields_to(_in_phase(d, phi=np.pi / 2), {"stribeck": 0.95}, 1.0, d) is None
    assert eff.yields_to(p, {"stribeck": 0.9}, 1.0) is None  # no record: nothing to read


def test_a_load_yields_only_to_a_rival_that_stands():
    """A 2f load yields to a Stribeck term, which itself yields to a series compliance (a
    speed-strengthening term): the load stands."""
    from types import SimpleNamespace

    from contactlab.diagnose.search import _yield_to_lookalikes
    from contactlab.diagnose.select import Verdict

    d = _record(3.0)
    fam = SimpleNamespace(kind="tangential")
    load = _in_phase(d)
    strib = {"h0": H0, "ac": AC, "s": -0.14, "v_s": 1e-3}

    def acc(name, gain, p):
        return Verdict(name, 1.0, gain, 10.0, -50.0, True, "accepted"), SimpleNamespace(
            full=SimpleNamespace(params=p)
        )

    both = [acc("normal_load", 1.0, load), acc("stribeck", 0.93, strib)]
    keep, _ = _yield_to_lookalikes(fam, both, [v for v, _ in both], d)
    assert [v.name for v, _ in keep] == ["stribeck"]
    three = [*both, acc("series_compliance", 0.8, {"h0": H0, "ac": AC, "C_s": 1e-6})]
    keep, verdicts = _yield_to_lookalikes(fam, three, [v for v, _ in three], d)
    assert [v.name for v, _ in keep] == ["normal_load", "series_compliance"]
    assert [v.accepted for v in verdicts] == [True, False, True]
