"""The free-form virgin curve test of the final residual (issue 29 item 3)."""

from __future__ import annotations

import numpy as np

from contactlab.diagnose._family import Prepared
from contactlab.diagnose.misfit import backbone_misfit
from contactlab.diagnose.scaled_masing import memory, scaled_force
from contactlab.masing import Masing


def _record(cycles: int = 20, spc: int = 200) -> tuple[Prepared, np.ndarray]:
    t = np.arange(cycles * spc) / spc
    u = 2e-5 * np.sin(2 * np.pi * t) * np.minimum(t / 2.0, 1.0)
    return Prepared.build(t, u, np.zeros(t.size), errors_in_input=False), u


def test_pure_noise_is_not_flagged() -> None:
    d, _ = _record()
    flagged = 0
    for seed in range(20):
        e = np.random.default_rng(seed).normal(0.0, 0.1, d.y.size)
        out = backbone_misfit(d, e, 1e5, 0.1)
        assert out is not None and out["cycles"] >= 15
        flagged += out["flagged"]
    assert flagged <= 1


def test_a_virgin_curve_of_another_shape_is_flagged() -> None:
    d, u = _record()
    ac = 1e5
    tanh = scaled_force(lambda s: 40.0 * np.tanh(ac * s), 2.0, memory(u))
    # what an exponential Masing element fitted by least squares leaves of it
    cols = np.column_stack([Masing(1.0, ac * k).force(u) for k in (1.0, 1.3)])
    coef, *_ = np.linalg.lstsq(cols, tanh, rcond=None)
    left = tanh - cols @ coef
    sigma = 2.0 * float(np.sqrt(np.mean(left * left)))  # the shape sits below the noise
    e = left + np.random.default_rng(1).normal(0.0, sigma, u.size)
    out = backbone_misfit(d, e, ac, sigma)
    assert out is not None and out["flagged"], out
    # and too few cycles: no test
    d4, _ = _record(cycles=3)
    assert backbone_misfit(d4, np.zeros(d4.y.size), ac, 1.0) is None
