"""Tangential contact: Masing hysteresis with non-local memory.

Implements the pre-sliding friction model of *Experimental investigation of tangential contact
stiffness and equivalent damping* (Masing's rules with an exponential virgin curve and the
Madelung wiping-out rules), with the corrected formulas of PHYSICS.md §1:

- virgin curve ``f(u) = h0 (1 - exp(-ac u))``, odd-extended;
- branch from a reversal ``(x_r, h_r)``: ``h = h_r + λ f((x - x_r) / λ)``, ``λ = 2`` (Masing);
- energy per symmetric cycle ``E(A) = 8 [h0 (A - (1 - e^{-ac A}) / ac) - A f(A) / 2]``;
- equivalent damping ``c_e ω = E / (π A²)`` (eq. 17); local stiffness ``f'(x)`` (eq. 18);
  global stiffness ``f(x) / x`` (eq. 19).

The history-dependent work runs in the Rust core with the GIL released.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import _core
from ._arrays import as_1d, positive, restore, scalar_or_array
from .errors import ContactLabError, InputError


class Masing:
    """Masing hysteresis model ``h(x)`` with non-local memory.

    Parameters
    ----------
    h0 : float
        Saturation force (static friction limit), N.
    ac : float
        Curvature of the virgin curve, 1/m.
    scale : float, default 2.0
        Branch scale λ (2 is Masing's rule; other values give generalized Masing).

    Examples
    --------
    >>> import numpy as np, contactlab
    >>> m = contactlab.Masing(h0=10.0, ac=2e5)
    >>> x = 5e-6 * np.sin(np.linspace(0, 4 * np.pi, 401))
    >>> F = m.force(x)
    >>> round(float(m.loop_energy(5e-6)), 10) > 0
    True
    """

    def __init__(self, h0: float, ac: float, scale: float = 2.0) -> None:
        self.h0 = positive(h0, "h0")
        self.ac = positive(ac, "ac")
        self.scale = positive(scale, "scale")
        self._backbone: tuple[np.ndarray, np.ndarray] | None = None
        self._core = _core.MasingCore.exponential(self.h0, self.ac, self.scale)

    @classmethod
    def from_backbone(cls, x_points: Any, f_points: Any, scale: float = 2.0) -> Masing:
        """Masing model on a measured virgin curve.

        The points must start at the origin, with ``x`` strictly increasing and ``f``
        non-decreasing; they are joined by a monotone cubic (PCHIP), odd-extended, and
        continued with the end slope beyond the last point.
        """
        xp = as_1d(x_points, "x_points")
        fp = as_1d(f_points, "f_points")
        if xp.size != fp.size:
            raise InputError(f"x_points has {xp.size} points but f_points has {fp.size}")
        self = cls.__new__(cls)
        self.h0 = float("nan")
        self.ac = float("nan")
        self.scale = positive(scale, "scale")
        self._backbone = (xp.copy(), fp.copy())
        self._core = _core.MasingCore.tabulated(xp, fp, self.scale)
        return self

    # -- pickling: rebuild the Rust object from the parameters -------------------------------
    def __getstate__(self) -> dict[str, Any]:
        return {"h0": self.h0, "ac": self.ac, "scale": self.scale, "backbone": self._backbone}

    def __setstate__(self, st: dict[str, Any]) -> None:
        if st["backbone"] is None:
            self.__init__(st["h0"], st["ac"], st["scale"])  # type: ignore[misc]
        else:
            other = Masing.from_backbone(*st["backbone"], scale=st["scale"])
            self.__dict__.update(other.__dict__)

    def __repr__(self) -> str:
        if self._backbone is not None:
            return f"Masing.from_backbone(<{self._backbone[0].size} points>, scale={self.scale})"
        return f"Masing(h0={self.h0!r}, ac={self.ac!r}, scale={self.scale!r})"

    @property
    def is_exponential(self) -> bool:
        return self._backbone is None

    # -- history-dependent response --------------------------------------------------------
    def force(
        self,
        x: Any,
        state: Any = None,
        out: np.ndarray | None = None,
        threads: int | None = 1,
    ) -> np.ndarray:
        """Force for the displacement history ``x`` (starting at the origin unless ``state``).

        ``out``: a float64 array of the same length to write into (reused between calls, as a
        fit's model evaluations do); returned. ``threads``: Rust threads for one long record
        (``None``: every CPU; default 1, so that callers already running in parallel do not
        oversubscribe). From 2^17 samples on the record is then cut into pieces of 2^16 whose
        start states a comparisons-only pre-pass finds (costing 0.1-0.6 of the force
        kernel's CPU, by how often the input reverses), and the pieces share the threads;
        the forces are those of one thread bit for bit.
        """
        xa = as_1d(x, "x", finite=False)  # the core names a non-finite sample's index
        if state is not None:
            op = self.operator()
            op.state = state
            return op.push(xa, out=out, threads=_threads_for(threads))
        # a fresh core of its own (no other thread holds it: no borrow guard), pushed once:
        # what ``operator().push`` runs, without its wrappers (a fit evaluates the model on a
        # few hundred bins a dozen times a window, where they were half of each call)
        n_threads = _threads_for(threads)
        return self._core.fresh().push(xa, _out_buffer(out, xa.size), n_threads)

    def operator(self) -> MasingOperator:
        """A stateful operator for streaming a recording chunk by chunk."""
        return MasingOperator(self)

    def virgin(self, x: Any) -> Any:
        """Virgin curve ``f(x)``."""
        flat, sc = scalar_or_array(x, "x")
        return restore(self._core.backbone(flat), x, sc)

    # -- analytic quantities -------------------------------------------------------------------
    def loop_energy(self, A: Any) -> Any:
        """Energy dissipated per symmetric cycle of amplitude ``A`` (J when x in m, F in N).

        For ``scale = λ`` a closed loop of range ``2A`` dissipates ``2 λ² B(2A/λ)`` with ``B``
        the area between the virgin curve and its chord; ``λ = 2`` gives PHYSICS.md's E(A).
        """
        flat, sc = scalar_or_array(A, "A")
        lam = self.scale
        e = 2.0 * lam * lam * self._core.chord_area(np.ascontiguousarray(2.0 * np.abs(flat) / lam))
        return restore(e, A, sc)

    def equivalent_damping(self, A: Any) -> Any:
        """Equivalent viscous damping times frequency, ``c_e ω = E(A) / (π A²)`` (N/m)."""
        flat, sc = scalar_or_array(A, "A")
        e = np.asarray(self.loop_energy(flat), dtype=float)
        with np.errstate(divide="ignore", invalid="ignore"):
            c = np.where(flat == 0.0, 0.0, e / (np.pi * flat * flat))
        return restore(np.ascontiguousarray(c), A, sc)

    def local_stiffness(self, x: Any) -> Any:
        """Tangent stiffness of the virgin curve ``f'(x)`` (eq. 18), N/m."""
        flat, sc = scalar_or_array(x, "x")
        return restore(self._core.slope(flat), x, sc)

    def global_stiffness(self, x: Any) -> Any:
        """Secant stiffness ``f(x) / x`` (eq. 19), with its limit ``f'(0)`` at ``x = 0``."""
        flat, sc = scalar_or_array(x, "x")
        f = self._core.backbone(flat)
        k0 = self._core.slope(np.zeros(1))[0]
        with np.errstate(divide="ignore", invalid="ignore"):
            k = np.where(flat == 0.0, k0, f / np.where(flat == 0.0, 1.0, flat))
        return restore(np.ascontiguousarray(k), x, sc)


def _check_threads(threads: Any) -> int:
    if isinstance(threads, bool) or not (isinstance(threads, int | np.integer) and threads >= 1):
        raise InputError(f"threads must be an integer >= 1, got {threads!r}")
    return int(threads)


def _threads_for(threads: int | None) -> int:
    """``threads``, or every CPU for ``None``."""
    import os

    return (os.cpu_count() or 1) if threads is None else _check_threads(threads)


@contextlib.contextmanager
def _one_thread() -> Iterator[None]:
    """An operator is stateful: a second thread pushing while the first one is (the kernel
    runs without the GIL) finds it borrowed. Say so as a ContactLabError, not PyO3's bare
    ``RuntimeError: Already borrowed``."""
    try:
        yield
    except RuntimeError as exc:
        if "borrowed" not in str(exc):
            raise
        raise ContactLabError(
            "this MasingOperator is in use by another thread; it carries the loop memory "
            "of one recording: create one operator per thread with model.operator()"
        ) from None


class MasingOperator:
    """Stateful Masing operator: ``push`` chunks of a recording, the memory carries over.

    ``op.push(a); op.push(b)`` equals ``model.force(np.r_[a, b])`` bit for bit. The state
    (``op.state``, a float array) can be stored and restored; operators pickle.
    """

    def __init__(self, model: Masing) -> None:
        self.model = model
        self._core = model._core.fresh()

    def push(self, chunk: Any, out: np.ndarray | None = None, threads: int = 1) -> np.ndarray:
        """Forces for the next chunk of displacement samples (into ``out`` when given).

        ``threads`` > 1 splits a long chunk over that many Rust threads (see
        :meth:`Masing.force`); the result is the same bit for bit.
        """
        x = as_1d(chunk, "x", allow_empty=True, finite=False)
        threads = _check_threads(threads)
        with _one_thread():
            return self._core.push(x, _out_buffer(out, x.size), threads)

    def cycles(self, chunk: Any) -> CycleTable:
        """Closed cycles in the next chunk (advances the state like ``push``)."""
        x = as_1d(chunk, "x", allow_empty=True, finite=False)
        with _one_thread():
            c = self._core.cycles(x)
        return CycleTable(c.range, c.mean, c.start, c.end, c.count, c.energy)

    def reset(self) -> None:
        """Forget the history: back to the origin on the virgin curve."""
        self._core.reset()

    @property
    def state(self) -> np.ndarray:
        """``[x, h, direction, count, (x_r, h_r, index_r)...]`` — a copy."""
        return self._core.get_state()

    @state.setter
    def state(self, value: Any) -> None:
        self._core.set_state(as_1d(value, "state", finite=False))

    def __getstate__(self) -> dict[str, Any]:
        return {"model": self.model, "state": self.state}

    def __setstate__(self, st: dict[str, Any]) -> None:
        self.__init__(st["model"])  # type: ignore[misc]
        self.state = st["state"]

    # Analytic quantities of the underlying model, for convenience.
    def loop_energy(self, A: Any) -> Any:
        return self.model.loop_energy(A)

    def equivalent_damping(self, A: Any) -> Any:
        return self.model.equivalent_damping(A)

    def local_stiffness(self, x: Any) -> Any:
        return self.model.local_stiffness(x)

    def global_stiffness(self, x: Any) -> Any:
        return self.model.global_stiffness(x)


def _out_buffer(out: Any, n: int) -> np.ndarray | None:
    """Validate a caller's output buffer: float64, 1-D, C-contiguous, writeable, length n."""
    if out is None:
        return None
    if not (
        isinstance(out, np.ndarray)
        and out.dtype == np.float64
        and out.ndim == 1
        and out.flags.c_contiguous
        and out.flags.writeable
    ):
        raise InputError("out must be a writeable, contiguous 1-D float64 numpy array")
    if out.size != n:
        raise InputError(f"out has {out.size} samples but x has {n}")
    return out


#: the keys of each dict ``force_many(..., stats=)`` receives (the core's ``WorkerStats``)
_WORKER_STATS = ("jobs", "samples", "start", "end", "cpu", "wait", "prepass", "prepass_cpu")


def force_many(
    models: Any,
    signals: Any,
    threads: int | None = None,
    out: Any = None,
    stats: list[dict[str, Any]] | None = None,
) -> list[np.ndarray]:
    """Forces of several channels or recordings at once, on all cores.

    Each signal starts at the origin with its own model (one :class:`Masing` for all, or a
    sequence with one per signal). The work runs on ``threads`` Rust threads inside one call
    with the GIL released (default: the number of CPUs). Channels of 2^17 samples or more are
    cut into pieces of 2^16 whose start states a comparisons-only pre-pass finds (one channel
    per thread); then pieces and short channels are handed out one at a time from one queue,
    longest first, so that threads of unequal speed finish together. The forces are those of
    :meth:`Masing.force` on one thread, bit for bit.

    ``out``: a sequence of float64 arrays, one per signal and of its length, written in place
    and returned (reused between calls: fresh output pages cost the first touch, which on
    some machines rivals the kernel). ``stats``: a list that receives one dict per worker
    thread — ``jobs``, ``samples``, ``start`` and ``end`` (seconds since the call began),
    ``cpu`` (CPU seconds) and ``wait`` (seconds runnable but waiting for a CPU; both None
    where the system does not tell), ``prepass`` and ``prepass_cpu`` (the pre-pass's share
    of the wall and CPU seconds) — to see whether the split, the start or other load limits
    the scaling.

    Examples
    --------
    >>> import numpy as np, contactlab
    >>> x = [1e-5 * np.sin(np.linspace(0, 9, 500)) * k for k in (1, 2, 3)]
    >>> F = contactlab.force_many(contactlab.Masing(10.0, 2e5), x, threads=2)
    >>> bool(np.array_equal(F[1], contactlab.Masing(10.0, 2e5).force(x[1])))
    True
    """
    import os

    sigs = [
        as_1d(x, f"signals[{i}]", allow_empty=True, finite=False) for i, x in enumerate(signals)
    ]
    ms = [models] * len(sigs) if isinstance(models, Masing) else list(models)
    if len(ms) != len(sigs):
        raise InputError(f"{len(ms)} models but {len(sigs)} signals")
    for i, m in enumerate(ms):
        if not isinstance(m, Masing):
            raise InputError(f"models[{i}] must be a contactlab.Masing, got {type(m).__name__}")
    threads = (os.cpu_count() or 1) if threads is None else _check_threads(threads)
    outs = None
    if out is not None:
        outs = list(out)
        if len(outs) != len(sigs):
            raise InputError(f"{len(outs)} output arrays but {len(sigs)} signals")
        for i, (o, x) in enumerate(zip(outs, sigs, strict=True)):
            try:
                _out_buffer(o, x.size)
            except InputError as e:
                raise InputError(f"out[{i}]: {e}") from None
    if stats is not None and not isinstance(stats, list):
        raise InputError(f"stats must be a list to fill, got {type(stats).__name__}")
    res, per_thread = _core.force_many(
        [m._core for m in ms], sigs, int(threads), outs, stats is not None
    )
    if stats is not None:
        stats.extend({k: getattr(s, k) for k in _WORKER_STATS} for s in per_thread)
    return res


@dataclass(frozen=True)
class CycleTable:
    """Closed cycles of a signal (rainflow pairing by the Masing memory).

    ``count`` is 1 for a closed inner loop and 0.5 for a half cycle that rejoined the virgin
    curve; ``energy`` already includes the count. ``start``/``end`` are sample indices.
    """

    range: np.ndarray
    mean: np.ndarray
    start: np.ndarray
    end: np.ndarray
    count: np.ndarray
    energy: np.ndarray

    def __len__(self) -> int:
        return int(self.range.size)

    @property
    def total_energy(self) -> float:
        return float(np.sum(self.energy))

    def to_dict(self) -> dict[str, list[float] | list[int]]:
        return {k: getattr(self, k).tolist() for k in self.__dataclass_fields__}


def cycle_energies(x: Any, model: Masing) -> CycleTable:
    """Each closed cycle of ``x`` (history from the origin) with its dissipated energy.

    Cycles are paired the way rainflow counting pairs reversals; a closed Masing loop of range
    ``2a`` dissipates ``E(a)``. Over a stretch that returns the operator to its start state the
    energies add up to ``∮ F dx``.
    """
    if not isinstance(model, Masing):
        raise InputError(f"model must be a contactlab.Masing, got {type(model).__name__}")
    return model.operator().cycles(as_1d(x, "x"))


def loop_area(x: Any, F: Any) -> float:
    """``∮ F dx`` around the closed polygon through the samples (last joined to first).

    Positive for a clockwise (dissipative) loop. Computed with the mean force removed and
    compensated summation, so offsets in the data cost no accuracy.
    """
    xa = as_1d(x, "x")
    fa = as_1d(F, "F")
    if xa.size != fa.size:
        raise InputError(f"x has {xa.size} samples but F has {fa.size}")
    return float(_core.loop_area(xa, fa))


def loop_areas(x: Any, F: Any, bounds: Any) -> np.ndarray:
    """``∮ F dx`` of each cycle ``x[bounds[k]:bounds[k+1]]`` in one call.

    Each cycle is closed on itself (its last sample joined to its first) and computed as
    :func:`loop_area` computes a whole loop: mean force removed, compensated summation, exact
    power-of-two scaling. A cycle of fewer than 3 samples gives NaN.

    Parameters
    ----------
    x, F : array_like
        Displacement and force, 1-d, of equal length, finite.
    bounds : array_like of int
        Non-decreasing sample indices within ``[0, len(x)]``; ``k`` cycles need ``k + 1``.

    Returns
    -------
    numpy.ndarray
        The ``len(bounds) - 1`` loop areas (energy dissipated per cycle for a dissipative
        loop), in the units of ``F`` times those of ``x``.

    Raises
    ------
    InputError
        On arrays of unequal length, non-finite samples or bounds out of order or range.

    Examples
    --------
    >>> import numpy as np, contactlab
    >>> x = np.array([0.0, 0.0, 1.0, 1.0] * 2)
    >>> F = np.array([0.0, 1.0, 1.0, 0.0] * 2)
    >>> contactlab.loop_areas(x, F, [0, 4, 8]).tolist()
    [1.0, 1.0]
    """
    xa = as_1d(x, "x")
    fa = as_1d(F, "F")
    if xa.size != fa.size:
        raise InputError(f"x has {xa.size} samples but F has {fa.size}")
    b = np.asarray(bounds)
    if b.ndim != 1 or not (b.size == 0 or np.issubdtype(b.dtype, np.integer)):
        raise InputError("bounds must be a 1-d array of sample indices (integers)")
    if b.size and (b[0] < 0 or np.any(np.diff(b) < 0) or b[-1] > xa.size):
        raise InputError(f"bounds must be non-decreasing sample indices within [0, {xa.size}]")
    return np.asarray(_core.loop_areas(xa, fa, [int(v) for v in b]))
