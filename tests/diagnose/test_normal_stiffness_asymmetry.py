"""Stiffening law against loss asymmetry (docs/effects.md §2): the physics the choice
between them reads, and the rule that makes it (issue 29, stop 42)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from contactlab.diagnose.candidates_normal import (
    kelvin_voigt_asymmetric,
    kelvin_voigt_exact,
    nonlinear_viscous,
)
from contactlab.diagnose.effects import registry
from contactlab.diagnose.effects.normal.asymmetric_branches import (
    shape_evidence,
    startup_samples,
)

K, PSI, F = 1.3e12, 0.15, 2.0
W = 2 * np.pi * F


def _steady(kind: str, size: float):
    """δ of the joint with one effect minus the linear joint's, over the last 4 of 12
    cycles of p = pa sin ωt, and the phase θ of the linear joint's δ."""
    t = np.arange(0, 12 / F, 1 / (400 * F))
    pa = 2e5
    pd = pa * np.sin(W * t)
    d0 = kelvin_voigt_exact(t, pd, K, PSI, W)
    D = pa / K
    if kind == "stiffness":
        d1 = nonlinear_viscous(t, pd, (K, size * K / D, 0.0), PSI, W, passes=8)
    else:
        d1 = kelvin_voigt_asymmetric(t, pd, K, PSI, W, size, passes=50, tol=1e-12)
    keep = t >= 8 / F
    lag = np.arctan(PSI / (2 * np.pi))
    theta = W * t[keep] - lag
    return d1[keep] - d0[keep], theta, D


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_mean_shift_against_second_harmonic(sign):
    """For the same 2ω part (along cos 2θ) the stiffening law moves the mean displacement
    by -1 times it and the loss asymmetry by +3/2 times it (κ1 δ² against a h |δ'|)."""
    ratios = {}
    for kind, size in (("stiffness", 0.05 * sign), ("asymmetry", 0.4 * sign)):
        s, theta, _ = _steady(kind, size)
        X = np.column_stack([np.ones_like(theta), np.cos(2 * theta), np.sin(2 * theta),
                             np.cos(4 * theta)])  # fmt: skip
        beta, *_ = np.linalg.lstsq(X, s, rcond=None)
        ratios[kind] = beta[0] / beta[1]
    assert ratios["stiffness"] == pytest.approx(-1.0, rel=0.1)
    assert ratios["asymmetry"] == pytest.approx(1.5, rel=0.1)


def test_asymmetry_has_fourth_harmonic_stiffness_not():
    """|δ'| has a kink at each turning point: its cos 4θ part is -1/5 of its cos 2θ part;
    a δ² law has none to first order."""
    out = {}
    for kind, size in (("stiffness", 0.05), ("asymmetry", 0.4)):
        s, theta, _ = _steady(kind, size)
        X = np.column_stack([np.ones_like(theta), np.cos(2 * theta), np.sin(2 * theta),
                             np.cos(4 * theta), np.sin(4 * theta)])  # fmt: skip
        beta, *_ = np.linalg.lstsq(X, s, rcond=None)
        out[kind] = np.hypot(beta[3], beta[4]) / np.hypot(beta[1], beta[2])
    assert out["asymmetry"] == pytest.approx(0.2, rel=0.25)
    assert out["stiffness"] < 0.05


