"""fitting.hac_covariance: the lag-window sandwich for correlated residuals, checked against
a dense ``(JᵀJ)⁻¹ Jᵀ Ω J (JᵀJ)⁻¹`` and against Monte Carlo with autocorrelated noise."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.signal import lfilter

from contactlab.errors import InputError
from contactlab.fitting import hac_covariance, least_squares_fit


def _linear_fit(X: np.ndarray, y: np.ndarray):
    names = [f"p{i}" for i in range(X.shape[1])]

    def res(p):
        return X @ np.array([p[n] for n in names]) - y

    return least_squares_fit(res, dict.fromkeys(names, 0.0))


def _dense(J: np.ndarray, r: np.ndarray, channels: int, L: int) -> np.ndarray:
    """The same estimate without FFTs: Ω from the tapered sample cross-covariances."""
    n = r.size // channels
    rc = r.reshape(n, channels)
    Om = np.zeros((r.size, r.size))
    for t in range(n):
        for s in range(n):
            lag = t - s
            if abs(lag) > L:
                continue
            w = 1.0 - abs(lag) / (L + 1.0)
            for a in range(channels):
                for b in range(channels):
                    if lag >= 0:
                        c = rc[lag:, a] @ rc[: n - lag, b] / n
                    else:
                        c = rc[: n + lag, a] @ rc[-lag:, b] / n
                    Om[t * channels + a, s * channels + b] = w * c
    A = np.linalg.inv(J.T @ J)
    k = J.shape[1]
    return A @ J.T @ Om @ J @ A * r.size / (r.size - k)


@pytest.mark.parametrize("channels,L", [(1, 7), (2, 5), (3, 0)])
def test_fft_sandwich_equals_dense_quadratic_form(channels, L):
    rng = np.random.default_rng(5)
    n = 40
    X = rng.standard_normal((n * channels, 3))
    e = lfilter([1.0], [1.0, -0.7], rng.standard_normal(n * channels))
    fit = _linear_fit(X, X @ [1.0, -2.0, 0.5] + e)
    h = hac_covariance(fit, channels=channels, lags=L)
    np.testing.assert_allclose(h.covar, _dense(fit.jac, fit.residual, channels, L), rtol=1e-9,
                               atol=1e-14)  # fmt: skip
    assert "Bartlett lag window of" in h.notes[-1]


def test_autocorrelated_noise_errors_match_monte_carlo_white_ones_do_not():
    rng = np.random.default_rng(2026)
    n = 1600
    x = np.linspace(0.0, 1.0, n)
    X = np.stack([np.ones(n), x, np.sin(60 * x)], axis=1)
    est, hac, white = [], [], []
    for _ in range(200):
        y = X @ [1.0, 2.0, 3.0] + lfilter([1.0], [1.0, -0.9], rng.standard_normal(n))
        fit = _linear_fit(X, y)
        est.append([fit.params[f"p{i}"].value for i in range(3)])
        white.append([fit.params[f"p{i}"].stderr for i in range(3)])
        h = hac_covariance(fit)
        hac.append([h.params[f"p{i}"].stderr for i in range(3)])
    mc = np.std(est, axis=0)
    # the white-noise errors are 3-4x too small; the sandwich's within 20 % of the spread
    # (it is biased low on short records: residuals of a fitted model under-show correlation)
    assert np.all(np.mean(white, axis=0) < 0.4 * mc)
    np.testing.assert_allclose(np.sqrt(np.mean(np.square(hac), axis=0)), mc, rtol=0.2)


def test_white_residuals_keep_the_usual_errors():
    rng = np.random.default_rng(11)
    X = np.stack([np.ones(2000), rng.standard_normal(2000)], axis=1)
    fit = _linear_fit(X, X @ [0.5, 1.5] + rng.standard_normal(2000))
    h = hac_covariance(fit)
    for n in ("p0", "p1"):
        assert 0.8 < h.params[n].stderr / fit.params[n].stderr < 1.25


def test_channels_must_split_the_residuals():
    rng = np.random.default_rng(1)
    X = rng.standard_normal((9, 2))
    fit = _linear_fit(X, rng.standard_normal(9))
    with pytest.raises(InputError, match="9 residuals do not split into 2 channels"):
        hac_covariance(fit, channels=2)


@settings(max_examples=30, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    channels=st.integers(1, 3),
    lags=st.one_of(st.none(), st.integers(0, 30)),
)
def test_covariance_is_symmetric_positive_semidefinite(seed, channels, lags):
    rng = np.random.default_rng(seed)
    n = 30
    X = rng.standard_normal((n * channels, 3))
    X[:, 2] = X[:, 0] + 1e-3 * X[:, 2]  # nearly collinear columns too
    fit = _linear_fit(X, rng.standard_normal(n * channels).cumsum())
    h = hac_covariance(fit, channels=channels, lags=lags)
    np.testing.assert_allclose(h.covar, h.covar.T, atol=0.0)
    ev = np.linalg.eigvalsh(h.covar)
    assert ev.min() >= -1e-9 * max(ev.max(), 1e-300)
