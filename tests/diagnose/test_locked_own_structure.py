"""The locked floor's effect on a flagged record: withdrawn as a patch over a misfit unless
the structure the phase bins flag without it is its own (issue 29, stop 53)."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from contactlab.diagnose import workflow


def _u(by=(), rivals=(), patches=(), flagged=True):
    return SimpleNamespace(
        flagged=flagged, calibrated={"by": list(by)}, rivals=tuple(rivals),
        patches=tuple(patches), absorbing=(), statistic=0.0, threshold=1.0, backbone={},
    )  # fmt: skip


def test_own_structure_needs_phase_bins_alone_without_and_no_structure_test_with() -> None:
    with_it = _u(rivals=[{"effect": "position_friction"}], patches=[{"x": 1}])
    own = workflow._takes_own_structure(with_it, _u(by=["phase_bins"]))
    assert own and "phase bins" in own
    # a virgin curve of another shape draws the structure (the free-form curve flags): a patch
    assert workflow._takes_own_structure(with_it, _u(by=["phase_bins", "backbone"])) is None
    assert workflow._takes_own_structure(with_it, _u(by=["backbone"])) is None
    # with it a structure test still flags: it left the misfit
    assert workflow._takes_own_structure(_u(by=["phase_bins"]), _u(by=["phase_bins"])) is None
    # without it nothing flags, or the refit's test is missing: not this rule's question
    assert workflow._takes_own_structure(with_it, _u(flagged=False)) is None
    assert workflow._takes_own_structure(with_it, None) is None
    # the shape checks flag without it too: the structure reads as a shape misfit
    assert workflow._takes_own_structure(with_it, _u(by=["phase_bins"], patches=[1])) is None


@pytest.mark.parametrize("rule", [True, False])
def test_withdraw_locked_keeps_an_effect_that_took_the_flagged_structure(monkeypatch, rule):
    calls = []
    monkeypatch.setattr(workflow, "LOCKED_OWN_STRUCTURE", rule)
    monkeypatch.setattr(workflow, "_locked_on_misfit", lambda st, d, ck: ("position_friction", "w"))
    monkeypatch.setattr(workflow, "_signature_at", lambda *a: None)
    monkeypatch.setattr(workflow, "_unexplained_without", lambda *a: (False, _u(by=["phase_bins"])))

    def withdraw(*a):
        calls.append(a[-1])
        return a[-2]

    monkeypatch.setattr(workflow, "_withdraw", withdraw)
    monkeypatch.setattr(workflow, "_assess", lambda b, d, st, *a: {"unexplained": a[-1]})
    monkeypatch.setattr(workflow, "_rivals", lambda b, d, st, ck: ck)
    monkeypatch.setattr(workflow, "_calibrated", lambda b, d, st, ck: ck)
    st = SimpleNamespace(added=["position_friction"], where=[])
    checks = {"unexplained": _u(rivals=[{"effect": "position_friction"}])}
    workflow._withdraw_locked(None, None, st, [], 3.0, 0.05, 2, None, {}, checks)
    if rule:
        assert calls == [] and any("is kept" in w for w in st.where)
    else:
        assert calls == [[("position_friction", "w")]]
