"""The friction coefficient μ = F/N of a tangential test that records its normal force.

A reciprocating tribometer (or a fretting rig) records the normal force ``N`` next to the
friction force ``F`` and the position ``x``. In gross sliding, the friction force of each
stroke levels off at a plateau: Coulomb's ``|F| = μ·N``. :func:`sliding_friction` measures
that plateau stroke by stroke, directly from the samples (no model fit): on each branch from
one reversal of ``x`` to the next, the samples of the last quarter of the stroke's travel
(the turn's dwell included) are the plateau when the force changes there by less than a
tenth of the branch's force swing (a pre-sliding loop, still curving at its turns, has no
plateau and gives no μ). Only loaded samples count (``N`` above half its largest value), so
the approach and unloading of the counter-body are left out.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .preprocess import find_reversals

#: the part of each stroke's travel, before the turn, taken as its plateau
TAIL = 0.25
#: a plateau: the force changes over the tail by less than this share of the branch's swing
FLAT = 0.1


@dataclass
class SlidingFriction:
    """μ from the sliding plateaus of a record (see :func:`sliding_friction`).

    Attributes
    ----------
    mu, mu_stderr : float or None
        Median of the strokes' ``|F|/N`` and its standard error (the strokes' scatter);
        None when not identifiable (``reason`` says why).
    normal_load : float or None
        Median normal force over the loaded samples, N.
    n_strokes : int
        Strokes that reached a plateau (of ``n_branches`` loaded branches).
    mu_up, mu_down : float or None
        Median ``|F|/N`` of the strokes towards larger and smaller ``x`` separately.
    """

    mu: float | None
    mu_stderr: float | None
    normal_load: float | None
    n_strokes: int
    n_branches: int
    mu_up: float | None = None
    mu_down: float | None = None
    reason: str = ""
    units: dict[str, str] = field(
        default_factory=lambda: {"mu": "1", "mu_stderr": "1", "normal_load": "N"}
    )

    def text(self) -> str:
        """``mu = 0.466 ± 0.002 (F/N of 98 sliding strokes at N = 5 N)`` or why not."""
        if self.mu is None:
            return f"mu not identifiable: {self.reason}"
        pm = f" ± {self.mu_stderr:.2g}" if self.mu_stderr is not None else ""
        return (
            f"mu = {self.mu:.4g}{pm} (F/N on the sliding plateau of {self.n_strokes} "
            f"stroke{'s' if self.n_strokes != 1 else ''}, N = {self.normal_load:.4g} N)"
        )

    def to_dict(self) -> dict[str, Any]:
        """``mu``, ``mu_stderr``, ``normal_load`` (None when not identifiable), counts, and
        ``mu_reason`` when μ is not identifiable."""
        d: dict[str, Any] = {
            "mu": self.mu,
            "mu_stderr": self.mu_stderr,
            "mu_up": self.mu_up,
            "mu_down": self.mu_down,
            "normal_load": self.normal_load,
            "mu_strokes": self.n_strokes,
        }
        if self.mu is None:
            d["mu_reason"] = f"not identifiable: {self.reason}"
        return d


def sliding_friction(
    t: np.ndarray,
    x: np.ndarray,
    F: np.ndarray,
    N: np.ndarray,
    *,
    tail: float = TAIL,
    flat: float = FLAT,
) -> SlidingFriction:
    """Friction coefficient μ = |F|/N on the sliding plateau of each stroke.

    Parameters
    ----------
    t, x, F, N : ndarray
        Time (s), position (m), friction force (N) and normal force (N), one sample each.
    tail : float
        Part of each stroke's travel, before its turn, taken as the plateau.
    flat : float
        The tail is a plateau when the force changes over it (a straight line fitted to F
        against x) by less than ``flat`` times the branch's force swing.

    Returns
    -------
    SlidingFriction

    Examples
    --------
    >>> import numpy as np
    >>> t = np.linspace(0, 4, 4001)
    >>> x = 1e-4 * np.sin(2 * np.pi * t)
    >>> F = np.zeros_like(x)                     # a Jenkins element: k = 1e6 N/m, slips at 2 N
    >>> for i in range(1, x.size):
    ...     F[i] = np.clip(F[i - 1] + 1e6 * (x[i] - x[i - 1]), -2.0, 2.0)
    >>> r = sliding_friction(t, x, F, np.full_like(t, 5.0))
    >>> round(r.mu, 3), r.n_strokes
    (0.4, 6)
    """
    t, x, F, N = (np.asarray(a, dtype=float) for a in (t, x, F, N))
    top = float(np.max(N)) if N.size else 0.0
    if not top > 0:
        return SlidingFriction(None, None, None, 0, 0, reason="the normal force is never positive")
    loaded = N > 0.5 * top
    normal_load = float(np.median(N[loaded]))
    rev = find_reversals(x, t)
    turns = np.unique(np.r_[rev.peaks, rev.valleys]).astype(np.int64)
    mus: list[float] = []
    up: list[float] = []
    down: list[float] = []
    branches = 0
    for a, b in itertools.pairwise(turns):
        if not loaded[a : b + 1].all():
            continue
        stroke = x[b] - x[a]
        if stroke == 0:
            continue
        branches += 1
        xs, fs_ = x[a : b + 1], F[a : b + 1]
        s = (xs - x[a]) / stroke  # 0 at the start of the stroke, 1 at its turn
        sel = s >= 1 - tail
        if np.count_nonzero(sel) < 3:
            continue
        swing = abs(F[b] - F[a])
        xt, ft = xs[sel], fs_[sel]
        span_x = float(np.ptp(xt))
        if not swing > 0 or span_x == 0:
            continue
        slope = np.polyfit(xt - xt.mean(), ft, 1)[0]
        if abs(slope) * span_x > flat * swing:
            continue  # still curving at the turn: no plateau
        mu = abs(float(np.mean(ft))) / float(np.mean(N[a : b + 1][sel]))
        mus.append(mu)
        (up if stroke > 0 else down).append(mu)
    if not mus:
        why = (
            "no loaded stroke between two reversals of x"
            if branches == 0
            else f"none of the {branches} loaded strokes reaches a sliding plateau (the force "
            f"still changes by more than {flat:.0%} of its swing over the last {tail:.0%} "
            "of the travel: pre-sliding, where F/N is not a friction coefficient)"
        )
        return SlidingFriction(None, None, normal_load, 0, branches, reason=why)
    m = np.asarray(mus)
    se = 1.2533 * float(np.std(m, ddof=1)) / np.sqrt(m.size) if m.size > 1 else None
    return SlidingFriction(
        float(np.median(m)),
        se,
        normal_load,
        int(m.size),
        branches,
        float(np.median(up)) if up else None,
        float(np.median(down)) if down else None,
        reason="" if se is not None else "one stroke: no scatter",
    )
