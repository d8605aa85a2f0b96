"""The interface every joint law shares (:class:`JointLaw`, :class:`JointOperator`) and the
parameter description (:class:`ParamSpec`); the laws are in :mod:`.leaf_laws` and
:mod:`.composite_laws`, the registry in :mod:`.laws`."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from ..errors import InputError
from . import _reference as ref

INF = math.inf


@dataclass(frozen=True)
class ParamSpec:
    """One scalar parameter: name, unit, bounds, and whether the lower bound is excluded."""

    name: str
    unit: str
    lo: float = -INF
    hi: float = INF
    open_lo: bool = False

    def check(self, value: Any, where: str) -> float:
        try:
            v = float(value)
        except (TypeError, ValueError):
            raise InputError(
                f"{where}: parameter {self.name} must be a number, got {value!r}"
            ) from None
        if not math.isfinite(v):
            raise InputError(f"{where}: parameter {self.name} is not finite ({v})")
        if v < self.lo or (self.open_lo and v == self.lo) or v > self.hi:
            lo = "(" if self.open_lo else "["
            raise InputError(
                f"{where}: parameter {self.name} = {v} is outside {lo}{self.lo}, {self.hi}]"
            )
        return v


def _pos(name: str, unit: str) -> ParamSpec:
    return ParamSpec(name, unit, 0.0, INF, True)


def _nonneg(name: str, unit: str) -> ParamSpec:
    return ParamSpec(name, unit, 0.0, INF, False)


def _array(v: Any, name: str, where: str) -> np.ndarray:
    try:
        a = np.ascontiguousarray(np.asarray(v, dtype=float).reshape(-1))
    except (TypeError, ValueError):
        raise InputError(f"{where}: {name} must be an array of numbers") from None
    if a.size == 0:
        raise InputError(f"{where}: {name} is empty")
    return a


def _check_series(name: str, a: Any, n: int | None = None) -> np.ndarray:
    try:
        arr = np.asarray(a)
        if np.iscomplexobj(arr):
            raise InputError(f"{name} is complex; pass a real array")
        arr = np.ascontiguousarray(arr, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} cannot be converted to a float array: {exc}") from None
    if arr.ndim != 1:
        raise InputError(f"{name} must be 1-D, got an array of shape {arr.shape}")
    if n is not None and arr.size != n:
        raise InputError(f"{name} has {arr.size} samples but x has {n}")
    bad = ~np.isfinite(arr)
    if bad.any():
        i = int(np.argmax(bad))
        raise InputError(f"{name}[{i}] is not finite ({arr[i]})")
    return arr


def _check_time(t: np.ndarray, t_prev: float | None) -> None:
    if t.size > 1:
        d = np.diff(t)
        bad = ~(d > 0)
        if bad.any():
            i = int(np.argmax(bad)) + 1
            raise InputError(
                f"t must be strictly increasing, but t[{i}] = {t[i]} does not exceed "
                f"t[{i - 1}] = {t[i - 1]}"
            )
    if t.size and t_prev is not None and not t[0] > t_prev:
        raise InputError(
            f"t must be strictly increasing across chunks, but t[0] = {t[0]} does not exceed "
            f"the previous chunk's last time {t_prev}"
        )


class JointLaw:
    """Base class of the displacement-driven joint laws (see the module docstring)."""

    #: Registry name of the law.
    name: ClassVar[str] = ""
    #: True when the law is odd: ``F(-x) = -F(x)`` for any history from the relaxed state.
    symmetric: ClassVar[bool] = True

    # -- parameters ---------------------------------------------------------------------
    def _specs(self) -> list[ParamSpec]:
        raise NotImplementedError

    def _values(self) -> list[float]:
        raise NotImplementedError

    def _rebuild(self, values: list[float]) -> JointLaw:
        raise NotImplementedError

    @property
    def param_names(self) -> tuple[str, ...]:
        """Names of the parameters, in the order of :attr:`vector`."""
        return tuple(s.name for s in self._specs())

    @property
    def params(self) -> dict[str, float]:
        """Parameter values by name."""
        return dict(zip(self.param_names, self._values(), strict=True))

    @property
    def vector(self) -> np.ndarray:
        """Parameter values as a float array in the order of :attr:`param_names`."""
        return np.array(self._values(), dtype=float)

    @property
    def units(self) -> dict[str, str]:
        """Unit of each parameter (SI; ``""`` for a dimensionless one)."""
        return {s.name: s.unit for s in self._specs()}

    @property
    def bounds(self) -> dict[str, tuple[float, float]]:
        """``(lo, hi)`` of each parameter (a positive parameter has ``lo = 0`` excluded)."""
        return {s.name: (s.lo, s.hi) for s in self._specs()}

    def with_params(self, values: Sequence[float] | np.ndarray | Mapping[str, float]) -> JointLaw:
        """A copy of this law with new parameter values.

        Parameters
        ----------
        values : array-like or mapping
            A full vector in the order of :attr:`param_names`, or a mapping of some names to
            new values (the others are kept).

        Returns
        -------
        JointLaw
            The new law (this one is unchanged).
        """
        names = self.param_names
        if isinstance(values, Mapping):
            unknown = [k for k in values if k not in names]
            if unknown:
                raise InputError(
                    f"{self.name}: unknown parameter(s) {', '.join(map(str, unknown))}; "
                    f"it has {', '.join(names)}"
                )
            cur = self.params
            cur.update({k: values[k] for k in values})
            vec = [cur[n] for n in names]
        else:
            arr = np.asarray(values, dtype=float).reshape(-1)
            if arr.size != len(names):
                raise InputError(
                    f"{self.name}: {arr.size} parameter values given for {len(names)} "
                    f"parameters ({', '.join(names)})"
                )
            vec = [float(v) for v in arr]
        checked = [s.check(v, self.name) for s, v in zip(self._specs(), vec, strict=True)]
        return self._rebuild(checked)

    # -- behaviour ----------------------------------------------------------------------
    @property
    def rate_dependent(self) -> bool:
        """True when the force depends on the velocity (``t`` is then required)."""
        return self._ref().rate_dependent

    def _ref(self) -> ref.RefLaw:
        """The plain-Python reference of this law (tests, and the fallback kernel)."""
        raise NotImplementedError

    def spec(self) -> tuple[str, list[float], list[Any]]:
        """``(kind, own parameters, children)``: the description the Rust core builds the law
        from (children: the specs of the laws a composite holds); :func:`from_spec` inverts
        it."""
        return (self._kind(), [float(v) for v in self._values()], [])

    def _kind(self) -> str:
        """Registry name of the nearest registered class (a subclass with a name of its own
        runs on its parent's kernel)."""
        for cls in type(self).__mro__:
            if REGISTRY.get(getattr(cls, "name", "")) is cls:
                return cls.name
        raise InputError(f"{self.name}: not derived from a registered joint law")

    @property
    def initial_stiffness(self) -> float:
        """Tangent stiffness from the relaxed state, N/m (0 for a law behind an open gap)."""
        return REGISTRY_HOOKS["initial_stiffness"](self)

    def _kernel(self, x0: float) -> Any:
        """The Rust operator of this law, relaxed at ``x0``."""
        from .. import _core

        return _core.JointOperatorCore(self.spec(), x0)

    def operator(self, x0: float = 0.0) -> JointOperator:
        """A stateful operator for a recording streamed in chunks.

        Parameters
        ----------
        x0 : float, default 0.0
            Displacement at which the joint starts relaxed (force 0, no history).

        Returns
        -------
        JointOperator
            ``op.push(t_chunk, x_chunk)`` returns the forces of the chunk.
        """
        return JointOperator(self, x0)

    def force(self, t: Any, x: Any, x0: float = 0.0) -> np.ndarray:
        """Force for the displacement history ``x`` sampled at times ``t``.

        Parameters
        ----------
        t : array-like or None
            Sample times, s, strictly increasing (None for a rate-independent law).
        x : array-like
            Displacement, m.
        x0 : float, default 0.0
            Displacement at which the joint starts relaxed.

        Returns
        -------
        numpy.ndarray
            Force, N, one value per sample.
        """
        return self.operator(x0).push(t, x)

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.params.items())
        return f"{type(self).__name__}({args})"

    def __eq__(self, other: object) -> bool:
        return (
            type(other) is type(self)
            and isinstance(other, JointLaw)
            and other.param_names == self.param_names
            and bool(np.array_equal(other.vector, self.vector))
        )

    __hash__ = None  # type: ignore[assignment]


