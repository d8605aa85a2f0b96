"""contactlab.fitting.add_covariance: errors of inputs a fit took as exact."""

from __future__ import annotations

import numpy as np
import pytest

from contactlab import InputError
from contactlab.fitting import add_covariance, least_squares_fit


def _line_fit():
    x = np.linspace(0.0, 1.0, 40)
    y = 2.0 * x + 1.0 + 0.05 * np.random.default_rng(1).standard_normal(x.size)
    return least_squares_fit(lambda p: p["a"] * x + p["b"] - y, {"a": 1.0, "b": 0.0}), x


def test_add_covariance_updates_errors_and_correlations():
    fit, _ = _line_fit()
    extra = np.array([[4e-4, 1e-4], [1e-4, 9e-4]])
    out = add_covariance(fit, extra)
    np.testing.assert_allclose(out.covar, fit.covar + extra)
    for i, n in enumerate(fit.var_names):
        assert out.params[n].stderr == pytest.approx(np.sqrt(fit.covar[i, i] + extra[i, i]))
        assert out.params[n].value == fit.params[n].value
    r = out.covar[0, 1] / np.sqrt(out.covar[0, 0] * out.covar[1, 1])
    assert out.correl[0, 1] == pytest.approx(r)
    assert fit.params["a"].stderr == pytest.approx(np.sqrt(fit.covar[0, 0]))  # not modified
    # derived quantities see the extra covariance
    g = np.array([1.0, 1.0])
    assert out.propagate(lambda v: v["a"] + v["b"])[1] == pytest.approx(
        np.sqrt(g @ (fit.covar + extra) @ g), rel=1e-5
    )


def test_add_covariance_of_an_input_matches_monte_carlo():
    # A line fitted to data from which an offset u (estimated, σu) was removed: the fitted
    # intercept moves one to one with u, so G = [0, -1] and b's error grows by σu.
    fit, _ = _line_fit()
    sigma_u = 0.03
    G = np.array([[0.0], [-1.0]])
    out = add_covariance(fit, G @ G.T * sigma_u**2)
    assert out.params["b"].stderr == pytest.approx(np.hypot(fit.params["b"].stderr, sigma_u))
    assert out.params["a"].stderr == pytest.approx(fit.params["a"].stderr)


def test_add_covariance_rejects_bad_shapes():
    fit, _ = _line_fit()
    with pytest.raises(InputError, match="2x2"):
        add_covariance(fit, np.eye(3))
    with pytest.raises(InputError, match="finite"):
        add_covariance(fit, np.full((2, 2), np.nan))
