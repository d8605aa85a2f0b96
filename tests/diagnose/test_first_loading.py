"""The first loading from rest tells a branch scale from a force offset (docs/effects.md §1):
at one amplitude both draw a Masing loop shifted by a constant force, but an offset is there
at rest and a branch scale's shift appears only with the motion. The held-out cycles begin
at the first maximum of the input, so only the candidate's plausibility can read the start.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from contactlab.diagnose._family import Prepared
from contactlab.diagnose.effects import registry
from contactlab.diagnose.effects.tangential._first_loading import (
    first_loading,
    misfit,
    model_first_loading,
)
from contactlab.diagnose.effects.tangential.non_masing_scaling import (
    loop_shift,
    turning_point_force,
    turning_points,
)
from contactlab.masing import Masing

H0, AC, ACA = 66.0, 4e4, 0.51
A = ACA / AC


def _drive(cycles=12, spc=200):
    """A sine started abruptly from rest (no ramp: the first loading is a quarter cycle)."""
    t = np.arange(cycles * spc) / (spc * 40.0)
    return t, A * np.sin(2 * np.pi * 40.0 * t)


def _prepared(t, x, F, x_noise, seed):
    rng = np.random.default_rng(seed)
    xn = x + x_noise * A * rng.normal(size=x.size)
    Fn = F + 0.01 * np.ptp(F) * rng.normal(size=x.size)
    d = Prepared.build(t, xn, Fn)
    d.extra["u_noise"] = x_noise * A
    return d


def _lam_for_shift(shift, x):
    """The λ whose element, with the base-equivalent parameters of (H0, AC), shifts the
    closed loop by ``shift`` on the drive ``x`` (what a fit of an offset record finds)."""
    turns = turning_points(x, 1e-12)

    def f(lam):
        g = turning_point_force(Masing(2 * H0 / lam, lam * AC / 2).virgin, lam, x, turns)
        return float(np.median(g[turns[0] :] - Masing(H0, AC).force(x)[turns[0] :])) - shift

    lam = brentq(f, 2.0 if shift < 0 else 0.3, 20.0 if shift < 0 else 2.0)
    return {"lam": lam, "h0": 2 * H0 / lam, "ac": lam * AC / 2}


def test_a_force_offset_is_no_branch_scale():
    """F0 = -5.7 N at h0 = 66 N, ac·A = 0.51 (the independent generator's case named
    λ = 4.1): the λ that draws the same closed loop misses the data at rest by the whole
    offset, and is refused with that reason; the data of that λ model itself pass."""
    t, x = _drive()
    F0 = -5.7
    p = _lam_for_shift(F0, x)
    assert p["lam"] > 3.0  # far from Masing's 2 on a near-linear loop
    nm = registry("tangential")["non_masing_scaling"]
    offset = _prepared(t, x, Masing(H0, AC).force(x) + F0, 0.02, seed=1)
    assert loop_shift(p, offset) == pytest.approx(F0, abs=0.3)
    ok, why = nm.plausible(offset, p)
    assert not ok and "first loading from rest" in why
    turns = turning_points(x, 1e-12)
    lam_data = turning_point_force(Masing(p["h0"], p["ac"]).virgin, p["lam"], x, turns)
    ok, why = nm.plausible(_prepared(t, x, lam_data, 0.02, seed=1), p)
    assert ok, why


def test_a_start_too_noisy_to_tell_leaves_the_offset():
    """An offset of 1 % of the range on a record whose first loading has 1 % force noise:
    the start cannot tell λ from the offset, so λ is not identified (the simpler reading, a
    sensor's zero, stays with the force_offset candidate)."""
    t, x = _drive()
    F = Masing(H0, AC).force(x)
    F0 = -0.005 * np.ptp(F)
    p = _lam_for_shift(F0, x)
    ok, why = registry("tangential")["non_masing_scaling"].plausible(
        _prepared(t, x, F + F0, 0.02, seed=2), p
    )
    assert not ok and why.startswith("not identifiable")


def test_beside_an_offset_the_start_is_the_offsets():
    t, x = _drive()
    p = {**_lam_for_shift(-5.7, x), "F0": -5.7}
    d = _prepared(t, x, Masing(H0, AC).force(x) - 5.7, 0.02, seed=3)
    assert registry("tangential")["non_masing_scaling"].plausible(d, p).ok


def test_misfit_at_rest_is_the_intercept():
    """A residual that a fit bent to meet the data further up the loading (a slope in the
    travel u) still gives its value at rest, with the standard error of the intercept."""
    rng = np.random.default_rng(0)
    u = np.linspace(0.0, 1.0, 60)
    got = [misfit(-5.0 + 4.0 * u + 0.5 * rng.normal(size=u.size), u) for _ in range(300)]
    m, se = np.array(got).T
    X = np.column_stack([np.ones_like(u), u])
    se_true = 0.5 * np.sqrt(np.linalg.inv(X.T @ X)[0, 0])
    assert abs(np.mean(m) + 5.0) < 3 * se_true / np.sqrt(m.size)
    assert np.std(m) == pytest.approx(se_true, rel=0.15)
    assert np.median(se) == pytest.approx(se_true, rel=0.15)


def test_only_models_whose_first_loading_is_known_are_checked():
    t, x = _drive()
    d = _prepared(t, x, Masing(H0, AC).force(x), 0.02, seed=4)
    n = first_loading(d)
    assert n is not None and abs(n - 50) <= 3  # a quarter of a 200-sample cycle
    p = {"h0": H0, "ac": AC, "lam": 2.0}
    F = model_first_loading(p, d, n)
    assert np.allclose(F, Masing(H0, AC).virgin(d.u[:n]))
    assert model_first_loading({**p, "tau": 1e-4}, d, n) is None
