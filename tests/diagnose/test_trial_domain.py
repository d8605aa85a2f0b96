"""A candidate's trial fit that steps out of the model's domain is a failed candidate, not
the end of the diagnosis (issue 29: "ac must be finite and > 0, got 0.0" from diagnose)."""

from __future__ import annotations

import tempfile
import warnings
from pathlib import Path

import contactlab
from contactlab.synthetic.rig import rig_recording


def test_trial_fit_reaching_ac_zero_is_fitted_and_the_diagnosis_goes_on() -> None:
    # a rig record in deep pre-sliding with a channel delay, fresh seed 931864028 of
    # benches/eval_diagnose_rig.py: a trial fit drove ac to its bound 0 and the InputError
    # of the Masing element ended the diagnosis; then the trial was a candidate "could not be
    # fitted: ac must be ..." (parallel_stiffness); since the Jacobian takes a one-sided
    # difference where the model refuses a step's end (fitting, stop 47) it is fitted
    rec = rig_recording(
        {"channel_delay": {"tau": 0.0010838150289017342}}, "tangential", seed=931864028,
        fs=1156.8, f=13.84, cycles=16, acA=0.332, x_noise=0.0032, F_noise=0.0076,
        x_drift=-0.0007894239635301654, bits=13,
    )  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp:
        r = contactlab.read_recording(str(rec.to_csv(Path(tmp) / "rec.csv")))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rep = contactlab.diagnose(r, model="tangential", max_effects=1)
    tried = [v for st in rep.steps for v in st.candidates]
    failed = [v for v in tried if v.reason.startswith("could not be fitted")]
    assert not any("ac must be" in v.reason for v in failed), [v.reason for v in failed]
    assert not any(v.accepted for v in failed)
    spring = [v for v in tried if v.name == "parallel_stiffness"]
    assert spring and "gain" in spring[0].reason  # fitted and judged by its gain
    assert rep.effect_names == ["channel_delay"]


def test_drop_check_whose_refit_leaves_the_domain_keeps_the_effect(monkeypatch) -> None:
    # the backward step's refit without an effect (search._drop_check) reached ac = 0 in a
    # difference step on a zero-initial-slope virgin curve (independent generator, seeds
    # 528174202 and 614094203) and the InputError ended the diagnosis: it is a verdict now
    from contactlab.diagnose import search
    from contactlab.errors import InputError

    def out_of_domain(*args, **kwargs):
        raise InputError("ac must be finite and > 0, got 0.0")

    monkeypatch.setattr(search, "evaluate", out_of_domain)
    current = type("T", (), {"effects": ("backlash",), "full": type("F", (), {"params": {}})})
    verdict, reduced = search._drop_check(
        "backlash", None, current, None, {}, 2, 1.0, 3.0, 0.05, 0.0
    )  # fmt: skip
    assert reduced is None and not verdict.accepted
    assert verdict.reason.startswith("could not be fitted: ac must be")
