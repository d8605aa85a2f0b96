"""contactlab.fitting: least squares with lmfit-style results, checked against closed forms."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from contactlab import ConvergenceError, InputError
from contactlab.fitting import Parameter, least_squares_fit


def _linear_reference(x, y):
    X = np.column_stack([x, np.ones_like(x)])
    beta, *_ = np.linalg.lstsq(X, y, rcond=None)
    r = y - X @ beta
    s2 = r @ r / (x.size - 2)
    return beta, s2 * np.linalg.inv(X.T @ X), float(r @ r)


@settings(max_examples=25, deadline=None)
@given(
    a=st.floats(-1e3, 1e3).filter(lambda v: abs(v) > 1e-3),
    b=st.floats(-1e3, 1e3).filter(lambda v: abs(v) > 1e-3),
    seed=st.integers(0, 2**31),
)
def test_linear_fit_matches_ordinary_least_squares(a, b, seed):
    rng = np.random.default_rng(seed)
    x = np.linspace(-1, 2, 40)
    y = a * x + b + 0.05 * (abs(a) + 1) * rng.standard_normal(x.size)
    res = least_squares_fit(lambda p: p["a"] * x + p["b"] - y, {"a": 1.0, "b": 1.0})
    beta, cov, chisqr = _linear_reference(x, y)
    assert res.success
    # agreement to a tiny fraction of the statistical error
    assert abs(res.params["a"].value - beta[0]) <= 1e-5 * math.sqrt(cov[0, 0])
    assert abs(res.params["b"].value - beta[1]) <= 1e-5 * math.sqrt(cov[1, 1])
    np.testing.assert_allclose(res.covar, cov, rtol=1e-4)
    assert res.chisqr == pytest.approx(chisqr, rel=1e-8)
    assert res.redchi == pytest.approx(chisqr / 38, rel=1e-8)
    n = x.size
    assert res.aic == pytest.approx(n * math.log(chisqr / n) + 4, rel=1e-9)
    assert res.bic == pytest.approx(n * math.log(chisqr / n) + 2 * math.log(n), rel=1e-9)
    r = cov[0, 1] / math.sqrt(cov[0, 0] * cov[1, 1])
    assert res.correl[0, 1] == pytest.approx(r, abs=1e-5)
    assert res.correl_dict()["a"]["b"] == pytest.approx(r, abs=1e-5)


def test_nonlinear_fit_recovers_exponential_with_honest_errors():
    # Coverage: the 2-sigma interval of the decay rate holds the truth ~95% of the time.
    x = np.linspace(0, 3, 30)
    hits = 0
    n = 120
    for seed in range(n):
        rng = np.random.default_rng(seed)
        y = 5.0 * np.exp(-1.3 * x) + 0.05 * rng.standard_normal(x.size)
        res = least_squares_fit(
            lambda p, y=y: p["A"] * np.exp(-p["k"] * x) - y,
            [Parameter("A", 1.0, min=0), Parameter("k", 0.5, min=0)],
        )
        k = res.params["k"]
        hits += abs(k.value - 1.3) <= 2 * k.stderr
    assert 0.88 * n <= hits <= 0.995 * n


def test_fixed_parameters_are_passed_but_not_fitted():
    x = np.linspace(0, 1, 20)
    y = 3.0 * x + 2.0
    res = least_squares_fit(
        lambda p: p["a"] * x + p["b"] - y, [Parameter("a", 1.0), Parameter("b", 2.0, vary=False)]
    )
    assert res.var_names == ["a"]
    assert res.nvarys == 1
    assert res.params["b"].value == 2.0 and res.params["b"].stderr is None
    assert res.params["a"].value == pytest.approx(3.0)
    assert "(fixed)" in res.report()


def test_degenerate_parameters_flagged_not_identifiable():
    x = np.linspace(0, 1, 30)
    y = 2.0 * x
    res = least_squares_fit(lambda p: (p["a"] + p["b"]) * x - y, {"a": 1.0, "b": 0.5})
    assert res.params["a"].identifiable is False
    assert res.params["b"].identifiable is False
    assert res.params["a"].stderr is None
    assert res.notes and "a, b" in res.notes[0]
    # the identified combination still has a finite propagated error
    s, ds = res.propagate(lambda v: v["a"] + v["b"])
    assert s == pytest.approx(2.0)
    assert np.isfinite(ds)
    assert "NOT IDENTIFIABLE" in res.report()


def test_max_rel_stderr_flags_poorly_determined():
    rng = np.random.default_rng(3)
    x = np.linspace(0, 1, 20)
    y = 1.0 + 1e-3 * x + 0.1 * rng.standard_normal(20)
    res = least_squares_fit(
        lambda p: p["a"] * x + p["b"] - y, {"a": 1.0, "b": 1.0}, max_rel_stderr=0.5
    )
    assert res.params["a"].identifiable is False
    assert "relative standard error" in res.params["a"].note
    assert res.params["b"].identifiable is True


def test_propagate_matches_analytic_linear_combination():
    rng = np.random.default_rng(0)
    x = np.linspace(0, 1, 50)
    y = 2 * x + 1 + 0.1 * rng.standard_normal(50)
    res = least_squares_fit(lambda p: p["a"] * x + p["b"] - y, {"a": 1.0, "b": 0.0})
    val, err = res.propagate(lambda v: v["a"] * 0.5 + v["b"])
    g = np.array([0.5, 1.0])
    assert val == pytest.approx(0.5 * res.params["a"].value + res.params["b"].value)
    assert err == pytest.approx(math.sqrt(g @ res.covar @ g), rel=1e-6)
    vals, errs = res.propagate(lambda v: v["a"] * x + v["b"])
    assert vals.shape == errs.shape == x.shape


def test_to_dict_is_json_safe():
    x = np.linspace(0, 1, 10)
    res = least_squares_fit(lambda p: p["a"] * x - 2 * x, {"a": 1.0})  # perfect fit: redchi 0
    d = res.to_dict()
    text = json.dumps(d, allow_nan=False)
    back = json.loads(text)
    assert back["params"]["a"]["value"] == pytest.approx(2.0)
    assert back["chisqr"] == pytest.approx(0.0, abs=1e-20)
    assert back["success"] is True and back["nfev"] == res.nfev
    assert back["params"]["a"]["min"] is None  # -inf bound
    # No degrees of freedom: redchi is NaN, which JSON cannot hold; it becomes null.
    one = least_squares_fit(lambda p: np.array([p["a"] - 2.0]), {"a": 1.0})
    assert math.isnan(one.redchi)
    assert json.loads(json.dumps(one.to_dict(), allow_nan=False))["redchi"] is None


def test_bad_input_raises_input_error():
    x = np.linspace(0, 1, 10)
    with pytest.raises(InputError, match="outside"):
        least_squares_fit(lambda p: p["a"] * x, [Parameter("a", -1.0, min=0.0)])
    with pytest.raises(InputError, match=r"residual\[0\]"):
        least_squares_fit(lambda p: np.full(10, np.nan), {"a": 1.0})
    with pytest.raises(InputError, match="cannot determine"):
        least_squares_fit(lambda p: np.array([p["a"] - p["b"]]), {"a": 1.0, "b": 2.0})
    with pytest.raises(InputError):
        least_squares_fit(lambda p: p["a"] * x, 3.0)


def test_model_errors_during_fit_become_convergence_errors():
    x = np.linspace(0, 1, 10)

    def bad(p):
        if p["a"] < 0.9:
            raise InputError("a must be >= 0.9")
        return (p["a"] - 0.0) * x

    with pytest.raises(ConvergenceError, match="bounds"):
        least_squares_fit(bad, {"a": 1.0})


def test_text_report_writes_an_undetermined_value_as_such():
    """No "+/- nan" nor an absurd "-0.0158 +/- 47.4 s" in the text report (issue 31): a
    parameter without a finite standard error, or with one over 1000 % of its value, is
    written "not identifiable"."""
    import dataclasses

    from contactlab.fitting import least_squares_fit

    x = np.linspace(0.0, 1.0, 50)
    y = 2.0 * x + 0.5
    res = least_squares_fit(lambda p: p["a"] * x + p["b"] - y, {"a": 1.0, "b": 0.0})
    a, b = res.params["a"], res.params["b"]
    res.params["a"] = dataclasses.replace(a, stderr=float("nan"))
    res.params["b"] = dataclasses.replace(b, value=-0.0158, stderr=47.4)
    text = res.report()
    assert "nan" not in text and "47.4 " not in text
    assert text.count("not identifiable") == 2
    assert "over 1000 % of the value" in text
