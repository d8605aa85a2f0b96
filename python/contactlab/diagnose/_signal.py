"""Signal helpers for the discrepancy workflow: sampling checks, noise-robust derivatives,
reversal and cycle detection, the noise level estimated from the data, fractional shifts.

Derivatives use Savitzky-Golay filters (a local cubic fitted over a window that is a fixed
fraction of the excitation period), so ``m·ẍ`` and ``c·ẋ`` candidates see the motion and not
the sensor noise. The noise level is the robust (MAD) scale of third differences of a
residual: for white noise ``var(Δ³e) = 20 σ²``, while a smooth misfit contributes almost
nothing at the sampling rates of hysteresis recordings.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .._arrays import next_fast_len
from ..errors import InputError
from ..reversals import excursions
from ._filters import savgol_coeffs, savgol_filter, uniform_filter1d

_MAD_TO_SIGMA = 1.0 / 0.6744897501960817
INPUT_FILTER_FRACTION = 0.04
INPUT_NOISE_FLOOR = 1e-5


def check_uniform(t: np.ndarray) -> float:
    """Sampling interval of ``t``; :class:`InputError` if ``t`` is not uniformly increasing."""
    if t.size < 16:
        raise InputError(f"the recording has {t.size} samples; at least 16 are needed")
    dt = np.diff(t)
    if np.any(dt <= 0):
        i = int(np.argmax(dt <= 0))
        raise InputError(f"t must increase strictly; t[{i + 1}] <= t[{i}]")
    step = float(np.median(dt))
    bad = np.abs(dt - step) > 1e-3 * step
    if bad.any():
        i = int(np.argmax(bad))
        raise InputError(
            f"t must be uniformly sampled (step {step:g} s); interval t[{i}]..t[{i + 1}] "
            f"is {dt[i]:g} s — resample the recording first"
        )
    return step


def dominant_period_samples(u: np.ndarray) -> float:
    """Samples per period of the strongest spectral line of ``u`` (mean removed).

    The windowed record is zero-padded to a fast FFT length (:func:`scipy.fft.next_fast_len`:
    an odd or prime length such as 999 256 took 20 times as long and 8 times the memory),
    so the lines are those of the record's own length, interpolated: the period is
    ``L / k`` on the padded grid of ``L`` points.
    """
    n = u.size
    size = next_fast_len(n, real=True)
    spec = np.abs(np.fft.rfft((u - u.mean()) * np.hanning(n), size))
    spec[0] = 0.0
    k = int(np.argmax(spec))
    if k == 0:
        raise InputError("the excitation signal is constant; no cycles to analyse")
    return size / k


def smooth_window(period_samples: float, fraction: float = 0.08, least: int = 7) -> int:
    """Odd Savitzky-Golay window covering ``fraction`` of a period (at least ``least``)."""
    w = max(least, round(fraction * period_samples))
    return w if w % 2 == 1 else w + 1


def derivatives(u: np.ndarray, dt: float, window: int) -> tuple[np.ndarray, np.ndarray]:
    """First and second time derivatives of ``u`` from a local cubic (Savitzky-Golay)."""
    w = min(window, u.size - (1 - u.size % 2))
    d1 = savgol_filter(u, w, 3, deriv=1, delta=dt, mode="interp")
    d2 = savgol_filter(u, w, 3, deriv=2, delta=dt, mode="interp")
    return d1, d2


def input_noise(u: np.ndarray) -> float:
    """Sensor-noise RMS of an input channel, estimated from the data.

    The smaller of two estimates that a smooth drive can only bias upwards: the tangential
    analysis's second-difference estimator
    (:func:`contactlab.tangential.uncertainty.x_noise_var`) and the robust scale of what a
    local cubic over 7 samples leaves (``var = σ² (1 - c0)``, ``c0`` the filter's centre
    coefficient), which a sine at 50 samples per period biases by about 3e-5 of its
    amplitude only. Zero when that is below :data:`INPUT_NOISE_FLOOR` of the input's RMS
    (a simulated or noise-free input: nothing to filter).
    """
    if u.size < 16:
        return 0.0
    r = u - savgol_filter(u, 7, 3, mode="interp")
    c0 = float(savgol_coeffs(7, 3)[3])
    mad = float(np.median(np.abs(r - np.median(r))))
    est = min(float(np.sqrt(second_difference_var(u))), mad * _MAD_TO_SIGMA / np.sqrt(1.0 - c0))
    ref = float(np.sqrt(np.mean((u - u.mean()) ** 2)))
    return est if est > INPUT_NOISE_FLOOR * ref else 0.0


def second_difference_var(x: np.ndarray) -> float:
    """Noise variance of ``x`` from the robust scale of its second differences
    (``var(Δ²x) = 6 σ²`` for white noise): :func:`contactlab.tangential.uncertainty.x_noise_var`
    without an averaged loop, here so that a diagnosis does not import the tangential
    analysis (tests/diagnose/test_fast_paths.py checks the two agree)."""
    d2 = np.diff(x, 2)
    if d2.size < 10:
        return 0.0
    mad = float(np.median(np.abs(d2 - np.median(d2))))
    return (1.4826 * mad) ** 2 / 6.0


def filter_input(u: np.ndarray, period_samples: float, sigma: float) -> tuple[np.ndarray, int]:
    """The input every candidate sees: zero-phase Savitzky-Golay smoothing (cubic) over
    :data:`INPUT_FILTER_FRACTION` of a period when the input carries noise, else ``u``.

    A cubic over 4 % of a period changes a sine by about 3e-5 of its amplitude (far below
    any sensor's noise) and divides white noise by ``√(w/2.25)``, leaving what remains
    correlated over the window: a fractional delay can no longer average it away.
    Returns the input and the window (0: not filtered).
    """
    if not sigma > 0.0:
        return u, 0
    w = smooth_window(period_samples, INPUT_FILTER_FRACTION, 5)
    w = min(w, u.size - (1 - u.size % 2))
    if w < 5:
        return u, 0
    return savgol_filter(u, w, 3, mode="interp"), w


def noise_rms(residual: np.ndarray) -> float:
    """Robust white-noise RMS of ``residual`` from its third differences (MAD scale)."""
    d3 = np.diff(residual, n=3)
    if d3.size < 8:
        raise InputError("too few samples to estimate the noise level")
    return float(np.median(np.abs(d3 - np.median(d3))) * _MAD_TO_SIGMA / np.sqrt(20.0))


@dataclass(frozen=True)
class Cycles:
    """Reversal indices of the excitation and the cycle each sample belongs to.

    ``reversals`` are sample indices of extrema (alternating max/min); ``cycle[i]`` numbers
    the cycles from one maximum to the next (``-1`` before the first maximum);
    ``phase_in_branch[i]`` is the fraction of the current half-cycle elapsed at sample i.
    """

    reversals: np.ndarray
    is_max: np.ndarray
    cycle: np.ndarray
    phase_in_branch: np.ndarray
    period_samples: float

    @property
    def n_cycles(self) -> int:
        return int(self.cycle.max()) + 1 if self.cycle.size else 0


def find_cycles(u: np.ndarray, period_samples: float | None = None) -> Cycles:
    """Reversals of ``u`` (smoothed, local mean removed) and the cycles between maxima."""
    n = u.size
    if period_samples is None:
        period_samples = dominant_period_samples(u)
    w = smooth_window(period_samples, 0.05)
    us = savgol_filter(u, min(w, n - (1 - n % 2)), 3, mode="interp") if n > 7 else u.copy()
    win = max(3, round(period_samples))
    uc = us - uniform_filter1d(us, win, mode="nearest")
    # Hysteresis so that noise around zero does not split a half-wave.
    thr = 0.2 * float(np.sqrt(np.mean(uc * uc)))
    # Half-waves = excursions of uc beyond ±thr (the package's Rust detector); the extreme of
    # each is located on the smoothed signal us.
    ex = excursions(uc, 0.0, thr, value=us) if thr > 0 else None
    rev, ismax = [], []
    if ex is not None and len(ex):
        ends = np.r_[ex.start[1:], n]
        for a, b, s, i in zip(
            ex.start.tolist(), ends.tolist(), ex.sign.tolist(), ex.extreme.tolist(), strict=True
        ):
            if b - a < 2:
                continue
            if i == 0 or i == n - 1 or (ismax and ismax[-1] == (s > 0)):  # interior extrema only
                continue
            rev.append(i)
            ismax.append(s > 0)
    reversals = np.asarray(rev, dtype=int)
    is_max = np.asarray(ismax, dtype=bool)
    cycle = np.full(n, -1, dtype=int)
    maxima = reversals[is_max]
    for k, (a, b) in enumerate(itertools.pairwise(maxima)):
        cycle[a:b] = k
    if maxima.size:
        cycle[maxima[-1] :] = -1  # an incomplete last cycle belongs to no fold
    phase = np.zeros(n)
    edges = np.r_[0, reversals, n - 1]
    for a, b in itertools.pairwise(edges):
        if b > a:
            phase[a:b] = (np.arange(a, b) - a) / (b - a)
    phase[-1] = 1.0
    return Cycles(reversals, is_max, cycle, phase, float(period_samples))


def shortest_period_samples(u: np.ndarray, period_samples: float) -> float:
    """Samples per period of the fastest cycles of ``u``: twice the 10th percentile of the
    half-cycle lengths between its reversals (:func:`find_cycles`), at most
    ``period_samples`` (the dominant period, which a record of several excitation rates
    takes from its strongest, not its fastest, block)."""
    half = np.diff(find_cycles(u, period_samples).reversals)
    if half.size < 4:
        return float(period_samples)
    return min(float(period_samples), 2.0 * float(np.percentile(half, 10)))


def shift(y: np.ndarray, t: np.ndarray, tau: float) -> np.ndarray:
    """``y(t - tau)`` by linear interpolation between samples; held constant off the ends."""
    if tau == 0.0:
        return y
    return np.interp(t - tau, t, y)


def cubic_shift_weights(tau_samples: float) -> tuple[int, np.ndarray]:
    """The four weights of Keys' cubic convolution (``a = -1/2``, Catmull-Rom) that give
    ``y(t - τ)`` at every sample from ``y`` at samples ``i + m - 1 … i + m + 2``: returns
    ``m`` and the weights, ``τ = tau_samples`` sample intervals.

    Zero phase error and a gain within 1.2e-3 of 1 up to 0.075 of the sampling frequency
    (``ωΔt = 0.47``), 3.5e-3 up to 0.1, whatever the fraction ``φ`` of a sample (the linear
    interpolation of :func:`shift` loses ``2φ(1-φ)(1 - cos ωΔt)`` of the power, 5.4 % at
    ``ωΔt = 0.47`` and ``φ = 1/2``): a fractional delay no longer smooths the noise or the
    signal by an amount that depends on its fraction of a sample. Its gain never exceeds 1.
    """
    pos = -float(tau_samples)
    m = int(np.floor(pos))
    f = pos - m
    s = np.abs(np.arange(-1, 3) - f)
    w = np.where(
        s <= 1.0,
        (1.5 * s - 2.5) * s * s + 1.0,
        np.where(s < 2.0, ((-0.5 * s + 2.5) * s - 4.0) * s + 2.0, 0.0),
    )
    return m, w


def shift_cubic(y: np.ndarray, dt: float, tau: float) -> np.ndarray:
    """``y(t - tau)`` on equally spaced samples by Keys' cubic convolution
    (:func:`cubic_shift_weights`); held at the end values off the ends (as :func:`shift`)."""
    if tau == 0.0:
        return y
    n = y.size
    m, w = cubic_shift_weights(tau / dt)
    i = np.arange(n) + m
    out = np.zeros(n)
    for j, wj in enumerate(w):
        out += wj * y[np.clip(i + j - 1, 0, n - 1)]
    return out


def cubic_shift_power(tau_samples: float, omega_dt: np.ndarray) -> np.ndarray:
    """``|L|²`` at the angular frequencies ``omega_dt`` (radians per sample) of the
    interpolation :func:`shift_cubic` applies for a delay of ``tau_samples``."""
    _, w = cubic_shift_weights(tau_samples)
    return np.abs(np.exp(1j * np.outer(omega_dt, np.arange(-1, 3))) @ w) ** 2


def modulation_gains(
    h: np.ndarray, r: np.ndarray, duration: float, f_lo: float, step: float, count: int
) -> np.ndarray:
    """How much of ``r`` the pair ``h cos 2πft, h sin 2πft`` explains, for ``count``
    frequencies ``f = f_lo + j·step`` at once: ``‖A (AᵀA)⁻¹ Aᵀ r‖²`` with ``A`` those two
    columns — what a least-squares fit of the pair at each frequency would give.

    The samples are taken uniformly spaced over ``duration`` (``t_n = n·duration/(N-1)``).
    The five sums of the 2×2 normal equations (``Σh²cos²``, ``Σh²sin²``, ``Σh²cos·sin``,
    ``Σh·r·cos``, ``Σh·r·sin``) come from two zero-padded FFTs, exact at these frequencies
    when ``step·duration`` is ``1/m`` for an integer ``m`` (the FFT length is ``m (N-1)``);
    other steps are summed directly. ``O(N log N)`` instead of one least-squares solve of
    ``N × 2`` per frequency.
    """
    n = h.size
    j = np.arange(count)
    m = 1.0 / (step * duration) if step * duration > 0 else 0.0
    ts = np.arange(n) * (duration / (n - 1))
    if m >= 1.0 and abs(m - round(m)) < 1e-9 * m and round(m) * (n - 1) < 2**26:
        big = round(m) * (n - 1)
        # Σ g_n e^{-i2π(f_lo + j·step) t_n} = FFT_L(g_n e^{-i2π f_lo t_n})[j], L = m (N-1)
        s1 = np.fft.fft(h * r * np.exp(-2j * np.pi * f_lo * ts), big)[j % big]
        s2 = np.fft.fft(h * h * np.exp(-4j * np.pi * f_lo * ts), big)[(2 * j) % big]
    else:  # direct sums, a block of frequencies at a time
        f = f_lo + j * step
        s1 = np.empty(count, complex)
        s2 = np.empty(count, complex)
        for a in range(0, count, 64):
            ph = np.exp(-2j * np.pi * np.outer(f[a : a + 64], ts))
            s1[a : a + 64] = ph @ (h * r)
            s2[a : a + 64] = (ph * ph) @ (h * h)
    hh = float(h @ h)
    scc = 0.5 * (hh + s2.real)
    sss = 0.5 * (hh - s2.real)
    scs = -0.5 * s2.imag
    bc, bs = s1.real, -s1.imag
    det = scc * sss - scs * scs
    ok = det > 1e-10 * hh * hh
    # where the two columns are (nearly) parallel (f near 0 or Nyquist), the projection on
    # their common direction, as a minimum-norm least-squares solve gives
    g = (bc * bc + bs * bs) / hh if hh > 0 else np.zeros(count)
    q = sss * bc * bc - 2.0 * scs * bc * bs + scc * bs * bs
    g[ok] = q[ok] / det[ok]
    return g


@dataclass(frozen=True)
class Knots:
    """Turning points of a record between the samples kept from it.

    A Masing element's memory holds the turning points of its input; a record kept every
    q-th sample loses the true extremes between the samples, and every branch after a
    reversal starts from the wrong point (up to ``A (1 - cos(π q / s))`` at ``s`` samples per
    cycle). Knots are the raw-rate samples that carry that memory: every local extremum of
    the input the candidates see (the filtered one) and every reversal of :func:`find_cycles`.
    The element run over the kept samples with the knots merged in (:meth:`merge`) gives, at
    the kept samples, exactly what it gives on the whole record (rate independence: a
    monotone stretch between extrema leaves no memory).

    ``pos``: where each knot goes (:func:`numpy.insert` positions among the kept samples);
    ``x``: the input at the knots; ``grid``: the positions of the kept samples in the merged
    sequence; ``t``: its times; ``reversals``: the merged positions of the raw reversals;
    ``turns``: those of every turning point (knots and turning points on kept samples).
    """

    pos: np.ndarray
    x: np.ndarray
    grid: np.ndarray
    t: np.ndarray
    reversals: np.ndarray
    turns: np.ndarray

    @property
    def size(self) -> int:
        """Length of the merged sequence."""
        return self.t.size

    def merge(self, x: np.ndarray, offset: float = 0.0) -> np.ndarray:
        """The kept input ``x`` with the knots (shifted by ``-offset`` like ``x``) merged in
        (what ``numpy.insert(x, pos, knots - offset)`` gives, without its sort)."""
        out = np.empty(self.t.size)
        out[self.grid] = x
        out[self.pos + np.arange(self.pos.size)] = self.x - offset
        return out


def local_extrema(u: np.ndarray) -> np.ndarray:
    """Indices of the local extrema of ``u`` (the first sample of a flat top or bottom)."""
    steps = np.flatnonzero(np.diff(u))
    if steps.size < 2:
        return steps[:0]
    up = np.diff(u)[steps] > 0
    turn = np.flatnonzero(up[1:] != up[:-1])
    return steps[turn] + 1


def minimize_bounded(
    fun: Callable[[float], float], lo: float, hi: float, xtol: float, maxiter: int = 60
) -> tuple[float, float, int]:
    """The minimum of a function of one variable on ``[lo, hi]`` by Brent's method (golden
    sections with parabolic steps; SciPy's ``fminbound``, absolute tolerance ``xtol``).
    Returns ``(x, fun(x), evaluations)``; on a unimodal ``fun`` the minimum to within
    ``xtol``, otherwise a local one (a bracket of one lobe is the caller's to choose)."""
    golden = 0.5 * (3.0 - 5.0**0.5)
    a, b = lo, hi
    v = w = x = a + golden * (b - a)
    fv = fw = fx = fun(x)
    n = 1
    d = e = 0.0
    while n < maxiter:
        m = 0.5 * (a + b)
        tol1 = 1.5e-8 * abs(x) + xtol / 3.0
        tol2 = 2.0 * tol1
        if abs(x - m) <= tol2 - 0.5 * (b - a):
            break
        golden_step = True
        if abs(e) > tol1:  # try a parabola through x, w, v
            r = (x - w) * (fx - fv)
            q = (x - v) * (fx - fw)
            p = (x - v) * q - (x - w) * r
            q = 2.0 * (q - r)
            if q > 0.0:
                p = -p
            q = abs(q)
            if abs(p) < abs(0.5 * q * e) and q * (a - x) < p < q * (b - x):
                e, d = d, p / q
                u = x + d
                if u - a < tol2 or b - u < tol2:  # not too close to the ends
                    d = tol1 if m >= x else -tol1
                golden_step = False
        if golden_step:
            e = (a if x >= m else b) - x
            d = golden * e
        u = x + (d if abs(d) >= tol1 else (tol1 if d > 0 else -tol1))
        fu = fun(u)
        n += 1
        if fu <= fx:
            if u >= x:
                a = x
            else:
                b = x
            v, fv, w, fw, x, fx = w, fw, x, fx, u, fu
        else:
            if u < x:
                a = u
            else:
                b = u
            if fu <= fw or w == x:
                v, fv, w, fw = w, fw, u, fu
            elif fu <= fv or v == x or v == w:
                v, fv = u, fu
    return x, fx, n
