"""A mass on a single-frequency record from rest, and a 2f load against a Stribeck term that
is only a parabola in speed (issue 29, stop 52).

- the mass's ``ẍ`` at the record's first samples: the local cubics read it from one side of
  their windows, far off the drive's on a record from rest; held at its rest value before
  the first sample (:func:`rest_padded_acceleration`) the input's ``ẍ`` is read two-sided;
- the mass's simulated null reads its size over the samples the search judges only
  (``mass_null.JUDGED_SAMPLES``): the start-up's first samples do not move it;
- a load in phase with the stroke yields only to a Stribeck term with a low-speed excess of
  its own (``normal_load.PARABOLA_VS``).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from contactlab.diagnose._family import Prepared
from contactlab.diagnose.effects import registry
from contactlab.diagnose.effects.tangential import inertia
from contactlab.diagnose.effects.tangential._common import smoothed_acceleration
from contactlab.masing import Masing

H0, AC = 40.0, 4.0e4


def _ramped(acA=0.83, f=23.9, fs=5000.0, cycles=8, x_noise=0.014, lead=0.0, seed=1):
    """A sine ramped up over its first cycle from rest (``lead``: the record cut that many
    periods into the motion instead), x noise as a share of the range; the true ẍ."""
    rng = np.random.default_rng(seed)
    A = acA / AC
    n = int(round(cycles * fs / f))
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


def test_the_mass_reads_the_start_from_rest_two_sided():
    d, acc = _ramped()
    assert d.extra["u_noise"] > 0
    rest = inertia.rest_padded_acceleration(d)
    assert rest is not None
    edge = int(0.05 * d.cycles.period_samples)
    one_sided = smoothed_acceleration(d)
    scale = float(np.max(np.abs(acc)))
    err_rest = float(np.sqrt(np.mean((rest[:edge] - acc[:edge]) ** 2))) / scale
    err_edge = float(np.sqrt(np.mean((one_sided[:edge] - acc[:edge]) ** 2))) / scale
    assert err_rest < 0.5 * err_edge, (err_rest, err_edge)
    # after the start both read the same
    mid = slice(3 * edge, d.t.size - 3 * edge)
    assert np.allclose(rest[mid], one_sided[mid], rtol=0, atol=1e-9 * scale)
    # ... and the mass reads it there (one drive frequency; beside the drive harmonics' ẍ
    # outside the start-up where they stand out)
    assert np.array_equal(inertia._mass_acc(d)[:edge], rest[:edge])


def test_a_record_cut_from_a_running_test_keeps_the_local_acceleration():
    d, _ = _ramped(lead=3.3)
    assert inertia.rest_padded_acceleration(d) is None
    edge = int(0.05 * d.cycles.period_samples)
    assert np.array_equal(inertia._mass_acc(d)[:edge], smoothed_acceleration(d)[:edge])


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


@pytest.mark.slow
def test_the_mass_null_reads_the_judged_samples_only():
    import contactlab
    from contactlab.diagnose import mass_null
    from contactlab.synthetic.rig import rig_recording

    rec = rig_recording({}, "tangential", seed=52400031, fs=2000.0, f=10.0, cycles=6,
                        acA=0.8, x_noise=0.012, F_noise=0.008)  # fmt: skip
    rep = contactlab.diagnose((rec.t, rec.channels["x"], rec.channels["F"]), model="tangential")
    d = rep.prepared
    from contactlab.diagnose.select import heldout_unit

    assert (heldout_unit(d) == 0).any()  # a start from rest, held out
    cur = rep.trials[-1]
    fam, base, eff = rep.final_model.family, dict(cur.full.params), tuple(cur.effects)
    edge = int(np.argmax(heldout_unit(d) >= 0))
    assert edge > 0
    y = np.array(d.y, float)
    y[:edge] += 5.0 * float(rep.noise_rms)  # the start's first samples, not judged

    def size(dd):
        res = mass_null.linear_term_null(fam, base, eff, "inertia", "m", dd,
                                         float(rep.noise_rms), draws=0)  # fmt: skip
        return res.size

    moved = dataclasses.replace(d, y=y, extra={**d.extra, "fixed": {}})
    assert size(moved) == pytest.approx(size(d), rel=1e-9, abs=1e-12)
    mass_null.JUDGED_SAMPLES = False
    try:
        assert size(moved) != pytest.approx(size(d), rel=1e-3)
    finally:
        mass_null.JUDGED_SAMPLES = True
