"""Preparing a record for the diagnosis: long records reduced or kept every q-th sample,
the errors-in-variables weights, the declared measurement filter and noise, and the samples
weighted out before any candidate is judged (moved from :mod:`.workflow`)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..errors import InputError
from ._family import Family, Prepared
from ._filters import decimate, savgol_coeffs, savgol_filter
from ._kept import MAX_SAMPLES, RawInput, knots_at
from ._signal import (
    Cycles,
    check_uniform,
    derivatives,
    dominant_period_samples,
    filter_input,
    find_cycles,
    input_noise,
    shortest_period_samples,
    smooth_window,
)

# longest record diagnosed sample by sample. Longer tangential ones keep every q-th sample
# over their whole length with the turning points between them (:func:`subsample_long`);
# longer normal ones likewise (:func:`subsample_normal`). :func:`reduce_long` (decimated,
# anti-aliased, zero phase, to no fewer than MIN_SAMPLES_PER_CYCLE per period of the fastest
# cycles and cut to the first MAX_SAMPLES samples) is the route before. MAX_SAMPLES itself is
# defined in :mod:`._kept` (imported above), which :mod:`.eiv` reads it from without
# importing this module
#: fewest samples per cycle of the fastest cycles :func:`reduce_long` decimates to
MIN_SAMPLES_PER_CYCLE = 64


def reduce_long(
    t: np.ndarray, u: np.ndarray, y: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, str]:
    """A long record brought to at most :data:`MAX_SAMPLES` samples, and a sentence saying
    how (empty when the record is used as it is).

    Both channels go through the same zero-phase FIR anti-alias filter before every q-th
    sample is kept, so neither channel is delayed against the other and the noise of both
    is reduced alike (the noise level is then estimated on the decimated record).
    """
    n = t.size
    if n <= MAX_SAMPLES:
        return t, u, y, ""
    check_uniform(t)
    per = dominant_period_samples(u)
    fastest = shortest_period_samples(u, per)
    q = max(1, int(min(fastest // MIN_SAMPLES_PER_CYCLE, -(-n // MAX_SAMPLES))))
    how = []
    if q > 1:
        u = decimate(u, q, ftype="fir", zero_phase=True)
        y = decimate(y, q, ftype="fir", zero_phase=True)
        t = t[::q][: u.size]
        how.append(f"decimated by {q} (zero-phase anti-alias filter on both channels)")
    if t.size > MAX_SAMPLES:
        cycles = t.size * q / per
        t, u, y = t[:MAX_SAMPLES], u[:MAX_SAMPLES], y[:MAX_SAMPLES]
        how.append(
            f"diagnosed on its first {MAX_SAMPLES * q / per:.0f} of {cycles:.0f} excitation cycles"
        )
    return t, u, y, f"the record of {n} samples was " + " and ".join(how)


#: fewest samples per cycle of the fastest cycles that a tangential record is subsampled to
#: (:func:`subsample_long`): the Masing memory is exact at any rate with the knots, but the
#: delay's interpolation, the reversal anchors and the cycle split want a dozen per cycle
MIN_KEPT_PER_CYCLE = 12


def subsample_long(t: np.ndarray, u: np.ndarray, y: np.ndarray) -> tuple[Prepared, str]:
    """A long tangential record kept every q-th sample over its whole length (q from the
    record's length, so that at most :data:`MAX_SAMPLES` are kept), ready for the
    candidates, and a sentence saying how.

    Everything the candidates see is computed at the raw rate and then sampled: the
    filtered input, its derivatives, the cycles and the input noise. No anti-alias filter:
    the kept force samples are the measured ones, so the model at the kept samples is the
    full-rate model there (a low-pass filter would take the loop's corners out of the
    force but not out of the model's prediction). The turning points between the kept
    samples go with them as :class:`~contactlab.diagnose._signal.Knots`, which the Masing
    element runs over, so its memory holds the true extremes. When the fastest cycles
    would keep fewer than :data:`MIN_KEPT_PER_CYCLE` samples, q is lowered and only the
    first :data:`MAX_SAMPLES` kept samples are diagnosed (said so).
    """
    n = t.size
    dt = check_uniform(t)
    per = dominant_period_samples(u)
    ud, udd = derivatives(u, dt, smooth_window(per))
    cyc = find_cycles(u, per)
    sig = input_noise(u)
    uf, wf = filter_input(u, per, sig)
    half = np.diff(cyc.reversals)
    fastest = min(per, 2.0 * float(np.percentile(half, 10))) if half.size >= 4 else per
    q = -(-n // MAX_SAMPLES)
    if fastest / q < MIN_KEPT_PER_CYCLE:
        q = max(1, int(fastest // MIN_KEPT_PER_CYCLE))
    stop = min(n, (MAX_SAMPLES - 1) * q + 1)
    g = slice(0, stop, q)
    raw, exact = RawInput.build(
        float(t[0]), dt, uf, ud, udd, cyc.reversals, q, limit=4 * MAX_SAMPLES
    )
    knots = knots_at(raw, np.arange(0, stop, q))
    cycle = cyc.cycle[g].copy()
    last = ((stop - 1) // q) * q
    if stop < n:  # the cycle cut at the end belongs to no fold
        cycle[cycle > np.count_nonzero(cyc.reversals[cyc.is_max] <= last) - 2] = -1
    keep = cyc.reversals <= last
    cycles = Cycles(
        np.rint(cyc.reversals[keep] / q).astype(int),
        cyc.is_max[keep],
        cycle,
        cyc.phase_in_branch[g],
        per / q,
    )
    extra: dict[str, Any] = {
        "u_raw": u[g], "u_noise": sig, "u_filter": wf, "knots": knots, "raw_input": raw,
        # the measured input at the raw rate and which turning points were kept, for the
        # errors-in-variables simulation (:func:`.eiv.eiv_bias`, its noise spectrum)
        "u_measured": u, "raw_exact": exact,
    }  # fmt: skip
    d = Prepared(t[g], uf[g], y[g], dt * q, smooth_window(per / q), ud[g], udd[g], cycles, extra)
    how = []
    if q > 1:
        whole = "" if stop < n else " over its whole length"
        how.append(f"kept one sample in {q}{whole} (no filter; the {knots.pos.size} turning "
                   "points between them kept in the Masing memory)")  # fmt: skip
    if not exact:
        how.append("the input's local extrema too many: its reversals only kept as turning points")
    if stop < n:
        how.append(
            f"diagnosed on its first {stop / per:.0f} of {n / per:.0f} excitation cycles "
            f"(the fastest cycles have {fastest:.0f} samples)"
        )
    return d, f"the record of {n} samples was " + " and ".join(how)


#: fewest samples per cycle of the fastest cycles that a normal record is kept at
#: (:func:`subsample_normal`): the model integrates the pressure's cubic Hermite between kept
#: samples with the slopes taken at the raw rate, whose error is ``(2π/s)⁴/384`` of the
#: displacement at ``s`` samples per cycle (2e-4 at 12, a fortieth of 1 % output noise)
MIN_KEPT_PER_CYCLE_NORMAL = 12


def average_kept(
    y: np.ndarray, fastest: float, q: int, g: slice
) -> tuple[np.ndarray, tuple[int, int] | None]:
    """The measured displacement at the kept samples ``g`` (one in ``q``), each averaged over
    the raw samples about it, and the filter ``(window, order)`` (None: kept as measured).

    Keeping one sample in ``q`` as measured throws away ``q - 1`` of every ``q`` samples'
    information: the noncentrality of every effect falls ``q`` times, the size it needs
    ``√q`` times (measured on 200 000-sample records: the stated bounds 5-22 times what the
    data hold). The mean over the (odd) ``q`` raw samples about each kept one when it stays
    flat to :data:`~contactlab.diagnose.candidates_normal.INPUT_PASS_ERROR` over the
    excitation and its second harmonic, else the Savitzky-Golay filter of least noise gain
    that does (:func:`~contactlab.diagnose.candidates_normal.input_filter_choice`) with a
    window of at most ``q`` raw samples, leaves the model's band as measured (the
    model is compared with it unfiltered) and the kept samples' noise independent (their
    windows do not overlap), its variance ``Σ c²`` of the raw one (1/q for the mean).
    """
    from .candidates_normal import INPUT_PASS_ERROR, INPUT_PASS_HARMONICS, input_filter_choice

    yk = np.ascontiguousarray(y[g], dtype=float)
    if q < 3:
        return yk, None
    n, order = q - 1 + q % 2, 1  # the mean over q samples (noise 1/q) when flat enough
    f = np.linspace(0.0, INPUT_PASS_HARMONICS / fastest, 48)
    j = np.arange(n) - n // 2
    if float(np.max(np.abs(1.0 - np.mean(np.cos(2 * np.pi * np.outer(f, j)), axis=1)))) > (
        INPUT_PASS_ERROR
    ):
        n, order = input_filter_choice(fastest, 0, longest=q)
    if n < order + 2 or n > y.size:
        return yk, None
    return np.ascontiguousarray(savgol_filter(y, n, order, mode="interp")[g]), (n, order)


def subsample_normal(t: np.ndarray, u: np.ndarray, y: np.ndarray) -> tuple[Prepared, str]:
    """A long normal-contact record kept every q-th sample over its whole length (q from
    the record's length, so that at most :data:`MAX_SAMPLES` are kept), ready for the
    candidates, and a sentence saying how.

    As :func:`subsample_long` does for a tangential record: the filtered pressure, its slope
    and the cycles are computed at the raw rate and then sampled, and the displacement
    at each kept sample is the measured one averaged over the raw samples about it by a
    filter flat over the model's band (:func:`average_kept`: every raw sample's information
    is kept; the model's displacement is compared unfiltered). The model integrates the pressure
    between kept samples by its cubic Hermite with the raw-rate slopes (``d.extra["u_slope"]``),
    so a drift, a creep and the frequency blocks are seen over the whole record, and a
    channel delay is evaluated on the pressure at the raw shifted times
    (:func:`contactlab.diagnose._kept.shifted`). When the fastest cycles would keep fewer
    than :data:`MIN_KEPT_PER_CYCLE_NORMAL` samples, q is lowered and only the first
    :data:`MAX_SAMPLES` kept samples are diagnosed (said so).
    """
    n = t.size
    dt = check_uniform(t)
    per = dominant_period_samples(u)
    ud, udd = derivatives(u, dt, smooth_window(per))
    cyc = find_cycles(u, per)
    sig = input_noise(u)
    uf, _ = filter_input(u, per, sig)
    fastest = shortest_period_samples(u, per)
    q = -(-n // MAX_SAMPLES)
    if fastest / q < MIN_KEPT_PER_CYCLE_NORMAL:
        q = max(1, int(fastest // MIN_KEPT_PER_CYCLE_NORMAL))
    stop = min(n, (MAX_SAMPLES - 1) * q + 1)
    g = slice(0, stop, q)
    cycle = cyc.cycle[g].copy()
    last = ((stop - 1) // q) * q
    if stop < n:  # the cycle cut at the end belongs to no fold
        cycle[cycle > np.count_nonzero(cyc.reversals[cyc.is_max] <= last) - 2] = -1
    keep = cyc.reversals <= last
    cycles = Cycles(
        np.rint(cyc.reversals[keep] / q).astype(int),
        cyc.is_max[keep],
        cycle,
        cyc.phase_in_branch[g],
        per / q,
    )
    raw = RawInput(float(t[0]), dt, uf, ud, udd, cyc.reversals, cyc.reversals, q)
    uk = np.ascontiguousarray(uf[g])
    yk, y_filter = average_kept(y, fastest, q, g)
    # the input noise as the candidates see it: the filtered pressure's noise, folded into
    # the kept band (white there), read off the kept samples with no further filter
    extra: dict[str, Any] = {
        "u_raw": uk, "u_noise": sig, "u_filter": 0, "u_slope": np.ascontiguousarray(ud[g]),
        "raw_input": raw,
    }  # fmt: skip
    if y_filter:
        extra["y_filter"] = y_filter
    d = Prepared(
        np.ascontiguousarray(t[g]), uk, yk, dt * q,
        smooth_window(per / q), ud[g], udd[g], cycles, extra,
    )  # fmt: skip
    how = []
    if q > 1:
        whole = "" if stop < n else " over its whole length"
        kept = (f"the displacement averaged about each by a {y_filter[0]}-sample "
                f"order-{y_filter[1]} zero-phase filter flat over the excitation's band"
                if y_filter else "no filter")  # fmt: skip
        how.append(f"kept one sample in {q}{whole} ({kept}; the pressure between them from "
                   "its full-rate slopes)")  # fmt: skip
    if stop < n:
        how.append(
            f"diagnosed on its first {stop / per:.0f} of {n / per:.0f} excitation cycles "
            f"(the fastest cycles have {fastest:.0f} samples)"
        )
    return d, f"the record of {n} samples was " + " and ".join(how)


#: the input noise read from its spectrum sets the weights when it passes at least this many
#: times what the white estimate says through the candidates' filter (the misfit test's
#: :data:`contactlab.diagnose.eiv.COLOURED_RATIO`: white noise reads 0.9-1.1)
SPECTRAL_WEIGHT_RATIO = 1.5


def input_seen(d: Prepared) -> float:
    """The input noise RMS per sample that the candidates see (after their zero-phase input
    filter), and the one the detection's weights use (kept in ``d.extra["u_seen"]``).

    The white estimate (:func:`~contactlab.diagnose._signal.input_noise`, from neighbouring
    samples) times the filter's noise gain, unless the noise's spectrum
    (:func:`contactlab.diagnose.eiv.input_noise_spectrum`) shows it coloured: an LVDT's
    demodulator and a Bessel anti-alias filter low-pass the sensor's noise, the white
    estimate then sees a fifth of it or less, and the filter, which passes the drive's
    band, removes little of it. Then what the spectrum passes through the filter is used
    (when it exceeds :data:`SPECTRAL_WEIGHT_RATIO` times the white figure), unless the
    record sticks (``d.extra["location_prior"]``): its jerks above the drive's band are
    motion, not noise."""
    if "u_seen" in d.extra:
        return float(d.extra["u_seen"])
    from .eiv import input_noise_spectrum

    su = float(d.extra.get("u_noise", 0.0) or 0.0)
    wlen = int(d.extra.get("u_filter", 0))
    gain = float(np.sum(savgol_coeffs(wlen, 3) ** 2)) if wlen else 1.0
    seen = su * float(np.sqrt(gain))
    # a record that sticks moves in jerks above the drive's band, which the spectrum would
    # read as noise (the friction frame at 450 g then named nothing, h0 off its plateau)
    sticks = float((d.extra.get("location_prior") or {}).get("sticking_fraction", 0.0)) > 0.0
    spec = input_noise_spectrum(d) if su > 0 and not sticks else None
    if spec is not None and spec.seen > SPECTRAL_WEIGHT_RATIO * seen:
        seen = float(spec.seen)
    d.extra["u_seen"] = seen
    return seen


def eiv_weight(
    family: Family, params: dict[str, float], d: Prepared, sigma: float
) -> tuple[np.ndarray, float] | None:
    """Errors-in-variables weights of the samples and the candidates' gain budget.

    ``w = σy² / (σy² + (s σu')²)`` with ``s`` the base model's local slope ``|dy/du|``
    (:meth:`Family.slope`) and ``σu'`` the noise left in the input the candidates see
    (:func:`input_seen`: the white estimate times the filter's noise gain, or what the
    noise's spectrum passes through the filter when it is coloured). The budget, in units
    of ``σy²``, is the mean of ``(s σu')² w``: what the input's noise contributes to the
    weighted error, the most that smoothing the input (a delay shorter than a sample) or
    absorbing the noise's bias (turning points pushed outward) could lower it; every
    candidate's held-out gain must beat it. None when the family has no slope or the input
    carries no measurable noise.
    """
    su = float(d.extra.get("u_noise", 0.0))
    if not su > 0.0:
        return None
    s = family.slope(params, d)
    if s is None:
        return None
    seen = input_seen(d)
    var = (s * seen) ** 2
    w = sigma**2 / (sigma**2 + var)
    prior = d.extra.get("weight")  # samples weighted out before (sticks, a filter's ends)
    if prior is None:
        return w, float(np.mean(var * w)) / sigma**2
    w = w * prior
    return w, float(np.sum(var * w) / max(float(np.sum(prior)), 1.0)) / sigma**2


def _declared(
    recording: Any,
    family: Family,
    taps: Any,
    noise: float | None,
    n: int,
    y: np.ndarray | None = None,
) -> tuple[np.ndarray | None, float | None]:
    """The output's declared measurement filter and noise RMS: the arguments, else the
    recording's ``meta`` (``output_filter``, ``output_noise``); checked (a noise RMS above the
    output's whole swing ``y`` is not a noise level of that channel, and its square would
    overflow the weights)."""
    meta = getattr(recording, "meta", None)
    if not isinstance(meta, dict):
        meta = {}
    if taps is None:
        taps = meta.get("output_filter")
    if noise is None:
        noise = meta.get("output_noise")
    if taps is not None:
        if family.kind != "tangential":
            raise InputError("output_filter is supported for the tangential model only")
        try:
            a = np.asarray(taps, dtype=float)
        except (TypeError, ValueError):
            raise InputError("output_filter must be a sequence of filter taps (numbers)") from None
        if a.ndim != 1 or a.size % 2 != 1 or not np.all(np.isfinite(a)):
            raise InputError(
                f"output_filter must be an odd number of finite taps (a zero-phase filter), "
                f"got shape {a.shape}"
            )
        if not abs(float(np.sum(a)) - 1.0) < 1e-6:
            raise InputError(
                f"output_filter's taps sum to {float(np.sum(a)):.6g}; a measurement filter "
                "passes a constant force unchanged (sum 1)"
            )
        if a.size >= n // 4:
            raise InputError(
                f"output_filter has {a.size} taps for a record of {n} samples: too long a "
                "filter to leave anything to diagnose"
            )
        taps = None if a.size == 1 else a
    if noise is not None:
        if not (isinstance(noise, (int, float, np.floating)) and np.isfinite(noise) and noise > 0):
            raise InputError(f"output_noise must be a finite number > 0, got {noise!r}")
        noise = float(noise)
        swing = float(np.ptp(y)) if y is not None and y.size else None
        if swing is not None and noise > swing:
            unit = family.output_unit
            raise InputError(
                f"output_noise {noise:.6g} {unit} exceeds the whole swing of channel "
                f"{family.output_name!r} ({swing:.6g} {unit} peak to peak): not a noise RMS "
                "of that channel — check its value and unit"
            )
    return taps, noise


def _same_clock(recording: Any, names: list[str], candidates: Sequence[str] | None) -> str | None:
    """A recording whose ``meta["same_clock"]`` is true has an output computed from the
    input's own samples (e.g. a friction force reconstructed from the displacements of a
    frame, :meth:`contactlab.tangential.FrameForce.recording`): the two channels cannot be
    skewed in time, so ``channel_delay`` is not tried (unless asked for by name in
    ``candidates``); removed from ``names`` in place, and the sentence that says so."""
    meta = getattr(recording, "meta", None)
    if not (isinstance(meta, dict) and meta.get("same_clock")) or candidates is not None:
        return None
    if "channel_delay" not in names:
        return None
    names.remove("channel_delay")
    return (
        "channel_delay not tried: the output was computed from the input's own samples "
        "(same clock), so it cannot lag them"
    )


def _prior_weight(
    family: Family, d: Prepared, taps: np.ndarray | None
) -> tuple[dict[str, Any] | None, list[str]]:
    """Samples no candidate is judged on, weighted 0 in every fit and held-out error
    (``d.extra["weight"]``): the half filter at either end of a record whose output passed a
    declared filter (:func:`diagnose`'s ``output_filter``, set as ``d.extra["output_filter"]``
    here) and the family's sticking samples (:meth:`TangentialFamily.sticking`). Returns the
    report's ``location`` entries and sentences, or ``(None, [])`` when nothing is weighted
    out."""
    w = np.ones(d.y.size)
    loc: dict[str, Any] = {}
    notes = []
    if taps is not None:
        d.extra["output_filter"] = taps
        h = taps.size // 2
        w[:h] = 0.0
        w[w.size - h :] = 0.0
        loc["output_filter"] = {"taps": int(taps.size), "span_s": float(taps.size * d.dt)}
        notes.append(
            f"the force passed a declared filter of {taps.size} taps ({1e3 * taps.size * d.dt:.3g} "
            "ms, e.g. a reconstruction's smoothing): every candidate's prediction passes the "
            f"same filter; the {h} samples at either end, where it is not defined, are not used"
        )
    stuck = family.sticking(d) if hasattr(family, "sticking") else None
    if stuck is not None and np.any(stuck):
        if taps is not None:  # the filter spreads the stuck force over half its span
            stuck = np.convolve(stuck, np.ones(taps.size), mode="same") > 0.5
        w[stuck] = 0.0
        share = float(np.mean(stuck))
        loc["sticking_fraction"] = share
        notes.append(
            f"{100 * share:.0f} % of the samples stick (the displacement stands still within "
            "its noise at the reversals while the force changes): the force there is set by "
            "what holds the body, not by the displacement, and no candidate is judged on them"
        )
    if not loc:
        return None, []
    d.extra["weight"] = w
    d.extra["location_prior"] = dict(loc)  # (read by .detection.output_noise_rms)
    return loc, notes
