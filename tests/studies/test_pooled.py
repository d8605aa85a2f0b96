"""Pooling windows into one value (:func:`contactlab.studies.pooled.pool`).

A window's standard error is estimated from the same noisy samples as its value, so the two
are correlated; inverse-variance weights then bias the pooled mean (666 windows of 3 cycles,
1 % noise on both channels: h0 −0.31 %, z −4.9). The pool weights windows by the error
typical of their size instead, and keeps a window's own error only where it is far larger.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from contactlab.studies.pooled import OWN_ERROR_ABOVE, pool


def _correlated_windows(seed: int, n: int = 2000, rel: float = 0.03):
    """Window values around 40 whose estimated errors grow steeply with the value (as a
    fitted h0's error does), all windows of the same size."""
    rng = np.random.default_rng(seed)
    v = 40.0 * (1.0 + rel * rng.standard_normal(n))
    s = 40.0 * rel * (v / 40.0) ** 6
    return v, s


@pytest.mark.parametrize("seed", [101, 202, 303])
def test_errors_correlated_with_values_do_not_bias_the_mean(seed):
    v, s = _correlated_windows(seed)
    sizes = np.full(v.size, 3.0)
    mean, err, birge = pool(v, s, sizes)
    assert abs(mean - 40.0) < 3 * err, (mean, err)
    # the inverse-variance mean (no sizes) is the biased one this replaces
    ivw, ivw_err, _ = pool(v, s)
    assert (ivw - 40.0) / ivw_err < -5
    # the error is the scatter of the mean, windows' sd / sqrt(n), or a little above it (the
    # Birge ratio with the windows' own, correlated errors exceeds 1 here)
    assert 0.9 < err / (np.std(v, ddof=1) / math.sqrt(v.size)) < 1.3
    assert 0.8 < birge < 1.3


def test_a_window_far_worse_than_its_size_keeps_its_own_weight():
    rng = np.random.default_rng(7)
    v = 40.0 + 0.4 * rng.standard_normal(50)
    s = np.full(50, 0.4)
    v[10], s[10] = 400.0, 0.4 * 100 * OWN_ERROR_ABOVE  # an undetermined window
    mean, _err, _ = pool(v, s, np.full(50, 10.0))
    assert abs(mean - 40.0) < 0.3
    # with the typical weight it would have pulled the mean by 360/50 = 7.2
    assert abs(np.mean(v) - 40.0) > 7


def test_windows_of_different_size_are_weighted_by_size():
    # two windows of 30 cycles, two of 3: each with the error its size implies
    v = np.array([40.0, 40.2, 39.0, 41.4])
    n = np.array([30.0, 30.0, 3.0, 3.0])
    s = 0.5 / np.sqrt(n)
    mean, err, _ = pool(v, s, n)
    expect = float(np.sum(n * v) / np.sum(n))
    assert mean == pytest.approx(expect, rel=1e-12)
    assert err >= 0.5 / math.sqrt(n.sum()) * (1 - 1e-12)


def test_fewer_than_three_windows_fall_back_to_inverse_variance():
    mean, _err, _ = pool([1.0, 2.0], [0.1, 0.2], [5, 5])
    w = np.array([100.0, 25.0])
    assert mean == pytest.approx((w @ [1.0, 2.0]) / w.sum())


def test_no_error_gives_plain_mean_and_scatter():
    mean, err, birge = pool([1.0, 2.0, 3.0], [None, math.nan, 0.0], [3, 3, 3])
    assert mean == pytest.approx(2.0)
    assert err == pytest.approx(1.0 / math.sqrt(3))
    assert math.isnan(birge)


def test_extreme_magnitudes_do_not_overflow():
    v = np.array([1e300, 1.1e300, 0.9e300, 1.05e300])
    s = np.array([1e299, 2e299, 1e299, 1e299])
    mean, err, birge = pool(v, s, [3, 3, 3, 3])
    assert math.isfinite(mean) and math.isfinite(err) and math.isfinite(birge)
    v2 = np.array([1e-300, 1.1e-300, 0.9e-300, 1.05e-300])
    mean2, err2, _ = pool(v2, v2 * 0.1, [3, 3, 3, 3])
    assert math.isfinite(mean2) and err2 > 0


@settings(max_examples=60, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.floats(-1e6, 1e6),
            st.floats(1e-3, 1e3),
            st.integers(1, 1000),
        ),
        min_size=1,
        max_size=30,
    ),
    st.floats(1e-6, 1e6),
)
def test_scale_and_order_invariance(rows, scale):
    v = np.array([r[0] for r in rows])
    s = np.array([r[1] for r in rows])
    n = np.array([r[2] for r in rows], dtype=float)
    m, e, _b = pool(v, s, n)
    m2, e2, _b2 = pool(scale * v, scale * s, n)
    assert m2 == pytest.approx(scale * m, rel=1e-9, abs=1e-9 * scale * (np.max(np.abs(v)) + 1))
    assert e2 == pytest.approx(scale * e, rel=1e-9)
    order = np.argsort(-v, kind="stable")
    m3, e3, _ = pool(v[order], s[order], n[order])
    assert m3 == pytest.approx(m, rel=1e-9, abs=1e-9 * (np.max(np.abs(v)) + 1))
    assert e3 == pytest.approx(e, rel=1e-9)
    # the mean lies within the windows' range
    assert np.min(v) - 1e-9 * (abs(np.min(v)) + 1) <= m <= np.max(v) + 1e-9 * (abs(np.max(v)) + 1)
