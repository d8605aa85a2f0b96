"""The flag route (issue 29): on a flagged final model, the one candidate that explains the
flagged structure is named, with the route stated; a misfit no candidate draws stays
flagged and unnamed (:mod:`contactlab.diagnose.flag_route`)."""

from __future__ import annotations

import json
import types
import warnings

import numpy as np
import pytest

import contactlab
from contactlab.diagnose import workflow
from contactlab.diagnose.flag_route import _flag_sources
from contactlab.synthetic.diagnosis import hidden_effect_recording

FEW = ["force_offset", "stribeck", "series_compliance", "position_friction", "parallel_stiffness"]


def _u(**kw):
    base = {
        "calibrated": None, "statistic": 1.0, "threshold": 2.0, "backbone": None,
        "rivals": (), "patches": (), "absorbing": (),
    }  # fmt: skip
    return types.SimpleNamespace(**{**base, **kw})


def test_flag_sources_read_the_tests_that_flagged() -> None:
    assert _flag_sources(_u(calibrated={"by": ["phase_bins"]})) == ["phase_bins"]
    assert _flag_sources(_u(statistic=3.0, backbone={"flagged": True})) == [
        "phase_bins",
        "backbone",
    ]
    got = _flag_sources(_u(calibrated={"by": []}, patches=({"effects": ["x"]},)))
    assert got == ["patches"]


def _diagnose(rec, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return contactlab.diagnose(rec, model="tangential", **kw)


@pytest.mark.slow
def test_an_offset_below_the_floors_is_named_by_the_route() -> None:
    """A force offset the search refuses (a per-sample floor no gain reaches) leaves a flag;
    the route names it, says so, and the flag clears."""
    rec = hidden_effect_recording(["force_offset"], magnitude=0.05, seed=2, cycles_per_block=4)
    rep = _diagnose(rec, min_gain=1e3, candidates=FEW)
    route = rep.location["flag_route"]
    assert route["before"]["named"] == [] and route["ran"], route
    assert route["named"] == "force_offset" and rep.effect_names == ["force_offset"], route
    assert not rep.unexplained.flagged
    assert any(w.startswith("named by the flag route: force_offset") for w in rep.where)
    doc = json.loads(json.dumps(rep.to_dict(), default=float))
    assert doc["flag_route"]["named"] == "force_offset" and doc["flag_route"]["route"] == "flag"
    # the route is what named it
    old = workflow.FLAG_ROUTE
    workflow.FLAG_ROUTE = False
    try:
        off = _diagnose(rec, min_gain=1e3, candidates=FEW)
    finally:
        workflow.FLAG_ROUTE = old
    assert off.effect_names == [] and off.unexplained.flagged
    assert "flag_route" not in off.location


@pytest.mark.slow
def test_a_tanh_virgin_curve_stays_flagged_and_unnamed() -> None:
    """Masing rules on a tanh virgin curve (no candidate draws it): the search's own floors
    lifted, the route must not name a shape absorber or anything else for it."""
    from contactlab.diagnose.scaled_masing import memory, scaled_force
    from contactlab.synthetic._common import block_excitation

    xfun, total, _ = block_excitation(np.array([0.4, 0.7, 1.0]) * 2e-5, np.array([5, 8.5, 3]), 6)
    t = np.arange(round(total * 600)) / 600.0
    x = xfun(t)
    F = scaled_force(lambda s: 50.0 * np.tanh(1e5 * s), 2.0, memory(x))
    rng = np.random.default_rng(3)
    rec = (t, x + rng.normal(0, 2e-8, t.size), F + rng.normal(0, 0.3, t.size))
    rep = _diagnose(rec, min_gain=1e3, candidates=FEW)
    assert rep.unexplained is not None and rep.unexplained.flagged, rep.effect_names
    assert rep.location["flag_route"]["named"] is None, rep.location["flag_route"]
    assert rep.effect_names == []


def test_signal_share_tells_a_spring_from_a_position_wave() -> None:
    """A candidate's own signal that a virgin curve of another shape draws (a spring k·x) has
    a share near 1; a friction that varies along the track (one wavelength over the largest
    amplitude) on a record of several amplitudes stays below the 0.8 the route asks."""
    from contactlab.diagnose._family import Prepared
    from contactlab.diagnose.candidates_tangential import TangentialFamily
    from contactlab.diagnose.flag_route import _signal_share
    from contactlab.masing import Masing

    # three amplitudes (on one steady amplitude every branch is some virgin curve's: any
    # effect odd over the cycle has a share near 1 there, and the route names none of them)
    t = np.arange(12 * 200) / 200.0
    A, ac = 5e-5, 4e4
    x = A * np.sin(2 * np.pi * t) * np.repeat([0.4, 0.7, 1.0], 4 * 200)
    f0 = Masing(40.0, ac).force(x)
    d = Prepared.build(t, x, f0, errors_in_input=False)
    TangentialFamily().prepare(d)
    full = types.SimpleNamespace(params={"h0": 40.0, "ac": ac})
    current = types.SimpleNamespace(full=full, fitted=f0)

    def cand(add):
        return types.SimpleNamespace(full=full, fitted=f0 + add)

    spring = _signal_share("parallel_stiffness", current, cand(2e4 * x), d)
    # the friction force modulated along the track, one wavelength over the amplitude
    wave = _signal_share(
        "position_friction", current, cand(0.02 * f0 * np.cos(2 * np.pi * x / A)), d
    )
    assert spring is not None and spring > 0.95, spring
    assert wave is not None and wave < 0.8, wave
    assert _signal_share("force_offset", current, cand(np.ones_like(x)), d) is None
