"""Errors in variables in the misfit test (issue 29, item 1): the residual structure the
input channel's noise alone leaves in a fitted nonlinear model, simulated
(:func:`eiv_bias`), which :mod:`.misfit`'s tests take out of the residual before they look
for structure no candidate explains."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from ..errors import ContactLabError
from ._family import Prepared
from ._filters import savgol_coeffs, savgol_filter, welch

__all__ = [
    "EIV_LEVELS",
    "EIV_REPS",
    "InputNoise",
    "eiv_bias",
    "input_noise_spectrum",
    "is_coloured",
    "reweighted",
]

#: fresh input-noise draws averaged by :func:`eiv_bias` at each added level
EIV_REPS = 6
#: more for short records: ``EIV_SAMPLES / n`` pairs, at most EIV_MAX_REPS
EIV_SAMPLES = 4e5
EIV_MAX_REPS = 48
#: the added input-noise variances of :func:`eiv_bias` (multiples of the measured one)
EIV_LEVELS = (1.0, 2.0, 3.0)
#: caches the models keep in ``d.extra`` (forces per ``ac``, merged knots), emptied in the
#: copies :func:`eiv_bias` drives with another input
_KEEP_EXTRA = ("regime_info", "meta")


NOISE_BAND_HARMONICS = 6.0
#: Welch segments span at least this many drive periods (resolution an eighth of the drive
#: frequency: the noise band starts tens of bins above the drive's own leakage)
NOISE_SEGMENT_PERIODS = 8.0
#: a bin of the noise band above this many times the band's median is a line (mains hum,
#: a drive harmonic) and is left out of the band's level
NOISE_LINE_FACTOR = 4.0
#: bins of the running median that a line is compared with
NOISE_LINE_BINS = 33


@dataclasses.dataclass(frozen=True)
class InputNoise:
    """The input channel's noise as a spectrum (errors in variables, coloured noise).

    Attributes
    ----------
    f : ndarray
        Frequencies (Hz) of Welch's periodogram of the measured input, at its raw rate.
    power : ndarray
        The noise's variance per frequency bin (sums to ``rms²``): measured above the
        band where the drive lives, flat at the band's level below it.
    dt : float
        Sampling interval (s) of the raw input.
    rms : float
        The noise's RMS as measured (input units).
    seen : float
        Its RMS after the candidates' zero-phase input filter (``d.extra["u_filter"]``).
    """

    f: np.ndarray
    power: np.ndarray
    dt: float
    rms: float
    seen: float


def _raw_input(d: Prepared) -> tuple[np.ndarray, float, int] | None:
    """``(u, dt, q)``: the measured input at its raw rate (``q`` raw samples per kept one)."""
    raw = d.extra.get("raw_input")
    if raw is not None:
        u = d.extra.get("u_measured")
        if u is None:
            return None
        return np.asarray(u, float), float(raw.dt), int(raw.q)
    u = d.extra.get("u_raw")
    return None if u is None else (np.asarray(u, float), float(d.dt), 1)


def input_noise_spectrum(d: Prepared) -> InputNoise | None:
    """The input channel's noise spectrum, estimated from the data (kept in ``d.extra``).

    A sensor's noise need not be white: an LVDT's demodulator and the anti-alias filter
    low-pass it, so it is correlated over many samples. An estimator from differences of
    neighbouring samples (:func:`contactlab.diagnose._signal.input_noise`) then sees only
    its fast part (a fifth of it and less behind a demodulator at 3 % of the sampling
    rate), and the candidates' smoothing filter removes little of it. Welch's periodogram
    of the measured input (Hann, segments of :data:`NOISE_SEGMENT_PERIODS` drive periods)
    is read above :data:`NOISE_BAND_HARMONICS` times the fastest drive frequency, where the
    drive has no power; below, the noise is taken flat at the level of the octave above
    (its mean without lines: :data:`NOISE_LINE_FACTOR`). None when the input carries no
    measurable noise (``d.extra["u_noise"]`` 0) or the record is too short.
    """
    if "u_noise_psd" in d.extra:
        return d.extra["u_noise_psd"]
    out = None
    src = _raw_input(d)
    if float(d.extra.get("u_noise", 0.0) or 0.0) > 0.0 and src is not None:
        u, dt, q = src
        per = float(d.cycles.period_samples) * q
        half = np.diff(d.cycles.reversals) * q
        fastest = min(per, 2.0 * float(np.percentile(half, 10))) if half.size >= 4 else per
        nper = int(min(u.size, 2 ** math.ceil(math.log2(max(NOISE_SEGMENT_PERIODS * per, 64)))))
        if nper >= 64 and fastest > 0:
            f, s = welch(u, 1.0 / dt, nper)
            df = float(f[1] - f[0])
            nyq = 0.5 / dt
            lo = min(NOISE_BAND_HARMONICS / (fastest * dt), 0.5 * nyq)
            lo = max(lo, 8.0 * df)
            band = (f >= lo) & (f <= min(2.0 * lo, nyq))
            if np.count_nonzero(band) >= 4:
                sb = s[band]
                level = float(np.mean(sb[sb <= NOISE_LINE_FACTOR * np.median(sb)]))
                # lines above the band (the drive's harmonics: a displacement that sticks
                # at its turns is no sine; mains hum) are no broadband noise: each bin is
                # held to NOISE_LINE_FACTOR times the running median around it
                k = NOISE_LINE_BINS // 2
                med = np.median(
                    np.lib.stride_tricks.sliding_window_view(np.pad(s, k, mode="edge"), 2 * k + 1),
                    axis=1,
                )
                s = np.minimum(s, NOISE_LINE_FACTOR * med)
                power = np.where(f < lo, level, s) * df
                wlen = int(d.extra.get("u_filter", 0))
                seen = power
                if wlen:
                    c = savgol_coeffs(wlen, 3)
                    j = np.arange(wlen) - wlen // 2
                    seen = power * np.abs(np.exp(-2j * np.pi * np.outer(f * dt, j)) @ c) ** 2
                out = InputNoise(
                    f, power, dt, float(np.sqrt(np.sum(power))), float(np.sqrt(np.sum(seen)))
                )
    d.extra["u_noise_psd"] = out
    return out


#: the input noise counts as coloured when what the candidates' filter passes of it, read
#: from its spectrum, exceeds this many times what white noise at the white estimate's level
#: would pass (white noise reads 0.9-1.1; behind an LVDT demodulator 3-20)
COLOURED_RATIO = 1.5


def is_coloured(d: Prepared, spec: InputNoise) -> bool:
    """True when the input noise's spectrum passes clearly more through the candidates'
    filter than white noise at the white estimate's level would (:data:`COLOURED_RATIO`)."""
    su = float(d.extra.get("u_noise", 0.0) or 0.0)
    wlen = int(d.extra.get("u_filter", 0))
    gain = float(np.sum(savgol_coeffs(wlen, 3) ** 2)) if wlen else 1.0
    return spec.seen > COLOURED_RATIO * su * math.sqrt(gain)


