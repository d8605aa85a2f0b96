"""Array conversion at the package boundary: float64, contiguous, 1-D, finite, named errors."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from . import _core
from .errors import InputError


def median(v: Any) -> Any:
    """``np.median(v)`` of a 1-D real array, bit for bit (the same order statistics, the same
    ``np.mean`` of the middle one or two, NaN where a NaN is present), without the import of
    ``numpy.ma`` that numpy's NaN check makes on its first call (20 ms of a command's start;
    ``np.median`` itself for anything else)."""
    a = np.asarray(v)
    n = a.size
    if a.ndim != 1 or n == 0 or a.dtype.kind not in "fiu":
        return np.median(a)
    h = n // 2
    inexact = a.dtype.kind == "f"
    kth = [h - 1, h] if n % 2 == 0 else [h]
    if inexact:
        kth.append(n - 1)  # NaNs sort last: the largest is NaN when any is
    part = np.partition(a, kth)
    if inexact and np.isnan(part[-1]):
        return part[-1]
    return np.mean(part[h - 1 : h + 1] if n % 2 == 0 else part[h : h + 1])


def scan(a: np.ndarray, extremes: bool = True) -> tuple[bool, float, float]:
    """``(all finite, min, max)`` of a float64 array, min and max over its finite samples
    (``inf, -inf`` when none; not computed, and NaN, with ``extremes=False``). A contiguous
    float64 array is read once by the core (``finite_min_max``: numpy's ``isfinite().all()``,
    ``min`` and ``max`` read it three times, 4 of a window's ~60 ms); anything else takes
    numpy's reductions (the plausibility checks used to add ``abs``, ``argmax`` and ``ptp``
    and a negated mask: 1.1 ns a sample and two temporaries)."""
    if not a.size:
        return True, float("inf"), float("-inf")
    if a.dtype == np.float64 and a.ndim == 1 and a.flags.c_contiguous:
        finite, lo, hi = _core.finite_min_max(a)
        if not extremes:
            return finite, float("nan"), float("nan")
        return finite, lo, hi
    finite = bool(np.isfinite(a).all())
    if not extremes:
        return finite, float("nan"), float("nan")
    if finite:
        return True, float(a.min()), float(a.max())
    good = a[np.isfinite(a)]
    if not good.size:
        return False, float("inf"), float("-inf")
    return False, float(good.min()), float(good.max())


def _float_array(x: Any, name: str) -> np.ndarray:
    """``x`` as a float64 array; complex input is an error (numpy would drop the imaginary
    part with only a warning)."""
    if type(x) is np.ndarray and x.dtype == np.float64 and x.ndim and x.flags.c_contiguous:
        return x  # (what the conversion below gives such an array: itself)
    try:
        a = np.asarray(x)
        complex_ = np.iscomplexobj(a)
        if not complex_:
            a = np.ascontiguousarray(a, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} cannot be converted to a float array: {exc}") from None
    if complex_:
        raise InputError(f"{name} is complex; pass a real array (e.g. its .real part)")
    return a


def as_1d(x: Any, name: str, *, allow_empty: bool = False, finite: bool = True) -> np.ndarray:
    """Return `x` as a contiguous 1-D float64 array or raise :class:`InputError`.

    int and float32 input is converted; NaN/inf is rejected with the index named; complex
    input is rejected (numpy would silently drop the imaginary part).
    """
    a = _float_array(x, name)
    if a.ndim != 1:
        raise InputError(f"{name} must be 1-D, got an array of shape {a.shape}")
    if a.size == 0 and not allow_empty:
        raise InputError(f"{name} is empty")
    if finite and not scan(a, extremes=False)[0]:
        i = int(np.argmax(~np.isfinite(a)))
        raise InputError(f"{name}[{i}] is not finite ({a[i]})")
    return a


def scalar_or_array(x: Any, name: str) -> tuple[np.ndarray, bool]:
    """Flatten a scalar or array for a vectorised kernel; tell whether it was a scalar."""
    if type(x) is float:  # (what the conversion below makes of it: one sample, and False)
        if not math.isfinite(x):
            raise InputError(f"{name}[0] is not finite ({x})")
        return np.array([x]), False
    a = _float_array(x, name)
    flat = np.ascontiguousarray(a.reshape(-1))
    bad = ~np.isfinite(flat)
    if bad.any():
        i = int(np.argmax(bad))
        raise InputError(f"{name}[{i}] is not finite ({flat[i]})")
    return flat, a.ndim == 0


def restore(flat: np.ndarray, like: Any, was_scalar: bool) -> Any:
    if was_scalar:
        return float(flat[0])
    return flat.reshape(np.shape(like))


def positive(value: Any, name: str) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(v) or v <= 0:
        raise InputError(f"{name} must be finite and > 0, got {v}")
    return v


def next_fast_len(target: int, real: bool = False) -> int:
    """The smallest FFT length ``>= target`` that is a product of 2, 3 and 5 (``real``) or of
    2, 3, 5, 7 and 11 (complex): :func:`scipy.fft.next_fast_len` without importing
    :mod:`scipy.fft` (a third of a second; tested equal to it)."""
    n = int(target)
    if n < 1:
        raise InputError(f"an FFT length must be a positive integer, got {target!r}")
    if n <= (6 if real else 12):
        return n
    best = 1 << (n - 1).bit_length()  # a power of 2 >= n
    # depth-first over the products of the primes, each prime from the last one used on
    # (every product once), pruned at the best length found
    stack = [(1, 0)]
    primes = (2, 3, 5) if real else (2, 3, 5, 7, 11)
    while stack:
        v, i = stack.pop()
        if v >= n:
            best = min(best, v)
            continue
        for j in range(i, len(primes)):
            w = v * primes[j]
            if w < best:
                stack.append((w, j))
    return best
