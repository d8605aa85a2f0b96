"""The stepwise search's moves (diagnose/search.py): the backward step and the parsimony
rule for effects acting through the velocity."""

from __future__ import annotations

import numpy as np

from contactlab.diagnose._family import Prepared
from contactlab.diagnose._parallel import EvaluationCounter
from contactlab.diagnose._signal import noise_rms
from contactlab.diagnose.candidates_tangential import TangentialFamily
from contactlab.diagnose.search import SearchState, StepwiseSearch
from contactlab.diagnose.select import evaluate, fit, fold_masks
from contactlab.diagnose.workflow import Step
from contactlab.synthetic.diagnosis import hidden_effect_recording


def _search(rec, effects):
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


def test_backward_step_drops_an_effect_the_others_explain():
    """A model holding a force drift beside the offset that made the record: refitted
    without the drift, the offset leaves it nothing to add, and the backward step drops it
    with a step and a sentence."""
    rec = hidden_effect_recording(["force_offset"], magnitude=0.05, noise=0.01, seed=5,
                                  samples_per_cycle=80)  # fmt: skip
    search, st = _search(rec, ["force_offset", "force_drift"])
    search.backward(st)
    assert st.added == ["force_offset"]
    assert st.steps[-1].removed == "force_drift" and st.steps[-1].label == "- force_drift"
    assert not st.steps[-1].removal.accepted
    assert st.where[-1].startswith("backward step: force_drift dropped")


def test_parsimony_keeps_one_of_two_velocity_terms_that_share_the_gain():
    """A viscous term and a channel delay both act through the velocity: on a record with
    a viscous force only, they are not named together."""
    rec = hidden_effect_recording(["viscous_damping"], magnitude=0.05, noise=0.01, seed=6,
                                  samples_per_cycle=80)  # fmt: skip
    search, st = _search(rec, ["viscous_damping", "channel_delay"])
    search.parsimony(st)
    assert st.added == ["viscous_damping"]
    assert any(w.startswith("parsimony: channel_delay dropped") for w in st.where)
