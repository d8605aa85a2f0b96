"""Cycles of a long recording, found while it streams past: crossings and per-cycle quantities.

A cycle runs from one upward crossing of the drive channel (``x`` of a tangential recording,
``p`` of a normal one) to the next. Crossings are found with a Schmitt trigger: the signal
must fall below ``centre - band`` before an upward passage of ``centre + band`` counts, so
noise at the level cannot count twice. ``centre`` and ``band`` come from each block's range
and follow a slowly drifting or shrinking amplitude; :func:`contactlab.track` hands in blocks
of fixed global sample ranges (``tracking.CYCLE_SEGMENT``, 2^18 samples), so that the cycles
do not depend on the chunks a file is read in.

Per cycle: the loop energy ∮ F dx (trapezoids, closed by the chord from the cycle's last
sample back to its first, i.e. the area of the polygon of the samples, as
:func:`contactlab.loop_area` computes it), the displacement amplitude (half its range) and
the force offset (centre of its range). One pass per block in Rust (``_core.CycleStream``, GIL
released; x and F checked finite in the same pass); the state carried between blocks is a few
scalars. A recording sampled at a fixed interval needs no time array: the times of the
crossings are computed (``time_step``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import _core

#: SI units of the per-cycle quantities of :func:`contactlab.studies.tracking.track`
CYCLE_UNITS = {
    "tangential": {"start": "s", "end": "s", "energy": "J", "amplitude": "m", "offset": "N"},
    "normal": {"start": "s", "end": "s", "energy": "J/m^2", "amplitude": "m", "offset": "Pa"},
}

#: smallest block the thresholds were judged on before fixed segments (samples; kept for
#: callers of :func:`block_cycles`)
MIN_BLOCK = 1 << 16
#: half width of the trigger band as a fraction of the block's half range
BAND = 0.25


class CycleState:
    """What :func:`block_cycles` carries from one block to the next (trigger level, the last
    crossing, ∮ F dx and extrema since it, the previous sample), kept in the Rust tracker."""

    def __init__(self) -> None:
        self.tracker = _core.CycleStream()


@dataclass
class Cycles:
    """Complete cycles found in a block (arrays of equal length) and every crossing."""

    crossings: np.ndarray  # global sample index of each upward crossing in the block
    start: np.ndarray = field(default_factory=lambda: np.empty(0))  # s
    end: np.ndarray = field(default_factory=lambda: np.empty(0))  # s
    energy: np.ndarray = field(default_factory=lambda: np.empty(0))
    amplitude: np.ndarray = field(default_factory=lambda: np.empty(0))
    offset: np.ndarray = field(default_factory=lambda: np.empty(0))


def trigger_levels(lo: float, hi: float) -> tuple[float, float]:
    """The trigger band ``(low, high)`` of a block whose drive spans ``[lo, hi]``: centred,
    :data:`BAND` of the half range wide on each side."""
    centre, half = 0.5 * (hi + lo), 0.5 * (hi - lo) * BAND
    return centre - half, centre + half


def block_cycles(
    t: np.ndarray,
    x: np.ndarray,
    F: np.ndarray,
    drive: np.ndarray,
    offset: int,
    s: CycleState,
    levels: tuple[float, float] | None = None,
    time_step: tuple[float, float] | None = None,
    quantities: bool = True,
    finite: bool = False,
) -> Cycles:
    """Crossings of ``drive`` and the cycles they complete in one block; updates ``s``.

    ``x``/``F`` are the loop's abscissa and ordinate (``x, F`` or ``delta, p``), ``drive`` the
    channel whose crossings mark the cycles, ``offset`` the global index of the block's first
    sample. ``levels = (low, high)`` fixes the trigger band (default: :func:`trigger_levels`
    of the drive's range in the block). ``time_step = (t0, dt)``: the recording is sampled
    every ``dt`` from ``t0`` (sample ``i`` at ``t0 + dt * i``, bit for bit
    ``contactlab._core.fill_time``) and ``t`` is not read. ``quantities=False``: the
    crossings alone (the same ones; the per-cycle arrays empty), without the chain of
    additions of ∮ F dx a sample; a state ``s`` is then cut so to the end. ``finite`` (with
    ``quantities=False``): the caller checked ``x``, ``F`` and ``drive`` finite (a checked
    reader's block, ``ChunkedRecording.checked``), so the crossings' pass does not scan them
    again (the same crossings).
    """
    if levels is None:
        lo_d, hi_d = (float(drive.min()), float(drive.max())) if drive.size else (0.0, 0.0)
        low, high = trigger_levels(lo_d, hi_d)
    else:
        low, high = float(levels[0]), float(levels[1])
    if not quantities:
        return Cycles(
            crossings=s.tracker.push_crossings(x, F, drive, int(offset), low, high, bool(finite))
        )
    if time_step is None:
        d = s.tracker.push(t, x, F, drive, int(offset), low, high)
    else:
        t0, dt = time_step
        d = s.tracker.push_sampled(float(t0), float(dt), x, F, drive, int(offset), low, high)
    return Cycles(
        crossings=d.crossings,
        start=d.start,
        end=d.end,
        energy=d.energy,
        amplitude=d.amplitude,
        offset=d.offset,
    )


__all__ = ["BAND", "MIN_BLOCK", "CycleState", "Cycles", "block_cycles", "trigger_levels"]
