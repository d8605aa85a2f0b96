"""An effect that cannot filter the input (``input_noise_locked``: a friction wave along the
track, a normal load at a harmonic) beats at most what the input noise's simulated bias gives
its own direction on the record (``search.locked_noise_gain``), not a fixed share of the
whole input-noise budget (issue 29); the stated bound models the same floor."""

from __future__ import annotations

import numpy as np
import pytest

from contactlab.diagnose._family import Prepared
from contactlab.diagnose.candidates_tangential import TangentialFamily
from contactlab.diagnose.effects import registry
from contactlab.diagnose.search import (
    LOCKED_ANCHOR_SHARE,
    LOCKED_STATE,
    _noise_floor,
    locked_anchor_margin,
    locked_noise_gain,
)
from contactlab.synthetic.rig import rig_recording

EFF = ("position_friction",)


def _record() -> tuple[TangentialFamily, Prepared, dict[str, float]]:
    rec = rig_recording(
        {}, "tangential", seed=5110, fs=2000.0, f=10.0, cycles=12, acA=2.0,
        x_noise=0.01, F_noise=0.01,
    )  # fmt: skip
    fam = TangentialFamily()
    d = Prepared.build(rec.t, rec.x, rec.F)
    fam.prepare(d)
    half = 0.5 * float(np.ptp(d.u))
    p = {**fam.initial_base(d), "a1": 0.01, "b1": -0.005, "L": 1.5 * half}
    return fam, d, p


def _direction(fam, d, p, name: str) -> np.ndarray:
    h = 1e-6
    up, dn = dict(p), dict(p)
    up[name], dn[name] = p[name] + h, p[name] - h
    return (np.asarray(fam.predict(up, EFF, d)) - np.asarray(fam.predict(dn, EFF, d))) / (2 * h)


def _state(d, b1: np.ndarray, b2: np.ndarray, s2: float = 1.0) -> None:
    n = d.y.size
    d.extra[LOCKED_STATE] = {
        "use": np.ones(n, bool), "sw": np.ones(n), "b1": b1, "b2": b2, "Q": None,
        "W": float(n), "s2": s2,
    }  # fmt: skip


def test_the_bias_along_the_direction_is_taken_whole_and_across_it_not_at_all() -> None:
    fam, d, p = _record()
    j1, j2 = _direction(fam, d, p, "a1"), _direction(fam, d, p, "b1")
    n = d.y.size
    b = 0.7 * j1 - 0.2 * j2
    _state(d, b, b, s2=0.5)
    assert locked_noise_gain(fam, EFF, EFF, d, p) == pytest.approx(float(b @ b) / n / 0.5, rel=1e-3)
    rng = np.random.default_rng(1)
    r = rng.standard_normal(n) * float(np.std(b))
    J = np.column_stack([j1, j2])
    orth = r - J @ np.linalg.lstsq(J, r, rcond=None)[0]
    _state(d, orth, orth)
    assert locked_noise_gain(fam, EFF, EFF, d, p) < 1e-9 * float(orth @ orth) / n
    # two independent simulations' scatter cancels in their product: of a shared bias
    # along the direction plus independent noise, about the shared part is left
    _state(d, b + 5 * r, b + 5 * rng.standard_normal(n) * float(np.std(b)))
    g = locked_noise_gain(fam, EFF, EFF, d, p)
    assert g == pytest.approx(float(b @ b) / n, rel=0.2)


def test_the_floor_is_the_smaller_of_the_share_and_the_locked_gain() -> None:
    fam, d, p = _record()
    share = registry("tangential")["position_friction"].input_noise_share
    j1 = _direction(fam, d, p, "a1")
    budget = 0.4
    # no simulated bias: the share of the whole budget, as before
    assert _noise_floor(fam, EFF, budget, d, p, EFF) == pytest.approx(share * budget)
    for scale in (1e-3, 1e3):
        b = scale * j1
        _state(d, b, b)
        locked = float(b @ b) / d.y.size + locked_anchor_margin(budget, d)
        got = _noise_floor(fam, EFF, budget, d, p, EFF)
        assert got == pytest.approx(min(share * budget, locked), rel=1e-3)
    # an effect that can filter the input keeps its whole share however small the bias
    _state(d, 1e-3 * j1, 1e-3 * j1)
    assert _noise_floor(fam, ("channel_delay",), budget, d, p, ("channel_delay",)) == budget


