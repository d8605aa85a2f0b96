"""The arrays a diagnosis works on, from a Recording, a dict or a tuple."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from .._arrays import as_1d
from ..errors import InputError
from ._family import Family


def arrays(recording: Any, family: Family) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(t, input, output)`` from a Recording-like object, a dict or a tuple of arrays."""
    uname, yname = family.input_name, family.output_name
    if hasattr(recording, "t") and hasattr(recording, "data"):
        data, t = recording.data, recording.t
    elif isinstance(recording, dict):
        data, t = recording, recording.get("t")
    elif isinstance(recording, Sequence) and len(recording) == 3:
        t, u, y = recording
        data = {uname: u, yname: y}
    else:
        raise InputError(
            "recording must be a contactlab.io.Recording, a dict with 't', "
            f"'{uname}', '{yname}', or a tuple (t, {uname}, {yname})"
        )
    for k in (uname, yname):
        if k not in data:
            raise InputError(
                f"the {family.kind} workflow needs channels '{uname}' and '{yname}'; "
                f"the recording has {sorted(data)}"
            )
    if t is None:
        raise InputError("the recording has no time vector 't'")
    ta = as_1d(t, "t")
    u = as_1d(data[uname], uname)
    y = as_1d(data[yname], yname)
    if not (ta.size == u.size == y.size):
        raise InputError(f"t, {uname}, {yname} have {ta.size}, {u.size}, {y.size} samples")
    return ta, u, y


#: channels beyond these magnitudes (in SI units) are not measurements: a unit or scaling
#: error, and squares of them overflow
_MAX_ABS = 1e100
_MIN_RMS = 1e-100


def check_channels(t: np.ndarray, named: dict[str, tuple[np.ndarray, str]]) -> None:
    """Sentences about the data for channels no model can be fitted to: a time axis or
    values too large to be SI measurements, a constant or vanishing output."""
    if float(np.max(np.abs(t))) > _MAX_ABS:
        raise InputError(
            f"the time axis reaches {float(np.max(np.abs(t))):.3g} s; that is not a time in "
            "seconds — check the time column's unit"
        )
    for name, (v, unit) in named.items():
        big = float(np.max(np.abs(v)))
        if big > _MAX_ABS:
            i = int(np.argmax(np.abs(v)))
            raise InputError(
                f"channel {name!r} holds {v[i]:.3g} {unit} at sample {i}; that is not a "
                f"measurement in {unit} — check the channel's unit or scaling"
            )
        if float(np.ptp(v)) == 0.0:
            raise InputError(
                f"channel {name!r} is constant ({v[0] + 0.0:.6g} {unit} at every sample): there is "
                "no loop to diagnose — is the sensor connected?"
            )
        rms = float(np.sqrt(np.mean((v / big) ** 2))) * big
        if rms < _MIN_RMS:
            raise InputError(
                f"channel {name!r} has an RMS of {rms:.3g} {unit}: no measurable signal — "
                f"check the channel's unit or scaling"
            )
