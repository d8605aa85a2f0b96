"""The arrays a diagnosis works on, from a Recording, a dict or a tuple."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from .._arrays import as_1d
from ..errors import InputError

# the plausibility checks live with the readers (issue 32); the diagnosis uses them from there
from ..io.checks import (  # noqa: F401
    GLITCH_MAX_SAMPLES,
    GLITCH_SCALE,
    GlitchError,
    check_channels,
    check_glitches,
    check_recording_glitches,
    glitch_suspect,
)
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
