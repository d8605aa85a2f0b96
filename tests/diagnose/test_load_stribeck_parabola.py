"""A 2f load against a Stribeck term that is only a parabola in speed (issue 29, stop 52):
a load in phase with the stroke yields only to a Stribeck term with a low-speed excess of
its own (``normal_load.PARABOLA_VS``; a 2f load of 1.4 % at 10 kHz, 6.8 Hz, 8 cycles, ac·A
2.19 was named ``stribeck`` with s = 0.037, v_s = 0.85 Aω).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from contactlab.diagnose._family import Prepared
from contactlab.diagnose.effects import registry
from contactlab.masing import Masing

H0, AC = 40.0, 4.0e4


def _ramped(acA=0.83, f=23.9, fs=5000.0, cycles=8, x_noise=0.014, lead=0.0, seed=1):
    """A sine ramped up over its first cycle from rest (``lead``: the record cut that many
    periods into the motion instead), x noise as a share of the range; the true ẍ."""
    rng = np.random.default_rng(seed)
    A = acA / AC
    n = round(cycles * fs / f)
    t = np.arange(n) / fs + lead / f
    w = 2 * np.pi * f
    T = 1.0 / f
    r = np.clip(t / T, 0.0, 1.0)
    rd = np.where(t < T, 1.0 / T, 0.0)
    x = A * r * np.sin(w * t)
    acc = A * (2 * rd * w * np.cos(w * t) - r * w * w * np.sin(w * t))
    F = Masing(H0, AC).force(x) + rng.normal(0, 0.005 * H0, n)
    xm = x + rng.normal(0, x_noise * 2 * A, n)
    return Prepared.build(t, xm, F), acc


def _load_record():
    """A sine from rest at 10 kHz, 6.8 Hz, 8 cycles, ac·A 2.19 (issue 29's visible 2f load
    named ``stribeck``)."""
    d, _ = _ramped(acA=2.19, f=6.8, fs=10000.0, x_noise=0.0)
    return d


def test_an_in_phase_load_yields_only_to_a_stribeck_term_with_its_own_excess():
    d = _load_record()
    load = registry("tangential")["normal_load"]
    A = 2.19 / AC
    aw = A * 2 * np.pi * 6.8
    p = {"h0": H0, "ac": AC, "eps_c": -0.0124, "eps_s": -0.0035, "f_n": 13.6}
    assert load.harmonic(d, p) == 2

    def why(st):
        dd = dataclasses.replace(d, extra={**d.extra, "step_accepted_params": {"stribeck": st}})
        return load.yields_to(p, {"stribeck": 0.69}, 0.72, dd)

    # a small s over a v_s near the peak speed: the parabola the load draws, no breakaway
    assert why({"h0": H0, "ac": AC, "s": 0.037, "v_s": 0.85 * aw}) is None
    # a breakaway beyond the sticks' tolerance, or a term concentrated at the turns: its own
    assert why({"h0": H0, "ac": AC, "s": 0.12, "v_s": 0.85 * aw})
    assert why({"h0": H0, "ac": AC, "s": 0.037, "v_s": 0.2 * aw})
    # the rule off: the load yields as before
    type(load).stribeck_excess_check = False
    try:
        assert why({"h0": H0, "ac": AC, "s": 0.037, "v_s": 0.85 * aw})
    finally:
        type(load).stribeck_excess_check = True