def reweighted(
    d: Prepared, slope: np.ndarray | None, sigma: float, white_seen: float, seen: float
) -> Prepared:
    """Recompute the errors-in-variables sample weights for the input noise read from its spectrum.

    The weights (``d.extra["weight"]``, ``σy² / (σy² + (s σu')²)`` times any prior weight)
    are recomputed for the input noise the candidates see read from its spectrum (``seen``)
    instead of the white estimate (``white_seen``): where a coloured input noise dominates
    the output's error (steep branches after a reversal), the misfit tests leave the
    samples out (:data:`contactlab.diagnose.misfit.MIN_WEIGHT`). Returns ``d`` itself when
    nothing changes."""
    w = d.extra.get("weight")
    if slope is None or w is None or not (seen > white_seen and sigma > 0):
        return d
    s2 = np.asarray(slope, float) ** 2
    ratio = (sigma**2 + s2 * white_seen**2) / (sigma**2 + s2 * seen**2)
    extra = dict(d.extra)
    extra["weight"] = np.asarray(w, float) * ratio
    return dataclasses.replace(d, extra=extra)


def _coloured(rng: np.random.Generator, n: int, spec: InputNoise | None) -> np.ndarray:
    """``n`` samples of unit-variance noise with the spectrum's shape (white without one)."""
    w = rng.standard_normal(n)
    if spec is None:
        return w
    fn = np.fft.rfftfreq(n, spec.dt)
    g = np.sqrt(np.maximum(np.interp(fn, spec.f, spec.power), 0.0))
    scale = math.sqrt(float(np.mean(g * g)))
    if not scale > 0:
        return w
    return np.fft.irfft(np.fft.rfft(w) * (g / scale), n)


