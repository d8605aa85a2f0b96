"""The three pure-Python reversal detectors the package had before its Rust detector, kept
verbatim (logic) as references: the hysteresis segments of ``find_reversals``, the per-sample
Schmitt trigger of ``diagnose._signal.find_cycles`` and the wiping-out stack of
``diagnose.scaled_masing.memory``.
"""

from __future__ import annotations

import itertools

import numpy as np


def crossing_time(t, x, i, level):
    if i <= 0:
        return float(t[0])
    x0, x1 = x[i - 1], x[i]
    if x1 == x0:
        return float(t[i])
    a = (level - x0) / (x1 - x0)
    return float(t[i - 1] + min(max(a, 0.0), 1.0) * (t[i] - t[i - 1]))


def reversal_segments(xa, ta, centre, threshold):
    """(peaks, valleys, peak_times, valley_times, edges) as find_reversals computed them."""
    hi_level = centre + threshold
    lo_level = centre - threshold
    state = np.where(xa > hi_level, 1, np.where(xa < lo_level, -1, 0))
    nz = np.flatnonzero(state)
    if nz.size == 0:
        return [], [], [], [], []
    s = state[nz]
    change = np.flatnonzero(np.diff(s) != 0) + 1
    seg_start = np.r_[nz[0], nz[change]]
    seg_state = s[np.r_[0, change]]
    seg_end = np.r_[nz[change], xa.size]
    peaks, valleys, ptimes, vtimes, edges = [], [], [], [], []
    last = len(seg_start) - 1
    for k, (a, b, st) in enumerate(zip(seg_start, seg_end, seg_state, strict=True)):
        seg = xa[a:b]
        level = hi_level if st > 0 else lo_level
        inside = seg > level if st > 0 else seg < level
        idx_in = np.flatnonzero(inside)
        i_ext = a + int(np.argmax(seg) if st > 0 else np.argmin(seg))
        if (k == 0 and a == 0) or (k == last and not np.any((xa[i_ext:] - centre) * st < 0)):
            edges.append(i_ext)
            continue
        t_in = crossing_time(ta, xa, a, level)
        j = a + int(idx_in[-1]) + 1
        t_out = crossing_time(ta, xa, min(j, xa.size - 1), level)
        if st > 0:
            peaks.append(i_ext)
            ptimes.append(0.5 * (t_in + t_out))
        else:
            valleys.append(i_ext)
            vtimes.append(0.5 * (t_in + t_out))
    return peaks, valleys, ptimes, vtimes, edges


def schmitt_extrema(uc, us):
    """(reversals, is_max) of find_cycles' per-sample trigger on ``uc``, extremes on ``us``."""
    n = uc.size
    thr = 0.2 * float(np.sqrt(np.mean(uc * uc)))
    sign = np.zeros(n, dtype=int)
    cur = 0
    for i in range(n):
        if uc[i] > thr:
            cur = 1
        elif uc[i] < -thr:
            cur = -1
        sign[i] = cur
    change = np.flatnonzero(np.diff(sign) != 0) + 1
    bounds = np.r_[0, change, n]
    rev, ismax = [], []
    for a, b in itertools.pairwise(bounds):
        s = sign[a]
        if s == 0 or b - a < 2:
            continue
        seg = us[a:b]
        i = a + int(np.argmax(seg) if s > 0 else np.argmin(seg))
        if i == 0 or i == n - 1 or (ismax and ismax[-1] == (s > 0)):
            continue
        rev.append(i)
        ismax.append(s > 0)
    return rev, ismax


def wiping_out_memory(x):
    """(anchor, target) of the old scaled_masing.memory loop."""
    n = x.size
    anchor = np.full(n, -1, dtype=np.int64)
    target = np.full(n, -1, dtype=np.int64)
    stack: list[int] = []
    direction = 0
    xs = x.tolist()
    prev = 0.0
    for i in range(n):
        step = xs[i] - prev
        if step != 0.0:
            d = 1 if step > 0 else -1
            if direction != 0 and d != direction:
                stack.append(i - 1)
            direction = d
            prev = xs[i]
        while stack:
            if len(stack) >= 2:
                xt = xs[stack[-2]]
                if direction * (xs[i] - xt) >= 0.0:
                    del stack[-2:]
                    continue
            else:
                xt = -xs[stack[0]]
                if direction * (xs[i] - xt) >= 0.0:
                    stack.clear()
                    continue
            break
        if stack:
            anchor[i] = stack[-1]
            target[i] = stack[-2] if len(stack) >= 2 else -1 - stack[0]
    return anchor, target
