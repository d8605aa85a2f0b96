"""The cheaper pieces of the misfit flag's simulated null (issue 29 item 3): the phase bins'
``T`` alone (against the full structure test's) and the coloured noise drawn at a fast
transform length."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from contactlab.diagnose._family import Prepared
from contactlab.diagnose.eiv import InputNoise
from contactlab.diagnose.misfit import (
    phase_statistic,
    unexplained_structure,
)
from contactlab.diagnose.misfit_null import _fast_length, _NoiseDraws
from contactlab.masing import Masing

AC = 1e5


def _record(seed: int, cycles: int = 10, spc: int = 300, bump: float = 0.0):
    t = np.arange(cycles * spc) / spc
    x = 2e-5 * np.sin(2 * np.pi * t) * np.minimum(t / 1.5, 1.0)
    y = Masing(40.0, AC).force(x)
    e = np.random.default_rng(seed).normal(0.0, 0.5, t.size)
    e += bump * np.cos(2 * np.pi * t)
    return Prepared.build(t, x, y), e


@settings(max_examples=8, deadline=None)
@given(seed=st.integers(0, 10_000), bump=st.sampled_from([0.0, 0.3]))
def test_phase_statistic_is_the_structure_tests_T(seed: int, bump: float) -> None:
    d, e = _record(seed, bump=bump)
    u = unexplained_structure(d, e, 0.5, min_weight=0.0)
    assert u is not None
    assert phase_statistic(d, e, 0.5) == u.statistic


def test_phase_statistic_is_nan_with_too_few_cycles() -> None:
    d, e = _record(0, cycles=3)
    assert unexplained_structure(d, e, 0.5, min_weight=0.0) is None
    assert np.isnan(phase_statistic(d, e, 0.5))


def test_fast_length() -> None:
    for n in (1, 2, 7, 97, 1000, 20341, 57_389, 131_071):
        m = _fast_length(n)
        assert m >= n
        k = m
        for p in (2, 3, 5):
            while k % p == 0:
                k //= p
        assert k == 1, (n, m)
        # no smaller 5-smooth number in between
        for j in range(n, m):
            k = j
            for p in (2, 3, 5):
                while k % p == 0:
                    k //= p
            assert k != 1, (n, j)


def test_noise_draws_have_unit_variance_and_the_shape() -> None:
    n, dt = 20341, 1e-3
    f = np.fft.rfftfreq(4096, dt)
    power = 1.0 / (1.0 + (f / 50.0) ** 4)  # a low-pass shape
    spec = InputNoise(f, power, dt, 1.0, 1.0)
    draw = _NoiseDraws(n, spec)
    rng = np.random.default_rng(0)
    v = np.stack([draw(rng) for _ in range(20)])
    assert v.shape == (20, n)
    assert abs(float(np.var(v)) - 1.0) < 0.05
    # coloured: neighbouring samples correlate as the shape says (a white draw would not)
    lag1 = float(np.mean(v[:, 1:] * v[:, :-1]))
    assert lag1 > 0.5
    white = _NoiseDraws(n, None)(rng)
    assert white.size == n and abs(float(np.var(white)) - 1.0) < 0.05


def test_noise_draws_through_a_flat_spectrum_are_white() -> None:
    """The white noise's transform drawn directly: through a flat gain it is white noise of
    unit variance (no correlation between neighbours, a normal distribution)."""
    n, dt = 4999, 1e-3  # odd: the last coefficient is complex
    f = np.fft.rfftfreq(1024, dt)
    draw = _NoiseDraws(n, InputNoise(f, np.ones(f.size), dt, 1.0, 1.0))
    assert draw.m == 5000
    rng = np.random.default_rng(5)
    v = np.stack([draw(rng) for _ in range(40)])
    assert abs(float(np.var(v)) - 1.0) < 0.03
    assert abs(float(np.mean(v[:, 1:] * v[:, :-1]))) < 0.02
    kurt = float(np.mean(v**4)) / float(np.var(v)) ** 2
    assert abs(kurt - 3.0) < 0.1


@settings(max_examples=6, deadline=None)
@given(seed=st.integers(0, 10_000), wlen=st.sampled_from([5, 11, 31]), coloured=st.booleans())
def test_noise_filtered_in_the_transform_is_the_savgol_filter(
    seed: int, wlen: int, coloured: bool
) -> None:
    """The candidates' input filter applied in the noise's own transform gives, half a
    window or more from the ends, exactly what the Savitzky-Golay filter gives of the
    unfiltered draw."""
    from contactlab.diagnose._filters import savgol_filter

    n, dt = 3001, 1e-3
    f = np.fft.rfftfreq(512, dt)
    power = 1.0 / (1.0 + (f / 80.0) ** 2) if coloured else np.ones(f.size)
    spec = InputNoise(f, power, dt, 1.0, 1.0)
    plain = _NoiseDraws(n, spec)(np.random.default_rng(seed))
    filtered = _NoiseDraws(n, spec, savgol=wlen)(np.random.default_rng(seed))
    ref = savgol_filter(plain, wlen, 3, mode="interp")
    h = wlen // 2
    assert np.allclose(filtered[h : n - h], ref[h : n - h], atol=1e-12, rtol=0)
    assert np.std(filtered) < np.std(plain)
