"""Where :func:`contactlab.studies.tracking.track` cuts a long recording into windows."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .._arrays import median
from .track_result import AUTO_WINDOW, MIN_CYCLES

__all__ = ["WindowCuts"]


class WindowCuts:
    """Where :func:`track` cuts its windows: at a crossing of the drive's trigger level,
    every ``size`` cycles (``mode="cycles"``), or once ``size`` seconds have passed and the
    window holds more than :data:`MIN_CYCLES` crossings (``"time"``); ``"auto"`` learns the
    cycle length from the first crossings and then cuts by cycles of about ``auto_window``
    samples."""

    def __init__(self, mode: str, size: float, auto_window: int = AUTO_WINDOW) -> None:
        self.mode, self.size, self.auto_window = mode, size, auto_window
        self.n_cross = 0  # crossings so far
        self.next_cross_target = int(size) if mode == "cycles" else None
        self.first_crossings: list[int] = []
        self.window_t0: float | None = None
        self.crossings_in_window = 0

    def block(self, t0: float, crossings: np.ndarray) -> None:
        """A new block of samples starting at ``t0`` with these crossings (sample indices)."""
        if self.window_t0 is None:
            self.window_t0 = t0
        if self.mode == "auto":
            self.first_crossings.extend(crossings[:64].tolist())
            if len(self.first_crossings) >= 3:
                per_cycle = float(median(np.diff(self.first_crossings)))
                self.size = float(max(MIN_CYCLES + 1, round(self.auto_window / per_cycle)))
                self.mode, self.next_cross_target = "cycles", int(self.size)

    def crossing(self, t_g: float) -> bool:
        """Count a crossing at time ``t_g``; True when a window ends there."""
        self.n_cross += 1
        self.crossings_in_window += 1
        if self.mode == "auto":
            cut = False
        elif self.mode == "cycles":
            assert self.next_cross_target is not None
            cut = self.n_cross == self.next_cross_target + 1
            if cut:
                self.next_cross_target += int(self.size)
        else:
            assert self.window_t0 is not None
            cut = t_g - self.window_t0 >= self.size and self.crossings_in_window > MIN_CYCLES
        if cut:
            self.window_t0 = t_g
            self.crossings_in_window = 1
        return cut

    def cuts(self, gs: list[int], time_of: Callable[[int], float]) -> list[tuple[int, int]]:
        """Count the crossings at samples ``gs`` (in order; ``time_of(g)`` the time of sample
        ``g``) as :meth:`crossing` one by one would; returns ``(g, complete cycles before
        g)`` for each at which a window ends. Cutting by cycles, the counts are arithmetic
        (the time is read at the cuts only): a crossing a cycle, tens of thousands in a long
        recording, each a Python call with a time lookup on the reader's thread (70 ms of
        a 3e7-sample run)."""
        target = self.next_cross_target
        if self.mode != "cycles" or not gs or target is None or target + 1 <= self.n_cross:
            out = []
            for g in gs:
                if self.crossing(time_of(g)):
                    out.append((g, self.n_cross - 1))
            return out
        step = int(self.size)
        n0, k = self.n_cross, len(gs)
        out = []
        # crossing j of gs (from 0) is crossing n0 + j + 1; a window ends at crossing
        # target + 1, then every `step` crossings
        while target + 1 <= n0 + k:
            g = gs[target - n0]
            out.append((g, target))
            self.window_t0 = time_of(g)
            target += step
        self.next_cross_target = target
        self.n_cross = n0 + k
        if out:
            self.crossings_in_window = n0 + k - out[-1][1]
        else:
            self.crossings_in_window += k
        return out
