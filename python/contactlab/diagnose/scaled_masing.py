"""Non-Masing branch scaling that keeps the loops closed.

Masing's rule draws a branch from a reversal ``(x_r, h_r)`` as ``h_r + λ f((x - x_r)/λ)``
with ``λ = 2``. With ``λ ≠ 2`` that branch no longer meets the point where the memory rules
(PHYSICS.md §1, rules 3 and 4) say it must end, so an operator following those rules jumps
there (``Masing(h0, ac, scale=λ)`` does: force discontinuities of several percent of ``h0``
at every peak that exceeds the previous one by a rounding error, which makes such a model
unusable on noisy data). This module keeps the λ-scaled *shape* and anchors each branch at
both ends — the reversal it starts from and the target it is heading to (the reversal where
the interrupted branch began, or the mirrored extreme point on the virgin curve):

    h(x) = h_r + (h_t - h_r) · f((x - x_r)/λ) / f((x_t - x_r)/λ)

For ``λ = 2`` and Masing's own end points this is exactly Masing's branch, because then
``h_t - h_r = 2 f((x_t - x_r)/2)``. Other ``λ`` change the curvature of the branches and the
dissipated energy per loop (λ > 2: thinner loops, λ < 2: fatter) while keeping return-point
memory, odd symmetry and rate independence. The reversal/target bookkeeping depends only on
the displacement history, so it is computed once per signal.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..masing import Masing
from ..reversals import branch_memory


@dataclass(frozen=True)
class Memory:
    """Per-sample branch bookkeeping of a displacement history.

    ``anchor[i]``: sample index of the reversal the branch at sample ``i`` starts from
    (``-1``: on the virgin curve). ``target[i]``: sample index of the reversal it heads for,
    or ``-1 - j`` when it heads for the mirror ``-x[j]`` of the first reversal ``j`` on the
    virgin curve. ``runs``: start indices of runs of constant ``(anchor, target)``.
    """

    x: np.ndarray
    anchor: np.ndarray
    target: np.ndarray
    runs: np.ndarray


def memory(x: np.ndarray) -> Memory:
    """Reversal stack of Masing's rules with wiping out, sample by sample.

    The same rules, tie-breaking and start at the origin as :class:`contactlab.Masing`: the
    bookkeeping comes from the core operator itself (:func:`contactlab.reversals.branch_memory`).
    """
    x = np.ascontiguousarray(x, dtype=float)
    anchor, target = branch_memory(x)
    change = np.flatnonzero((np.diff(anchor) != 0) | (np.diff(target) != 0)) + 1
    return Memory(x, anchor, target, np.r_[0, change])


def scaled_force(virgin: Callable[[np.ndarray], np.ndarray], lam: float, mem: Memory) -> np.ndarray:
    """Force of the closed-loop λ-scaled Masing element along the history in ``mem``.

    Parameters
    ----------
    virgin : callable
        Odd virgin curve ``f(u)``, vectorised (e.g. ``Masing(h0, ac).virgin``).
    lam : float
        Branch scale λ > 0 (2 gives Masing's rule).
    mem : Memory
        From :func:`memory` of the displacement history.

    Examples
    --------
    >>> import numpy as np, contactlab
    >>> from contactlab.diagnose.scaled_masing import memory, scaled_force
    >>> x = 3e-5 * np.sin(np.linspace(0, 6 * np.pi, 301))
    >>> m = contactlab.Masing(50.0, 5e4)
    >>> bool(np.allclose(scaled_force(m.virgin, 2.0, memory(x)), m.force(x)))
    True
    """
    if not (np.isfinite(lam) and lam > 0):
        raise InputError(f"branch scale lam must be finite and > 0, got {lam}")
    model = getattr(virgin, "__self__", None)
    if isinstance(model, Masing) and getattr(virgin, "__func__", None) is Masing.virgin:
        # The core operator with branches anchored at both ends (BranchRule::Anchored): one
        # pass in Rust, the same memory rules as ``mem`` (which only depends on ``mem.x``).
        return _anchored(model, float(lam)).force(mem.x)
    return _scaled_force_python(virgin, float(lam), mem)


def _anchored(model: Masing, lam: float) -> Masing:
    """``model``'s virgin curve with branch scale ``lam`` and the anchored branch rule."""
    if model.is_exponential:
        m = Masing(model.h0, model.ac, scale=lam)
    else:
        m = Masing.from_backbone(*model._backbone, scale=lam)  # type: ignore[misc]
    m._core = m._core.fresh(anchored=True)
    return m


def _scaled_force_python(
    virgin: Callable[[np.ndarray], np.ndarray], lam: float, mem: Memory
) -> np.ndarray:
    """:func:`scaled_force` for any vectorised virgin curve (numpy, one loop step per branch)."""
    x = mem.x
    n = x.size
    anchor, target = mem.anchor, mem.target
    on_branch = anchor >= 0
    # The virgin curve is evaluated in three vectorised calls; only the end points of each
    # branch need the sequential pass below.
    xa = x[np.where(on_branch, anchor, 0)]
    mirror = target < 0
    xt = np.where(mirror, -x[np.clip(-1 - target, 0, n - 1)], x[np.clip(target, 0, n - 1)])
    f = virgin(np.concatenate([np.where(on_branch, (x - xa) / lam, x), (xt - xa) / lam, xt]))
    g, den, f_xt = f[:n], f[n : 2 * n], f[2 * n :]
    h = np.where(on_branch, 0.0, g)  # virgin-curve samples are final already
    starts = mem.runs
    ends = np.r_[starts[1:], n]
    hl = h  # local alias; the loop writes branch runs in time order
    for a, b in zip(starts.tolist(), ends.tolist(), strict=True):
        r = int(anchor[a])
        if r < 0:
            continue
        tg = int(target[a])
        hr = hl[r]
        ht = f_xt[a] if tg < 0 else hl[tg]
        dn = den[a]
        if dn == 0.0:
            hl[a:b] = hr
        else:
            hl[a:b] = hr + (ht - hr) / dn * g[a:b]
    return h
