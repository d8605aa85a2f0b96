"""The filters a diagnosis needs, in numpy: Savitzky-Golay coefficients and smoothing,
zero-phase FIR decimation, the analytic signal, Welch's periodogram, and the exact
first-order response that evaluates the linear Kelvin-Voigt base model
(:func:`first_order_response`).

They follow :func:`scipy.signal.savgol_coeffs`, :func:`scipy.signal.savgol_filter`
(``mode="interp"``), :func:`scipy.signal.decimate` (``ftype="fir", zero_phase=True``) and
:func:`scipy.signal.hilbert` and :func:`scipy.signal.welch` (Hann window, half overlap, linear
detrend, density scaling) step for step (same designs, same edge handling, same output
alignment) and agree with them to rounding (tests/diagnose/test_fast_paths.py,
tests/base/test_filters.py). They exist because importing :mod:`scipy.signal` (which imports
:mod:`scipy.stats`) costs 0.5-1.2 s: a sixth of a ``contactlab diagnose`` run on a million
samples, and four fifths of a ``contactlab analyze`` of one tangential recording (1.4-1.6 s
-> 0.3 s), paid again by every worker process of a study.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

#: the largest ``(window // 2) ** polyorder`` whose Savitzky-Golay design keeps the plain
#: integer abscissa (as scipy does); longer windows are designed on one scaled to [-1, 1]
_UNSCALED_SPAN = 1e8


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
    # the abscissa scaled to [-1, 1]: the plain powers of up to ±pos make the normal matrix
    # singular to rounding for long windows (a quintic over 907 samples kept 0.27 of a sine
    # it should pass whole); a derivative in the scaled abscissa is divided by ``pos``
    # (short windows keep scipy's unscaled abscissa: its coefficients to the last bit)
    scale = float(pos) if float(pos) ** polyorder > _UNSCALED_SPAN else 1.0
    x = np.arange(-pos, window_length - pos, dtype=float)[::-1] / scale  # reversed: a convolution
    A = x ** np.arange(polyorder + 1, dtype=float).reshape(-1, 1)
    y = np.zeros(polyorder + 1)
    if deriv <= polyorder:
        y[deriv] = math.factorial(deriv) / (delta * scale) ** deriv
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
            x,
            n - window_length,
            n,
            np.arange(window_length - half, window_length),
            polyorder,
            deriv,
            delta,
        )
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


def welch(x: np.ndarray, fs: float, nperseg: int) -> tuple[np.ndarray, np.ndarray]:
    """Welch's one-sided power spectral density of ``x`` (per Hz), as
    ``scipy.signal.welch(x, fs, window="hann", nperseg=nperseg, detrend="linear")``:
    segments of ``nperseg`` samples overlapping by half, each less its least-squares line,
    through a periodic Hann window, the periodograms averaged."""
    x = np.asarray(x, float)
    if not 2 <= nperseg <= x.size:
        raise ValueError(f"welch: nperseg {nperseg} must be within 2..{x.size}")
    step = nperseg - nperseg // 2
    segs = sliding_window_view(x, nperseg)[::step]
    t = np.arange(nperseg) - 0.5 * (nperseg - 1)
    tt = float(t @ t)
    seg = segs - segs.mean(axis=1, keepdims=True)
    if tt > 0:
        seg = seg - np.outer(seg @ t / tt, t)
    win = 0.5 - 0.5 * np.cos(2.0 * np.pi * np.arange(nperseg) / nperseg)
    spec = np.abs(np.fft.rfft(seg * win, axis=1)) ** 2
    p = spec.mean(axis=0) / (fs * float(win @ win))
    if nperseg % 2:
        p[1:] *= 2.0
    else:
        p[1:-1] *= 2.0
    return np.fft.rfftfreq(nperseg, 1.0 / fs), p


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


def _exp_moments(lam: np.ndarray) -> tuple[np.ndarray, ...]:
    """``I_k(λ) = ∫₀¹ e^{-λ(1-u)} uᵏ du`` for k = 0..3: by the recursion
    ``I_k = (1 - k I_{k-1}) / λ`` from ``I_0 = (1 - e^{-λ})/λ`` where ``λ >= 2`` (each step
    amplifies an error by at most 3/2), else by the series ``k! Σ_j (-λ)^j / (k+j+1)!``."""
    out = [np.empty_like(lam) for _ in range(4)]
    big = lam >= 2.0
    if np.any(big):
        lb = lam[big]
        i_k = -np.expm1(-lb) / lb
        out[0][big] = i_k
        for k in (1, 2, 3):
            i_k = (1.0 - k * i_k) / lb
            out[k][big] = i_k
    small = ~big
    if np.any(small):
        ls = lam[small]
        for k in range(4):
            # k! Σ_j (-λ)^j / (k+j+1)!, 30 terms: 2^30 / 31! is below 1e-24
            term = np.full_like(ls, math.factorial(k) / math.factorial(k + 1))
            acc = term.copy()
            for j in range(1, 30):
                term = term * (-ls) / (k + j + 1)
                acc += term
            out[k][small] = acc
    return tuple(out)


#: largest sum of ``λ`` over a block of the scan in :func:`first_order_response`
#: (``e^600`` is far from overflow, ``e^-600`` from underflow)
_SCAN_SPAN = 600.0


def hermite_coefficients(t: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, ...]:
    """Step lengths and the cubic of each step, ``p(u) = c0 + c1 u + c2 u² + c3 u³`` for
    ``u`` from 0 to 1, of the Hermite interpolant with slopes
    ``numpy.gradient(p, t, edge_order=2)`` (straight lines for two samples): ``(Δ, c0, c1,
    c2, c3)``, as :class:`contactlab.normal.KelvinVoigt` continues a sampled pressure."""
    t = np.asarray(t, dtype=float)
    p = np.asarray(p, dtype=float)
    dt = np.diff(t)
    if p.size == 2:
        m = np.full(2, (p[1] - p[0]) / dt[0])
    else:
        m = np.gradient(p, t, edge_order=2)
    m0, m1 = dt * m[:-1], dt * m[1:]
    p0, p1 = p[:-1], p[1:]
    return dt, p0, m0, 3.0 * (p1 - p0) - 2.0 * m0 - m1, 2.0 * (p0 - p1) + m0 + m1


def first_order_response(
    t: np.ndarray,
    p: np.ndarray,
    a: float,
    gain: float,
    y0: float,
    coeffs: tuple[np.ndarray, ...] | None = None,
) -> np.ndarray:
    """Exact solution at the samples of ``y' = a (gain · p(t) - y)``, ``y(t[0]) = y0``, with
    ``p`` between samples the cubic Hermite interpolant of :func:`hermite_coefficients`
    (``coeffs``: those, when computed already) — the forcing
    :meth:`contactlab.normal.KelvinVoigt.simulate` integrates by default; its adaptive
    solver approximates this to its tolerance.

    On a step of length ``Δ`` with ``λ = aΔ`` and ``p(u) = Σ c_k uᵏ`` (``u`` from 0 to 1):
    ``y₁ = e^{-λ} y₀ + gain · λ Σ c_k I_k(λ)``, ``I_k = ∫₀¹ e^{-λ(1-u)} uᵏ du`` (once, when
    the steps are equal to 1e-9). The recursion is run in blocks whose ``λ`` sum is at most
    :data:`_SCAN_SPAN`: ``y_{b+i} = e^{-L_i} (y_b + Σ_{j<i} e^{L_{j+1}} g_{b+j})`` with ``L``
    the block's running sum of ``λ``, all blocks at once, then a short loop over the blocks'
    ends (a step's ``λ`` is capped at the span there: ``e^{-600}`` forgets ``y₀`` as well).
    Kelvin-Voigt ``p = k δ + h δ'`` is ``a = k/h``, ``gain = 1/k``.
    """
    n = np.size(p)
    y = np.empty(n)
    y[0] = y0
    if n < 2:
        return y
    dt, c0, c1, c2, c3 = hermite_coefficients(t, p) if coeffs is None else coeffs
    lam = a * dt
    lo, hi = float(np.min(lam)), float(np.max(lam))
    # equal steps: the moments once. Times stored as k / fs differ from equal steps by
    # rounding (1e-11 of a step at 1e6 samples, so 1e-13 missed them); a step 1e-9 off
    # changes a moment by that fraction, far below the interpolant's own error
    uniform = hi - lo <= 1e-9 * hi
    if uniform:  # equal steps (to rounding): the moments once
        lam1 = 0.5 * (lo + hi)
        i0, i1, i2, i3 = (float(v[0]) for v in _exp_moments(np.array([lam1])))
        g = (gain * lam1) * (c0 * i0 + c1 * i1 + c2 * i2 + c3 * i3)
        lam1 = min(lam1, _SCAN_SPAN)
    else:
        i0, i1, i2, i3 = _exp_moments(lam)
        g = gain * lam * (c0 * i0 + c1 * i1 + c2 * i2 + c3 * i3)
        lam = np.minimum(lam, _SCAN_SPAN)
        lam1 = float(np.max(lam))
    s = n - 1
    width = int(max(1, min(s, _SCAN_SPAN // max(lam1, 1e-300))))
    nb = -(-s // width)
    pad = nb * width - s
    g_b = np.concatenate((g, np.zeros(pad))).reshape(nb, width)
    if uniform:  # the same running sum in every block
        run = lam1 * np.arange(1, width + 1, dtype=float)
        acc = np.cumsum(np.exp(run) * g_b, axis=1)  # Σ_{j<=i} e^{L_{j+1}} g_j
        decay = np.exp(-run)  # e^{-L_{i+1}}
        ends_a = np.full(nb, decay[-1])
    else:
        run = np.cumsum(np.concatenate((lam, np.zeros(pad))).reshape(nb, width), axis=1)
        acc = np.cumsum(np.exp(run) * g_b, axis=1)
        decay = np.exp(-run)
        ends_a = decay[:, -1]
    ends_c = (ends_a * acc[:, -1]).tolist()
    ends_l = ends_a.tolist()
    starts = np.empty(nb)
    cur = float(y0)
    for k in range(nb):  # y at each block's start
        starts[k] = cur
        cur = ends_l[k] * cur + ends_c[k]
    y[1:] = (decay * (starts[:, None] + acc)).reshape(-1)[:s]
    return y
