"""Fitting joint laws to force-displacement records (contactlab.joints.fit)."""

from __future__ import annotations

import itertools
import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from contactlab.errors import InputError
from contactlab.joints import Dahl, Jenkins, JointRecord, LuGre, Segalman, compare, fit
from contactlab.joints.fit import loop_features, thin_indices, turning_points


def _history(n=1200, cycles=3.0, amp=2e-3, seed=0):
    t = np.linspace(0.0, cycles, n)
    x = amp * np.sin(2 * np.pi * t) * (0.6 + 0.4 * np.sin(0.7 * np.pi * t + seed))
    return t, x


def test_jenkins_recovered_from_noisy_loops_within_its_errors():
    rng = np.random.default_rng(7)
    t, x = _history()
    true = Jenkins(k=5e3, fs=4.0)
    F = true.force(t, x) + rng.normal(0, 0.05, t.size)
    res = fit(t, x, F, law="jenkins")
    assert res.success
    for n, v in (("k", 5e3), ("fs", 4.0)):
        p = res.params[n]
        assert p.stderr is not None and p.stderr > 0
        assert abs(p.value - v) < 5 * p.stderr, (n, p.value, p.stderr)
    assert set(res.correl) == {"k", "fs"}


def test_multi_record_fit_shares_the_parameters_and_predicts_a_new_history():
    true = Segalman(F_S=6.0, K_T=8e3, chi=-0.4, beta=0.3)
    recs = []
    for k, amp in enumerate((0.6e-3, 2e-3)):
        t, x = _history(900, amp=amp, seed=k)
        recs.append(JointRecord(t, x, true.force(t, x) * 1.0, f"A{k}"))
    res = fit(recs, law="segalman")
    assert res.success and res.records == ["A0", "A1"]
    t, x = _history(700, amp=1.3e-3, seed=5)
    F_new = true.force(t, x)
    assert np.max(np.abs(res.force(t, x) - F_new)) < 1e-6 * np.max(np.abs(F_new))


def test_lugre_fit_converges_from_loop_start_values():
    rng = np.random.default_rng(3)
    t = np.linspace(0.0, 2.0, 1600)
    x = 1e-3 * np.sin(2 * np.pi * t)
    true = LuGre(sigma0=2e5, sigma1=20.0, sigma2=8.0, Fc=10.0, Fs=13.0, vs=2e-3)
    F = true.force(t, x) + rng.normal(0, 0.05, t.size)
    res = fit(t, x, F, law="lugre")
    assert res.success
    assert res.params["Fc"].value == pytest.approx(10.0, rel=0.05)
    assert res.params["Fs"].value == pytest.approx(13.0, rel=0.05)
    assert not res.params["delta"].vary  # held at its start by default
    tab = compare({"fit": res}, [(t, x, F)])
    assert tab.pooled("fit")["rrse"] < 0.02


def test_linear_terms_are_recovered_exactly():
    t, x = _history(1000)
    law = Dahl(sigma0=1e4, Fc=3.0, alpha=1.0)
    P = law.force(t, x, float(x[0]))
    v = np.gradient(x, t, edge_order=2)
    a = np.gradient(v, t, edge_order=2)
    F = P + 0.7 + 0.2 * np.abs(P) + 0.05 * a
    res = fit(t, x, F, law=Dahl(sigma0=1.3e4, Fc=2.5, alpha=1.0), fixed=["alpha"], offset=True,
              asymmetry=True, mass=True)  # fmt: skip
    assert res.success
    assert res.terms["offset"] == pytest.approx(0.7, rel=1e-6)
    assert res.terms["asymmetry"] == pytest.approx(0.2, rel=1e-6)
    assert res.terms["mass"] == pytest.approx(0.05, rel=1e-5)
    assert res.params["sigma0"].value == pytest.approx(1e4, rel=1e-6)
    np.testing.assert_allclose(res.force(t, x), F, atol=1e-6)


def test_unidentified_parameter_is_said_so_never_plus_minus_nan():
    # a loop that never slips: only the stiffness is seen, the slip force is not determined
    rng = np.random.default_rng(1)
    t, x = _history(600, amp=1e-4)
    F = Jenkins(k=5e3, fs=4.0).force(t, x) + rng.normal(0, 1e-3, t.size)
    res = fit(t, x, F, law=Jenkins(k=4e3, fs=6.0), restarts=False)
    p = res.params["fs"]
    assert p.identifiable is False
    assert p.stderr is None
    assert p.note.startswith("not identifiable: ")
    text = res.report()
    assert "nan" not in text.lower()
    doc = json.dumps(res.to_dict(), allow_nan=False)
    assert "not identifiable" in doc
    assert res.params["k"].value == pytest.approx(5e3, rel=1e-3)


