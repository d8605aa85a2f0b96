"""The reported amplitude's standard error covers the cycles' own spread: a rig whose stroke
wanders from cycle to cycle (the measured friction frame: 1613-1648 µm) was reported to
0.009 µm, the fit's error of the averaged loop's tips."""

from __future__ import annotations

import math

import numpy as np

from contactlab import Masing, Recording
from contactlab.tangential import analyze_tangential


def test_amplitude_error_covers_cycle_to_cycle_spread():
    rng = np.random.default_rng(20261128)
    fs, n_cyc, per = 2000.0, 24, 2000
    amps = 20e-6 * (1.0 + 0.02 * rng.standard_normal(n_cyc))
    phase = 2 * np.pi * np.arange(per) / per
    x = np.concatenate([a * np.sin(phase) for a in amps])
    t = np.arange(x.size) / fs
    F = Masing(40.0, 4e4).force(x) + rng.normal(0, 0.02, x.size)
    res = analyze_tangential(Recording(t, {"x": x, "F": F}, {"x": "m", "F": "N"}, "wander"))
    # per cycle the peak and the valley have amplitudes of neighbouring cycles: their
    # spread is about that of the cycles' amplitudes
    sem = float(np.std(amps, ddof=1)) / math.sqrt(n_cyc)
    assert res.amplitude_stderr > 0.5 * sem
    assert abs(res.amplitude - float(np.mean(amps))) < 4 * res.amplitude_stderr
