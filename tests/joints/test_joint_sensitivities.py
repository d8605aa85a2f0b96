"""Forward sensitivities of joint laws (the fit's Jacobian in one pass of the Rust core)
against an independent route: central differences of the plain-Python reference."""

from __future__ import annotations

import importlib

import numpy as np
import pytest

from contactlab import _core
from contactlab.errors import ContactLabError
from contactlab.joints import (
    BoucWen,
    Dahl,
    Jenkins,
    KelvinVoigt,
    LuGre,
    MaxwellSlip,
    Parallel,
    fit,
)
from contactlab.joints import _reference as ref

fit_module = importlib.import_module("contactlab.joints.fit_problem")


def _signal(n=400):
    t = np.arange(n) * 2e-3
    x = 1e-3 * np.sin(5.0 * t) * (1 + 0.5 * np.sin(1.1 * t)) + 1.5e-4 * np.sin(37.0 * t)
    return t, x


LAWS = [
    Jenkins(k=1e4, fs=3.0),
    MaxwellSlip(k=[1e4, 2e4, 5e3], fs=[1.0, 4.0, 2.0]),
    Dahl(sigma0=3e4, Fc=5.0, alpha=1.0),
    Dahl(sigma0=3e4, Fc=5.0, alpha=0.6),
    Dahl(sigma0=3e4, Fc=5.0, alpha=1.8),
    LuGre(sigma0=1e5, sigma1=30.0, sigma2=2.0, Fc=4.0, Fs=5.0, vs=2e-3, delta=2.0),
    LuGre(sigma0=1e5, sigma1=30.0, sigma2=2.0, Fc=4.0, Fs=5.0, vs=2e-3, delta=1.3),
    Parallel(LuGre(1e5, 30.0, 2.0, 4.0, 5.0, 2e-3), Jenkins(1e4, 3.0), k=2e3, c=1.5),
    KelvinVoigt(k=1e3, c=2.0),
]


def _ref_force(law, t, x):
    return np.asarray(ref.run(law._ref(), list(t), list(x))[0])


@pytest.mark.parametrize("law", LAWS, ids=lambda law: repr(law)[:40])
def test_sensitivities_equal_differences_of_the_python_reference(law):
    t, x = _signal()
    F, J = _core.joint_force_sens(law.spec(), t, x, 0.0)
    assert J.shape == (x.size, len(law.param_names))
    np.testing.assert_allclose(F, _ref_force(law, t, x), rtol=0, atol=1e-12 * np.abs(F).max())
    v = law.vector
    for j, name in enumerate(law.param_names):
        rel = 1e-4 if name.endswith("alpha") else 1e-6
        h = rel * abs(v[j])
        up, dn = v.copy(), v.copy()
        up[j] += h
        dn[j] -= h
        fd = _ref_force(law.with_params(up), t, x) - _ref_force(law.with_params(dn), t, x)
        fd /= 2 * h
        scale = max(np.abs(fd).max(), np.abs(F).max() / abs(v[j]))
        assert np.abs(fd - J[:, j]).max() <= 1e-5 * scale, name


def test_laws_without_sensitivities_fall_back_and_bad_input_is_typed():
    t, x = _signal(50)
    bw = BoucWen(alpha=1e4, beta=1e3, gamma=0.5, delta=0.5, nu=1.0)
    assert not fit_module.has_sensitivities(bw)
    assert fit_module.has_sensitivities(LuGre(1e5, 30.0, 2.0, 4.0, 5.0, 2e-3))
    lg = LuGre(1e5, 30.0, 2.0, 4.0, 5.0, 2e-3)
    with pytest.raises(ContactLabError):
        _core.joint_force_sens(bw.spec(), t, x, 0.0)
    with pytest.raises(ContactLabError, match="rate-dependent"):
        _core.joint_force_sens(lg.spec(), None, x, 0.0)
    bad = x.copy()
    bad[7] = np.nan
    with pytest.raises(ContactLabError, match=r"x\[7\]"):
        _core.joint_force_sens(lg.spec(), t, bad, 0.0)


@pytest.mark.parametrize("law", ["dahl", "lugre"])
def test_fit_with_sensitivities_equals_the_finite_difference_fit(law, monkeypatch):
    t = np.linspace(0.0, 4.0, 4001)
    x = 1e-3 * np.sin(2 * np.pi * t) * (1 + 0.3 * np.sin(0.9 * t)) + 5e-5 * np.sin(45 * t)
    true = {"dahl": Dahl(3e4, 10.0, 1.0), "lugre": LuGre(2e5, 30.0, 5.0, 10.0, 12.0, 2e-3)}[law]
    F = true.force(t, x) + np.random.default_rng(3).normal(0, 0.05, t.size)
    a = fit(t, x, F, law=law, offset=True, asymmetry=True)
    monkeypatch.setattr(fit_module, "has_sensitivities", lambda _law: False)
    b = fit(t, x, F, law=law, offset=True, asymmetry=True)
    assert a.success and b.success
    assert a.result.chisqr <= b.result.chisqr * (1 + 1e-6)
    for n, p in a.params.items():
        q = b.params[n]
        if p.vary and q.stderr:
            assert abs(p.value - q.value) <= 0.05 * q.stderr, n
            assert p.stderr == pytest.approx(q.stderr, rel=1e-3), n


def test_lugre_on_a_one_speed_quantised_record_converges_with_stribeck_held():
    """A stage that strokes at one speed in 100 nm steps, holding still every other sample
    (the micro-tribometer's record): Fs and vs cannot be separated from Fc, σ1 runs to 0;
    the fit holds them (with notes) and converges."""
    n = 6000
    t = np.arange(n) * 5e-3
    steps = np.tile(np.r_[np.ones(600), -np.ones(600)], n // 1200 + 1)[:n] * (np.arange(n) % 2)
    x = 1e-7 * np.cumsum(steps)
    true = LuGre(sigma0=4e4, sigma1=0.0, sigma2=20.0, Fc=2.5, Fs=3.0, vs=1e-6)
    F = true.force(t, x) + np.random.default_rng(5).normal(0, 0.02, n)
    res = fit(t, x, F, law="lugre", offset=True)
    assert res.success, res.result.message
    assert not res.params["Fs"].vary and not res.params["vs"].vary
    assert any("one speed" in n for n in res.notes)
    assert res.params["Fc"].stderr is not None
    for name, v in (("Fc", 2.5), ("sigma0", 4e4)):
        p = res.params[name]
        assert abs(p.value - v) < 5 * p.stderr, name
