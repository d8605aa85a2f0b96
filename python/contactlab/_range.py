"""The numerical range the analyses accept, checked on the data before any fit.

Fits square residuals and multiply forces by displacements: channels whose values exceed
``MAX_ABS`` (in SI units) could overflow double precision on the way, and a channel whose
whole span is below ``MIN_SPAN`` (or zero: a constant channel) carries no loop to fit. Both are
refused with a sentence about the data instead of an overflow deep inside a fit, a
``ValueError: array must not contain infs or NaNs`` or a result of 1e-295 ± nan (issue 12).
Between the two, results do not depend on the units: the fits scale parameters and residuals
internally (see :mod:`contactlab.fitting`), tested from nN/nm to kN/mm.
"""

from __future__ import annotations

import numpy as np

from .errors import InputError

#: largest |value| accepted in SI units (1e100 N, m, Pa: squares and products stay finite)
MAX_ABS = 1e100
#: smallest span (max - min) accepted in SI units
MIN_SPAN = 1e-100

_WHAT = {"x": "displacement", "F": "force", "p": "pressure", "delta": "normal displacement"}


def check_magnitude(a: np.ndarray, name: str, unit: str, source: str = "") -> None:
    """Raise :class:`InputError` when a channel's values exceed ``MAX_ABS`` (part of
    :func:`check_channel`, for pieces of a recording that may well be constant)."""
    if a.size and float(np.max(np.abs(a))) > MAX_ABS:
        where = f"{source}: " if source else ""
        what = f"{_WHAT.get(name, 'channel')} channel {name!r}"
        raise InputError(
            f"{where}the {what} reaches {float(np.max(np.abs(a))):.3g} {unit}, beyond the "
            f"range the analysis can handle (|value| ≤ {MAX_ABS:g} {unit}); is the unit in "
            "the file right?"
        )


def check_channel(a: np.ndarray, name: str, unit: str, source: str = "") -> None:
    """Raise :class:`InputError` naming the channel when it is constant, too small or too
    large for the analyses (``a`` finite, 1-D)."""
    where = f"{source}: " if source else ""
    what = f"{_WHAT.get(name, 'channel')} channel {name!r}"
    if a.size == 0:
        raise InputError(f"{where}the {what} is empty")
    check_magnitude(a, name, unit, source)
    span = float(np.max(a) - np.min(a))
    if span == 0.0:
        raise InputError(
            f"{where}the {what} is constant ({float(a[0]):.6g} {unit} throughout): the "
            "recording holds no loop to fit"
        )
    if span < MIN_SPAN:
        raise InputError(
            f"{where}the {what} varies by only {span:.3g} {unit}, below the range the "
            f"analysis can handle (≥ {MIN_SPAN:g} {unit}); is the unit in the file right?"
        )
