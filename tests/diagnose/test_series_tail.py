"""The plateau-tail check of a named series compliance (issue 29, tanh_shape): behind a
compliance the branches keep the exponential approach in the contact's own displacement,
a tanh virgin curve approaches faster."""

from __future__ import annotations

import numpy as np
import pytest

from contactlab.diagnose._family import Prepared
from contactlab.diagnose.effects.tangential.series_compliance import (
    plateau_tail,
    series_backbone,
    tail_fails,
)
from contactlab.diagnose.scaled_masing import memory, scaled_force
from contactlab.diagnose.shape import tail_check
from contactlab.masing import Masing

A, H0 = 1e-5, 40.0


def _record(virgin: str, aca: float, seed: int, m: float = 0.0) -> Prepared:
    """Ten cycles of a sine through a Masing element with an exponential or a tanh virgin
    curve (behind a compliance ``m/(h0 ac)`` for the exponential one), 1 % force noise and
    0.5 % input noise."""
    rng = np.random.default_rng(seed)
    ac = aca / A
    t = np.arange(10 * 400) / 400.0
    x = A * np.sin(2 * np.pi * t)
    if virgin == "tanh":
        F = scaled_force(lambda s: H0 * np.tanh(ac * s), 2.0, memory(x))
    else:
        F = Masing.from_backbone(*series_backbone(H0, ac, m / (H0 * ac), A)).force(x)
    F = F + rng.normal(0.0, 0.01 * np.ptp(F), F.size)
    xm = x + rng.normal(0.0, 0.005 * np.ptp(x), x.size)
    return Prepared.build(t, xm, F)


def _series_fit(d: Prepared) -> dict[str, float]:
    """The base behind a compliance, least squares over a grid of ``ac`` and of the
    compliance's share ``m = C_s h0 ac`` (``h0`` and an offset linear): what a diagnosis
    that names series_compliance alone ends with."""
    best = None
    half = float(np.ptp(d.u)) / 2
    for aca in np.linspace(1.0, 8.0, 29):
        ac = aca / half
        for m in np.linspace(0.0, 2.0, 11):
            bx, bf = series_backbone(1.0, ac, m / ac, half)
            X = np.column_stack([Masing.from_backbone(bx, bf).force(d.u), np.ones(d.u.size)])
            c, *_ = np.linalg.lstsq(X, d.y, rcond=None)
            ss = float(np.sum((d.y - X @ c) ** 2))
            if best is None or ss < best[0]:
                best = (ss, {"h0": float(c[0]), "ac": ac, "C_s": m / (ac * float(c[0]))})
    return best[1]


@pytest.mark.parametrize("seed", [1, 2])
def test_tanh_curve_behind_a_compliance_fails_the_tail_check(seed: int) -> None:
    d = _record("tanh", 2.5, seed)
    p = _series_fit(d)
    assert p["C_s"] > 0  # the compliance takes up the tanh curve's straighter turn
    s = plateau_tail(d, p["ac"], p["C_s"], p["h0"])
    assert s["branches"] >= 10
    assert tail_fails(s) is True
    got, note = tail_check(("series_compliance",), d, p)
    assert note is None and got and got[0]["tail"] and got[0]["effects"] == ["series_compliance"]


@pytest.mark.parametrize("seed", [1, 2])
def test_genuine_compliance_passes_the_tail_check(seed: int) -> None:
    d = _record("exp", 2.5, seed, m=0.6)
    p = _series_fit(d)
    s = plateau_tail(d, p["ac"], p["C_s"], p["h0"])
    assert s["branches"] >= 10
    assert tail_fails(s) is False
    assert tail_check(("series_compliance",), d, p) == ([], None)
    # no compliance named: nothing checked
    assert tail_check(("parallel_stiffness",), d, p) == ([], None)


def test_short_loops_give_no_verdict_and_say_so() -> None:
    d = _record("exp", 0.3, 3, m=0.6)
    p = {"ac": 0.3 / A, "h0": H0, "C_s": 0.6 / (H0 * 0.3 / A)}
    got, note = tail_check(("series_compliance",), d, p)
    assert got == [] and note is not None and "not checked" in note