class JointOperator:
    """A law with its carried state; see :meth:`JointLaw.operator`."""

    def __init__(self, law: JointLaw, x0: float = 0.0) -> None:
        self.law = law
        self.x0 = ParamSpec("x0", "m").check(x0, law.name)
        self.reset()

    def reset(self) -> None:
        """Back to the relaxed state at ``x0``."""
        self._kernel = self.law._kernel(self.x0)
        self._t_prev: float | None = None
        self._started = False

    def push(self, t: Any, x: Any) -> np.ndarray:
        """Forces for the next chunk ``(t, x)``, continuing the carried history.

        Parameters
        ----------
        t : array-like or None
            Times of the chunk, s (strictly increasing, after the previous chunk's), or None
            for a rate-independent law.
        x : array-like
            Displacement of the chunk, m.

        Returns
        -------
        numpy.ndarray
            Force, N.
        """
        xa = _check_series("x", x)
        if t is None:
            if self.law.rate_dependent:
                raise InputError(f"{self.law.name} is rate-dependent: pass the sample times t")
            if self._t_prev is not None:
                raise InputError("t was given for an earlier chunk: pass it for every chunk")
            ta = None
        else:
            ta = _check_series("t", t, xa.size)
            if self._started and self._t_prev is None:
                raise InputError("t was None for an earlier chunk: pass None for every chunk")
            _check_time(ta, self._t_prev)
        out = self._kernel.push(ta, xa)
        self._started = True
        if ta is not None and ta.size:
            self._t_prev = float(ta[-1])
        return out


#: the registry of :mod:`.laws` (name -> class), filled when it is imported (the laws are
#: defined in modules that import this one)
REGISTRY: dict[str, type[JointLaw]] = {}
#: functions over every law that :mod:`.laws` defines: ``initial_stiffness``
REGISTRY_HOOKS: dict[str, Any] = {}
