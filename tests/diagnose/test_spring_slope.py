"""The plateau-slope check of a named parallel stiffness (issue 29 item 3, spring_shape):
a spring adds one slope along every branch, a rational virgin curve one that decays."""

from __future__ import annotations

import numpy as np
import pytest

from contactlab.diagnose._family import Prepared
from contactlab.diagnose.effects.tangential.parallel_stiffness import (
    plateau_slopes,
    spring_slope_fails,
)
from contactlab.diagnose.scaled_masing import memory, scaled_force
from contactlab.diagnose.shape import slope_check
from contactlab.masing import Masing

A, H0 = 1e-5, 40.0


def _record(virgin: str, aca: float, seed: int, k_p: float = 0.0) -> Prepared:
    """Ten cycles of a sine through a Masing element with an exponential or a rational
    virgin curve (plus a spring ``k_p x``), 1 % force noise and 0.5 % input noise."""
    rng = np.random.default_rng(seed)
    ac = aca / A
    t = np.arange(10 * 400) / 400.0
    x = A * np.sin(2 * np.pi * t)
    if virgin == "rational":
        f = lambda s: H0 * ac * s / (1.0 + ac * np.abs(s))  # noqa: E731
    else:
        f = lambda s: H0 * np.sign(s) * (1.0 - np.exp(-ac * np.abs(s)))  # noqa: E731
    F = scaled_force(f, 2.0, memory(x)) + k_p * x
    F = F + rng.normal(0.0, 0.01 * np.ptp(F), F.size)
    xm = x + rng.normal(0.0, 0.005 * np.ptp(x), x.size)
    return Prepared.build(t, xm, F)


def _spring_fit(d: Prepared) -> dict[str, float]:
    """The base with a spring, least squares over a grid of ac (what a diagnosis that
    names parallel_stiffness alone ends with)."""
    best = None
    for aca in np.linspace(0.5, 12.0, 116):
        ac = aca / A
        X = np.column_stack([Masing(1.0, ac).force(d.u), d.u, np.ones(d.u.size)])
        c, *_ = np.linalg.lstsq(X, d.y, rcond=None)
        ss = float(np.sum((d.y - X @ c) ** 2))
        if best is None or ss < best[0]:
            best = (ss, {"h0": float(c[0]), "ac": ac, "k_p": float(c[1])})
    return best[1]


@pytest.mark.parametrize("seed", [1, 2])
def test_rational_curve_under_a_spring_fails_the_slope_check(seed: int) -> None:
    d = _record("rational", 3.0, seed)
    p = _spring_fit(d)
    assert p["k_p"] > 0  # the spring takes up the rational curve's slow tail
    s = plateau_slopes(d, p["ac"])
    assert s["branches"] >= 10
    assert s["k_far"] < 0.9 * s["k_near"]
    assert spring_slope_fails(s) is True
    got, note = slope_check(("parallel_stiffness",), d, p)
    assert note is None and got and got[0]["slope"] and got[0]["effects"] == ["parallel_stiffness"]


@pytest.mark.parametrize("seed", [1, 2])
def test_genuine_spring_passes_the_slope_check(seed: int) -> None:
    d = _record("exp", 3.0, seed, k_p=0.25 * H0 / A)
    p = _spring_fit(d)
    s = plateau_slopes(d, p["ac"])
    assert s["branches"] >= 10
    assert abs(s["k_far"] / s["k_near"] - 1.0) < 0.1
    assert spring_slope_fails(s) is False
    assert slope_check(("parallel_stiffness",), d, p) == ([], None)
    # no spring named: nothing checked
    assert slope_check(("series_compliance",), d, p) == ([], None)


def test_short_loops_give_no_verdict_and_say_so() -> None:
    d = _record("exp", 0.6, 3, k_p=0.25 * H0 / A)
    got, note = slope_check(("parallel_stiffness",), d, {"ac": 0.6 / A, "h0": H0})
    assert got == [] and note is not None and "not checked" in note
