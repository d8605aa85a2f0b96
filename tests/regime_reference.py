"""The whole-signal velocity and stick search as they were before issue 9 made them O(n) in
bounded memory, kept verbatim (logic) as the reference the blocked versions must reproduce:
``frame.difference_noise`` (lag differences as fresh arrays), ``frame.lepski_window`` (every
candidate window's estimate held over the whole record, every pair compared over it),
``regime.velocity`` and ``regime.stick_slip`` (every run of the stuck mask a Python tuple).
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from contactlab.tangential import regime
from contactlab.tangential.frame import LEPSKI_KAPPA, savgol_coefficients, savgol_derivative


def _lag_noise(v, lag, order):
    d = v
    for _ in range(order):
        d = d[lag:] - d[:-lag]
    if d.size < 10:
        return math.nan
    c = math.comb(2 * order, order)
    return 1.4826 * float(np.median(np.abs(d - np.median(d)))) / math.sqrt(c)


def difference_noise(v, order=4):
    lags = [lag for lag in (1, 2, 4, 8, 16) if v.size > order * lag + 10]
    if not lags:
        return 0.0
    est = [_lag_noise(v, lag, order) for lag in lags]
    if len(est) < 2 or not est[0] > 0:
        return float(est[0]) if est and math.isfinite(est[0]) else 0.0
    ratios = [b / a if a > 0 else math.inf for a, b in itertools.pairwise(est)]
    k = int(np.argmin(ratios))
    return float(est[k + 1] if ratios[k] < 4.0 else est[0])


def lepski_window(x, dt, sigma, *, kappa=LEPSKI_KAPPA):
    n = x.size
    top = min(401, max(7, n // 5))
    cands = sorted({w | 1 for w in np.geomspace(7, top, 16).astype(int) if w >= 7})
    if sigma <= 0 or len(cands) < 2:
        return cands[0]
    ests = {w: savgol_derivative(x, w, 2, dt) for w in cands}
    chosen = cands[0]
    for i, w in enumerate(cands[1:], start=1):
        ok = True
        cw = savgol_coefficients(w, 2, dt)
        for wp in cands[:i]:
            cp = np.pad(savgol_coefficients(wp, 2, dt), (w - wp) // 2)
            sd = sigma * float(np.linalg.norm(cw - cp))
            inner = slice(w // 2, n - w // 2)
            rms = float(np.sqrt(np.mean((ests[w][inner] - ests[wp][inner]) ** 2)))
            if rms > kappa * sd:
                ok = False
                break
        if not ok:
            break
        chosen = w
    return chosen


def velocity(t, x):
    tt = np.arange(x.size, dtype=float) if t is None else t
    dt = float(np.median(np.diff(tt)))
    sx = difference_noise(x)
    window = min(lepski_window(x, dt, sx), max(5, (x.size // 2) * 2 - 1))
    v = savgol_derivative(x, window, 1, dt)
    thr = regime.VELOCITY_SIGMAS * sx * float(np.linalg.norm(savgol_coefficients(window, 1, dt)))
    if not thr > 0:
        thr = 1e-9 * float(np.max(np.abs(v)))
    return v, thr, window


def _runs(mask):
    d = np.diff(np.r_[0, mask.astype(np.int8), 0])
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1), strict=True))


def stick_slip(t, x, F, rev, v, thr, window, offset=0.0):
    turns = np.sort(np.r_[rev.peaks, rev.valleys]).astype(np.int64)
    if turns.size < 2 or x.size < 20:
        return None
    tt = np.arange(x.size, dtype=float) if t is None else t
    peaks_t = rev.peak_times if rev.peak_times.size >= 2 else rev.valley_times
    if peaks_t.size >= 2:
        period = float(np.median(np.diff(peaks_t)))
    else:
        period = 2.0 * float(np.median(np.diff(tt[turns])))
    amp = 0.5 * float(np.ptp(x[turns[0] : turns[-1] + 1]))
    omega = 2.0 * math.pi / period
    dt = float(np.median(np.diff(tt)))
    smooth = 2.0 * thr / (amp * omega**2) if amp > 0 else math.inf
    min_len = max(4, math.ceil(regime.STICK_DWELL_FACTOR * smooth / dt))
    spans = {}
    for a, b in _runs(np.abs(v) < thr):
        if b - a < min_len:
            continue
        mid = tt[(a + b - 1) // 2]
        k = int(np.argmin(np.abs(tt[turns] - mid)))
        if abs(tt[turns[k]] - mid) > 0.25 * period + 0.5 * (b - a) * dt:
            continue
        sp = spans.setdefault(k, [a, b, 0])
        sp[0], sp[1], sp[2] = min(sp[0], a), max(sp[1], b), sp[2] + (b - a)
    durations, breakaway = [], []
    sliding = regime.SLIDE_ONSET * amp * omega
    sx = difference_noise(x)
    for a, b, _n_stuck in spans.values():
        durations.append(_n_stuck * dt)
        breakaway.append(regime._breakaway(F - offset, x, v, (a, b), window, max(sliding, thr), sx))
    return regime.StickSlip(int(turns.size), np.asarray(durations), np.asarray(breakaway),
                            float(thr), float(smooth), len(spans))  # fmt: skip
