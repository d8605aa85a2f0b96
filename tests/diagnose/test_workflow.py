"""The discrepancy workflow on recordings with hidden effects (issue 5).

The workflow sees only the recording. Each effect must be named alone, clean data must give
nothing, two effects must both be named, and the held-out RMS must come down to within 1.5×
the noise level estimated from the data. Seeds are arbitrary (not chosen to pass); the
confusion matrix over many seeds, magnitudes and noise levels is benches/eval_diagnose.py.
"""

from __future__ import annotations

import functools
import json

import matplotlib
import numpy as np
import pytest

import contactlab
from contactlab import InputError
from contactlab.diagnose import ExtendedModel
from contactlab.synthetic.diagnosis import TANGENTIAL_EFFECTS, hidden_effect_recording

matplotlib.use("Agg")

SEED = 20261123
# recordings of 18 cycles at 80 samples per cycle keep the suite quick; the bench uses 120
hidden_effect_recording = functools.partial(hidden_effect_recording, samples_per_cycle=80)


def _check_layout(d: dict) -> None:
    # the issue-5 layout; later issues extend it (29: "regime", "h0_check", the effects'
    # "plausibility"; both channels' noise, the stated power of each candidate not named and
    # the test of structure left in the residual), never rename or drop a key
    assert {
        "model", "effects", "steps", "where", "noise_rms", "final_model", "channel_noise",
        "not_detected", "unexplained",
    } <= set(d)  # fmt: skip
    named = {e["name"] for e in d["effects"]}
    for b in d["not_detected"]:
        assert b["effect"] not in named
        assert {"effect", "parameter", "detectable_above", "unit"} <= set(b)
    assert isinstance(d["unexplained"]["flagged"], bool)
    assert isinstance(d["model"], str) and isinstance(d["noise_rms"], float)
    for e in d["effects"]:
        assert {"name", "parameters", "stderr"} <= set(e)
        assert isinstance(e.get("plausibility", ""), str)
        assert all(isinstance(v, float) for v in e["parameters"].values())
    for s in d["steps"]:
        assert set(s) == {"added", "removed", "heldout_rms", "heldout_peak", "energy_error"}
    # forward steps add, backward steps drop: what is left is the effects reported, in order
    kept = [s["added"] for s in d["steps"][1:] if s["added"] is not None]
    for s in d["steps"][1:]:
        if s["removed"] is not None:
            kept.remove(s["removed"])
    assert d["steps"][0]["added"] is None and d["steps"][0]["removed"] is None
    assert kept == [e["name"] for e in d["effects"]]
    assert all(isinstance(w, str) for w in d["where"])
    json.loads(json.dumps(d, allow_nan=False))


#: the branch scale from rest at the turning points (docs/effects.md) makes every branch
#: after the first a Masing branch of (λ h0/2, 2 ac/λ): a base refit absorbs all but the
#: amplitude-dependent loop offset and the first loading, under 1 % of the force's RMS
#: whatever λ (1.1-3), so at a 5 % raw size it is not identifiable (tested apart below)
ALONE = [e for e in TANGENTIAL_EFFECTS if e != "non_masing_scaling"]


@pytest.mark.parametrize("effect", ALONE)
def test_each_effect_is_named_alone(effect):
    rec = hidden_effect_recording([effect], magnitude=0.05, noise=0.01, seed=SEED)
    rep = contactlab.diagnose(rec, model="tangential")
    assert rep.effect_names == [effect]
    assert rep.steps[-1].heldout_rms <= 1.5 * rep.noise_rms
    assert rep.steps[-1].heldout_rms < rep.steps[0].heldout_rms
    _check_layout(rep.to_dict())


def test_branch_scale_is_named_when_its_offset_and_first_loading_show():
    """λ = 2.9 from rest at 0.2 % noise: named, h0 back at the truth (50 N) where the base
    fit read the loop's height λ h0/2 = 72 N; at 5 % raw size (λ = 2.13) nothing is named
    (not identifiable beside a base refit: see ALONE)."""
    rec = hidden_effect_recording(["non_masing_scaling"], magnitude=0.3, noise=0.002, seed=SEED)
    rep = contactlab.diagnose(rec, model="tangential")
    assert rep.effect_names == ["non_masing_scaling"]
    assert rep.final_model.params["lam"] == pytest.approx(2.89, rel=0.15)
    assert rep.final_model.params["h0"] == pytest.approx(50.0, rel=0.15)
    assert "settles" in rep.effects[0].plausibility
    weak = hidden_effect_recording(["non_masing_scaling"], magnitude=0.05, noise=0.01, seed=SEED)
    assert contactlab.diagnose(weak, model="tangential").effect_names == []


