"""contactlab.loop_area / loop_areas: exact against rational arithmetic, the same on every
SIMD level, per-cycle areas equal to one loop_area per cycle, clear errors."""

from __future__ import annotations

import os
import subprocess
import sys
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import contactlab
from contactlab import _core
from contactlab.errors import InputError


def exact_area(x: np.ndarray, f: np.ndarray) -> Fraction:
    n = x.size
    X = [Fraction(v) for v in x.tolist()]
    F = [Fraction(v) for v in f.tolist()]
    return sum((F[i] + F[(i + 1) % n]) * (X[(i + 1) % n] - X[i]) for i in range(n)) / 2


@settings(max_examples=60, deadline=None)
@given(
    n=st.integers(3, 200),
    seed=st.integers(0, 2**32 - 1),
    scale=st.sampled_from([1.0, 1e-6, 1e6, 1e-150, 1e150]),
    offset=st.floats(-100.0, 100.0),
)
def test_loop_area_is_exact_to_rounding(n, seed, scale, offset):
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    x = scale * (np.sin(t) + 0.01 * rng.standard_normal(n))
    f = scale * (np.sin(t + 0.5) + offset + 0.01 * rng.standard_normal(n))
    exact = exact_area(x, f)
    # the terms' scale: Σ |ΔF| |Δx| with the mean force removed
    fm = Fraction(float(np.mean(f)))
    X = [Fraction(v) for v in x.tolist()]
    F = [Fraction(v) - fm for v in f.tolist()]
    mag = sum(abs((F[i] + F[(i + 1) % n]) * (X[(i + 1) % n] - X[i])) for i in range(n)) / 2
    got = Fraction(contactlab.loop_area(x, f))
    assert abs(got - exact) <= Fraction(1, 10**14) * mag + Fraction(1, 10**15) * abs(exact)


def test_per_cycle_areas_equal_one_call_per_cycle():
    rng = np.random.default_rng(3)
    n = 10_007
    t = np.arange(n) * (2 * np.pi / 997)
    x = np.sin(t) + 1e-3 * rng.standard_normal(n)
    f = np.sin(t + 0.4) + 1e-3 * rng.standard_normal(n)
    bounds = np.array([0, 2, 997, 1994, 5000, 5000, n])
    got = contactlab.loop_areas(x, f, bounds)
    assert got.shape == (6,)
    assert np.isnan(got[0]) and np.isnan(got[4])  # fewer than 3 samples
    for k in (1, 2, 3, 5):
        a, b = bounds[k], bounds[k + 1]
        assert got[k] == contactlab.loop_area(x[a:b], f[a:b])
    assert contactlab.loop_areas(x, f, []).shape == (0,)


@pytest.mark.parametrize(
    ("x", "f", "bounds", "match"),
    [
        (np.zeros(5), np.zeros(4), [0, 4], "samples"),
        (np.zeros(5), np.zeros(5), [3, 1], "non-decreasing"),
        (np.zeros(5), np.zeros(5), [0, 6], "within"),
        (np.zeros(5), np.zeros(5), [0.0, 4.0], "integers"),
        (np.array([0.0, np.nan, 1.0]), np.zeros(3), [0, 3], "finite"),
    ],
)
def test_loop_areas_bad_input_is_an_input_error(x, f, bounds, match):
    with pytest.raises(InputError, match=match):
        contactlab.loop_areas(x, f, bounds)


def test_every_simd_level_gives_the_same_areas():
    """The level is fixed per process: run the generic one in a child and compare bits."""
    rng = np.random.default_rng(9)
    x = rng.standard_normal(100_003).cumsum()
    f = rng.standard_normal(100_003)
    here = contactlab.loop_area(x, f).hex()
    code = (
        "import numpy as np, contactlab; from contactlab import _core;"
        "r = np.random.default_rng(9); x = r.standard_normal(100_003).cumsum();"
        "f = r.standard_normal(100_003);"
        "print(_core.simd_level(), contactlab.loop_area(x, f).hex())"
    )
    env = dict(os.environ, CONTACTLAB_SIMD="generic")
    out = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
    )
    level, value = out.stdout.split()
    assert level == "generic"
    assert value == here, f"{_core.simd_level()} {here} vs generic {value}"