def _fake(n=400, start=40):
    """A record of ``n`` samples whose first maximum is at ``start`` and two trials."""
    cyc = np.full(n, -1)
    cyc[start:] = (np.arange(n - start) // 60) % 6
    maxima = np.arange(start, n, 60)
    rev = np.sort(np.r_[maxima, maxima[:-1] + 30])
    is_max = np.isin(rev, maxima)
    cycles = SimpleNamespace(cycle=cyc, reversals=rev, is_max=is_max)
    rng = np.random.default_rng(0)
    y = rng.normal(0, 1.0, n)
    d = SimpleNamespace(cycles=cycles, y=y, extra={})
    held = cyc >= 0

    def trial(fitted, mse):
        return SimpleNamespace(fitted=fitted, heldout=held, heldout_mse=mse, heldout_noise=0.0,
                               full=SimpleNamespace(params={"a": 0.3}),
                               full_residual=lambda dd, f=fitted: f - dd.y)  # fmt: skip

    return d, trial, start


def test_startup_samples_before_first_maximum():
    d, _, start = _fake()
    s = startup_samples(d)
    assert s[:start].all() and not s[start:].any()


def test_shape_evidence_reads_the_startup():
    """Equal held-out errors: the start-up decides (the model whose residual is smaller
    before the first maximum has the larger likelihood)."""
    d, trial, start = _fake()
    cur = trial(d.y.copy() * 0 + 0.0, 1.0)
    good = d.y * 0.0
    bad = good.copy()
    bad[:start] += 2.0  # a step of 2 σ that builds out by the first maximum
    stiff, asym = trial(good, 1.0), trial(bad, 1.0)
    total, held, st = shape_evidence(d, cur, stiff, asym)
    assert held == pytest.approx(0.0)
    assert st > 0 and total == pytest.approx(st)
    total2, _, _ = shape_evidence(d, cur, asym, stiff)
    assert total2 == pytest.approx(-total)


def test_choice_between_the_two_follows_the_evidence():
    """The asymmetry yields to an accepted stiffening law that fits at least as well; the
    law yields to an accepted asymmetry that fits better; neither yields to a rival that
    was not accepted."""
    reg = registry("normal")
    asym, stiff = reg["asymmetric_branches"], reg["stiffness_nonlinearity"]
    d, trial, _ = _fake()
    cur = trial(d.y * 0.0, 1.2)
    # fits 0.3 σ apart: the held-out errors' difference (0.1 σ² over 360 samples) is
    # 3 deviations of the ratio's noise, beyond SHAPE_Z
    better = trial(d.y * 0.0, 1.0)
    worse = trial(d.y * 0.0 + 0.3, 1.1)
    v = SimpleNamespace(gain=0.2, accepted=True, reason="accepted")
    weak = SimpleNamespace(gain=0.2, accepted=False, reason="gain not significant (t = 2.6)")
    odd = SimpleNamespace(gain=0.2, accepted=False, reason="implausible: at its limit")
    pa, ps = {"a": 0.3}, {"kappa": 0.0, "kappa1": 0.03}
    # the law fits better: the asymmetry yields, the law stays
    why = asym.yields_to_tried(pa, v, worse, {"stiffness_nonlinearity": (v, better)}, cur, d)
    assert why and "stiffening law" in why and "neither" not in why
    assert stiff.yields_to_tried(ps, v, better, {"asymmetric_branches": (v, worse)}, cur, d) is None
    # the asymmetry fits better: the law yields, the asymmetry stays
    assert (
        asym.yields_to_tried(pa, v, better, {"stiffness_nonlinearity": (v, worse)}, cur, d) is None
    )
    why = stiff.yields_to_tried(ps, v, worse, {"asymmetric_branches": (v, better)}, cur, d)
    assert why and "loss asymmetry" in why
    # a law that fits better but did not pass on its own: the asymmetry yields all the
    # same (neither is named); an implausible law takes nothing
    why = asym.yields_to_tried(pa, v, worse, {"stiffness_nonlinearity": (weak, better)}, cur, d)
    assert why and "neither is named" in why
    assert (
        asym.yields_to_tried(pa, v, worse, {"stiffness_nonlinearity": (odd, better)}, cur, d)
        is None
    )
    # and the other way round
    why = stiff.yields_to_tried(ps, v, worse, {"asymmetric_branches": (weak, better)}, cur, d)
    assert why and "neither is named" in why
    why = stiff.yields_to_tried(ps, v, worse, {"asymmetric_branches": (odd, better)}, cur, d)
    assert why is None


def test_weak_evidence_names_neither():
    """Where the two fits lie far apart (2 σ a sample) and the likelihood ratio over them
    is within SHAPE_Z of its noise from a tie, neither shape is named, whichever fits a
    little better and whether or not the rival passed."""
    from contactlab.diagnose.effects.normal.asymmetric_branches import SHAPE_Z, shape_test

    reg = registry("normal")
    asym, stiff = reg["asymmetric_branches"], reg["stiffness_nonlinearity"]
    d, trial, _ = _fake()
    cur = trial(d.y * 0.0, 1.2)
    better = trial(d.y * 0.0, 1.0)
    alt = np.where(d.cycles.cycle >= 0, 2.0 * np.sign(np.sin(np.arange(d.y.size))), 0.0)
    worse = trial(alt, 1.05)
    _, _, _, z = shape_test(d, cur, better, worse)
    assert 0.0 < z < SHAPE_Z
    v = SimpleNamespace(gain=0.2, accepted=True, reason="accepted")
    pa, ps = {"a": 0.3}, {"kappa": 0.0, "kappa1": 0.03}
    # the law fits a little better: the asymmetry yields, and so does the law
    why = asym.yields_to_tried(pa, v, worse, {"stiffness_nonlinearity": (v, better)}, cur, d)
    assert why and "not named either" in why
    why = stiff.yields_to_tried(ps, v, better, {"asymmetric_branches": (v, worse)}, cur, d)
    assert why and "does not tell the two apart" in why
    # the asymmetry fits a little better: both yield the same way round
    why = asym.yields_to_tried(pa, v, better, {"stiffness_nonlinearity": (v, worse)}, cur, d)
    assert why and "does not tell the two apart" in why
    why = stiff.yields_to_tried(ps, v, worse, {"asymmetric_branches": (v, better)}, cur, d)
    assert why and "not named either" in why


def _rig(effect: dict, seed: int):
    from contactlab.synthetic.rig import rig_recording

    p0 = 5e5
    r = rig_recording(effect, "normal", seed=seed, fs=1000.0, f=4.0, cycles=10, k=K, psi=PSI,
                      p0=p0, pa=0.5 * p0, x_noise=0.01, F_noise=0.01, ramp_cycles=1.0)  # fmt: skip
    return {"t": r.t, "p": r.channels["p"], "delta": r.channels["delta"]}


@pytest.mark.parametrize(
    ("effect", "seed", "named", "yielded"),
    [
        # a stiffening law 2 % at the amplitude: the asymmetry passes too, and yields
        ({"stiffness_nonlinearity": {"a2": 0.02 * K / (2.5e5 / K), "a3": 0.0}}, 3,
         "stiffness_nonlinearity", "asymmetric_branches"),
        # a loss asymmetry a = 0.5: the law passes too, and yields
        ({"asymmetric_branches": {"a": 0.5}}, 2, "asymmetric_branches", "stiffness_nonlinearity"),
    ],
)  # fmt: skip
def test_rig_records_name_the_effect_that_fits_better(effect, seed, named, yielded):
    """On the rig (one tone ramped in from rest over a cycle, 1 % noise on both channels)
    both candidates pass; the one the record favours is named and the other's verdict
    says why it gave way."""
    import warnings

    import contactlab

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = contactlab.diagnose(_rig(effect, seed), "normal")
    assert list(res.effect_names) == [named]
    why = {v.name: v.reason for v in res.steps[0].candidates}
    assert why[yielded].startswith("look-alike:")
    assert "χ² units" in why[yielded]
