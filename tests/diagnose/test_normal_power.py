"""The normal diagnosis keeps the power its data hold (issue 29 items 1-2): a long record's
kept samples carry the mean of the raw ones about them, the per-sample gain floors are
totals over the record, and the stated power models the family's proportional t."""

from __future__ import annotations

import numpy as np
import pytest

from contactlab.diagnose._prepare import average_kept
from contactlab.diagnose.candidates_normal import GAIN_REFERENCE_SAMPLES, gain_scale
from contactlab.diagnose.power import DRAWS, _bound, _proportional_t, _Setting


def test_kept_samples_average_the_noise_and_pass_the_signal() -> None:
    q, per = 9, 4000.0
    n = 40 * int(per)
    i = np.arange(n)
    clean = np.sin(2 * np.pi * i / per) + 0.3 * np.sin(4 * np.pi * i / per + 0.4)
    noise = np.random.default_rng(1).normal(0.0, 0.1, n)
    g = slice(0, n, q)
    yk, filt = average_kept(clean + noise, per, q, g)
    assert filt is not None and filt[0] <= q
    ck, _ = average_kept(clean, per, q, g)
    # the excitation and its second harmonic pass as measured
    assert np.max(np.abs(ck - clean[g])[5:-5]) < 2e-4
    e = (yk - ck)[5:-5]
    # the mean of q samples: the noise's variance q times smaller, the kept samples'
    # noise independent of each other (their windows do not overlap)
    assert np.var(e) == pytest.approx(0.01 / q, rel=0.1)
    assert abs(np.corrcoef(e[:-1], e[1:])[0, 1]) < 0.05
    # one sample in q as measured would keep the raw variance
    assert np.var(noise[g]) > 5 * np.var(e)


def test_short_windows_are_left_alone() -> None:
    y = np.random.default_rng(2).normal(size=1000)
    yk, filt = average_kept(y, 100.0, 1, slice(0, 1000, 1))
    assert filt is None and np.array_equal(yk, y)


@pytest.mark.parametrize("n", [10, 500, GAIN_REFERENCE_SAMPLES, 4 * GAIN_REFERENCE_SAMPLES])
def test_gain_floors_are_totals_beyond_the_reference_length(n: int) -> None:
    s = gain_scale(n)
    assert s == pytest.approx(min(1.0, GAIN_REFERENCE_SAMPLES / n))
    assert s * n >= min(n, GAIN_REFERENCE_SAMPLES) - 1e-9


def _setting(proportional: bool, m: int = 20, n_c: int = 200) -> _Setting:
    n = m * n_c
    rng = np.random.default_rng(5)
    return _Setting(
        w=np.ones(n), var=1.0, cycle_of=np.arange(n) // n_c, fold_of_cycle=np.arange(m) % 2,
        cycle_mse=np.ones(m), sigma=1.0, z=3.0, gain_floor=0.002, y_rms=10.0,
        rng_normals=rng.standard_normal((DRAWS, m)), fit_rows=np.arange(n),
        rng_fit=rng.standard_normal(DRAWS),
    )  # fmt: skip


def test_proportional_t_lowers_the_bound_of_an_effect_in_the_first_cycles() -> None:
    """A creep settles in the first cycles: the per-cycle log ratios' t is bounded by the
    few cycles that carry it, the proportional t grows with the effect's size."""
    n = 20 * 200
    t = np.arange(n) / n
    creep = -np.expm1(-t / 0.05)
    jp = creep - np.mean(creep)
    plain = _bound(jp, _setting(False), 0.0, False)
    prop = _bound(jp, _setting(True), 0.0, True)
    assert prop is not None
    assert plain is None or prop < 0.7 * plain


def test_proportional_t_against_the_rule_it_models() -> None:
    """The linearised t of one draw equals select.proportional_t on the records it stands
    for: residual ``a j + e`` of the current model, a candidate moving each held-out cycle's
    prediction by ``(a + δ_fold) j``."""
    from types import SimpleNamespace

    from contactlab.diagnose.select import proportional_t

    rng = np.random.default_rng(9)
    m, n_c = 8, 50
    n = m * n_c
    cyc = np.arange(n) // n_c
    j = np.sin(np.arange(n) / 7.0) + 0.3
    e = rng.normal(0.0, 0.4, n)
    a, fold = 0.7, cyc % 2
    est = {k: a + rng.normal(0.0, 0.05) for k in (0, 1)}
    ah = np.array([est[k] for k in fold])
    y = a * j + e
    d = SimpleNamespace(y=y, extra={}, cycles=SimpleNamespace(cycle=cyc))
    held = np.ones(n, bool)
    current = SimpleNamespace(prediction=np.zeros(n), heldout=held)
    cand = SimpleNamespace(prediction=ah * j, heldout=held)
    want = proportional_t(current, cand, d)
    W = np.bincount(cyc, minlength=m).astype(float)
    A = np.bincount(cyc, j * j, m) / W
    B = np.bincount(cyc, j * e, m) / W
    delta = (np.array([est[k] for k in np.arange(m) % 2]) - a)[None]
    got = _proportional_t(np.array([[a]]), delta, A[None], B[None], W[None], np.ones(m, bool))
    assert got[0] == pytest.approx(want, rel=1e-9)


@pytest.mark.slow
def test_a_loss_asymmetry_without_bound_says_how_far_the_record_is():
    """On three single-tone cycles in steady state the stiffening law takes most of the
    asymmetry's direction and no |a| < 0.95 reaches 95 % power: the bound is stated beyond
    the range (since stop 53; before, none) and its note gives the range end's relative
    size and detection probability and names what the drive leaves to tell the two apart
    (issue 29: a bare "not identifiable" says nothing)."""
    import re
    import warnings

    import contactlab
    from contactlab.synthetic.diagnosis import hidden_effect_recording

    # (1.5 % noise on δ, 1.05 % on p: at 1 % and 0.7 % the bound has lain just inside the
    # range, 0.92, since stop 52's rival margin on the search's scale)
    rec = hidden_effect_recording([], model="normal", noise=0.015, seed=291500,
                                  cycles_per_block=3, samples_per_cycle=120, input_noise=0.0105,
                                  frequencies=[1.0], start="steady")  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = contactlab.diagnose(rec, "normal")
    b = next(x.to_dict() for x in r.not_detected if x.to_dict()["effect"] == "asymmetric_branches")
    assert b["detectable_above"] is not None and b["detectable_above"] > 0.95, b["reason"]
    m = re.search(r"change the output by ([0-9.e+-]+) % of its RMS and be found with "
                  r"probability ([0-9.]+)", b["note"])  # fmt: skip
    assert m is not None, b["note"]
    assert "beyond the range" in b["note"]
    assert 0.0 < float(m.group(1)) < 100.0 and 0.0 <= float(m.group(2)) < 0.95
    assert "one excitation frequency" in b["note"] and "no start from rest" in b["note"]
