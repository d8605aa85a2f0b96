"""Plausibility of a measured channel before any fit sees it.

A fit given a constant channel, a channel of zeros or values near the float64 limits fails
deep inside (singular Jacobians, overflowing squares, NaN bounds) with messages about its
internals. These checks say what is wrong with the data instead, naming the channel, the
value and the sample. ``1e100`` is far beyond any force (N), pressure (Pa) or displacement
(m) a contact measurement records, yet leaves squares and products of two channels finite
(float64 overflows near 1e308, so squares near 1e154).
"""

from __future__ import annotations

import numpy as np

from ._arrays import scan
from .errors import InputError

MAX_MAGNITUDE = 1e100
MIN_MAGNITUDE = 1e-100


def check_channel(
    name: str, v: np.ndarray, unit: str, what: str, extremes: tuple[float, float] | None = None
) -> bool:
    """Refuse a channel that is out of any physical scale, zero throughout, or constant.

    ``what`` names the sensor in the sentence (e.g. "force"). Returns whether every sample
    is finite (the scan the checks made; a NaN or inf is not refused here, the caller's
    conversion names it), so a caller need not scan the channel again. ``extremes``: the
    channel's ``(min, max)``, every sample known finite (a streamed reader's scan of the
    same samples): the checks use them instead of reading ``v`` (the same outcome).

    Examples
    --------
    >>> check_channel("F", np.full(5, 3.0), "N", "force")
    Traceback (most recent call last):
    ...
    contactlab.errors.InputError: F is constant (3 N in all 5 samples): ...
    """
    v = np.asarray(v, dtype=np.float64)
    if extremes is None:
        finite, lo, hi = scan(v)  # the largest magnitude is max(-min, max)
    else:
        finite, lo, hi = True, float(extremes[0]), float(extremes[1])
    big = max(-lo, hi) if v.size else 0.0
    if big > MAX_MAGNITUDE:
        i = int(np.argmax(np.abs(v)))
        raise InputError(
            f"{name} reaches {float(v[i]):.3g} {unit} at sample {i}: beyond any physical "
            f"{what}; a unit mix-up or a corrupt file?"
        )
    if big == 0.0:
        raise InputError(
            f"{name} is zero in all {v.size} samples: the {what} sensor recorded nothing, so "
            "there is no loop to analyse"
        )
    if big < MIN_MAGNITUDE:
        raise InputError(
            f"{name} is at most {big:.3g} {unit} in magnitude in all {v.size} samples: far "
            f"below any physical {what}; a unit mix-up or a corrupt file?"
        )
    spread = hi - lo
    if spread <= 1e-12 * big:
        raise InputError(
            f"{name} is constant ({float(v[0]):.6g} {unit} in all {v.size} samples): the "
            f"{what} sensor recorded no change, so there is no loop to analyse"
        )
    return finite


__all__ = ["MAX_MAGNITUDE", "MIN_MAGNITUDE", "check_channel"]