def test_mask_compares_only_the_selected_samples():
    t, x = _history(900)
    F = Jenkins(k=5e3, fs=4.0).force(t, x)
    bad = F.copy()
    bad[:300] += 50.0  # garbage outside the mask
    mask = np.zeros(t.size, bool)
    mask[300:] = True
    res = fit([JointRecord(t, x, bad, "r", mask)], law=Jenkins(k=3e3, fs=3.0))
    assert res.params["k"].value == pytest.approx(5e3, rel=1e-6)
    assert res.n_samples == 600


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 10_000), st.integers(2, 40))
def test_thinning_is_exact_for_rate_independent_laws(seed, every):
    # a path through random turning points (each swing at least 5 % of the range), sampled
    # finely: thinning keeps every turning point, so the forces there are the full run's
    rng = np.random.default_rng(seed)
    swings = rng.uniform(0.05, 1.0, 12) * np.where(np.arange(12) % 2 == 0, 1.0, -1.0)
    ends = (np.cumsum(swings) - 0.5) * 1e-3
    x = np.concatenate([np.linspace(a, b, 37)[:-1] for a, b in itertools.pairwise(ends)])
    n = x.size
    t = np.arange(n) / 100.0
    idx = thin_indices(JointRecord(t, x, np.zeros(n), "r"), every)
    turns = np.flatnonzero(np.diff(np.sign(np.diff(x))) != 0) + 1
    assert turns.size == 10 and np.isin(turns, idx).all()
    assert idx[0] == 0 and idx[-1] == n - 1
    for law in (Jenkins(k=1e4, fs=0.5), Segalman(F_S=0.5, K_T=1e4, chi=-0.5, beta=0.2),
                Dahl(sigma0=1e4, Fc=0.5, alpha=1.0)):  # fmt: skip
        full = law.force(t, x, float(x[0]))[idx]
        thin = law.force(t[idx], x[idx], float(x[0]))
        np.testing.assert_allclose(thin, full, rtol=0, atol=1e-12)


def test_turning_points_with_a_gate():
    x = np.array([0.0, 1.0, 0.98, 1.2, 0.0, 0.5, 0.45, 0.47, -1.0, 0.0])
    # every local extremum without a gate; the 0.02 wiggles dropped with a gate of 0.1
    assert turning_points(x, 0.0).tolist() == [1, 2, 3, 4, 5, 6, 7, 8]
    assert turning_points(x, 0.1).tolist() == [0, 3, 4, 5, 8]


def test_thinned_fit_matches_the_full_one_without_noise():
    t, x = _history(3000)
    F = Jenkins(k=5e3, fs=4.0).force(t, x)
    a = fit(t, x, F, law=Jenkins(k=3e3, fs=3.0), max_samples=500)
    assert a.thinned_every > 1 and a.n_samples < 1000
    assert a.params["k"].value == pytest.approx(5e3, rel=1e-6)


def test_loop_features_of_a_jenkins_loop():
    t, x = _history()
    f = loop_features([JointRecord(t, x, Jenkins(k=5e3, fs=4.0).force(t, x), "r")])
    assert f.force_level == pytest.approx(4.0, rel=1e-3)
    # the force swings through 80 % of 2 fs over 1.6 fs / k of travel
    assert f.stiffness == pytest.approx(5e3, rel=0.05)


def test_backlash_chain_and_fit_of_a_dead_band():
    from contactlab.joints import Backlash

    t = np.linspace(0.0, 3.0, 900)
    x = 3e-3 * np.sin(2 * np.pi * t)
    true = Backlash(1e-3, Jenkins(k=2e4, fs=10.0))
    F = true.force(t, x, 0.0)
    res = fit(t, x, F, law="backlash:jenkins")
    assert res.law.name == "backlash"
    assert res.params["gap"].value == pytest.approx(1e-3, rel=1e-3)


def test_bad_input_is_refused_with_a_named_error():
    t, x = _history(100)
    F = np.sin(t)
    with pytest.raises(InputError, match="unknown law 'nope'"):
        fit(t, x, F, law="nope")
    with pytest.raises(InputError, match="F has 99 samples"):
        fit(t, x, F[:-1], law="jenkins")
    with pytest.raises(InputError, match="time must increase"):
        fit(t[::-1].copy(), x, F, law="jenkins")
    with pytest.raises(InputError, match="constant"):
        fit(t, x, np.ones_like(t), law="jenkins")
    with pytest.raises(InputError, match="unknown parameter"):
        fit(t, x, F, law="jenkins", fixed=["sigma0"])
    with pytest.raises(InputError, match=r"x.* not finite"):
        fit(t, np.where(t > 1, np.nan, x), F, law="jenkins")
    with pytest.raises(InputError, match="max_samples must be"):
        fit(t, x, F, law="jenkins", max_samples=0)
    with pytest.raises(InputError, match="give t, x and F"):
        fit(t, x, law="jenkins")


def test_to_dict_is_json_and_names_units():
    t, x = _history(400)
    F = Jenkins(k=5e3, fs=4.0).force(t, x) + 0.01 * np.cos(17 * t)
    res = fit(t, x, F, law="jenkins", offset=True)
    d = res.to_dict()
    json.dumps(d, allow_nan=False)
    assert d["units"]["k"] == "N/m" and d["units"]["offset"] == "N"
    assert d["law"] == "jenkins" and math.isfinite(d["chisqr"])


def test_bouc_wen_identifies_the_products_beta_gamma_and_beta_delta():
    from contactlab.joints import BoucWen

    t = np.linspace(0.0, 3.0, 900)
    x = 2e-3 * np.sin(2 * np.pi * t)
    F = BoucWen(alpha=5e3, beta=800.0, gamma=0.5, delta=0.5).force(t, x)
    F = F + np.random.default_rng(0).normal(0, 0.05, t.size)
    res = fit(t, x, F, law="bouc_wen")
    assert res.success and not res.params["beta"].vary  # ν = 1: β only scales γ, δ
    b = res.law.beta
    assert b * res.law.gamma == pytest.approx(400.0, rel=0.05)
    assert b * res.law.delta == pytest.approx(400.0, rel=0.05)
