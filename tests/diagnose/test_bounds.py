"""The bounds on a diagnosis's work (issue 12, the slow fuzz input): a budget of model
evaluations for the candidate search, and a cap on the ODE steps of one normal-contact
evaluation. Either, when it binds, is reported, never a hang."""

from __future__ import annotations

import json

import numpy as np

import contactlab
from contactlab.diagnose import candidates_normal, search
from contactlab.synthetic.diagnosis import hidden_effect_recording


def test_spent_budget_leaves_candidates_untested_and_says_so(monkeypatch):
    rec = hidden_effect_recording(["force_offset"], magnitude=0.05, seed=2)
    monkeypatch.setattr(search, "MAX_EVALUATIONS", 1)  # spent by the base fit already
    report = contactlab.diagnose(rec, model="tangential")
    assert report.effect_names == []
    reasons = [v.reason for v in report.steps[0].candidates]
    assert reasons and all(r.startswith("not tested: the budget of 1 model") for r in reasons)
    said = [w for w in report.where if "candidate search stopped after" in w]
    assert len(said) == 1 and "force_offset" in said[0].split("not tested: ")[1]
    json.loads(report.to_json())  # the untested verdicts serialise (no NaN in the JSON)


def test_default_budget_does_not_bind_on_a_typical_diagnosis():
    rec = hidden_effect_recording(["force_offset"], magnitude=0.05, seed=2)
    report = contactlab.diagnose(rec, model="tangential")
    assert report.effect_names == ["force_offset"]
    assert not any("candidate search stopped" in w for w in report.where)


def test_ode_step_cap_ends_one_evaluation_with_a_finite_held_value(monkeypatch):
    # the adaptive route (the reference of the fixed-grid one the candidates use) keeps it
    t = np.arange(3000) * 1e-3
    pd = 0.4e6 * np.sin(2 * np.pi * 5 * t)
    full = candidates_normal.nonlinear_adaptive(t, pd, (1.2e12, 0.0), 0.2, 2 * np.pi * 5)
    assert np.all(np.isfinite(full))
    monkeypatch.setattr(candidates_normal, "MAX_STEPS_PER_SAMPLE", 0)  # cap: 1000 steps
    cut = candidates_normal.nonlinear_adaptive(t, pd, (1.2e12, 0.0), 0.2, 2 * np.pi * 5)
    assert cut.shape == full.shape and np.all(np.isfinite(cut))
    stop = int(np.argmax(cut != full))
    assert 0 < stop < t.size - 1  # stopped inside the record, the same response up to there
    np.testing.assert_array_equal(cut[:stop], full[:stop])
    assert np.all(cut[stop:] == cut[stop])  # then the last value held


def test_grid_evaluation_work_is_bounded_and_a_failed_solve_holds_its_last_value():
    """The fixed-grid route the stiffness candidates use has no step cap to bind: each sample
    interval takes at most 1 + 2 + ... + 64 = 127 times its steps (retries) of at most 20
    Newton iterations. A law whose response runs to k_s = 0 ends with a failed solve, and
    the candidate's prediction holds the last value reached (finite)."""
    from contactlab.normal import NonlinearContact

    t = np.arange(3000) * 1e-3
    pd = 0.4e6 * np.sin(2 * np.pi * 5 * t)
    coeffs = (1.2e12, 1e19)  # k_s = 0 at δ = -1.2e-7 m, inside the response's range
    res = NonlinearContact(k_s_delta=list(coeffs), psi=0.2, omega=2 * np.pi * 5).simulate_grid(
        t, pd
    )
    assert not res.success and 0 < res.delta.size < t.size
    assert res.n_steps <= 127 * t.size
    out = candidates_normal.nonlinear(t, pd, coeffs, 0.2, 2 * np.pi * 5)
    assert out.shape == t.shape and np.all(np.isfinite(out))
    np.testing.assert_array_equal(out[: res.delta.size], res.delta)
    assert np.all(out[res.delta.size :] == res.delta[-1])
