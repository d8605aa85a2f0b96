"""Velocity-like effects on a noisy displacement channel (issue 29, helper velocity_noise):
the dashpot may lower the base it biased, and the Masing element turns where the smoothed
input turns, not where the noise on x peaked."""

from __future__ import annotations

import numpy as np
import pytest

from contactlab.diagnose._family import Prepared
from contactlab.diagnose.candidates_tangential import TangentialFamily
from contactlab.diagnose.effects.tangential import _common
from contactlab.diagnose.effects.tangential._common import turn_clipped_input
from contactlab.diagnose.search import _takes_over

FAM = TangentialFamily()


@pytest.mark.parametrize("regime", ["transition", "pre-sliding", "gross sliding"])
def test_a_dashpot_may_lower_the_base_it_biased_not_raise_it(regime):
    # the base fitted without a dashpot read its loop area as a stiffer, more curved contact
    # (rig: h0·ac 3.38e6 N/m where the contact has 1.6e6); the dashpot's fit lowers it
    base = {"h0": 24.0, "ac": 1.41e5}
    low = {"h0": 40.0, "ac": 0.5 * 24.0 * 1.41e5 / 40.0, "c": 1900.0}
    low["h0"] = 0.5 * 24.0 if regime == "gross sliding" else low["h0"]
    assert _takes_over(FAM, base, low, ("viscous_damping",), 1.0, regime=regime) is None
    # another effect may not move it as far, nor may the dashpot raise it
    assert _takes_over(FAM, base, low, ("stribeck",), 1.0, regime=regime) is not None
    high = {"h0": 1.6 * 24.0, "ac": 1.41e5, "c": 1900.0}
    assert _takes_over(FAM, base, high, ("viscous_damping",), 1.0, regime=regime) is not None
    # nor lower it beyond its own share
    gone = {**low, "h0": 0.2 * low["h0"]}
    assert _takes_over(FAM, base, gone, ("viscous_damping",), 1.0, regime=regime) is not None


def _noisy_sine(x_noise=0.02, n_per=500, cycles=12, seed=3):
    rng = np.random.default_rng(seed)
    f, A = 5.0, 1e-5
    t = np.arange(cycles * n_per) / (n_per * f)
    ramp = 0.5 - 0.5 * np.cos(np.pi * np.clip(t * f, 0, 1))
    x = A * ramp * np.sin(2 * np.pi * f * t)
    d = Prepared.build(t, x + rng.normal(0.0, x_noise * A, t.size), 40.0 * np.tanh(4e4 * x))
    FAM.prepare(d)
    return d, x


def test_the_element_turns_where_the_input_turned_not_where_its_noise_peaked(monkeypatch):
    monkeypatch.setattr(_common, "CLIP_TURNS", True)  # (tried, off by default)
    d, x = _noisy_sine()
    sigma = float(d.extra["u_noise"])
    assert sigma > 0
    rev = d.cycles.reversals[d.cycles.cycle[d.cycles.reversals] >= 1]
    assert rev.size >= 10
    clipped = turn_clipped_input(d)
    # the noisy (filtered) input peaks beyond the true turning points, its clipped copy not
    mids = np.r_[0, (d.cycles.reversals[:-1] + d.cycles.reversals[1:]) // 2, d.u.size]
    k_of = {int(r): k for k, r in enumerate(d.cycles.reversals)}
    out_raw, out_clip = [], []
    for r in rev:
        k = k_of[int(r)]
        a, b = mids[k], mids[k + 1]
        s = 1.0 if d.cycles.is_max[k] else -1.0
        true_ext = float(np.max(s * x[a:b]))
        out_raw.append(float(np.max(s * d.u[a:b])) - true_ext)
        out_clip.append(float(np.max(s * clipped[a:b])) - true_ext)
    assert np.mean(out_raw) > 0.2 * sigma
    assert abs(np.mean(out_clip)) < 0.25 * np.mean(out_raw)
    # only the excursions beyond the turn are cut: elsewhere the element sees the input
    moved = clipped != d.u
    assert 0 < np.count_nonzero(moved) < 0.2 * d.u.size
    # and the model's element runs over it
    p = {"h0": 40.0, "ac": 4e4}
    np.testing.assert_allclose(FAM.predict(p, (), d), 40.0 * _unit(clipped), rtol=1e-9)


def _unit(x):
    from contactlab.masing import Masing

    return Masing(1.0, 4e4).force(x)


def test_a_noise_free_input_or_the_switch_off_leaves_the_input(monkeypatch):
    monkeypatch.setattr(_common, "CLIP_TURNS", True)
    d, _ = _noisy_sine(x_noise=0.0)
    assert turn_clipped_input(d) is d.u
    monkeypatch.setattr(_common, "CLIP_TURNS", False)
    d2, _ = _noisy_sine()
    assert turn_clipped_input(d2) is d2.u
