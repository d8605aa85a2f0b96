"""Detection calibrated to the record's own noise on both channels (issue 29, item 1).

A diagnosis compares candidate models through their errors against the measured output.
Two channels carry noise: the output (force ``F`` or displacement ``δ``) and the input the
model is driven by (displacement ``x`` or pressure ``p``). Input noise reaches the output
error through the model's local slope ``s = |dy/du|``, so the variance of an output error is
not ``σy²`` but the *effective variance* (errors in variables)::

    V = σy² + s² σu²

This module estimates ``σu`` and ``σy`` separately from the data (:func:`channel_noise`) and
forms ``V`` per sample (:func:`effective_variance`); :mod:`.power` uses it for the stated
power and :mod:`.misfit` for the test of structure left in the residual.

Noise estimates (high-frequency residuals, robust to drift and start-up: every estimate is
local, over a few samples, and a median over the record):

- input ``σu``: :func:`contactlab.diagnose._signal.input_noise` — the smaller of the robust
  scale of second differences and of what a local cubic over 7 samples leaves;
- output ``σy``: the robust scale of third differences of the base model's residual
  (:func:`contactlab.diagnose._signal.noise_rms`). The candidates see a smoothed input, so
  the input noise reaches the residual smoothed too and its third differences are small;
  what is left of it is removed by subtracting the filtered input noise's share
  (:func:`channel_noise`). Where an anti-alias filter colours the output's noise, third
  differences see only its fast part; a tangential record's ``σy`` is then read from the
  residual's spectrum between the drive's harmonics (:func:`output_noise_rms`);
- the input noise the candidates see per sample, ``σu'``, likewise from the input's spectrum
  where it is coloured (:func:`contactlab.diagnose._prepare.input_seen`: an LVDT's
  demodulator low-passes it); the errors-in-variables weights and the input-noise budget
  use it.

What ``V`` means for a smooth effect: the candidates see the input after a zero-phase
filter of unit DC gain, which lowers the *per-sample* input noise to ``σu'`` (``eiv_weight``
in :mod:`.workflow` weights samples with it), but a smooth direction ``J`` (what an effect
adds over many samples) sums the filtered noise back: ``Σ J_i (h * ξ)_i ≈ Σ J_i ξ_i``, so
for detection ``σu`` (unfiltered) is the right input noise.

Thresholds. The significance rules of :func:`contactlab.diagnose.select.judge` (``z``, the
held-out gain ``min_gain`` σ² plus the input-noise budget) decide what is named. Their
false-alarm rate per record was measured by simulation on clean records of the package's
generator over the sampling rate, number of cycles, input noise and ``ac·A``
(``benches/eval_false_alarm.py``: tuning seeds 0-999, reported on fresh seeds from 10 000);
:data:`FALSE_ALARM_RATE` is the per-record rate those rules were tuned to stay below. The
structure test of :mod:`.misfit` has its own null calibration (:data:`MISFIT_FALSE_ALARM`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ._family import Prepared
from ._filters import savgol_coeffs
from ._signal import noise_rms

__all__ = [
    "FALSE_ALARM_RATE",
    "MISFIT_FALSE_ALARM",
    "OUTPUT_COLOURED_RATIO",
    "ChannelNoise",
    "channel_noise",
    "effective_variance",
    "model_slope",
    "output_noise_rms",
]

#: the per-record false-alarm rate the naming rules are calibrated to stay below, and the
#: level at which :mod:`.power` states what a record would have revealed
FALSE_ALARM_RATE = 0.03
#: the per-record false-alarm rate of the structure test of :mod:`.misfit`
MISFIT_FALSE_ALARM = 0.03


@dataclass(frozen=True)
class ChannelNoise:
    """Noise of the two channels of a recording, estimated from the data.

    Attributes
    ----------
    input : float
        Sensor-noise RMS of the input channel (``x`` in m, or ``p`` in Pa), as measured
        (before the candidates' smoothing); 0 when none is measurable.
    output : float
        Noise RMS of the output channel (``F`` in N, or ``δ`` in m).
    input_seen : float
        What the candidates' zero-phase input filter leaves of ``input`` per sample.
    input_unit, output_unit : str
        Units of the two values.
    output_declared : bool
        True when ``output`` was declared by the caller (``output_noise``), not estimated.
    """

    input: float
    output: float
    input_seen: float
    input_unit: str = ""
    output_unit: str = ""
    output_declared: bool = False

    def to_dict(self) -> dict[str, Any]:
        """JSON layout: ``{"input": σu, "output": σy, "input_seen": σu', "units": {...},
        "output_declared": bool}``."""
        return {
            "input": self.input,
            "output": self.output,
            "input_seen": self.input_seen,
            "output_declared": self.output_declared,
            "units": {
                "input": self.input_unit,
                "output": self.output_unit,
                "input_seen": self.input_unit,
            },
        }


def filter_noise_gain(d: Prepared) -> float:
    """Variance gain of the candidates' input filter on white noise (1 when unfiltered)."""
    wlen = int(d.extra.get("u_filter", 0))
    return float(np.sum(savgol_coeffs(wlen, 3) ** 2)) if wlen else 1.0


def channel_noise(
    d: Prepared,
    residual: np.ndarray,
    *,
    declared_output: float | None = None,
    slope: np.ndarray | None = None,
    input_unit: str = "",
    output_unit: str = "",
) -> ChannelNoise:
    """Input and output channel noise of a prepared recording, estimated separately.

    Parameters
    ----------
    d : Prepared
        The recording as the diagnosis sees it (``d.extra["u_noise"]``: the input channel's
        noise estimated at preparation, :func:`contactlab.diagnose._signal.input_noise`).
    residual : ndarray
        A model's residual (either sign) on ``d``'s samples; its third differences give the
        output noise.
    declared_output : float, optional
        The output noise RMS when the caller declared it (then used as given).
    slope : ndarray, optional
        The model's local slope ``|dy/du|`` per sample (``Family.slope``): the filtered
        input noise it passes into the residual's third differences is taken out.
    input_unit, output_unit : str
        Units, carried into :meth:`ChannelNoise.to_dict`.

    Returns
    -------
    ChannelNoise

    Notes
    -----
    The residual's third differences hold the output noise and what the filtered input noise
    leaves in them through the local slope; that share is ``Σ c3² · g`` of ``(s σu)²`` per
    sample, with ``c3`` the third-difference filter convolved with the input filter and ``g``
    its normalisation, and is subtracted (never more than half of the estimate).
    """
    su = float(d.extra.get("u_noise", 0.0))
    gain = filter_noise_gain(d)
    if declared_output is not None:
        sy = float(declared_output)
    elif "y_noise_spectral" in d.extra:  # coloured: the level the detection used
        sy = float(d.extra["y_noise_spectral"])
    else:
        sy = noise_rms(residual)
        wlen = int(d.extra.get("u_filter", 0))
        if su > 0 and wlen and slope is not None:
            # the input noise after the filter, seen by the third differences
            h = savgol_coeffs(wlen, 3)
            c3 = np.convolve(h, [1.0, -3.0, 3.0, -1.0])
            leak = float(np.sum(c3 * c3)) / 20.0  # in units of what white noise gives
            share = leak * float(np.median(np.asarray(slope) ** 2)) * su * su
            sy = float(np.sqrt(max(sy * sy - share, 0.25 * sy * sy)))
    return ChannelNoise(
        input=su,
        output=sy,
        input_seen=su * float(np.sqrt(gain)),
        input_unit=input_unit,
        output_unit=output_unit,
        output_declared=declared_output is not None,
    )


def effective_variance(
    slope: np.ndarray | None, noise: ChannelNoise, *, smooth: bool = True
) -> np.ndarray | float:
    """Variance of an output error per sample: ``σy² + s² σu²`` (errors in variables).

    Parameters
    ----------
    slope : ndarray or None
        The model's local slope ``|dy/du|`` per sample (``Family.slope``); None: no input
        term.
    noise : ChannelNoise
        The two channels' noise (:func:`channel_noise`).
    smooth : bool
        True (default): the input noise as a smooth direction sees it (``σu``, the filter's
        unit DC gain passes it back); False: per sample, after the candidates' filter
        (``σu'``).

    Returns
    -------
    ndarray or float
        Per-sample variance (a float when ``slope`` is None).
    """
    sy2 = noise.output**2
    if slope is None:
        return sy2
    su = noise.input if smooth else noise.input_seen
    return sy2 + (np.asarray(slope, float) * su) ** 2


def model_slope(family: Any, params: dict[str, float], d: Prepared) -> np.ndarray | None:
    """The model's local slope ``|dy/du|`` per sample, through which the input's noise
    reaches the output: the family's own (``Family.slope``: a Masing element's, steep after
    each reversal), else for a model with a stiffness ``k`` (normal contact) its static
    compliance ``1/k`` (a Kelvin-Voigt element passes slow input noise at that gain); None
    when neither is known."""
    s = family.slope(params, d) if hasattr(family, "slope") else None
    if s is None and params.get("k", 0.0) > 0:
        s = np.full(d.y.size, 1.0 / float(params["k"]))
    return s


#: the output noise read from the residual's spectrum replaces the white estimate (third
#: differences, :func:`contactlab.diagnose._signal.noise_rms`) when it is this many times
#: larger: white noise reads 0.9-1.2 (plus what the input's noise leaves through the slope,
#: which is taken out), noise behind a Bessel anti-alias filter at 0.2-0.4 fs several times
OUTPUT_COLOURED_RATIO = 1.5
#: bins of Welch's periodogram either side of each drive harmonic that
#: :func:`output_noise_rms` leaves out (the model's misfit and the effects are periodic:
#: their residual sits on the harmonics; a Hann window's main lobe spans two bins)
HARMONIC_GUARD_BINS = 2.5
#: the residual's spectrum is read from this many times the fastest drive frequency up
#: (from 1.5 times it, another block's harmonics and an unmodelled effect's content, a
#: delay's on the package generator's three blocks, were read as noise: 0.52 N of 0.30 N)
OUTPUT_BAND_HARMONICS = 6.0
#: what is left of the residual's noise after the input's share is taken out, at least
#: (as :func:`channel_noise` keeps of its estimate): returning None where the input's share
#: dominates left the friction frame at 450 g with nothing named and a held-out error 26
#: times the white estimate (its rectangular loops pass a sensor's noise through a
#: near-vertical slope)
INPUT_SHARE_FLOOR = 0.25


def output_noise_rms(
    d: Prepared, residual: np.ndarray, slope: np.ndarray | None, white: float
) -> float | None:
    """The output channel's noise RMS read from the residual's spectrum, or None when it is
    white (not :data:`OUTPUT_COLOURED_RATIO` times ``white``) or cannot be read.

    An anti-alias filter (a Bessel at 0.2-0.4 fs) or a load cell's conditioning low-passes
    the force channel's noise, so neighbouring samples are correlated and an estimate from
    their differences (third differences of the residual, ``white``) sees only its fast
    part: on such a chain it read 0.09 N where the force noise was 0.58 N, every held-out
    gain in units of it was 40 times too large and a clean record named inertia at 2 σ²
    (benches/eval_detect.py, misfit chain). Welch's periodogram of the base model's
    residual (segments of eight drive periods) is read between the drive's harmonics
    (:data:`HARMONIC_GUARD_BINS` either side of each left out: the model's misfit and any
    effect are periodic and sit on them) from :data:`OUTPUT_BAND_HARMONICS` times the
    fastest drive frequency up, lines above four times the running median clipped; the
    harmonics' bins read as their noise neighbours, those below as the octave above, and
    the whole is summed; samples weighted out (sticking phases, where
    the force is what holds the body) are left out. The share the input's noise passes through
    the model's local slope ``s`` (the mean ``s²`` times the input noise the candidates see,
    :func:`contactlab.diagnose._prepare.input_seen`) is taken out of the total, leaving at
    least :data:`INPUT_SHARE_FLOOR` of it."""
    from ._filters import welch
    from .eiv import NOISE_LINE_BINS, NOISE_LINE_FACTOR, input_noise_spectrum

    r = np.asarray(residual, float)
    # a record that sticks (samples weighted out as sticking) leaves a misfit the model
    # cannot draw, spread between the harmonics (the friction frame at 250 g: 0.06 N of it
    # read as noise, the held-out error then 1.0 of it): its white estimate is kept
    if float((d.extra.get("location_prior") or {}).get("sticking_fraction", 0.0)) > 0.0:
        return None
    # samples no candidate is judged on (a declared filter's ends: weight 0): zeroed, and
    # the sum scaled back up
    prior = d.extra.get("weight")
    keep = np.isfinite(r) & (np.ones(r.size, bool) if prior is None else np.asarray(prior) > 0)
    share = float(np.mean(keep))
    r = np.where(keep, r, 0.0)
    n = r.size
    per = float(d.cycles.period_samples)
    if not (n >= 256 and per > 0 and white > 0 and share > 0.25):
        return None
    nper = int(min(n, 2 ** int(np.ceil(np.log2(max(8.0 * per, 64.0))))))
    if nper < 64:
        return None
    f, psd = welch(np.where(keep, r - float(np.mean(r[keep])), 0.0), 1.0 / d.dt, nper)
    psd = psd / share
    df = float(f[1] - f[0])
    f0 = 1.0 / (per * d.dt)
    half = np.diff(d.cycles.reversals)
    fastest = min(per, 2.0 * float(np.percentile(half, 10))) if half.size >= 4 else per
    lo = max(1.5 * f0, OUTPUT_BAND_HARMONICS / (fastest * d.dt))
    # the bins between the drive's harmonics, from lo up: noise only
    k = np.maximum(np.rint(f / f0), 1.0)
    noise = (np.abs(f - k * f0) > HARMONIC_GUARD_BINS * df) & (f >= lo)
    band = noise & (f <= 2.0 * lo)
    if np.count_nonzero(noise) < 8 or np.count_nonzero(band) < 4:
        return None
    fn, pn = f[noise], psd[noise]
    kk = NOISE_LINE_BINS // 2
    med = np.median(
        np.lib.stride_tricks.sliding_window_view(np.pad(pn, kk, mode="edge"), 2 * kk + 1), axis=1
    )
    pn = np.minimum(pn, NOISE_LINE_FACTOR * med)  # lines (hum, another block's harmonics)
    # the harmonics' bins read as their noise neighbours; below lo, flat at the octave's level
    level = float(np.mean(pn[fn <= 2.0 * lo]))
    psd = np.where(f < lo, level, np.interp(f, fn, pn))
    total2 = float(np.sum(psd) * df)
    spec = input_noise_spectrum(d) if slope is not None else None
    if spec is not None:
        # the input noise the candidates see (:func:`._prepare.input_seen`), through the
        # slope: spread over the band by the slope's modulation, so taken out in total
        from ._prepare import input_seen

        s2 = float(np.mean(np.asarray(slope, float)[keep] ** 2))
        total2 = max(total2 - s2 * input_seen(d) ** 2, INPUT_SHARE_FLOOR * total2)
    total = float(np.sqrt(total2))
    return total if total > OUTPUT_COLOURED_RATIO * white else None
