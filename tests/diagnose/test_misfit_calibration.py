"""The misfit flag through the whole diagnosis (issue 29 item 3): a clean record with noise
on both channels is not flagged, a virgin curve of another shape is (deterministic seeds)."""

from __future__ import annotations

import numpy as np
import pytest

from contactlab.diagnose.scaled_masing import memory, scaled_force
from contactlab.diagnose.workflow import diagnose
from contactlab.masing import Masing

A = 1e-5


def _record(virgin: str, acA: float, cycles: int, x_noise: float, seed: int):
    """Masing joint (h0 50 N) under a sine from rest, noise on both channels (% of range)."""
    fs, f0 = 2000.0, 5.0
    t = np.arange(round((cycles + 1.5) * fs / f0)) / fs
    x = A * np.sin(2 * np.pi * f0 * t) * np.minimum(t * f0, 1.0)
    ac = acA / A
    if virgin == "tanh":
        F = scaled_force(lambda s: 50.0 * np.tanh(ac * s), 2.0, memory(x))
    else:
        F = Masing(50.0, ac).force(x)
    rng = np.random.default_rng(seed)
    xm = x + rng.normal(0.0, x_noise * np.ptp(x), x.size)
    Fm = F + rng.normal(0.0, 0.01 * np.ptp(F), F.size)
    return t, xm, Fm


@pytest.mark.parametrize(
    ("acA", "x_noise", "seed"), [(2.0, 0.015, 3), (1.0, 0.02, 4), (5.0, 0.005, 6)]
)
def test_clean_record_with_input_noise_is_not_flagged(acA: float, x_noise: float, seed: int):
    rep = diagnose(_record("exp", acA, 15, x_noise, seed), model="tangential")
    u = rep.unexplained
    assert u is not None
    assert not u.flagged, u.sentence()
    assert u.backbone is not None and not u.backbone["flagged"]


def test_strong_tanh_virgin_curve_is_flagged():
    rep = diagnose(_record("tanh", 2.0, 40, 0.0, 5), model="tangential")
    u = rep.unexplained
    assert u is not None and u.flagged, (rep.effect_names, u and u.sentence())
    # both tests see it: the phase bins and the free-form virgin curve
    assert u.statistic > u.threshold
    assert u.backbone is not None and u.backbone["flagged"]
    assert u.backbone["t_half"] > u.backbone["z_half"]
    assert "systematic misfit that no candidate explains" in u.sentence()
