"""The normal-load fluctuation's frequency search (TangentialFamily.search_start, issue 9):
``f_n`` searched in one dimension with the amplitudes ``eps_c, eps_s`` projected out, then
one joint fit — against the truth of a generated record on a seed nothing was tuned on, and
against the old path (the solver alone from the periodogram's start, tolerances 1e-8)."""

from __future__ import annotations

import numpy as np
import pytest

from contactlab.diagnose import select
from contactlab.diagnose._family import Prepared
from contactlab.diagnose._signal import minimize_bounded
from contactlab.diagnose.candidates_tangential import TangentialFamily
from contactlab.synthetic.diagnosis import hidden_effect_recording


class _OldPath(TangentialFamily):
    """The fit as before the search: no search, the solver's tolerances at 1e-8 and the
    polish run to its end."""

    search_start = None
    quick_polish = False


def _prepared(fam: TangentialFamily, seed: int) -> tuple[Prepared, dict, dict]:
    rec = hidden_effect_recording(
        ["normal_load"], seed=seed, cycles_per_block=20, samples_per_cycle=200,
        input_noise=0.002,
    )  # fmt: skip
    t, x, F = rec.arrays()
    d = Prepared.build(t, x, F)
    fam.prepare(d)
    return d, fam.scales(d), rec.truth["effects"]["normal_load"]


def test_minimize_bounded_finds_the_minimum_of_one_lobe():
    calls = []

    def f(x: float) -> float:
        calls.append(x)
        return float(-(np.sinc(3.0 * (x - 0.37)) ** 2))  # main lobe 0.37 ± 1/3

    x, fx, n = minimize_bounded(f, 0.1, 0.6, 1e-7)
    assert abs(x - 0.37) < 1e-6 and fx == pytest.approx(-1.0, abs=1e-10)
    assert n == len(calls) and n < 40
    x, _, _ = minimize_bounded(lambda v: (v - 2.0) ** 2, 0.0, 1.0, 1e-8)  # at the bound
    assert 1.0 - x < 1e-6


def test_load_search_recovers_frequency_and_amplitude_as_the_old_path():
    fam = TangentialFamily()
    d, scales, truth = _prepared(fam, 84517)
    everything = np.ones(d.y.size, bool)
    base = select.fit(fam, (), d, everything, fam.initial_base(d), scales)
    start = dict(base.params)
    start.update(fam.start_effect("normal_load", start, d, d.y - fam.predict(start, (), d)))
    old = select.fit(_OldPath(), ("normal_load",), d, everything, start, scales)
    assert old.success
    # the search from a start 0.35 of the record's resolution off the periodogram's peak
    lobe = 1.0 / d.duration
    off = dict(start, f_n=start["f_n"] + 0.35 * lobe)
    ys = float(np.sqrt(np.mean(d.y**2)))
    x0 = {**off, "eps_c": 0.0, "eps_s": 0.0}
    found, spent = fam.search_start(
        ("normal_load",), d, np.arange(0, d.y.size, 3), d.y[::3], np.full(d.y[::3].size, 1 / ys), x0
    )
    assert 0 < spent < 80
    for k in ("f_n", "eps_c", "eps_s"):  # the search alone lands within 2 errors of the minimum
        assert abs(found[k] - old.params[k]) < 2.0 * old.stderr[k], k
    new = select.fit(fam, ("normal_load",), d, everything, off, scales)
    assert new.success
    for k in ("h0", "ac", "f_n", "eps_c", "eps_s"):  # the old path's fit within its errors
        assert abs(new.params[k] - old.params[k]) < old.stderr[k], k
    # and the truth: eps sin(2π f_n t + φ) = eps_c cos + eps_s sin
    eps, phase = truth["eps"], truth["phase"]
    want = {"f_n": truth["f_n"], "eps_c": eps * np.sin(phase), "eps_s": eps * np.cos(phase)}
    for k, v in want.items():
        assert abs(new.params[k] - v) < 4.0 * new.stderr[k], (k, new.params[k], v)
