"""The four filters a diagnosis needs, in numpy: Savitzky-Golay coefficients and smoothing,
zero-phase FIR decimation and the analytic signal.

They follow :func:`scipy.signal.savgol_coeffs`, :func:`scipy.signal.savgol_filter`
(``mode="interp"``), :func:`scipy.signal.decimate` (``ftype="fir", zero_phase=True``) and
:func:`scipy.signal.hilbert` step for step (same designs, same edge handling, same output
alignment) and agree with them to rounding (tests/test_diagnose_speed.py). They exist because
importing :mod:`scipy.signal` (which imports :mod:`scipy.stats`) costs about half a second,
a sixth of a ``contactlab diagnose`` run on a million samples; nothing else on that path
needs it.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view


def savgol_coeffs(
    window_length: int, polyorder: int, deriv: int = 0, delta: float = 1.0
) -> np.ndarray:
    """Convolution coefficients of the least-squares polynomial of degree ``polyorder``
    over ``window_length`` samples (odd), evaluated — or its ``deriv``-th derivative, for
    sample spacing ``delta`` — at the centre of the window."""
    if not (window_length % 2 == 1 and 0 <= polyorder < window_length and deriv >= 0):
        raise ValueError(
            f"savgol window {window_length} must be odd and above polyorder {polyorder}"
        )
    pos = window_length // 2
    x = np.arange(-pos, window_length - pos, dtype=float)[::-1]  # reversed: a convolution
    A = x ** np.arange(polyorder + 1, dtype=float).reshape(-1, 1)
    y = np.zeros(polyorder + 1)
    if deriv <= polyorder:
        y[deriv] = math.factorial(deriv) / delta**deriv
    return np.linalg.lstsq(A, y, rcond=None)[0]


def _fit_edge(
    x: np.ndarray, start: int, stop: int, at: np.ndarray, polyorder: int, deriv: int, delta: float
) -> np.ndarray:
    """The polynomial fitted to ``x[start:stop]`` (or its derivative) at sample offsets
    ``at`` from ``start``."""
    c = np.polyfit(np.arange(stop - start), x[start:stop], polyorder)
    if deriv > 0:
        c = np.polyder(c, deriv) if deriv <= polyorder else np.zeros(1)
    return np.polyval(c, at) / delta**deriv


def savgol_filter(
    x: np.ndarray,
    window_length: int,
    polyorder: int,
    deriv: int = 0,
    delta: float = 1.0,
    mode: str = "interp",
) -> np.ndarray:
    """Savitzky-Golay smoothing (or derivative) of ``x``; within half a window of either
    end, the polynomial fitted to the first (last) ``window_length`` samples (``mode``:
    only scipy's ``"interp"``)."""
    if mode != "interp":
        raise ValueError(f"savgol_filter: only mode='interp' is implemented, got {mode!r}")
    x = np.asarray(x, dtype=float)
    n = x.size
    if window_length > n:
        raise ValueError(f"savgol window {window_length} is longer than the {n} samples")
    c = savgol_coeffs(window_length, polyorder, deriv, delta)
    y = np.convolve(x, c, mode="same")
    half = window_length // 2
    if half:
        y[:half] = _fit_edge(x, 0, window_length, np.arange(half), polyorder, deriv, delta)
        y[n - half :] = _fit_edge(
            x, n - window_length, n, np.arange(window_length - half, window_length),
            polyorder, deriv, delta,
        )  # fmt: skip
    return y


def _firwin_lowpass(numtaps: int, cutoff: float) -> np.ndarray:
    """Hamming-windowed sinc low-pass, ``cutoff`` relative to Nyquist, unit gain at DC."""
    m = np.arange(numtaps) - 0.5 * (numtaps - 1)
    h = cutoff * np.sinc(cutoff * m)
    h *= 0.54 + 0.46 * np.cos(np.linspace(-np.pi, np.pi, numtaps))
    return h / np.sum(h)


def decimate(x: np.ndarray, q: int, ftype: str = "fir", zero_phase: bool = True) -> np.ndarray:
    """Every ``q``-th sample of ``x`` after a zero-phase FIR anti-alias filter (Hamming-
    windowed sinc of ``20 q + 1`` taps, cut-off at the new Nyquist frequency); the output
    has ``ceil(N / q)`` samples, sample ``k`` centred on input sample ``k q``, the signal
    taken as zero outside the record (``ftype``, ``zero_phase``: only scipy's ``"fir"``,
    ``True``)."""
    if ftype != "fir" or not zero_phase:
        raise ValueError("decimate: only the zero-phase FIR filter is implemented")
    x = np.asarray(x, dtype=float)
    if q == 1:
        return x.copy()
    half = 10 * q
    h = _firwin_lowpass(2 * half + 1, 1.0 / q)
    n_out = -(-x.size // q)
    # y[k] = Σ_j h[j] x[k q + half - j]: a window of the zero-padded record for each kept
    # sample (only those are computed), dotted with the reversed filter
    xp = np.concatenate((np.zeros(half), x, np.zeros(half + q)))
    win = sliding_window_view(xp, h.size)[: n_out * q : q]
    return win @ h[::-1]


def hilbert(x: np.ndarray) -> np.ndarray:
    """The analytic signal ``x + i H[x]`` of a real ``x`` (FFT of the whole record)."""
    x = np.asarray(x, dtype=float)
    n = x.size
    g = np.zeros(n)
    if n % 2 == 0:
        g[0] = g[n // 2] = 1.0
        g[1 : n // 2] = 2.0
    else:
        g[0] = 1.0
        g[1 : (n + 1) // 2] = 2.0
    return np.fft.ifft(np.fft.fft(x) * g)


def uniform_filter1d(x: np.ndarray, size: int, mode: str = "nearest") -> np.ndarray:
    """Moving average over ``size`` samples, ``x`` extended by its end values (scipy.ndimage's
    ``uniform_filter1d`` with ``mode="nearest"``: sample ``i`` averages
    ``x[i - size//2 : i - size//2 + size]``)."""
    if mode != "nearest":
        raise ValueError(f"uniform_filter1d: only mode='nearest' is implemented, got {mode!r}")
    x = np.asarray(x, dtype=float)
    lo = size // 2
    m = float(np.mean(x))  # running sums of the deviations: less rounding on an offset
    xp = np.concatenate((np.full(lo, x[0]), x, np.full(size - 1 - lo, x[-1]))) - m
    c = np.concatenate(([0.0], np.cumsum(xp)))
    return (c[size:] - c[:-size]) / size + m
