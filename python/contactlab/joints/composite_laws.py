"""Compositions of joint laws: in series, in parallel (with a stiffness and a viscous
term), and behind a clearance (backlash)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, ClassVar

from ..errors import InputError
from . import _reference as ref
from .law_base import INF, JointLaw, ParamSpec, _nonneg
from .leaf_laws import KelvinVoigt


def _child_names(laws: Sequence[JointLaw]) -> list[str]:
    names = [law.name for law in laws]
    return [n if names.count(n) == 1 else f"{n}{i}" for i, n in enumerate(names)]


class _Composite(JointLaw):
    """Own parameters first, then each child's prefixed with ``<child>.``."""

    symmetric = True
    _OWN: ClassVar[tuple[ParamSpec, ...]] = ()
    laws: list[JointLaw]

    def _own(self) -> list[float]:
        return [getattr(self, s.name) for s in self._OWN]

    def _specs(self) -> list[ParamSpec]:
        out = list(self._OWN)
        for pre, law in zip(_child_names(self.laws), self.laws, strict=True):
            out += [
                ParamSpec(f"{pre}.{s.name}", s.unit, s.lo, s.hi, s.open_lo) for s in law._specs()
            ]
        return out

    def _values(self) -> list[float]:
        out = self._own()
        for law in self.laws:
            out += law._values()
        return out

    def spec(self) -> tuple[str, list[float], list[Any]]:
        return (self._kind(), [float(v) for v in self._own()], [law.spec() for law in self.laws])

    def _split(self, values: list[float]) -> tuple[list[float], list[JointLaw]]:
        n = len(self._OWN)
        own, rest = values[:n], values[n:]
        laws = []
        for law in self.laws:
            m = len(law._specs())
            laws.append(law._rebuild(rest[:m]))
            rest = rest[m:]
        return own, laws


def _as_law(law: Any, where: str) -> JointLaw:
    if isinstance(law, JointLaw):
        return law
    raise InputError(f"{where}: expected a joint law, got {type(law).__name__}")


class Series(_Composite):
    """Laws in series: the same force, displacements adding up (``x = Σ x_i``).

    The split is found at every sample by a bracketed root search on the force balance
    (the laws must have a non-decreasing force in their own displacement over a step).

    Parameters
    ----------
    *laws : JointLaw
        Two or more laws.
    """

    name = "series"

    def __init__(self, *laws: JointLaw) -> None:
        if len(laws) < 2:
            raise InputError("series: give two or more laws")
        self.laws = [_as_law(law, self.name) for law in laws]

    @property
    def symmetric(self) -> bool:  # type: ignore[override]
        return all(law.symmetric for law in self.laws)

    def _rebuild(self, values: list[float]) -> JointLaw:
        return Series(*self._split(values)[1])

    def _ref(self) -> ref.RefLaw:
        refs = [law._ref() for law in self.laws]
        out = refs[-1]
        for r in reversed(refs[:-1]):
            out = ref.RefSeries(r, out)
        return out


class Parallel(_Composite):
    """Laws in parallel with a linear stiffness and a viscous term.

    ``F = Σ F_i(x) + k (x - x0) + c ẋ``.

    Parameters
    ----------
    *laws : JointLaw
        Zero or more laws.
    k : float, default 0
        Parallel stiffness, N/m (>= 0).
    c : float, default 0
        Viscous coefficient, N s/m (>= 0).
    """

    name = "parallel"
    _OWN = (_nonneg("k", "N/m"), _nonneg("c", "N s/m"))

    def __init__(self, *laws: JointLaw, k: float = 0.0, c: float = 0.0) -> None:
        self.laws = [_as_law(law, self.name) for law in laws]
        self.k = self._OWN[0].check(k, self.name)
        self.c = self._OWN[1].check(c, self.name)

    @property
    def symmetric(self) -> bool:  # type: ignore[override]
        return all(law.symmetric for law in self.laws)

    def _rebuild(self, values: list[float]) -> JointLaw:
        own, laws = self._split(values)
        return Parallel(*laws, k=own[0], c=own[1])

    def _ref(self) -> ref.RefLaw:
        return ref.RefParallel([law._ref() for law in self.laws], self.k, self.c)


class Backlash(_Composite):
    """A clearance (dead band) of total width ``gap`` in series with a law.

    While the gap is open the force is 0; in contact the law is driven by ``x ∓ gap/2``.
    ``Backlash(gap, law)`` with a number for ``law`` uses a linear spring of that stiffness
    (a pure dead-zone spring).

    Parameters
    ----------
    gap : float
        Total free play, m (>= 0); the joint starts centred in it.
    law : JointLaw or float
        The law behind the clearance (or a contact stiffness, N/m).
    """

    name = "backlash"
    _OWN = (_nonneg("gap", "m"),)

    def __init__(self, gap: float, law: JointLaw | float | None = None) -> None:
        self.gap = self._OWN[0].check(gap, self.name)
        if law is None:
            raise InputError("backlash: give the law behind the clearance (or a contact stiffness)")
        if not isinstance(law, JointLaw):
            law = KelvinVoigt(ParamSpec("k", "N/m", 0.0, INF, True).check(law, self.name))
        self.laws = [law]

    @property
    def symmetric(self) -> bool:  # type: ignore[override]
        return self.laws[0].symmetric

    def _rebuild(self, values: list[float]) -> JointLaw:
        own, laws = self._split(values)
        return Backlash(own[0], laws[0])

    def _ref(self) -> ref.RefLaw:
        return ref.RefBacklash(self.gap, self.laws[0]._ref())
