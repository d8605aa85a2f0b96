"""Named effects that absorb a virgin curve no candidate draws (issue 29 item 3):
:func:`contactlab.diagnose.misfit.absorbed_backbone`, a free-form virgin curve with none of
the named shape effects against them on held-out cycles, and the flag it raises."""

from __future__ import annotations

import numpy as np
import pytest

from contactlab.diagnose._family import Prepared
from contactlab.diagnose.candidates_tangential import TangentialFamily
from contactlab.diagnose.misfit import Unexplained, absorbed_backbone
from contactlab.diagnose.scaled_masing import memory, scaled_force
from contactlab.diagnose.select import fit

AC = 2e5
B1 = 0.0


def _record(virgin: str, effects: tuple[str, ...], seed: int, cycles: int = 12):
    """A record (no input noise, ac·A 4, 1 % output noise) of a Masing element with a gamma
    virgin curve (zero initial slope) or the family's own model with ``effects``; the family
    fitted with ``effects`` named."""
    spc = 200
    t = np.arange(cycles * spc) / spc
    u = 2e-5 * np.sin(2 * np.pi * t) * np.minimum(t / 1.5, 1.0)
    d = Prepared.build(t, u, np.zeros(t.size), errors_in_input=False)
    fam = TangentialFamily()
    fam.prepare(d)
    start = {"h0": 40.0, "ac": AC}
    if virgin == "gamma":

        def g(s: np.ndarray) -> np.ndarray:
            a = AC * np.abs(s)
            return 40.0 * np.sign(s) * (1.0 - (1.0 + a) * np.exp(-a))

        y = scaled_force(g, 2.0, memory(u))
    else:  # the family's own: a friction 15 % higher at one end of the stroke
        start = {"h0": 40.0, "ac": AC, "a1": 0.15, "b1": B1, "L": 2e-5}
        y = np.asarray(fam.predict(start, ("position_friction",), d))
    sigma = 0.01 * float(np.ptp(y))
    y = y + np.random.default_rng(seed).normal(0.0, sigma, y.size)
    d = Prepared.build(t, u, y, errors_in_input=False)
    fam.prepare(d)
    scales = fam.scales(d)
    f = fit(fam, effects, d, np.ones(d.y.size, bool), start, scales)
    return fam, effects, d, dict(f.params), scales, sigma


@pytest.mark.parametrize("seed", [1, 2])
def test_a_gamma_curve_absorbed_by_a_named_set_is_flagged(seed: int) -> None:
    fam, eff, d, p, scales, sigma = _record("gamma", ("backlash", "position_friction"), seed)
    got = absorbed_backbone(fam, eff, d, p, scales, sigma)
    assert got is not None and got["held_out"], got
    assert got["flagged"] and got["gain_virgin"] >= got["gain_effects"] > 0, got
    assert got["effects"] == ["backlash", "position_friction"]


@pytest.mark.parametrize("seed", [1, 2])
def test_a_genuine_position_friction_is_not_flagged(seed: int) -> None:
    # named with a backlash it does not need: the pair predicts better than a free-form
    # curve; named alone: no verdict (the rivals' check)
    pair = ("backlash", "position_friction")
    fam, eff, d, p, scales, sigma = _record("own", pair, seed)
    got = absorbed_backbone(fam, eff, d, p, scales, sigma)
    assert got is not None and got["gain_effects"] > 100, got
    assert not got["flagged"] and got["share"] < 1.0, got
    fam, eff, d, p, scales, sigma = _record("own", ("position_friction",), seed)
    assert absorbed_backbone(fam, eff, d, p, scales, sigma) is None


def test_a_set_of_reshaped_virgin_curves_alone_gets_no_verdict() -> None:
    fam, eff, d, p, scales, sigma = _record("gamma", ("series_compliance",), 1)
    assert absorbed_backbone(fam, eff, d, p, scales, sigma) is None


def test_the_flag_says_so() -> None:
    u = Unexplained(
        flagged=True, statistic=10.0, threshold=30.0, p_value=0.5, cycles=12, bins_tested=20,
        where=[], rms=0.01, peak=0.02, rms_percent_of_range=0.1, peak_percent_of_range=0.2,
        rms_over_noise=0.1, unit="N", profile={},
        calibrated={"flagged": False, "by": [], "alpha": 0.01, "draws": 40, "t": 1.0,
                    "t_threshold": 3.0, "T": 10.0, "T_threshold": 40.0, "gain": 0.0},
        patches=[{"effects": ["backlash", "position_friction"], "params_effects": 3,
                  "params_virgin": 15, "gain_effects": 900.0, "gain_virgin": 950.0,
                  "share": 950 / 900, "held_out": True, "flagged": True}],
    )  # fmt: skip
    s = u.sentence()
    assert s.startswith("systematic misfit that no candidate explains")
    assert "backlash + position_friction absorb" in s and "held-out" in s