def test_clean_data_names_nothing():
    rec = hidden_effect_recording([], noise=0.01, seed=SEED)
    rep = contactlab.diagnose(rec, model="tangential")
    assert rep.effects == []
    d = rep.to_dict()
    _check_layout(d)
    assert d["effects"] == [] and len(d["steps"]) == 1
    assert rep.steps[0].heldout_rms <= 1.5 * rep.noise_rms
    # every candidate of the library was tried and refused, with a reason
    from contactlab.diagnose.effects import registry

    assert {v.name for v in rep.steps[0].candidates} == set(registry("tangential"))
    assert all(not v.accepted for v in rep.steps[0].candidates)


@pytest.mark.parametrize(
    "pair",
    [("channel_delay", "force_offset"), ("parameter_drift", "viscous_damping")],
)
def test_two_effects_are_both_named(pair):
    rec = hidden_effect_recording(list(pair), magnitude=0.05, noise=0.01, seed=SEED + 1)
    rep = contactlab.diagnose(rec, model="tangential")
    assert sorted(rep.effect_names) == sorted(pair)
    assert rep.steps[-1].heldout_rms <= 1.5 * rep.noise_rms
    assert rep.steps[0].heldout_rms > rep.steps[1].heldout_rms > rep.steps[2].heldout_rms


def test_parameters_recovered_within_their_errors():
    rec = hidden_effect_recording(["channel_delay"], magnitude=0.05, noise=0.01, seed=SEED + 2)
    rep = contactlab.diagnose(rec, model="tangential")
    tau_true = rec.truth["effects"]["channel_delay"]["tau"]
    (eff,) = rep.effects
    assert abs(eff.parameters["tau"] - tau_true) < 5 * eff.stderr["tau"]
    assert eff.stderr["tau"] < 0.05 * tau_true
    p = rep.final_model.params
    assert p["h0"] == pytest.approx(50.0, rel=0.01)
    assert p["ac"] == pytest.approx(5e4, rel=0.02)
    # the noise level estimated from the data includes the displacement noise seen through
    # the contact stiffness, so it is a little above the force-sensor noise alone
    assert 0.9 < rep.noise_rms / rec.truth["noise_rms"]["F"] < 1.3


def test_final_model_is_an_ordinary_model():
    rec = hidden_effect_recording(["force_offset"], magnitude=0.05, noise=0.01, seed=SEED + 3)
    rep = contactlab.diagnose(rec)
    m = rep.final_model
    assert isinstance(m, ExtendedModel) and m.effects == ("force_offset",)
    assert isinstance(m.base, contactlab.Masing)
    F = m.simulate(rec.t, rec.data["x"])
    assert np.sqrt(np.mean((F - rec.data["F"]) ** 2)) < 1.2 * rep.noise_rms
    refit = m.fit(rec)
    assert refit.params["F0"] == pytest.approx(m.params["F0"], rel=1e-3)
    assert "F0" in m.report() and m.to_dict()["effects"] == ["force_offset"]
    # a diagnosis can start from the model found before: nothing more to add
    again = contactlab.diagnose(rec, model=m)
    assert again.effects == [] and again.final_model.effects == ("force_offset",)


def test_where_statements_point_at_the_effect():
    rec = hidden_effect_recording(["force_offset"], magnitude=0.08, noise=0.01, seed=SEED + 4)
    rep = contactlab.diagnose(rec)
    assert rep.location["harmonics"]["mean"] > 0.5  # an offset is a constant residual
    assert any("constant offset" in w for w in rep.where)
    assert any("right after a reversal" in w for w in rep.where)
    rec = hidden_effect_recording(["asymmetry"], magnitude=0.08, noise=0.01, seed=SEED + 4)
    rep = contactlab.diagnose(rec)
    h = rep.location["harmonics"]
    assert h["even"] + h["mean"] > h["odd"]  # α|h| is even in the excitation phase


def test_callable_package_attribute_and_plain_arrays():
    import contactlab.synthetic.diagnosis as gen

    rec = gen.hidden_effect_recording(["force_offset"], seed=SEED + 5)
    a = contactlab.diagnose(rec.arrays(), model="tangential")
    b = contactlab.diagnose.diagnose({"t": rec.t, **rec.data})
    assert a.effect_names == b.effect_names == ["force_offset"]
    assert a.to_dict() == b.to_dict()