def _driven(d: Prepared, u: np.ndarray) -> Prepared:
    """A copy of ``d`` whose model input is ``u`` (the models' caches emptied)."""
    extra = {
        k: ({} if isinstance(v, dict) and k not in _KEEP_EXTRA else v) for k, v in d.extra.items()
    }
    return dataclasses.replace(d, u=u, extra=extra)


def _kept_driven(d: Prepared, nu_raw: np.ndarray) -> Prepared | None:
    """A copy of the kept record ``d`` whose raw-rate input carries ``nu_raw`` more: its
    kept samples and the turning points between them (:func:`._kept.knots_at`) rebuilt
    as :func:`._prepare.subsample_long` builds them; None when the added noise changes
    which turning points are kept (all local extrema, or the reversals only)."""
    from ._kept import MAX_SAMPLES, RawInput, knots_at

    raw = d.extra["raw_input"]
    u = raw.u + nu_raw
    new, exact = RawInput.build(
        raw.t0, raw.dt, u, raw.ud, raw.udd, raw.reversals, raw.q, limit=4 * MAX_SAMPLES
    )
    if exact != d.extra.get("raw_exact", exact):
        return None
    pos = np.arange(d.u.size) * raw.q
    out = _driven(d, u[pos])
    out.extra["raw_input"] = new
    out.extra["knots"] = knots_at(new, pos)
    return out