@pytest.mark.slow
def test_the_stated_bound_models_the_locked_floor() -> None:
    import contactlab
    from contactlab.diagnose import power

    rec = rig_recording(
        {}, "tangential", seed=5111, fs=2000.0, f=10.0, cycles=16, acA=1.5,
        x_noise=0.015, F_noise=0.01,
    )  # fmt: skip
    rep = contactlab.diagnose((rec.t, rec.x, rec.F), model="tangential")
    d = rep.prepared
    assert d.extra.get(LOCKED_STATE) is not None
    fam = rep.final_model.family
    st0 = power._setting(d, rep.trials[-1], rep.channel_noise, None, rep.noise_rms, 3.0, 0.0, 2, 0)
    p0 = {**rep.trials[-1].full.params, "a1": 0.0, "b1": 0.0, "L": 1.5 * float(np.ptp(d.u)) / 2}
    with_at = power._own_floor(fam, "position_friction", d, st0, (p0, EFF))
    without = power._own_floor(fam, "position_friction", d, st0)
    budget = float(d.extra["gain_rules"]["budget"])
    locked = locked_noise_gain(fam, EFF, EFF, d, p0)
    assert locked is not None and locked >= 0.0
    assert with_at.gain_floor <= without.gain_floor + 1e-12
    locked += locked_anchor_margin(budget, d)
    assert with_at.gain_floor == pytest.approx(
        max(0.05 * 0.2 + min(0.25 * budget, locked), with_at.rel_floor), rel=1e-6
    )


def test_the_locked_floor_keeps_a_margin_for_the_records_own_noise_falling_with_cycles(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The simulated bias averages fresh draws; the record's own noisy turning points, held
    in the Masing memory, leave a cycle-locked part of their own (stop 52: a clean 1 kHz
    record of 20 cycles named a track's wave at 0.065 σ² held out, the simulated bias 0.016
    σ²). The lowered floor adds LOCKED_ANCHOR_SHARE budgets over the complete cycles."""
    from types import SimpleNamespace

    from contactlab.diagnose import search

    fam, d, p = _record()
    j1 = _direction(fam, d, p, "a1")
    budget = 0.4
    n = d.cycles.n_cycles
    assert n >= 10
    b = 1e-3 * j1  # a bias too small to matter: the margin alone stands above it
    _state(d, b, b)
    locked = float(b @ b) / d.y.size
    got = _noise_floor(fam, EFF, budget, d, p, EFF)
    assert LOCKED_ANCHOR_SHARE > 0
    assert got == pytest.approx(locked + LOCKED_ANCHOR_SHARE * budget / n, rel=1e-6)
    assert got > locked + 0.1 * budget / n
    # twice the cycles, half the margin
    short = locked_anchor_margin(budget, d)
    assert locked_anchor_margin(budget, SimpleNamespace(cycles=SimpleNamespace(
        n_cycles=2 * n))) == pytest.approx(short / 2)  # fmt: skip
    # without it, stop 51's floor: the simulated bias alone
    monkeypatch.setattr(search, "LOCKED_ANCHOR_SHARE", 0.0)
    assert _noise_floor(fam, EFF, budget, d, p, EFF) == pytest.approx(locked, rel=1e-6)


def test_an_effect_named_only_by_the_lowered_floor_is_marked_for_a_flagged_record() -> None:
    from types import SimpleNamespace

    from contactlab.diagnose.search import LOCKED_ONLY
    from contactlab.diagnose.workflow import _locked_on_misfit

    d = SimpleNamespace(extra={LOCKED_ONLY: {"position_friction": 0.05}})
    st = SimpleNamespace(added=["series_compliance", "position_friction"])
    flagged = {"unexplained": SimpleNamespace(flagged=True)}
    quiet = {"unexplained": SimpleNamespace(flagged=False)}
    got = _locked_on_misfit(st, d, flagged)
    assert got is not None and got[0] == "position_friction" and "0.05" in got[1]
    assert _locked_on_misfit(st, d, quiet) is None
    assert _locked_on_misfit(st, d, {"unexplained": None}) is None
    assert _locked_on_misfit(SimpleNamespace(added=["series_compliance"]), d, flagged) is None


def test_the_springs_bound_projects_out_a_stribeck_term() -> None:
    """The spring's stated bound takes out what a Stribeck term would take of its direction
    (stop 52: on 50-cycle rig records at ac·A 4.15 a Stribeck term out-gained springs of 2-3
    times the ideal size and was named in their place, under a bound of 1.2 times the ideal
    size that left it in)."""
    from contactlab.diagnose import power

    fam, d, _ = _record()
    p0 = {**fam.initial_base(d), "k_p": 0.0}
    scales = fam.scales(d)
    got = power._rival_directions(fam, p0, ("parallel_stiffness",), "parallel_stiffness", d, scales)
    load = [q for q in fam.candidates["normal_load"].params if np.isfinite(q.null)]
    assert len(got) == len(load) + 1  # normal_load's magnitudes and stribeck's s
