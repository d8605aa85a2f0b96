"""One window of a long tangential recording, analysed as :func:`analyze_tangential`
analyses a whole record but with the samples folded once (in Rust) and the orientation and
detrending decided on that one fold (:func:`analyze_window`, used by
:func:`contactlab.studies.tracking.track`)."""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from .. import _core
from .._arrays import as_1d
from .._physical import check_channel
from ..errors import InputError
from ..io import Recording
from . import lag, steps
from .analysis import _analyze, _check_options, _inputs, analyze_tangential
from .orientation import Orientation
from .preprocess import (
    AveragedLoop,
    _fold_loop,
    _lerp_tails,
    _reversals,
    _tail_ranks,
    average_loop,
    find_reversals,
    negated_loop,
    tail_percentiles,
)
from .result import TangentialAnalysis
from .uncertainty import trend


def _fast_orientation(
    x: np.ndarray, F: np.ndarray, loop: AveragedLoop, force_sign: Any
) -> Orientation | None:
    """The force sign from the averaged loop's per-cycle areas (the signed loop area of the
    complete cycles, its noise error from the bins' cycle-to-cycle spread); None when the
    area does not decide it (then the full :func:`orient` does)."""
    from .orientation import SIGNIFICANCE, parse_force_sign

    e = loop.scatter.energy
    ok = np.isfinite(e)
    area = float(np.sum(e[ok])) if ok.any() else 0.0
    n = loop.n_cycles
    err = math.nan
    if loop.cycle_bounds is not None and n > 1:
        per_cycle = loop.count / n
        vF, vx = loop.F_std**2 * per_cycle, loop.x_std**2 * per_cycle
        if np.any(np.isfinite(vF)) and np.any(np.isfinite(vx)):
            g_F, g_x = (
                loop.sensitivity  # of x, F: the loop was folded from them
                if loop.sensitivity is not None
                else _core.loop_area_sensitivity(x, F, [int(b) for b in loop.cycle_bounds[: n + 1]])
            )
            err = math.sqrt(
                float(np.sum(g_F)) * float(np.nanmean(vF))
                + float(np.sum(g_x)) * float(np.nanmean(vx))
            )
    fixed = parse_force_sign(force_sign)
    if fixed is not None:
        return Orientation(fixed, f"force sign {fixed:+d} given by the user", area, err, "user")
    if not (math.isfinite(err) and area != 0 and abs(area) > SIGNIFICANCE * err):
        return None
    sign = 1 if area > 0 else -1
    what = "as recorded" if sign > 0 else "after inverting F (the load cell counts the other way)"
    reason = (
        f"a passive joint dissipates (∮F dx > 0): the signed loop area is {area:.4g} J "
        f"± {err:.2g} J, so the force is analysed {what}"
    )
    return Orientation(sign, reason, area, err, "loop area")


