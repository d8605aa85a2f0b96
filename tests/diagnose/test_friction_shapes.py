"""The friction-shape effects as docs/effects.md §1 defines them (issue 29 item 4).

``stribeck``: ``h0(v) = h0 (1 + s exp(-(ẋ/v_s)²))`` (Gaussian, not ``exp(-|ẋ|/v_s)``);
``position_friction``: one wave of its own length along the track, ``h0 (1 + a1 cos φ + b1
sin φ)``, ``φ = 2π (x - x_mid)/L`` (harmonics of the stroke do not follow a wave of another
length). Checked term by term against the definitions, and on records of the independent
rig, where the old shapes named an extra effect beside the true one.
"""

from __future__ import annotations

import numpy as np
import pytest

import contactlab
from contactlab.diagnose._family import Prepared
from contactlab.diagnose.candidates_tangential import TangentialFamily
from contactlab.diagnose.effects import registry
from contactlab.synthetic.rig import rig_recording

H0, AC = 40.0, 4.0e4


def _prepared(acA=2.0):
    rec = rig_recording({}, "tangential", seed=3, fs=2000.0, f=5.0, cycles=4, acA=acA,
                        x_noise=0.0, F_noise=0.0, bits=None)  # fmt: skip
    d = Prepared.build(rec.t, rec.channels["x"], rec.channels["F"])
    fam = TangentialFamily()
    fam.prepare(d)
    return fam, d


def test_stribeck_is_gaussian_in_the_speed():
    fam, d = _prepared()
    p = {"h0": H0, "ac": AC, "s": 0.2, "v_s": 0.3 * float(np.sqrt(np.mean(d.ud**2)))}
    base = fam.predict(p, (), d)
    got = fam.predict(p, ("stribeck",), d)
    want = base * (1.0 + 0.2 * np.exp(-((d.ud / p["v_s"]) ** 2)))
    assert np.max(np.abs(got - want)) <= 1e-12 * H0


def test_position_friction_is_one_wave_of_its_own_length():
    fam, d = _prepared()
    A = 0.5 * float(np.ptp(d.u))
    L, eps, phi = 1.5 * A, 0.1, 0.8
    xm = d.extra["x_mid"]
    # h0 (1 + ε cos(2π x/L + φ)) in the candidate's parameters (phase about x_mid)
    a1 = eps * np.cos(2 * np.pi * xm / L + phi)
    b1 = -eps * np.sin(2 * np.pi * xm / L + phi)
    p = {"h0": H0, "ac": AC, "a1": a1, "b1": b1, "L": L}
    got = fam.predict(p, ("position_friction",), d)
    want = fam.predict(p, (), d) * (1.0 + eps * np.cos(2 * np.pi * d.u / L + phi))
    assert np.max(np.abs(got - want)) <= 1e-12 * H0
    eff = registry("tangential")["position_friction"]
    assert eff.size(p, {"a1": 0.01, "b1": 0.01})[0] == pytest.approx(eps)
    assert not eff.plausible(d, {**p, "L": 30 * A}).ok  # a level over the stroke
    assert eff.plausible(d, p).ok


@pytest.mark.parametrize(
    ("effect", "params"),
    [
        ("stribeck", {"s": 0.2}),
        ("position_friction", {"eps": 0.1, "L": 2 * 0.6 * 1.5 / AC, "phi": 2.0}),
    ],
)
def test_rig_friction_shapes_named_alone(tmp_path, effect, params):
    rec = rig_recording({effect: params}, "tangential", seed=1112, fs=1500.0, f=8.0, cycles=8,
                        acA=1.5, x_noise=0.007, F_noise=0.01)  # fmt: skip
    r = contactlab.read_recording(str(rec.to_csv(tmp_path / "r.csv")))
    rep = contactlab.diagnose(r, model="tangential")
    assert rep.effect_names == [effect]
    if effect == "position_friction":
        assert rep.effects[0].parameters["L"] == pytest.approx(params["L"], rel=0.1)


def _search(rec, effects):
    """A stepwise search holding ``effects`` fitted to ``rec`` (as tests/diagnose/
    test_search.py builds it)."""
    from contactlab.diagnose._parallel import EvaluationCounter
    from contactlab.diagnose._signal import noise_rms
    from contactlab.diagnose.search import SearchState, StepwiseSearch
    from contactlab.diagnose.select import evaluate, fit, fold_masks
    from contactlab.diagnose.workflow import Step

    fam = TangentialFamily()
    d = Prepared.build(*rec.arrays())
    d.extra["evaluations"] = EvaluationCounter()
    fam.prepare(d)
    scales = fam.scales(d)
    fold_masks(d, 2)
    base = fit(fam, (), d, np.ones(d.y.size, bool), fam.initial_base(d), scales)
    sigma = noise_rms(fam.predict(base.params, (), d) - d.y)
    start = dict(base.params)
    for e in effects:
        start.update(fam.start_effect(e, start, d, d.y - fam.predict(base.params, (), d)))
    current = evaluate(fam, tuple(effects), d, start, scales, 2)
    search = StepwiseSearch(fam, list(fam.candidates), d, scales, 2, sigma, 3.0, 0.05, 0.0,
                            dict(base.params), 3, Step)  # fmt: skip
    st = SearchState(current, [Step(None, 1.0, 1.0, 0.0)], [], [current], added=list(effects))
    return search, st


def test_parsimony_between_friction_shapes():
    """Stribeck and position friction both reshape the friction between reversals (item 5):
    on a Stribeck record they are not named together; with both in the record, each stands
    on its own after the other and both stay."""
    from contactlab.synthetic.diagnosis import hidden_effect_recording

    kw = {"noise": 0.01, "seed": 7, "samples_per_cycle": 80}
    search, st = _search(hidden_effect_recording(["stribeck"], magnitude=0.05, **kw),
                         ["stribeck", "position_friction"])  # fmt: skip
    search.parsimony(st)
    assert st.added == ["stribeck"]
    assert any(w.startswith("parsimony: position_friction dropped") for w in st.where)
    both = hidden_effect_recording({"stribeck": 0.05, "position_friction": 0.05}, **kw)
    search, st = _search(both, ["stribeck", "position_friction"])
    search.parsimony(st)
    assert st.added == ["stribeck", "position_friction"]
    assert any("friction along the branch" in w and "named together" in w for w in st.where)
