"""Reversal detection by a hysteresis (Schmitt) threshold, in the Rust core.

One detector for the package: a turn counts only after the signal has crossed a band of
half-width ``threshold`` around ``centre`` (the "gate" of ASTM E1049-85 peak counting), so
noise smaller than the band never makes a reversal. It reports *excursions* — stretches from
where the signal leaves the band on one side to where it next leaves it on the other — with
the sample of each one's extreme. It streams: a :class:`ReversalDetector` carries its state
across ``push`` calls, so a recording of any length can be fed chunk by chunk, and the GIL is
released while it runs.

Used by :func:`contactlab.tangential.preprocess.find_reversals` and by the cycle detection of
the diagnosis; the Masing memory rules themselves (the wiping-out stack) are the core
operator's, exported per sample by :func:`branch_memory`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from . import _core
from ._arrays import as_1d
from .errors import InputError


@dataclass(frozen=True)
class Excursions:
    """Excursions beyond the band, one row each (indices are global sample indices).

    ``sign``: +1 above ``centre + threshold``, -1 below ``centre - threshold``; ``start``:
    first sample beyond the level; ``extreme``: sample of the extreme of the value signal up to
    the next excursion's start; ``last_beyond``: last sample still beyond the level;
    ``returned``: the signal crossed the centre after the extreme (true for every completed
    excursion; for the open one it says whether its turn is confirmed).
    """

    sign: np.ndarray
    start: np.ndarray
    extreme: np.ndarray
    extreme_value: np.ndarray
    last_beyond: np.ndarray
    returned: np.ndarray

    def __len__(self) -> int:
        return int(self.sign.size)

    @classmethod
    def concat(cls, parts: list[Excursions]) -> Excursions:
        names = cls.__dataclass_fields__
        return cls(**{k: np.concatenate([getattr(p, k) for p in parts]) for k in names})


def _excursions(t: _core.ExcursionTable) -> Excursions:
    """The binding's columns as :class:`Excursions`."""
    return Excursions(
        sign=t.sign,
        start=t.start,
        extreme=t.extreme,
        extreme_value=t.extreme_value,
        last_beyond=t.last_beyond,
        returned=t.returned,
    )


class ReversalDetector:
    """Streaming hysteresis-threshold detector.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.sin(np.linspace(0, 6.5 * np.pi, 651))
    >>> det = ReversalDetector(centre=0.0, threshold=0.5)
    >>> done = det.push(x[:300]); more = det.push(x[300:])
    >>> len(done) + len(more), len(det.open())
    (6, 1)
    """

    def __init__(self, centre: float, threshold: float) -> None:
        c, t = float(centre), float(threshold)
        if not np.isfinite(c):
            raise InputError(f"centre must be finite, got {centre}")
        if not (np.isfinite(t) and t > 0):
            raise InputError(f"threshold must be finite and > 0, got {threshold}")
        self._core = _core.ReversalDetector(c, t)

    def push(self, x: Any, value: Any = None, *, finite: bool = False) -> Excursions:
        """Excursions completed in the chunk ``x`` (``value``: where extremes are located,
        default ``x``; same length). ``finite``: the caller has checked ``x`` and ``value``
        finite, so they are not scanned again (a NaN or inf then only makes the excursions
        meaningless)."""
        xa = as_1d(x, "x", allow_empty=True, finite=False)
        va = None if value is None else as_1d(value, "value", allow_empty=True, finite=False)
        return _excursions(self._core.push(xa, va, finite))

    def open(self) -> Excursions:
        """The excursion in progress (0 or 1 rows)."""
        return _excursions(self._core.open())

    @property
    def count(self) -> int:
        """Samples pushed so far."""
        return int(self._core.count)


def excursions(
    x: Any, centre: float, threshold: float, value: Any = None, *, finite: bool = False
) -> Excursions:
    """All excursions of ``x``, the last (open) one included: one-shot :class:`ReversalDetector`
    (``finite``: as :meth:`ReversalDetector.push`)."""
    det = ReversalDetector(centre, threshold)
    return Excursions.concat([det.push(x, value, finite=finite), det.open()])


def branch_memory(x: Any) -> tuple[np.ndarray, np.ndarray]:
    """Per-sample branch bookkeeping of the Masing memory rules (history from the origin).

    ``anchor[i]``: sample index of the reversal the branch at sample ``i`` starts from (-1 on
    the virgin curve); ``target[i]``: index of the reversal it heads for, or ``-1 - j`` when
    it heads for the mirror ``-x[j]`` of the first reversal ``j``. The same rules and ties as
    :class:`contactlab.Masing`, from the core operator.
    """
    return _core.branch_memory(as_1d(x, "x", allow_empty=True, finite=False))