def test_plots_and_html(tmp_path):
    rec = hidden_effect_recording(["viscous_damping"], magnitude=0.05, seed=SEED + 6)
    rep = contactlab.diagnose(rec)
    from matplotlib.figure import Figure

    from contactlab.report.diagnosis import write_html
    from contactlab.report.diagnosis_plots import (
        plot_gap,
        plot_location,
        plot_overlay,
        plot_residual,
    )

    for fn in (plot_overlay, plot_residual, plot_location, plot_gap):
        ax = Figure().add_subplot()
        assert fn(rep, ax=ax) is ax
        assert ax.has_data()
    with pytest.deprecated_call():  # the old method forwards (issue 32)
        rep.plot_gap(ax=Figure().add_subplot())
    path = write_html(rep, tmp_path / "out")
    text = path.read_text(encoding="utf-8")
    assert text.count("data:image/png;base64,") == 4
    assert "&quot;viscous_damping&quot;" in text and "Gap shrink" in text
    files = sorted(p.relative_to(tmp_path / "out").as_posix() for p in path.parent.rglob("*.*"))
    assert files == [
        "diagnose.html",
        "diagnose.json",
        "figures/gap.png",
        "figures/location.png",
        "figures/loops.png",
        "figures/residual.png",
    ]
    assert json.loads((path.parent / "diagnose.json").read_text()) == rep.to_dict()
    assert "viscous_damping" in rep.summary() and "base model" in rep.table()


def test_bad_input_is_named():
    rec = hidden_effect_recording([], seed=SEED + 7)
    t, x, F = rec.arrays()
    bad = F.copy()
    bad[123] = np.nan
    with pytest.raises(InputError, match=r"F\[123\]"):
        contactlab.diagnose((t, x, bad))
    with pytest.raises(InputError, match="samples"):
        contactlab.diagnose((t, x, F[:-5]))
    with pytest.raises(InputError, match="model must be"):
        contactlab.diagnose(rec, model="rotational")
    with pytest.raises(InputError, match="max_effects"):
        contactlab.diagnose(rec, max_effects=-1)
    with pytest.raises(InputError, match="folds"):
        contactlab.diagnose(rec, folds=1)
    with pytest.raises(InputError, match="unknown tangential candidate"):
        contactlab.diagnose(rec, candidates=["wear"])
    with pytest.raises(InputError, match="channels 'x' and 'F'"):
        contactlab.diagnose({"t": t, "x": x, "force": F}, model="tangential")
    n = 260  # two cycles only: nothing to hold out
    with pytest.raises(InputError, match="complete excitation cycles"):
        contactlab.diagnose((t[:n], rec.data["x"][:n], rec.data["F"][:n]))


def test_cli_diagnose_writes_json_and_report(tmp_path, capsys):
    from contactlab.cli import main
    from contactlab.io import write_recording

    rec = hidden_effect_recording(["asymmetry"], magnitude=0.05, noise=0.01, seed=SEED + 8)
    path = write_recording(tmp_path / "run.csv", rec)
    out, rep = tmp_path / "result.json", tmp_path / "report"
    code = main(
        ["diagnose", str(path), "--model", "tangential", "--json", str(out), "--report", str(rep)]
    )
    assert code == 0
    d = json.loads(out.read_text(encoding="utf-8"))
    _check_layout(d)
    assert [e["name"] for e in d["effects"]] == ["asymmetry"]
    assert (rep / "diagnose.html").is_file()
    text = capsys.readouterr().out
    assert "asymmetry" in text and "held-out RMS" in text
    # a file without the channels the model needs: one clear error line, exit code 1
    code = main(["diagnose", str(path), "--model", "normal"])
    assert code == 1
    assert "diagnose: error:" in capsys.readouterr().err


def test_unexplained_gap_is_reported_not_hidden():
    # the delay is hidden, but only the offset candidate is offered: nothing is named and the
    # report says the remaining discrepancy is outside the library
    rec = hidden_effect_recording(["channel_delay"], magnitude=0.05, seed=SEED + 9)
    rep = contactlab.diagnose(rec, candidates=["force_offset"])
    assert rep.effects == []
    assert rep.steps[-1].heldout_rms > 2 * rep.noise_rms
    assert "not explained by any candidate" in rep.where[-1]


def test_independent_synthetic_recordings():
    # recordings from contactlab.tangential's own simulator (another route to the data)
    from contactlab.synthetic.tangential import synthetic_recording

    kw = {"frequency": 5.0, "n_cycles": 16, "fs": 600.0, "noise": 0.01, "seed": SEED % 1000}
    clean = synthetic_recording(50.0, 5e4, 4e-5, **kw)
    assert contactlab.diagnose(clean).effects == []
    drift = synthetic_recording(50.0, 5e4, 4e-5, drift=2.0, **kw)
    (eff,) = contactlab.diagnose(drift).effects
    assert eff.name == "force_drift"
    assert eff.parameters["F1"] == pytest.approx(2.0 * 16 / 5.0, rel=0.05)  # N/s × duration


