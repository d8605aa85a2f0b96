"""A named effect that a free-form virgin curve explains as well (issue 29 item 3):
:func:`contactlab.diagnose.shape.rival_share` and the flag it raises in the report."""

from __future__ import annotations

import numpy as np
import pytest

from contactlab.diagnose._family import Prepared
from contactlab.diagnose.misfit import Unexplained
from contactlab.diagnose.scaled_masing import memory, scaled_force
from contactlab.diagnose.shape import RIVAL_SHARE, rival_share
from contactlab.masing import Masing

AC = 1e5


def _record(cycles: int = 16, spc: int = 200) -> tuple[Prepared, np.ndarray, np.ndarray]:
    t = np.arange(cycles * spc) / spc
    u = 2e-5 * np.sin(2 * np.pi * t) * np.minimum(t / 1.5, 1.0)
    return Prepared.build(t, u, np.zeros(t.size), errors_in_input=False), u, t


def _left(u: np.ndarray, f) -> np.ndarray:
    """What an exponential Masing element (two curvatures) leaves of the force of ``f``."""
    y = scaled_force(f, 2.0, memory(u))
    cols = np.column_stack([Masing(1.0, AC * k).force(u) for k in (1.0, 1.3)])
    coef, *_ = np.linalg.lstsq(cols, y, rcond=None)
    return y - cols @ coef


@pytest.mark.parametrize(
    "virgin",
    [
        lambda s: 40.0 * np.tanh(AC * s),
        lambda s: 40.0 * AC * s / (1.0 + AC * np.abs(s)),
    ],
    ids=["tanh", "rational"],
)
def test_a_shape_taken_up_by_an_effect_is_a_rival(virgin) -> None:
    # the effect took up the shape's remainder (its residual is the noise alone); without
    # it the remainder is back, and a free-form virgin curve explains all of it
    d, u, _ = _record()
    left = _left(u, virgin)
    sigma = 0.5 * float(np.sqrt(np.mean(left * left)))
    e = np.random.default_rng(3).normal(0.0, sigma, u.size)
    got = rival_share(d, e, left + e, AC, sigma, n_params=2)
    assert got is not None and got["share"] >= RIVAL_SHARE, got
    assert got["gain_virgin"] > 0 and got["rms"] > 0


def test_an_effect_no_virgin_curve_draws_is_no_rival() -> None:
    # a normal load fluctuating at a frequency apart from the drive's harmonics: what it
    # explains is no shape of the branches
    d, u, t = _record()
    y = Masing(40.0, AC).force(u)
    eff = 0.05 * y * np.sin(2 * np.pi * 0.37 * t)
    sigma = 0.5 * float(np.sqrt(np.mean(eff * eff)))
    e = np.random.default_rng(4).normal(0.0, sigma, u.size)
    got = rival_share(d, e, eff + e, AC, sigma, n_params=3)
    assert got is not None and got["share"] < 0.3, got
    # and an effect that explains nothing beyond its parameters: no verdict
    assert rival_share(d, e, e, AC, sigma, n_params=3) is None


def test_rivals_flag_and_say_so() -> None:
    u = Unexplained(
        flagged=True, statistic=10.0, threshold=30.0, p_value=0.5, cycles=12, bins_tested=20,
        where=[], rms=0.01, peak=0.02, rms_percent_of_range=0.1, peak_percent_of_range=0.2,
        rms_over_noise=0.1, unit="N", profile={},
        rivals=({"effect": "normal_load", "share": 0.97, "gain_effect": 500.0,
                 "gain_virgin": 485.0, "rms": 0.12},),
    )  # fmt: skip
    s = u.sentence()
    assert s.startswith("systematic misfit that no candidate explains")
    assert "normal_load" in s and "97 %" in s
    out = u.to_dict()
    assert out["rivals"][0]["effect"] == "normal_load" and out["flagged"] is True
