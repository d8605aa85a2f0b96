"""Common pieces of the candidate libraries: parameter specifications, candidate effects,
the prepared recording every candidate is evaluated on, and the model-family interface."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from ._signal import (
    Cycles,
    check_uniform,
    derivatives,
    dominant_period_samples,
    find_cycles,
    smooth_window,
)


@dataclass(frozen=True)
class ParamSpec:
    """One fitted parameter: bounds, the value meaning "effect absent" and its unit.

    ``scale`` names the typical magnitude (a key of :meth:`Family.scales`) used to
    normalise the optimisation variable.
    """

    name: str
    unit: str
    null: float
    lower: float
    upper: float
    scale: str


@dataclass(frozen=True)
class Candidate:
    """A physically meaningful extension of a base model with its own parameters."""

    name: str
    params: tuple[ParamSpec, ...]
    description: str


@dataclass
class Prepared:
    """A recording ready for model evaluation: input ``u`` (displacement x, or pressure p),
    output ``y`` (force F, or displacement δ), derivatives of ``u`` and the cycle split."""

    t: np.ndarray
    u: np.ndarray
    y: np.ndarray
    dt: float
    window: int
    ud: np.ndarray
    udd: np.ndarray
    cycles: Cycles
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def duration(self) -> float:
        return float(self.t[-1] - self.t[0])

    @classmethod
    def build(cls, t: np.ndarray, u: np.ndarray, y: np.ndarray | None = None) -> Prepared:
        dt = check_uniform(t)
        per = dominant_period_samples(u)
        window = smooth_window(per)
        ud, udd = derivatives(u, dt, window)
        cyc = find_cycles(u, per)
        yy = np.full_like(u, np.nan) if y is None else y
        return cls(t, u, yy, dt, window, ud, udd, cyc)


class Family(Protocol):
    """A base model with its library of candidate effects."""

    kind: str
    base_params: tuple[ParamSpec, ...]
    candidates: dict[str, Candidate]

    input_name: str
    output_name: str

    def prepare(self, d: Prepared) -> None: ...

    def context(self, d: Prepared) -> dict[str, float]: ...

    def check(self, effects: tuple[str, ...]) -> bool: ...

    def scales(self, d: Prepared) -> dict[str, float]: ...

    def loop_energy(self, u: np.ndarray, y: np.ndarray) -> float: ...

    def initial_base(self, d: Prepared) -> dict[str, float]: ...

    def predict(self, p: dict[str, float], effects: tuple[str, ...], d: Prepared) -> np.ndarray: ...

    def derived(
        self, p: dict[str, float], se: dict[str, float], effect: str
    ) -> tuple[dict[str, float], dict[str, float]]: ...

    def base_model(self, p: dict[str, float], context: dict[str, float]) -> Any: ...