def eiv_bias(
    family: Any,
    params: dict[str, float],
    effects: tuple[str, ...],
    d: Prepared,
    *,
    reps: int | None = None,
    seed: int = 0,
    coloured: bool = True,
) -> np.ndarray | None:
    """The residual structure the input's noise alone leaves in a fitted model's residual
    (errors in variables), by simulation-extrapolation; measured minus model, per sample.

    A nonlinear model driven by a noisy input is biased where it bends: the noise pushes a
    Masing element's turning points outward at every reversal (a shift in proportion to the
    noise's level ``s``) and a curved branch's mean by ``F''·s²/2``, cycle after cycle:
    structure locked to the phase, no misfit. The model is run on the candidates' input
    with fresh draws of the estimated input noise ``σu`` added through the candidates' own
    filter, at added variances :data:`EIV_LEVELS` times the measured one (antithetic pairs,
    ``EIV_SAMPLES / n`` of them, between :data:`EIV_REPS` and :data:`EIV_MAX_REPS`); per
    sample the mean prediction ``y(s)``, ``s = √(1 + λ)``, is fitted by ``c0 + c1 s + c2 s²``
    and extrapolated to ``s = 0`` (no noise): the bias is ``b = y(1) - c0``. The fit to all
    data has already absorbed the part of ``-b`` its parameters can draw, so the residual
    expects ``-(I - P) b`` with ``P`` the weighted projection on the model's Jacobian
    (central differences); that is returned.

    The noise drawn has the input noise's own spectrum (:func:`input_noise_spectrum`: an
    LVDT's demodulator and the anti-alias filter colour it) and its level (the larger of
    the spectrum's and the white estimate's). A kept record (every q-th sample, the turning
    points between them in the Masing memory) gets the noise at its raw rate and its
    turning points rebuilt per draw. None when the input carries no measurable noise, the
    model cannot be driven, or a draw changes which turning points a kept record keeps.
    ``coloured=False`` draws white noise at the white estimate's level and skips kept
    records (the null before the spectrum was read; kept for comparison in benches).
    """
    from .select import sample_weight, specs_for

    su = float(d.extra.get("u_noise", 0.0))
    wlen = int(d.extra.get("u_filter", 0))
    kept = "raw_input" in d.extra
    if not (su > 0 and wlen) or (kept and "knots" not in d.extra):
        return None
    spec = input_noise_spectrum(d) if coloured else None
    if spec is not None and not is_coloured(d, spec):
        spec = None  # white: drawn as before (the spectrum's own scatter adds nothing)
    if kept and spec is None:
        return None
    if spec is not None:  # coloured noise: its level and shape from the spectrum
        su = max(su, spec.rms)

    n = d.u.size
    n_draw = d.extra["raw_input"].u.size if kept else n
    rng = np.random.default_rng(seed)
    if reps is None:  # the simulation's own noise falls with the record's length
        reps = int(np.clip(round(EIV_SAMPLES / n), EIV_REPS, EIV_MAX_REPS))
        if kept:  # each draw rebuilds the raw-rate turning points
            reps = int(np.clip(round(EIV_SAMPLES / n_draw), EIV_REPS, EIV_MAX_REPS))

    def predict(u: np.ndarray, p: dict[str, float]) -> np.ndarray:
        return np.asarray(family.predict(p, effects, _driven(d, u)), float)

    def noisy(nu: np.ndarray) -> np.ndarray:
        if not kept:
            return predict(d.u + nu, params)
        dn = _kept_driven(d, nu)
        if dn is None:
            raise ValueError("the added noise changed the kept turning points")
        return np.asarray(family.predict(params, effects, dn), float)

    try:
        # the model's mean prediction with the input's noise raised to s = √(1+λ) times its
        # level, λ = 0 (the input as measured) and each of EIV_LEVELS
        curves = [predict(d.u, params)]
        for lam in EIV_LEVELS:
            acc = np.zeros(n)
            for _ in range(reps):  # antithetic pairs: the noise's linear response cancels
                draw = _coloured(rng, n_draw, spec) * (su * math.sqrt(lam))
                nu = savgol_filter(draw, wlen, 3, mode="interp")
                acc += noisy(nu) + noisy(-nu)
            curves.append(acc / (2 * reps))
        # per sample, y(s) = c0 + c1 s + c2 s² (a turning point pushed out by the noise
        # moves in proportion to s, a curvature's mean by s²) extrapolated to s = 0
        sv = np.sqrt(1.0 + np.r_[0.0, EIV_LEVELS])
        X = np.column_stack([np.ones(sv.size), sv, sv * sv])
        c0 = np.linalg.pinv(X)[0] @ np.vstack(curves)
        b = curves[0] - c0
        cols = []
        scales = family.scales(d)
        for spec in specs_for(family, effects):
            v = params.get(spec.name)
            if v is None or not np.isfinite(v):
                continue
            h = 1e-4 * max(abs(v), float(scales.get(spec.scale, 1.0)) * 1e-2)
            up, dn = dict(params), dict(params)
            up[spec.name], dn[spec.name] = v + h, v - h
            cols.append((predict(d.u, up) - predict(d.u, dn)) / (2 * h))
    except (ContactLabError, ValueError, ArithmeticError):  # refused: no correction
        return None
    if not np.all(np.isfinite(b)):
        return None
    w = sample_weight(d)
    use = np.isfinite(d.y) & (w > 0)
    if cols:
        J = np.column_stack(cols)[use]
        sw = np.sqrt(w[use])
        A = J * sw[:, None]
        norm = np.linalg.norm(A, axis=0)
        norm[norm == 0] = 1.0
        coef, *_ = np.linalg.lstsq(A / norm, b[use] * sw, rcond=1e-10)
        b = b - (np.column_stack(cols) / norm) @ coef
    return -b
