"""Shared helpers of the tangential effects: the record's scales as the plausibility
arguments quote them."""

from __future__ import annotations

import numpy as np

from ..._family import Prepared

_INF = np.inf


def period(d: Prepared) -> float:
    """The excitation period, s."""
    return float(d.cycles.period_samples * d.dt)


def amplitude(d: Prepared) -> float:
    """Half the displacement's range, m."""
    return 0.5 * float(np.ptp(d.u))


def peak_speed(d: Prepared) -> float:
    """The 99th percentile of ``|ẋ|`` (m/s): the sliding speed the record reaches."""
    return float(np.percentile(np.abs(d.ud), 99.0))


def peak_acceleration(d: Prepared) -> float:
    """The 99th percentile of ``|ẍ|`` (m/s²)."""
    return float(np.percentile(np.abs(d.udd), 99.0))


def meta(d: Prepared) -> dict:
    """The recording's own meta (a reconstructed force, a frame), as the workflow kept it."""
    m = d.extra.get("meta")
    return m if isinstance(m, dict) else {}


def reconstructed(d: Prepared) -> str | None:
    """Why the force was computed from the displacement itself (a frame's equation of
    motion, ``meta["frame"]`` / ``meta["same_clock"]``), or None."""
    m = meta(d)
    if isinstance(m.get("frame"), dict):
        return "the force was reconstructed from the displacements of a frame (--frame)"
    if m.get("same_clock"):
        return "the force was computed from the displacement's own samples (same clock)"
    return None