@pytest.mark.parametrize(
    ("make", "match"),
    [
        (lambda t, x, F: (t, x, 0.0 * F), r"channel 'F' is constant \(0 N"),
        (lambda t, x, F: (t, x, 0.0 * F + 3.0), r"channel 'F' is constant \(3 N"),
        (lambda t, x, F: (t, x, F * 1e300), r"channel 'F' holds .*e\+30\d N at sample \d+"),
        (lambda t, x, F: (t, x * 1e300, F), r"channel 'x' holds .* m at sample"),
        (lambda t, x, F: (t, x, F * 1e-300), "no measurable signal"),
        (lambda t, x, F: (t * 1e300, x, F), "not a time in seconds"),
        (lambda t, x, F: (t, x, -F), r"wrong way: ∮F dx = -"),
        (
            lambda t, x, F: (t, x, np.random.default_rng(1).normal(0.0, 1.0, F.size)),
            "force does not follow the displacement",
        ),
    ],
)
def test_bad_data_gets_a_sentence_about_the_data(make, match):
    # issue 8: no "initial value 1.0 outside [nan, nan]", "h0 must be finite and > 0, got
    # -2.9e-17", overflow warning or traceback reaches the user (warnings are errors here)
    rec = hidden_effect_recording([], seed=SEED + 10)
    with pytest.raises(InputError, match=match) as exc:
        contactlab.diagnose(make(*rec.arrays()), max_effects=1)
    assert "initial value" not in str(exc.value) and "must be finite" not in str(exc.value)


def test_input_noise_does_not_buy_a_sub_sample_delay():
    # issue 8 item 3, an independent route to the data: Masing from rest, ac·A = 2, 500
    # samples per cycle, 20 cycles, F noise 0.5 % of h0 and x noise 0.2 % of the amplitude.
    # Before errors in variables the clean record got channel_delay (τ ≈ 0.45 sample) named,
    # and so did each single-effect record beside its effect.
    h0, ac = 40.0, 4e4
    amp = 2.0 / ac
    t = np.arange(20 * 500 + 1) / 2500.0
    x = amp * np.sin(2 * np.pi * 5.0 * t)
    rng = np.random.default_rng(SEED + 11)
    xm = x + rng.normal(0.0, 0.002 * amp, x.size)
    F = contactlab.Masing(h0, ac).force(x) + rng.normal(0.0, 0.005 * h0, x.size)
    rep = contactlab.diagnose((t, xm, F))
    assert rep.effects == []
    assert rep.final_model.params["h0"] == pytest.approx(h0, rel=0.02)
    # the displacement noise is found from the data
    assert rep._data.extra["u_noise"] == pytest.approx(0.002 * amp, rel=0.2)
    rep = contactlab.diagnose((t, xm, F + 0.02 * h0))
    assert rep.effect_names == ["force_offset"]


def test_a_candidate_that_cannot_be_fitted_is_skipped_not_fatal(monkeypatch):
    """A candidate whose fit fails (the normal joint's solver can reject a trial stiffness
    with no equilibrium) is reported as not fitted; the diagnosis goes on with the others."""
    from contactlab.diagnose import search
    from contactlab.errors import ConvergenceError

    real_fit = search.fit

    def fit(family, effects, *args, **kwargs):
        if "inertia" in effects:
            raise ConvergenceError("the model rejected the parameters the solver tried")
        return real_fit(family, effects, *args, **kwargs)

    monkeypatch.setattr(search, "fit", fit)  # the search's moves fit the candidates
    rec = hidden_effect_recording(["force_offset"], magnitude=0.05, noise=0.01, seed=SEED + 77)
    rep = contactlab.diagnose(rec, candidates=["force_offset", "inertia"], max_effects=1)
    assert rep.effect_names == ["force_offset"]
    (v,) = [v for v in rep.steps[0].candidates if v.name == "inertia"]
    assert not v.accepted and v.reason.startswith("could not be fitted")


def test_cli_diagnose_takes_fs_for_a_file_without_time(tmp_path, capsys):
    from contactlab.cli import main

    rec = hidden_effect_recording(["asymmetry"], magnitude=0.05, noise=0.01, seed=SEED + 8)
    fs = 1.0 / float(rec.t[1] - rec.t[0])
    path = tmp_path / "no_t.csv"
    np.savetxt(path, np.column_stack([rec["x"], rec["F"]]), delimiter=",", header="x,F",
               comments="", fmt="%.17g")  # fmt: skip
    assert main(["diagnose", str(path), "--model", "tangential"]) == 1
    assert "--fs" in capsys.readouterr().err
    out = tmp_path / "d.json"
    code = main(["diagnose", str(path), "--model", "tangential", "--fs", repr(fs),
                 "--json", str(out)])  # fmt: skip
    assert code == 0
    assert [e["name"] for e in json.loads(out.read_text())["effects"]] == ["asymmetry"]