def analyze_window(
    recording: Recording,
    *,
    force_sign: int | str = "auto",
    n_points: int | None = None,
    rel_threshold: float = 0.5,
    min_cycles: int = 2,
    max_rel_stderr: float = 0.2,
    fit_offset: bool = True,
    fit_x0: bool | None = None,
    fit_amplitude: bool = True,
    detrend: bool = True,
    initial: dict[str, float] | None = None,
    delay: float | None = None,
    period_means: bool = True,
    scanned: dict[str, tuple[float, float]] | None = None,
    time_step: tuple[float, float, int] | None = None,
) -> TangentialAnalysis:
    """:func:`analyze_tangential` of one window of a streamed recording (``on="averaged"``,
    steady history), with the per-sample work in one pass of Rust kernels.

    The samples are folded once: the drifts come from the period means between the raw
    displacement's peaks (what :func:`steps.detrend`'s first fold gives them from), the
    detrended samples are folded in one Rust pass (:func:`contactlab._core.fold_window`:
    phase bins, cycle bounds, per-cycle areas and their sensitivities, period means), and
    that loop is reused: the force sign follows from its per-cycle areas (an inverted force
    negates the fold), the drift covariance from its bins' mean time, the numeric energy's
    error from the cycles' area sensitivities. The velocity and stick search over the
    samples (which only decide between gross sliding and stick-slip) runs only when the loop
    reaches gross sliding, and then the window is analysed exactly as
    :func:`analyze_tangential` does; below it, ``stick_slip`` gives the window's reversals
    and null for what only the search measures. The results are those of
    :func:`analyze_tangential` (warnings are kept in ``.warnings``, not issued; the recorded
    loop area of the orientation is that of the detrended samples).

    ``period_means=False`` leaves the per-cycle mean force and displacement of the detrended
    window (``scatter.mean_force``, ``scatter.mean_x``) NaN instead of computing them; no
    other number depends on them (:func:`contactlab.studies.tracking.track`, which keeps only
    the quantities, saves the fold's trapezoid chain: about 6 % of a window's CPU).

    ``scanned``: what the caller's reader already checked of these very samples
    (:func:`contactlab.studies.tracking.track`'s): ``{"x": (min, max), "F": (min, max)}``
    of channels it found finite, with a time axis it found finite. The channel checks then
    use these extremes, and the time axis is not scanned again (three reads of the window
    fewer; the same results).

    ``time_step``: ``(t0, dt, offset)`` when the recording's time axis is
    :func:`contactlab._core.fill_time`'s ``t0 + dt·(offset + i)`` (a streamed window of a
    sampled recording, :func:`contactlab.studies.tracking.track`'s): the detrending pass then
    makes the axis as it goes instead of reading it (the same numbers).
    """
    xa, Fa, ta, source = _inputs(recording, None, None, None)
    _check_options("averaged", "steady", n_points)
    known = scanned or {}
    finite_x = check_channel("x", xa, "m", "displacement", known.get("x"))
    finite_f = check_channel("F", Fa, "N", "force", known.get("F"))
    dropped = 0
    if delay is not None:  # ``delay`` as in analyze_tangential
        ta, xa, Fa, dropped = lag.shift_force(ta, xa, Fa, delay)
    opts: dict[str, Any] = {
        "n_points": n_points,
        "rel_threshold": rel_threshold,
        "min_cycles": min_cycles,
        "max_rel_stderr": max_rel_stderr,
        "fit_offset": fit_offset,
        "fit_x0": fit_x0,
        "fit_amplitude": fit_amplitude,
        "detrend": detrend,
        "initial": initial,
    }
    # (a recording's channels are contiguous float64 arrays unless replaced since)
    plain = all(a.dtype == np.float64 and a.ndim == 1 and a.flags.c_contiguous for a in (xa, Fa))
    pre = window_detrended(
        xa,
        Fa,
        ta,
        opts,
        checked=finite_x and finite_f and plain,
        period_means=period_means,
        time_checked=scanned is not None and delay is None,
        time_step=time_step if delay is None else None,
    )
    ori = _fast_orientation(pre.x, pre.F, pre.loop, force_sign)
    res = None
    if ori is not None:
        if ori.sign < 0:
            pre = _negated(pre)
        res = _analyze(
            xa,
            Fa,
            ta,
            source,
            ori,
            pre,
            on="averaged",
            history="steady",
            streamed=True,
            delay=delay,
            **opts,
        )
    if res is None:  # the sign undecided by the area, or gross sliding: the full analysis
        return analyze_tangential(recording, force_sign=force_sign, warn=False, delay=delay, **opts)
    lag.record(res, delay, dropped)
    return res


