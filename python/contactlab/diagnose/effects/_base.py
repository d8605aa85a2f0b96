"""The effect interface and its registry (see the package docstring)."""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from .._family import Candidate, ParamSpec, Prepared

#: the families that have effects, and the subpackage each one's effects live in
KINDS = ("tangential", "normal")

#: order of composition of the tangential effects (their ``stage``): the displacement the
#: contact sees; the element (a series spring reshaping it; then one element law replacing
#: the exponential Masing element); terms on the element's force; the breakaway after each
#: reversal; factors on the friction force; terms added to it; the measurement of the sum
TANGENTIAL_STAGES = (
    "input", "element_input", "core", "element", "element_force", "branch", "factor",
    "additive", "output",
)  # fmt: skip
#: the normal-contact stages: the stiffness law's coefficients, an element replacing the
#: Kelvin-Voigt solve, a loss that depends on the joint's own rate (solved again with it),
#: terms added to the displacement, the measurement
NORMAL_STAGES = ("law", "element", "loss", "additive", "output")


@dataclass
class Plausibility:
    """Whether a fitted effect is physically plausible on this record, and why.

    ``ok`` False refuses the effect (it is then not named); the ``reason`` is reported
    either way: for a named effect it is the physical argument for it, in numbers."""

    ok: bool
    reason: str

    def __iter__(self) -> Any:  # ``ok, why = effect.plausible(...)``
        return iter((self.ok, self.reason))


@dataclass
class ForceContext:
    """What a tangential effect's :meth:`EffectModel.apply` sees besides the value it acts
    on: the record ``d``, the displacement the contact sees ``x`` (full record), the one the
    element runs over ``xm`` (the kept record's merged turning points, or a span of it),
    the span ``sp`` (None: the whole record), the rows asked for (``rows``; None: all) and
    the element's core (a :class:`~contactlab.masing.Masing`, once the ``core`` stage set
    one)."""

    d: Prepared
    effects: tuple[str, ...]
    x: np.ndarray
    xm: np.ndarray
    x0: float | None
    sp: Any = None
    at: np.ndarray | None = None
    rows: np.ndarray | None = None
    core: Any = None
    scratch: dict[str, Any] = field(default_factory=dict)

    def pick(self, a: np.ndarray) -> np.ndarray:
        """``a`` (one value per sample of the record) at the rows asked for."""
        return a if self.rows is None else a[self.rows]

    def fixed(self, key: str, make: Callable[[], Any]) -> Any:
        """An array that depends on the recording only, computed once per record."""
        cache = self.d.extra.setdefault("fixed", {})
        k = (key, self.d.t.size)
        if k not in cache:
            cache[k] = make()
        return cache[k]

    @property
    def t_rel(self) -> np.ndarray:
        """Time from the record's start at the samples the element runs over."""
        if self.sp is None:
            return self.fixed("t_rel", lambda: self.d.t - self.d.t[0])
        return self.sp.t - self.d.t[0]

    @property
    def period(self) -> float:
        return float(self.d.cycles.period_samples * self.d.dt)


