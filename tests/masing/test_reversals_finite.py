"""``ReversalDetector.push(..., finite=True)`` (the window's raw and detrended displacement,
scanned finite already): the excursions of ``push``, without its finiteness scan."""

from __future__ import annotations

import numpy as np
import pytest

from contactlab.errors import ContactLabError
from contactlab.reversals import ReversalDetector, excursions


def _same(a, b) -> None:
    for k in ("sign", "start", "extreme", "extreme_value", "last_beyond", "returned"):
        np.testing.assert_array_equal(getattr(a, k), getattr(b, k))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_finite_push_gives_the_excursions_of_push(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = 20_000 + 37 * seed
    x = np.sin(np.arange(n) * 0.013) + 0.3 * rng.standard_normal(n)
    v = x + 0.1 * rng.standard_normal(n)
    for value in (None, v):
        _same(excursions(x, 0.05, 0.4, value), excursions(x, 0.05, 0.4, value, finite=True))
    # in chunks: the open excursion carried over
    a, b = ReversalDetector(0.05, 0.4), ReversalDetector(0.05, 0.4)
    for s in range(0, n, 3001):
        _same(a.push(x[s : s + 3001]), b.push(x[s : s + 3001], finite=True))
        _same(a.open(), b.open())


def test_push_still_refuses_a_non_finite_sample() -> None:
    x = np.sin(np.arange(1000) * 0.05)
    x[321] = np.nan
    with pytest.raises(ContactLabError, match="321"):
        ReversalDetector(0.0, 0.5).push(x)
