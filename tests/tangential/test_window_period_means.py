"""``analyze_window(period_means=False)`` (what ``track``'s windows run): the per-cycle means
of the detrended window are left out of the fold, and nothing else changes."""

from __future__ import annotations

import numpy as np
import pytest

from contactlab.errors import InputError
from contactlab.io import Recording
from contactlab.synthetic.tangential import synthetic_recording
from contactlab.tangential.window import analyze_window

# fresh seeds: drifts on both channels, pre-sliding, an inverted load cell (the negated fold)
_CASES = {
    "drifts": dict(h0=25.0, ac=8e4, amplitude=10e-6, n_cycles=9.4, fs=800.0, noise=0.02,
                   x_noise=0.01, drift=0.3, x_drift=1.5e-7, seed=7311),
    "pre-sliding": dict(h0=30.0, ac=5e4, amplitude=12e-6, n_cycles=11, fs=1200.0, noise=0.02,
                        seed=7312),
}  # fmt: skip


@pytest.mark.parametrize("case", sorted(_CASES))
@pytest.mark.parametrize("invert", [False, True])
def test_a_window_without_period_means_has_every_other_number(case, invert):
    rec = synthetic_recording(**_CASES[case])
    if invert:
        rec = Recording(rec.t, {"x": rec["x"], "F": -rec["F"]}, rec.units, rec.source, {})
    a = analyze_window(rec)
    b = analyze_window(rec, period_means=False)
    assert a.to_dict() == b.to_dict()
    sa, sb = a.scatter, b.scatter
    assert sa is not None and sb is not None
    for k in ("amplitude", "force_range", "energy", "period", "time"):
        np.testing.assert_array_equal(getattr(sa, k), getattr(sb, k), err_msg=k)
    # the means were computed with them, and are NaN (one a cycle) without
    assert np.all(np.isfinite(sa.mean_force)) and np.all(np.isfinite(sa.mean_x))
    for k in ("mean_force", "mean_x"):
        v = getattr(sb, k)
        assert v.shape == (sb.n_cycles,) and np.all(np.isnan(v)), k


@pytest.mark.parametrize("case", sorted(_CASES))
def test_a_window_scanned_by_its_reader_is_not_scanned_again(case):
    """``analyze_window(scanned=...)`` (a streamed reader's extremes of x and F, t known
    finite): the channel checks take those extremes instead of reading the samples, and every
    number is that of the window checked by its own scans."""
    rec = synthetic_recording(**_CASES[case])
    x, F = rec["x"], rec["F"]
    exact = {"x": (float(x.min()), float(x.max())), "F": (float(F.min()), float(F.max()))}
    a = analyze_window(rec, period_means=False)
    b = analyze_window(rec, period_means=False, scanned=exact)
    assert a.to_dict() == b.to_dict() and a.warnings == b.warnings
    # the extremes given are the ones checked: a channel said constant is refused as one
    with pytest.raises(InputError, match="F is constant"):
        analyze_window(rec, scanned={**exact, "F": (1.0, 1.0)})


@pytest.mark.parametrize("case", sorted(_CASES))
def test_a_sampled_window_is_detrended_on_its_axis_made_as_it_goes(case):
    """``analyze_window(time_step=(t0, dt, offset))`` (a streamed window of a sampled
    recording): the detrending pass makes ``fill_time``'s axis instead of reading it, and
    every number is that of the window read with its axis. An axis said to start a sample
    later is used (the numbers move), so the axis made is the one given."""
    from contactlab import _core

    src = synthetic_recording(**_CASES[case])
    n = len(src.t)
    t0, dt, offset = 0.125, 1.0 / _CASES[case]["fs"], 2_000_003
    t = np.empty(n)
    _core.fill_time(t, t0, dt, offset)
    rec = Recording(t, {"x": src["x"], "F": src["F"]}, src.units, src.source, {})
    a = analyze_window(rec, period_means=False)
    b = analyze_window(rec, period_means=False, time_step=(t0, dt, offset))
    assert a.to_dict() == b.to_dict() and a.warnings == b.warnings
    c = analyze_window(rec, period_means=False, time_step=(t0, dt, offset + 1))
    assert c.to_dict() != a.to_dict()


@pytest.mark.parametrize("n", [40_000, 100_003])
def test_the_raw_scan_gives_order_stats_and_period_means_bit_for_bit(n):
    """``_core.order_stats_trapezoids`` (the raw window's order statistics with the period
    means' checkpoints in one pass, what ``window_detrended`` runs) and
    ``period_means_pair(..., scan)`` resumed from it give the numbers of ``order_stats`` and
    ``period_means_pair`` bit for bit; a scan of another axis is not resumed, and a bad axis
    is refused by name as without a scan."""
    from contactlab import _core

    rng = np.random.default_rng(7313)
    t = 2.0 + np.cumsum(rng.uniform(0.5e-4, 1.5e-4, n))
    x = np.sin(60.0 * t) + 0.01 * rng.standard_normal(n)
    F = 40.0 * np.sin(60.0 * t + 0.3) + rng.standard_normal(n)
    ranks = [n // 200, n // 200 + 1, n - 2 - n // 200, n - 1 - n // 200]
    scan = _core.order_stats_trapezoids(x, t, F, ranks)
    assert scan.order_stats.tobytes() == _core.order_stats(x, ranks).tobytes()
    edges = np.sort(np.concatenate([rng.uniform(t[0] - 0.01, t[-1] + 0.01, 300), t[::997]]))
    got = _core.period_means_pair(t, F, x, edges, scan)
    want = _core.period_means_pair(t, F, x, edges)
    for g, w in zip(got, want, strict=True):
        assert g.tobytes() == w.tobytes()
    shifted = t + 1.0
    got = _core.period_means_pair(shifted, F, x, edges, scan)
    want = _core.period_means_pair(shifted, F, x, edges)
    for g, w in zip(got, want, strict=True):
        assert g.tobytes() == w.tobytes()
    bad = t.copy()
    bad[n // 2] = bad[n // 2 - 1]
    scan = _core.order_stats_trapezoids(x, bad, F, ranks)
    with pytest.raises(InputError, match="increasing"):
        _core.period_means_pair(bad, F, x, edges, scan)