def window_detrended(
    xa: np.ndarray,
    Fa: np.ndarray,
    ta: np.ndarray | None,
    opts: dict[str, Any],
    checked: bool = False,
    period_means: bool = True,
    time_checked: bool = False,
    time_step: tuple[float, float, int] | None = None,
) -> steps.Detrended:
    """:func:`steps.detrend` of the window with one fold instead of two: the linear drifts
    come from the period means between the raw displacement's peaks (what the first fold's
    per-cycle means are: the same Rust kernel on the same edges), so the samples are
    detrended before the only fold. The same numbers as :func:`steps.detrend`. ``checked``:
    x and F (a recording's float64 channels) were scanned finite by :func:`check_channel`,
    so only t is checked here (else x, t and F are, naming a non-finite sample).
    ``period_means=False``: the final loop's per-cycle means of F and x are NaN (not
    computed; see :func:`analyze_window`). ``time_checked`` (with ``checked``): t too is
    known finite (a streamed reader's axis), so it is not scanned either. ``time_step``:
    ``(t0, dt, offset)`` of ``ta`` when it is :func:`contactlab._core.fill_time`'s axis (see
    :func:`analyze_window`)."""
    n_points, rel = opts["n_points"], opts["rel_threshold"]
    min_cycles = opts["min_cycles"]
    # the raw samples' scan (x, F and tc, the axis t's values as float64 and checked)
    raw: _core.RawScan | None = None
    if checked:
        # find_reversals(checked=True) of an x known finite: the reversal detector does not
        # scan it again
        if ta is None:
            tc = np.arange(xa.size, dtype=float)
        else:
            tc = as_1d(ta, "t", finite=not time_checked)
        if tc.size != xa.size:
            raise InputError(f"t has {tc.size} samples but x has {xa.size}")
        sel = _tail_ranks(xa.size)
        if sel is not None:
            # tail_percentiles(xa) and, in the same pass, the checkpoints of the period
            # means' trapezoid integrals below (issue 33: that walk's own pass, 3 ns a
            # sample, resumed from them instead; the same numbers)
            raw = _core.order_stats_trapezoids(xa, tc, Fa, sel[0])
            pct = _lerp_tails(raw.order_stats, sel[1])
        else:
            pct = tail_percentiles(xa)
        rev = _reversals(xa, tc, pct, rel, None, finite=True)
    else:
        rev = find_reversals(xa, ta, rel_threshold=rel)  # checks x and t
        Fa = as_1d(Fa, "F")
    if not (opts["detrend"] and rev.peaks.size - 1 >= 3):
        loop = average_loop(
            xa, Fa, ta, n_points=n_points, rel_threshold=rel, min_cycles=min_cycles, checked=True
        )
        return steps.Detrended(xa, Fa, loop, None)
    tt = ta if ta is not None else np.arange(xa.size, dtype=float)
    pt = rev.peak_times
    time = 0.5 * (pt[:-1] + pt[1:])
    tm = float(np.mean(time))
    # period_means of F and of x in one pass over t (bit for bit the two calls)
    edges = np.ascontiguousarray(pt, dtype=float)
    if raw is not None:  # (tc: tt's values, the axis the scan read)
        f_means, x_means = _core.period_means_pair(tc, Fa, xa, edges, raw)
    else:
        f_means, x_means = _core.period_means_pair(tt, Fa, xa, edges)
    f_drift = trend(time, f_means)
    x_drift = trend(time, x_means)
    # Fa - s·(tt - tm) for both channels in one Rust pass without the interpreter lock (bit
    # for bit numpy's a + (tt - tm)·(-s), which is a - s·τ): 16 bytes a sample at the peak
    # instead of 32 (τ, a product and the two results), one pass instead of six
    # (into numpy.empty arrays: numpy's allocator asks for huge pages, where the core's own
    # buffers faulted in every 4 KiB page, 5 ms of system time a window of 2^19 samples)
    F, x = np.empty_like(Fa), np.empty_like(xa)
    # the same pass gathers what the next two passes over the detrended samples read them
    # for: the tails of x for its robust amplitude (the reversal search's band) and the
    # fold's checks and scales (issue 33: a pass a window less each; the same numbers)
    sel = _tail_ranks(x.size)
    ranks = sel[0] if sel is not None else []
    if time_step is not None and ta is not None:
        # the axis made as the pass goes (fill_time's numbers): 8 of its 40 bytes a sample
        t0, dt, offset = time_step
        scan = _core.detrend_pair_scan_uniform_into(
            t0, dt, offset, tm, Fa, f_drift[0], xa, x_drift[0], F, x, ranks
        )
    else:
        scan = _core.detrend_pair_scan_into(tt, tm, Fa, f_drift[0], xa, x_drift[0], F, x, ranks)
    drift = steps.Drift(f_drift, x_drift, tt, tm)
    if not scan.clean:  # the fold names what is wrong (as before the scan)
        loop = average_loop(
            x, F, ta, n_points=n_points, rel_threshold=rel, min_cycles=min_cycles, checked=True
        )
        return steps.Detrended(x, F, loop, drift)
    pct = _lerp_tails(scan.order_stats, sel[1]) if sel is not None else tail_percentiles(x)
    rev = _reversals(x, tt, pct, rel, None, finite=True)  # (the scan found x finite)
    loop = _fold_loop(
        x,
        F,
        tt,
        rev,
        n_points=n_points,
        min_cycles=min_cycles,
        scan=scan,
        period_means=period_means,
    )
    return steps.Detrended(x, F, loop, drift)


def _negated(d: steps.Detrended) -> steps.Detrended:
    """The detrended window of ``-F`` (bit for bit: negation commutes with every step)."""
    dr = d.drift
    if dr is not None:
        dr = replace(dr, force=(-dr.force[0], dr.force[1]))
    loop = negated_loop(d.loop) if d.loop is not None else None
    return steps.Detrended(d.x, -d.F, loop, dr)
