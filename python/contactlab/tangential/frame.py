"""Friction force of a base-excited single-storey frame, from its equation of motion.

A frame whose top plate (mass ``M``, displacement ``x``) rubs on a fixed wall, driven through
its columns (stiffness ``K``, damping ``C``) by a base displacement ``y`` (Marino & Cicirello,
arXiv:2303.03858, the rig of ``../shared/data/friction_frame``), obeys

    M x'' + C x' + K x + F_f = K y + C y'

so the friction force is ``F_f = K (y - x) + C (y' - x') - M x''``: the force the wall
exerts against the plate's motion, positive when the plate slides in +x, so that a passive
contact gives ``∮ F_f dx > 0``.

The derivatives come from measured displacements. Their noise is amplified by ``1/dt`` and
``1/dt²`` (with dt = 4 ms and 0.5 µm of noise a plain second difference gives M x'' a noise
of about 0.5 N, as large as the friction force), so they are Savitzky-Golay derivatives
(local cubic least squares) with a window chosen from the data by Lepski's rule: the noise
σ of each channel is estimated from its fourth differences (``var(Δ⁴x) = 70 σ²`` for white
noise, read at the lag where a sensor filter's correlation has died out:
:func:`difference_noise`), and the window
grows while the estimate of ``x''`` stays within ``κ`` noise standard deviations of every
smaller window's estimate (the standard deviation of that difference follows exactly from
the two filters' coefficients). The largest window whose estimate the smaller ones do not
contradict is the widest one whose bias is still below its noise: the usual bias-variance
balance, without assuming how smooth the motion is. The choice is reported
(``window``, ``noise_x``, ``noise_y``, ``force_noise``), with the larger error near the
force's jumps where a contact sticks and slips (``force_error_near_jumps``, ``jump_share``).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .._arrays import as_1d
from .._physical import MAX_MAGNITUDE
from ..errors import InputError
from ..io import Recording

#: Lepski's threshold: differences beyond κ noise standard deviations are taken as bias
LEPSKI_KAPPA = 1.5
POLYORDER = 3


def _lag_noise(v: np.ndarray, lag: int, order: int) -> float:
    m = v.size - order * lag
    if m < 10:
        return math.nan
    # the differences in one buffer (in place; the same values as fresh arrays), the medians
    # partition it in place: two n-sized arrays at most however long the record
    d = np.subtract(v[lag:], v[:-lag])
    for k in range(2, order + 1):
        size = v.size - k * lag
        np.subtract(d[lag : lag + size], d[:size], out=d[:size])
    d = d[:m]
    med = np.median(d, overwrite_input=True)
    np.subtract(d, med, out=d)
    np.abs(d, out=d)
    c = math.comb(2 * order, order)
    return 1.4826 * float(np.median(d, overwrite_input=True)) / math.sqrt(c)


#: :func:`spectral_noise`: a band run whose log-log slope (power per frequency, across two
#: bands) is above this has stopped falling like a signal's floor (≤ -2 between a smooth
#: motion's harmonics) and is read as a noise pass band
FLAT_SLOPE = -1.5


def spectral_noise(v: np.ndarray, *, quantile: float = 0.25, bands: int = 24) -> float:
    """Noise standard deviation of ``v`` from the floor of its spectrum, for noise that a
    sensor's low-pass (anti-alias) filter has coloured.

    The record is pre-whitened by its second difference (so the large, slow signal leaks
    nothing into the floor; the difference's gain is divided out again) and Hann-windowed; in
    each of ``bands`` log-spaced frequency bands the lower ``quantile`` of the periodogram,
    divided by the exponential distribution's ``-ln(1 - quantile)``, is the level of the
    noise between the signal's harmonics. The pass band is the first run of bands where that
    level has stopped falling (log-log slope above :data:`FLAT_SLOPE` across two bands)
    after the signal's decline. Below it the noise is taken as flat at the pass-band level
    (a low-pass filter passes low frequencies unchanged), above it at the observed level,
    capped at the pass band's (the filter's roll-off). σ² is the mean of that noise spectrum
    over all frequencies. NaN when fewer than three bands have enough bins or no pass band
    shows (the signal dominates up to the roll-off, or there is no noise)."""
    v = np.asarray(v, dtype=float)
    if v.size < 64:
        return math.nan
    d = np.diff(v, 2)
    d = d - float(np.mean(d))
    n = d.size
    w = np.hanning(n)
    P = np.abs(np.fft.rfft(d * w)) ** 2 / float(np.sum(w * w))
    k = np.arange(P.size)
    gain = (2.0 * np.sin(np.pi * k / n)) ** 4
    edges = np.unique(np.geomspace(4, P.size, bands + 1).astype(int))
    scale = -math.log(1.0 - quantile)
    lo, hi, lv = [], [], []
    for a, b in itertools.pairwise(edges):
        if b - a >= 8:
            lo.append(int(a))
            hi.append(int(b))
            lv.append(float(np.quantile(P[a:b] / gain[a:b], quantile)) / scale)
    if len(lv) < 3 or not all(x > 0 for x in lv):
        return math.nan
    f = np.sqrt(np.array(lo, float) * np.array(hi, float))
    level = np.array(lv)
    # slopes over two bands (a factor ~1.5 in frequency): one band pair's scatter does not
    # make a pass band of a signal's floor
    logf, logl = np.log(f), np.log(level)
    slope = (logl[2:] - logl[:-2]) / (logf[2:] - logf[:-2])
    first = next((i for i, sl in enumerate(slope) if sl > FLAT_SLOPE), None)
    if first is None:
        return math.nan
    last = first
    while last + 1 < slope.size and slope[last + 1] > FLAT_SLOPE:
        last += 1
    passband = float(np.median(level[first : last + 3]))
    total = lo[first] * passband  # under the signal: flat at the pass-band level
    total += float(
        np.sum((np.array(hi[first:]) - np.array(lo[first:])) * np.minimum(level[first:], passband))
    )
    total += max(P.size - hi[-1], 0) * min(float(level[-1]), passband)
    return math.sqrt(total / P.size)


def difference_noise(v: np.ndarray, order: int = 4) -> float:
    """Noise standard deviation of ``v`` from its ``order``-th differences (MAD scale;
    ``var(Δᵏ v) = C(2k, k) σ²`` for white noise).

    A sensor's anti-alias filter correlates neighbouring samples and hides the noise from
    one-sample differences; differences at lag L see it once L exceeds the correlation
    length. So the estimate is taken at lags 1, 2, 4, 8, 16: noise alone grows slowly with
    the lag and levels off, a smooth signal grows like L⁴ (16× per doubling). The estimate
    is read where it grows least between two lags, if that growth is below 4× (a plateau).

    Without a plateau the noise is correlated beyond the lags where the signal is still
    small (a strong anti-alias filter: at 250 Hz with a cut-off at 0.2 of Nyquist the lag-1
    value reads such noise ~15× low): then the estimate at the lag of least growth, but no
    more than the noise floor of the spectrum (:func:`spectral_noise`: both read signal as
    well as noise there, each in its own way) and no less than the lag-1 value. When the
    spectrum shows no noise floor either, the lag-1 value (an upper bound of white noise:
    a clean record).
    """
    lags = [lag for lag in (1, 2, 4, 8, 16) if v.size > order * lag + 10]
    if not lags:
        return 0.0
    est = [_lag_noise(v, lag, order) for lag in lags]
    if len(est) < 2 or not est[0] > 0:
        return float(est[0]) if est and math.isfinite(est[0]) else 0.0
    ratios = [b / a if a > 0 else math.inf for a, b in itertools.pairwise(est)]
    k = int(np.argmin(ratios))
    if ratios[k] < 4.0:
        return float(est[k + 1])
    floor = spectral_noise(v)
    if not math.isfinite(floor):  # no noise floor in sight either: the signal dominates
        return float(est[0])
    return max(float(est[0]), min(float(est[k + 1]), floor))


def savgol_derivative(v: np.ndarray, window: int, deriv: int, dt: float) -> np.ndarray:
    """``deriv``-th derivative of ``v`` by a cubic Savitzky-Golay filter of ``window``
    samples (sampling interval ``dt``; the ends by the filter's own polynomial fit)."""
    from .._filters import savgol_filter

    return savgol_filter(v, window, POLYORDER, deriv=deriv, delta=dt, mode="interp")


def savgol_coefficients(window: int, deriv: int, dt: float) -> np.ndarray:
    """Savitzky-Golay weights of the ``deriv``-th derivative (dot with a centred window):
    white noise σ on the samples gives the estimate a noise ``σ ‖weights‖``."""
    from .._filters import savgol_coeffs

    return savgol_coeffs(window, POLYORDER, deriv=deriv, delta=dt)[::-1]  # dot: not reversed


def force_kernel(window: int) -> np.ndarray:
    """The smoothing the reconstruction applies to the friction force: ``window`` taps,
    symmetric, positive, summing to 1.

    The cubic Savitzky-Golay ``x''`` filter ``c₂`` (``window`` taps) annihilates constants
    and straight lines, so it factors exactly as ``c₂ = g ⊛ Δ²/dt²`` with ``g`` of
    ``window - 2`` taps (the double cumulative sum of ``c₂ dt²``): the filter's ``x''`` is the
    plain second difference smoothed by ``g``. A second difference is the hat-weighted mean
    of ``x''`` over a sample either side (``Δ²x/dt² = ∫ x''(t + s) Λ(s/dt) ds/dt``), which on
    samples of a force (linear between them) is the kernel ``[1, 4, 1]/6``. So the
    reconstruction, which smooths every term of the equation of motion by ``g``
    (:func:`frame_friction_force`), gives ``force_kernel ⊛ F_f`` plus noise:
    ``g ⊛ [1, 4, 1]/6`` (for a sinusoid at ``θ`` radians per sample the inertial term's
    smoothing differs from it by ``θ²/12`` of that term). :func:`contactlab.diagnose.diagnose`
    passes every candidate's predicted force through the same kernel (``output_filter``), so
    that no candidate can win by imitating the smoothing of the force's jumps at stick and
    slip.
    """
    g = np.cumsum(np.cumsum(savgol_coefficients(window, 2, 1.0)))[:-2]
    return np.convolve(g, np.array([1.0, 4.0, 1.0]) / 6.0)


def lepski_window(
    x: np.ndarray,
    dt: float,
    sigma: float,
    *,
    kappa: float = LEPSKI_KAPPA,
    coefficients: Callable[[int, int, float], np.ndarray] | None = None,
) -> int:
    """Savitzky-Golay window (odd, samples) for ``x''`` by Lepski's rule (module docstring).

    Candidate windows grow geometrically from 7 samples to a fifth of the record (at most
    401); with no measurable noise the smallest is used. The comparisons run over the record
    in blocks (:func:`lepski_square_sums`): O(n) time, memory independent of its length.
    ``coefficients(window, deriv, dt)``: the filter weights (dot orientation) when not
    :func:`savgol_coefficients` (a numpy implementation spares importing scipy.signal).
    """
    coefficients = coefficients or savgol_coefficients
    n = x.size
    top = min(401, max(7, n // 5))
    cands = sorted({w | 1 for w in np.geomspace(7, top, 16).astype(int) if w >= 7})
    if sigma <= 0 or len(cands) < 2:
        return cands[0]
    sq = lepski_square_sums(np.asarray(x, dtype=float), cands, dt, coefficients=coefficients)
    chosen = cands[0]
    for i, w in enumerate(cands[1:], start=1):
        ok = True
        cw = coefficients(w, 2, dt)
        count = n - 2 * (w // 2)
        for j, wp in enumerate(cands[:i]):
            cp = np.pad(coefficients(wp, 2, dt), (w - wp) // 2)
            sd = sigma * float(np.linalg.norm(cw - cp))
            rms = math.sqrt(sq[i, j] / count)
            if rms > kappa * sd:
                ok = False
                break
        if not ok:
            break
        chosen = w
    return chosen


#: samples per block of :func:`lepski_square_sums`
LEPSKI_BLOCK = 1 << 16


def lepski_square_sums(
    x: np.ndarray,
    cands: list[int],
    dt: float,
    block: int = LEPSKI_BLOCK,
    coefficients: Callable[[int, int, float], np.ndarray] | None = None,
) -> np.ndarray:
    """``S[i, j]`` (``j < i``): sum of the squared differences between the Savitzky-Golay
    ``x''`` of windows ``cands[i]`` and ``cands[j]`` over the samples where the wider window
    fits inside the record (``w//2 … n - w//2``: there both are plain convolutions, the
    polynomial end fits of :func:`savgol_derivative` lie outside).

    Block by block with a halo of the widest half window, so memory does not grow with the
    record: each estimate is the dot product of :func:`savgol_derivative`'s convolution (the
    same filter, summed in another order: equal to rounding, ~1e-13 of the estimates' RMS),
    the sums of squares added block by block. Buffers are allocated once.
    """
    n, k = x.size, len(cands)
    halves = [w // 2 for w in cands]
    halo = halves[-1]
    if coefficients is None:
        from .._filters import savgol_coeffs

        coeffs = [savgol_coeffs(w, POLYORDER, deriv=2, delta=dt) for w in cands]
    else:  # convolution orientation: the dot weights reversed
        coeffs = [coefficients(w, 2, dt)[::-1] for w in cands]
    width = max(min(block, n), 1)  # a short record's buffers no wider than it (2 x 8 MB)
    est = np.empty((k, width))
    diff = np.empty((k, width))
    out = np.zeros((k, k))
    for s in range(0, n, block):
        e = min(s + block, n)
        lo, hi = max(s - halo, 0), min(e + halo, n)
        seg = x[lo:hi]
        for i, (c, h) in enumerate(zip(coeffs, halves, strict=True)):
            a, b = max(s, h), min(e, n - h)  # where window cands[i] fits in the record
            if b > a:
                valid = np.convolve(seg, c, mode="valid")  # centred at lo + h + index
                est[i, a - s : b - s] = valid[a - lo - h : b - lo - h]
        for i in range(1, k):
            a, b = max(s, halves[i]), min(e, n - halves[i])
            if b <= a:
                continue
            d = diff[:i, : b - a]
            np.subtract(est[:i, a - s : b - s], est[i, a - s : b - s], out=d)
            np.multiply(d, d, out=d)
            out[i, :i] += d.sum(axis=1)
    return out


def step_error(window: int) -> float:
    """RMS error, per unit jump, of the filter's ``M x''`` over the ``2 (window // 2 + 1)``
    samples around an ideal step of the force (``x''`` jumps by ``J/M``: ``x = J t²/2M`` after
    it), the step half-way between two samples."""
    half = window // 2 + 1
    n = 4 * window + 1
    tt = np.arange(n, dtype=float) - n // 2 - 0.5
    q = 0.5 * np.where(tt > 0, tt, 0.0) ** 2
    est = savgol_derivative(q, window, 2, 1.0)
    c = n // 2
    err = est[c - half + 1 : c + half + 1] - (tt[c - half + 1 : c + half + 1] > 0)
    return float(np.sqrt(np.mean(err * err)))


def jump_samples(xd: np.ndarray, x: np.ndarray, window: int, dt: float, sigma: float) -> np.ndarray:
    """Indices where the plate starts or stops sticking (the smoothed velocity enters or
    leaves ``3σv``, σv from the displacement noise ``sigma``): where the friction force of a
    stick-slip contact jumps (static to kinetic, sliding to the drive's force)."""
    thr = 3.0 * sigma * float(np.linalg.norm(savgol_coefficients(window, 1, dt)))
    if not thr > 0:
        thr = 1e-9 * float(np.max(np.abs(xd)))
    stuck = np.abs(xd) < thr
    edges = np.flatnonzero(np.diff(stuck.astype(np.int8)) != 0) + 1
    return edges[(edges > window) & (edges < x.size - window)]


@dataclass(frozen=True)
class FrameForce:
    """Result of :func:`frame_friction_force` (SI): the friction force ``F`` and the plate's
    displacement ``x`` (the loop is ``F`` against ``x``), velocity and acceleration, the
    Savitzky-Golay ``window`` (samples and seconds), the channels' noise and the resulting
    noise of ``F`` (from the filters' coefficients).

    ``force_noise`` is the error of ``F`` where the force is smooth. Where the plate starts or
    stops sticking the true force jumps and the filter spreads each jump over its window
    (half a window each side): ``jump_share`` is the share of samples that close to a jump and
    ``force_error_near_jumps`` the RMS error expected there, from the jumps' sizes (the force
    a window after minus a window before) and the filter's error at an ideal step
    (:func:`step_error`); ``force_error`` is the RMS over the whole record. On independent
    Coulomb-frame simulations (tests/frame_sim.py) away from the jumps the error is the
    noise (0.011 vs 0.011 N at 250 Hz), near them 0.11-0.14 N."""

    t: np.ndarray
    x: np.ndarray
    F: np.ndarray
    x_dot: np.ndarray
    x_ddot: np.ndarray
    window: int
    window_s: float
    noise_x: float
    noise_y: float
    force_noise: float
    jump_share: float = 0.0
    force_error_near_jumps: float = 0.0
    force_error: float = 0.0
    #: the smoothing the reconstruction applied to the friction force (:func:`force_kernel`):
    #: away from the record's ends, ``F`` is this kernel convolved with the true force, plus
    #: noise of RMS ``force_noise``
    force_filter: np.ndarray | None = None
    #: the frame's ``{"M": kg, "C": N s/m, "K": N/m}``, and where the displacements came
    #: from when read from a file (:func:`read_frame`: ``{"x": column, "y": column, "t": ...}``
    #: and their units in the file)
    frame: dict[str, float] | None = None
    columns: dict[str, str] | None = None
    file_units: dict[str, str] | None = None
    source: str = "<frame>"

    def to_dict(self) -> dict[str, object]:
        """The reconstruction's figures (SI; JSON-ready): the Savitzky-Golay window, the
        channels' noise, the force's noise and error, the frame and the columns read."""
        out: dict[str, object] = {
            "window": int(self.window),
            "window_s": float(self.window_s),
            "noise_x": float(self.noise_x),
            "noise_y": float(self.noise_y),
            "force_noise": float(self.force_noise),
            "force_error": float(self.force_error),
            "force_error_near_jumps": float(self.force_error_near_jumps),
            "jump_share": float(self.jump_share),
            "force_filter_taps": 0 if self.force_filter is None else int(self.force_filter.size),
        }
        if self.frame is not None:
            out.update({k: float(v) for k, v in self.frame.items()})
        if self.columns is not None:
            out["columns"] = dict(self.columns)
        if self.file_units is not None:
            out["file_units"] = dict(self.file_units)
        out["units"] = {
            "window": "samples",
            "window_s": "s",
            "noise_x": "m",
            "noise_y": "m",
            "force_noise": "N",
            "force_error": "N",
            "force_error_near_jumps": "N",
            "jump_share": "",
            "M": "kg",
            "C": "N s/m",
            "K": "N/m",
        }
        return out

    def describe(self) -> str:
        """One paragraph: which columns in which units, the frame, the window and noises
        (:func:`describe_reconstruction` of :meth:`to_dict`)."""
        return describe_reconstruction(self.to_dict())

    def recording(self, source: str = "<frame>") -> Recording:
        """A tangential :class:`~contactlab.io.Recording` (``x`` in m, ``F`` in N) whose
        ``meta`` declares the reconstruction's smoothing and noise (``output_filter``:
        :attr:`force_filter`, ``output_noise``: :attr:`force_noise`), which
        :func:`contactlab.diagnose.diagnose` applies to every candidate and takes as the
        force's noise level, and ``same_clock``: the force is computed from the displacement's
        own samples, so it cannot lag them and ``channel_delay`` is not a candidate; and
        ``frame``: the constants ``M, C, K`` it used (an inertia term the diagnosis finds is
        the frame's own ``M x''``: reported as a reading of ``M``, not as a joint effect)."""
        meta: dict[str, object] = {"output_noise": self.force_noise, "same_clock": True}
        if self.frame is not None:
            meta["frame"] = dict(self.frame)
        if self.force_filter is not None:
            meta["output_filter"] = self.force_filter
        if source == "<frame>":
            source = self.source
        return Recording(
            self.t, {"x": self.x, "F": self.F}, {"x": "m", "F": "N"}, source=source, meta=meta
        )


def frame_friction_force(
    t: object,
    x: object,
    y: object,
    M: float,
    C: float,
    K: float,
    *,
    window: int | None = None,
) -> FrameForce:
    """Friction force ``F_f = K (y - x) + C (y' - x') - M x''`` of a base-excited frame.

    Parameters
    ----------
    t : array_like
        Sample times, s (uniform sampling).
    x, y : array_like
        Top-plate and base displacements, m.
    M, C, K : float
        Moving mass (kg), column damping (N s/m) and stiffness (N/m).
    window : int, optional
        Savitzky-Golay window in samples (odd, ≥ 5). Default: chosen from the data by
        Lepski's rule (see the module docstring).

    Returns
    -------
    FrameForce

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(2500) * 0.004; w = 2 * np.pi
    >>> x = 1e-3 * np.sin(w * t); y = 2e-3 * np.sin(w * t)
    >>> r = frame_friction_force(t, x, y, M=3.0, C=0.0, K=1000.0)
    >>> F = (1000 * 1e-3 + 3.0 * w**2 * 1e-3) * np.sin(w * t)  # the true force
    >>> float(np.max(np.abs(r.F - F))) < 1e-3  # the smoothing: 5e-4 N of 1.1 N
    True
    >>> inner = slice(r.window, -r.window)  # the declared smoothing, away from the ends
    >>> float(np.max(np.abs(r.F - np.convolve(F, r.force_filter, "same"))[inner])) < 2e-5
    True
    """
    ta = as_1d(t, "t")
    xa = as_1d(x, "x")
    ya = as_1d(y, "y")
    if not (ta.size == xa.size == ya.size):
        raise InputError(f"t, x, y have {ta.size}, {xa.size}, {ya.size} samples; they must match")
    for name, v in (("M", M), ("C", C), ("K", K)):
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0):
            raise InputError(f"{name} must be a finite number >= 0, got {v!r}")
    if ta.size < 20:
        raise InputError(f"{ta.size} samples are too few to differentiate (at least 20)")
    for name, v in (("x", xa), ("y", ya)):
        i = int(np.argmax(np.abs(v)))
        if not abs(float(v[i])) <= MAX_MAGNITUDE:
            raise InputError(
                f"{name} reaches {float(v[i]):.3g} m at sample {i}: beyond any physical "
                "displacement; a unit mix-up or a corrupt file?"
            )
    dts = np.diff(ta)
    dt = float(np.median(dts))
    if not dt > 0 or np.max(np.abs(dts - dt)) > 1e-3 * dt:
        raise InputError("frame_friction_force needs uniformly sampled, increasing t")
    sx, sy = difference_noise(xa), difference_noise(ya)
    if window is None:
        window = lepski_window(xa, dt, sx)
    elif not (isinstance(window, (int, np.integer)) and window >= 5 and window % 2 == 1):
        raise InputError(f"window must be an odd number of samples >= 5, got {window!r}")
    if window > xa.size:
        raise InputError(f"window of {window} samples is longer than the record ({xa.size})")
    xd = savgol_derivative(xa, window, 1, dt)
    xdd = savgol_derivative(xa, window, 2, dt)
    yd = savgol_derivative(ya, window, 1, dt)
    # every term smoothed alike (force_kernel): M x'' is g ⊛ Δ²x/dt² already, i.e.
    # force_kernel ⊛ M x'', so K (y - x) and C (y' - x') pass the same smoothing and F is
    # force_kernel ⊛ F_f plus noise. Within half a window of
    # the ends (the polynomial end fits) the unsmoothed terms, as before.
    c2 = savgol_coefficients(window, 2, dt)
    g = np.cumsum(np.cumsum(c2 * dt * dt))[:-2]
    # K (y - x) through the whole kernel (g and the second difference's [1, 4, 1]/6), the
    # small damping term (C ẋ is ~1 % of the force) through g and a central difference
    gk = np.convolve(g, np.array([1.0, 4.0, 1.0]) / 6.0)  # window taps: force_kernel
    gd = np.convolve(g, np.array([1.0, 0.0, -1.0]) / (2.0 * dt))  # g ⊛ central difference
    fx = -K * gk - C * gd - M * c2  # F = fy ⊛ y + fx ⊛ x (convolution taps)
    fy = K * gk + C * gd
    F = K * (ya - xa) + C * (yd - xd) - M * xdd
    half = window // 2
    if xa.size > 2 * half:
        inner = np.convolve(ya, fy, mode="valid") + np.convolve(xa, fx, mode="valid")
        F[half : xa.size - half] = inner
    f_noise = math.hypot(sx * float(np.linalg.norm(fx)), sy * float(np.linalg.norm(fy)))
    half = half + 1
    jumps = jump_samples(xd, xa, window, dt, sx)
    near = np.zeros(F.size, bool)
    sizes = []
    for j in jumps:
        near[j - half : j + half] = True
        before, after = F[max(j - 2 * half, 0) : j - half], F[j + half : j + 2 * half]
        if before.size and after.size:
            sizes.append(float(np.median(after) - np.median(before)))
    share = float(np.mean(near))
    jump_rms = math.sqrt(float(np.mean(np.square(sizes)))) if sizes else 0.0
    near_err = math.hypot(f_noise, jump_rms * step_error(window))
    total = math.sqrt((1.0 - share) * f_noise**2 + share * near_err**2)
    return FrameForce(
        ta,
        xa,
        F,
        xd,
        xdd,
        int(window),
        window * dt,
        sx,
        sy,
        f_noise,
        share,
        near_err,
        total,
        force_kernel(window),
        {"M": float(M), "C": float(C), "K": float(K)},
    )


def describe_reconstruction(d: dict[str, object]) -> str:
    """:meth:`FrameForce.to_dict` as a sentence: the columns read and their units, the
    frame, the Savitzky-Golay window and the noise of x, y and F."""
    parts = []
    cols = d.get("columns")
    if isinstance(cols, dict) and cols:
        units = d.get("file_units")
        units = units if isinstance(units, dict) else {}
        said = []
        for k, v in cols.items():
            unit = units.get(k) or ("no unit: taken as s" if k == "t" else "no unit: taken as m")
            said.append(f"{k} = {v!r} ({unit})")
        parts.append("columns " + ", ".join(said))
    if all(isinstance(d.get(k), float) for k in "MCK"):
        parts.append(f"M = {d['M']:.6g} kg, C = {d['C']:.6g} N s/m, K = {d['K']:.6g} N/m")
    w, ws = d.get("window"), d.get("window_s")
    nx, ny, nf = d.get("noise_x"), d.get("noise_y"), d.get("force_noise")
    if isinstance(w, int) and all(isinstance(v, float) for v in (ws, nx, ny, nf)):
        parts.append(
            f"F = K (y - x) + C (y' - x') - M x'' with a cubic Savitzky-Golay window of {w} "
            f"samples ({1e3 * ws:.3g} ms); noise of x {1e6 * nx:.3g} um, of y "  # type: ignore[operator]
            f"{1e6 * ny:.3g} um, of F {nf:.3g} N"  # type: ignore[operator]
        )
    return "; ".join(parts)


def parse_frame(text: str) -> tuple[float, float, float]:
    """``"3.0799,0.669,1191"`` or ``"M=3.0799,C=0.669,K=1191"`` (SI: kg, N s/m, N/m) → the
    frame's ``(M, C, K)``; a clear :class:`~contactlab.InputError` otherwise. ``M`` and ``C``
    must be >= 0, ``K`` > 0 (the base drives the plate through the columns)."""
    parts = [p.strip() for p in str(text).replace(";", ",").split(",") if p.strip()]
    if len(parts) != 3:
        raise InputError(
            f"--frame {text!r}: give the frame's mass, damping and stiffness as M,C,K "
            "(kg, N s/m, N/m), e.g. 3.0799,0.669,1191 or M=3.0799,C=0.669,K=1191"
        )
    named = [p for p in parts if "=" in p]
    if named and len(named) != 3:
        raise InputError(f"--frame {text!r}: name all three (M=..,C=..,K=..) or none")
    values: dict[str, str] = {}
    for key, p in zip("MCK", parts, strict=True):
        if named:
            k, v = (q.strip() for q in p.split("=", 1))
            if k.upper() not in ("M", "C", "K") or k.upper() in values:
                raise InputError(f"--frame {text!r}: {k!r} is not one of M, C, K (each once)")
            values[k.upper()] = v
        else:
            values[key] = p
    out: list[float] = []
    for key, unit in (("M", "kg"), ("C", "N s/m"), ("K", "N/m")):
        try:
            num = float(values[key])
        except ValueError:
            raise InputError(f"--frame: {key} = {values[key]!r} is not a number ({unit})") from None
        if not math.isfinite(num) or num < 0 or (key == "K" and num == 0):
            need = "> 0" if key == "K" else ">= 0"
            raise InputError(f"--frame: {key} = {values[key]} {unit}: must be finite and {need}")
        out.append(num)
    return out[0], out[1], out[2]


def read_frame(
    path: object,
    M: float,
    C: float,
    K: float,
    *,
    x: str | None = None,
    y: str | None = None,
    fs: float | None = None,
    window: int | None = None,
) -> FrameForce:
    """Read a frame's displacements from a file (CSV, TDMS, HDF5, MAT; see
    :func:`contactlab.io.read_recording`) and reconstruct the friction force
    (:func:`frame_friction_force`).

    ``x``, ``y``: the top-plate and base displacement columns; default: the one column whose
    name has the word ``x`` (or ``top``, ``plate``) / ``y`` (or ``base``). Units from the
    name (``x [mm]``, ``x_top_plate_disp_mm``), else metres; the result names the columns and
    units it used (:attr:`FrameForce.columns`, :attr:`FrameForce.file_units`).
    """
    from ..io import read_recording

    columns = {k: v for k, v in (("x", x), ("y", y)) if v}
    rec = read_recording(str(path), columns=columns or None, kind="frame", fs=fs)
    try:
        r = frame_friction_force(rec.t, rec["x"], rec["y"], M, C, K, window=window)
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from exc
    meta = rec.meta or {}
    cols = {k: str(v) for k, v in dict(meta.get("columns") or {}).items()}
    units = {k: str(v) if v else "" for k, v in dict(meta.get("file_units") or {}).items()}
    import dataclasses

    return dataclasses.replace(r, columns=cols, file_units=units, source=str(path))


__all__ = [
    "FrameForce",
    "describe_reconstruction",
    "difference_noise",
    "force_kernel",
    "frame_friction_force",
    "lepski_window",
    "parse_frame",
    "read_frame",
    "savgol_coefficients",
    "savgol_derivative",
    "spectral_noise",
    "step_error",
]
