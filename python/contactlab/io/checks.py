"""Plausibility checks of recorded channels, shared by every analysis: a sensor glitch (a few
samples orders of magnitude outside the rest), a time axis or values too large to be SI
measurements, a constant or vanishing channel. ``analyze``, ``track`` and ``diagnose`` refuse
such a recording with a sentence naming the channel, the sample and how to go on.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import InputError

__all__ = [
    "GLITCH_MAX_SAMPLES",
    "GLITCH_SCALE",
    "GlitchError",
    "check_channels",
    "check_glitches",
    "check_recording_glitches",
    "glitch_suspect",
]


class GlitchError(InputError):
    """A channel holds a sensor glitch: a few samples orders of magnitude outside the rest.
    ``channel``, ``sample`` (0-based index of the largest) and ``value`` are attributes, so
    a caller that knows the file can add where it is (a CSV line)."""

    def __init__(self, message: str, *, channel: str, sample: int, value: float) -> None:
        super().__init__(message)
        self.channel = channel
        self.sample = sample
        self.value = value


#: a sample this many robust standard deviations (1.4826 × the median absolute deviation)
#: from its channel's median is no measurement of the same quantity: a sensor glitch
GLITCH_SCALE = 1e3
#: ... when at most this many samples (or a thousandth of the record) are that far out; more
#: is a change of the signal itself (a record that starts at rest, then loads), not a glitch
GLITCH_MAX_SAMPLES = 3


def glitch_suspect(v: np.ndarray, sub_size: int = 4096) -> bool:
    """A cheap pre-check for :func:`check_glitches` (about 1 ms on 10⁶ samples against
    60 ms): does any sample lie beyond half :data:`GLITCH_SCALE` robust deviations of an
    evenly strided subsample of about ``sub_size``? False means no glitch (a glitch is one
    of a few samples, so the subsample's median and spread are the channel's); True needs
    the full check."""
    if v.size < 8:
        return False
    sub = v[:: max(1, v.size // sub_size)]
    med = float(np.median(sub))
    scale = 1.4826 * float(np.median(np.abs(sub - med)))
    if not scale > 0.0:
        return True  # let the full check decide
    far = max(float(np.max(v)) - med, med - float(np.min(v)))
    return not far <= 0.5 * GLITCH_SCALE * scale


def check_glitches(
    t: np.ndarray, named: dict[str, tuple[np.ndarray, str]], *, offset: int = 0
) -> None:
    """Refuse a channel with a sensor glitch (found by audit: a normal recording whose
    displacement, ~0.1 µm throughout, read −2.17 m at one sample was fitted, the fit dragged
    by the glitch). A glitch is a sample more than :data:`GLITCH_SCALE` robust standard
    deviations from the channel's median, and there are only a few of them; the message
    names the channel, the sample (0-based; ``offset`` added: a window's first sample in its
    file), its time and value, and how to go on."""
    for name, (v, unit) in named.items():
        n = v.size
        if n < 8 or not glitch_suspect(v):
            continue
        med = float(np.median(v))
        dev = np.abs(v - med)
        scale = 1.4826 * float(np.median(dev))
        if not scale > 0.0:  # more than half the samples equal: no spread to judge by
            continue
        far = np.flatnonzero(dev > GLITCH_SCALE * scale)
        if far.size == 0 or far.size > max(GLITCH_MAX_SAMPLES, n // 1000):
            continue
        i = int(far[np.argmax(dev[far])])
        k = i + int(offset)
        others = "" if far.size == 1 else f" (and {far.size - 1} more such sample(s))"
        raise GlitchError(
            f"channel {name!r} reads {float(v[i]):.6g} {unit} at sample {k} (t = "
            f"{float(t[i]):.9g} s){others}, {float(dev[i]) / scale:.3g} times the channel's "
            f"robust spread (1.4826 × median absolute deviation = {scale:.3g} {unit}) from its "
            f"median {med:.3g} {unit}: a sensor glitch, not a measurement; remove or replace "
            "the sample(s) (e.g. by the neighbours' mean), or cut the record around them, and "
            "run again",
            channel=name,
            sample=k,
            value=float(v[i]),
        )


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


def check_recording_glitches(rec: Any, *, offset: int = 0) -> None:
    """:func:`check_glitches` on a recording's analysed channels (``x``, ``F`` or ``p``,
    ``delta``): ``analyze`` and ``track`` refuse a glitch as ``diagnose`` does."""
    named = {
        k: (np.asarray(rec.data[k], dtype=float), str((rec.units or {}).get(k, "")))
        for k in ("x", "F", "p", "delta")
        if k in rec.data
    }
    if named:
        check_glitches(np.asarray(rec.t, dtype=float), named, offset=offset)