class EffectModel:
    """One candidate effect: its physics, parameters and bounds, what it does to the base
    model's prediction (:meth:`apply`), whether a fitted value is physically plausible on a
    record (:meth:`plausible`) and the smallest size a record would reveal
    (:meth:`detectable`).

    Subclasses set the class attributes and are registered with :func:`register`; the
    family composes the effects of a model in the order of their ``stage``
    (:data:`TANGENTIAL_STAGES`, :data:`NORMAL_STAGES`), then ``rank``.
    """

    name: ClassVar[str]
    kind: ClassVar[str]
    params: ClassVar[tuple[ParamSpec, ...]]
    description: ClassVar[str]
    #: the physics the effect models, in one paragraph (the report and the docs quote it)
    physics: ClassVar[str] = ""
    #: effects that act through the same signal are told apart only when each is needed
    #: beside the other: "velocity" (delay, viscous damping, Stribeck, inertia: a term in
    #: ẋ or ẍ, or a shift of the force along the velocity), "friction along the branch"
    #: (Stribeck, position friction, stick-slip: a reshaping of the friction force between
    #: reversals); a tuple for an effect in several — see the search's parsimony rule
    acts_through: ClassVar[str | tuple[str, ...] | None] = None
    stage: ClassVar[str]
    rank: ClassVar[float] = 0.0
    #: position in the library (the order verdicts are listed and ties are broken in)
    order: ClassVar[int] = 100
    #: the parameter that measures the effect's size (for :meth:`detectable`)
    size_param: ClassVar[str | None] = None

    @property
    def candidate(self) -> Candidate:
        return Candidate(self.name, self.params, self.description)

    def apply(self, value: Any, p: dict[str, float], ctx: Any) -> Any:
        """What the effect does to the base model's prediction (or input) at its stage."""
        raise NotImplementedError(f"{self.name}: apply at stage {self.stage}")

    def start(
        self, p: dict[str, float], d: Prepared, residual: np.ndarray, family: Any = None
    ) -> dict[str, float]:
        """Starting values of the nonlinear parameters from the current residual (``family``:
        the model family asking, for effects that need its base prediction)."""
        return {}

    def derived(
        self, p: dict[str, float], se: dict[str, float], **more: Any
    ) -> tuple[dict[str, float], dict[str, float]]:
        """Extra reported quantities, with their standard errors."""
        return {}, {}

    def plausible(self, recording: Prepared, p: dict[str, float]) -> Plausibility:
        """Whether the fitted parameters ``p`` are physically plausible on ``recording``
        (the record as the diagnosis prepared it; ``recording.extra["meta"]`` holds the
        recording's own meta: a force reconstructed from the displacement, a frame), and
        the argument in numbers. The base class checks the shared rules: finite values,
        not at the edge of the physical range."""
        for s in self.params:
            v = p[s.name]
            if not np.isfinite(v):
                return Plausibility(False, f"{s.name} is not finite")
            span = s.upper - s.lower if np.isfinite(s.upper - s.lower) else None
            for bound in (s.lower, s.upper):
                if (
                    np.isfinite(bound)
                    and span
                    and abs(v - bound) <= 1e-3 * span
                    and bound != s.null
                ):
                    return Plausibility(
                        False,
                        f"{s.name} = {v:.4g} {s.unit} sits at the limit of its physical range",
                    )
        return Plausibility(True, self.argument(recording, p))

    def base_equivalent(self, p: dict[str, float]) -> dict[str, float]:
        """The base parameters this effect's model is equivalent to, where it rescales the
        base (a branch scale λ: loops of a Masing element with ``h0 λ / 2``); empty when it
        does not. The search compares these, not the raw values, with the base fit."""
        return {}

    #: a named effect's size must lie this many standard errors from "absent"
    IDENTIFIED_SIGMAS: ClassVar[float] = 2.0

    def size(self, p: dict[str, float], se: dict[str, float]) -> tuple[float, float]:
        """The effect's size (distance of ``size_param`` from its null) and its standard
        error; effects with several amplitude parameters combine them."""
        s = next((q for q in self.params if q.name == self.size_param), self.params[0])
        null = s.null if np.isfinite(s.null) else 0.0
        return abs(p[s.name] - null), float(se.get(s.name, np.inf))

    def identified(self, p: dict[str, float], se: dict[str, float]) -> str | None:
        """Why the fitted effect is not identified (its size within
        :attr:`IDENTIFIED_SIGMAS` standard errors of "absent": its parameters trade off with
        the others', and the held-out gain it brings is not its own), or None."""
        v, e = self.size(p, se)
        if np.isfinite(e) and v < self.IDENTIFIED_SIGMAS * e:
            return (
                f"not identifiable: its size {v:.3g} ± {e:.2g} is within "
                f"{self.IDENTIFIED_SIGMAS:g} standard errors of no effect (its parameters "
                "trade off with the others')"
            )
        return None

    def argument(self, recording: Prepared, p: dict[str, float]) -> str:
        """The physical argument for a plausible fitted effect, in numbers."""
        vals = ", ".join(f"{s.name} = {p[s.name]:.4g} {s.unit}" for s in self.params)
        return f"{vals}: within the physical range of {self.description}"

    def detectable(self, recording: Any) -> Any:
        """The smallest size of this effect that ``recording`` would reveal at 95 % power
        and the calibrated false-alarm rate, in the effect's own unit (a
        :class:`contactlab.diagnose.power.Detectable`).

        ``recording``: the :class:`~contactlab.diagnose.DiagnosisReport` of the record (the
        bound for its final model and data). Delegates to
        :func:`contactlab.diagnose.power.stated_power` (issue 29 item 2); raises
        :class:`NotImplementedError` where that module is not installed."""
        try:
            power = importlib.import_module(f"{__package__.rsplit('.', 1)[0]}.power")
        except ImportError:
            raise NotImplementedError(
                "detectable() needs contactlab.diagnose.power (the stated-power module)"
            ) from None
        report = recording
        if not hasattr(report, "final_model"):
            raise TypeError(
                f"{self.name}.detectable() takes the DiagnosisReport of the record "
                "(contactlab.diagnose(recording)), which holds the data and the fitted model"
            )
        if self.name in report.effect_names:
            raise ValueError(f"{self.name} is named by this diagnosis: it was detected")
        for bound in power.stated_power(report):
            if bound.effect == self.name:
                return bound
        raise ValueError(f"{self.name}: no bound stated for this record")

    def __repr__(self) -> str:
        ps = ", ".join(f"{s.name} [{s.unit}]" for s in self.params)
        return f"<{self.kind} effect {self.name}: {ps}>"


_REGISTRY: dict[str, dict[str, EffectModel]] = {k: {} for k in KINDS}
_LOADED: set[str] = set()


def register(cls: type[EffectModel]) -> type[EffectModel]:
    """Class decorator: add one instance of the effect to its family's registry."""
    if cls.kind not in _REGISTRY:
        raise ValueError(f"{cls.__name__}: unknown kind {cls.kind!r}")
    stages = TANGENTIAL_STAGES if cls.kind == "tangential" else NORMAL_STAGES
    if cls.stage not in stages:
        raise ValueError(f"{cls.__name__}: unknown stage {cls.stage!r} for {cls.kind}")
    _REGISTRY[cls.kind][cls.name] = cls()
    return cls


def registry(kind: str) -> dict[str, EffectModel]:
    """The effects of one family, ``name -> effect``, in library order. Every module of
    ``contactlab.diagnose.effects.<kind>`` is imported on first use: a new effect is one
    new file there."""
    if kind not in _REGISTRY:
        raise KeyError(kind)
    if kind not in _LOADED:
        pkg = importlib.import_module(f"{__package__}.{kind}")
        for mod in pkgutil.iter_modules(pkg.__path__):
            if not mod.name.startswith("_"):
                importlib.import_module(f"{pkg.__name__}.{mod.name}")
        _LOADED.add(kind)
    found = _REGISTRY[kind]
    return dict(sorted(found.items(), key=lambda kv: (kv[1].order, kv[0])))


def ordered(kind: str, effects: tuple[str, ...]) -> list[EffectModel]:
    """The effects of a model in their order of composition (stage, then rank)."""
    reg = registry(kind)
    stages = TANGENTIAL_STAGES if kind == "tangential" else NORMAL_STAGES
    chosen = [reg[e] for e in effects]
    return sorted(chosen, key=lambda e: (stages.index(e.stage), e.rank))
