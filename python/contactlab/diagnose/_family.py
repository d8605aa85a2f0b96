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
    filter_input,
    find_cycles,
    input_noise,
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
    def build(
        cls,
        t: np.ndarray,
        u: np.ndarray,
        y: np.ndarray | None = None,
        *,
        errors_in_input: bool = True,
    ) -> Prepared:
        """Checks, derivatives and cycles of a recording.

        Errors in variables: with ``errors_in_input`` the input's sensor noise ``σu`` is
        estimated from the data (:func:`input_noise`) and every candidate sees the same
        zero-phase filtered input (:func:`filter_input`), so that no candidate can lower the
        error by smoothing the input itself (a fractional delay interpolates between
        samples and would). ``extra`` records ``u_noise`` (σu), ``u_filter`` (the
        window, samples; 0 when the input is used as measured) and ``u_raw``.
        """
        dt = check_uniform(t)
        per = dominant_period_samples(u)
        window = smooth_window(per)
        ud, udd = derivatives(u, dt, window)
        cyc = find_cycles(u, per)
        yy = np.full_like(u, np.nan) if y is None else y
        extra: dict[str, Any] = {"u_raw": u, "u_noise": 0.0, "u_filter": 0}
        uf = u
        if errors_in_input:
            sig = input_noise(u)
            extra["u_noise"] = sig
            uf, extra["u_filter"] = filter_input(u, per, sig)
        return cls(t, uf, yy, dt, window, ud, udd, cyc, extra)


#: largest plausible channel delay, as a fraction of the excitation period (both families'
#: ``channel_delay`` effects, :mod:`contactlab.diagnose.effects`): anti-alias
#: filters and converters of a test rig skew channels by a few samples, which at any sensible
#: sampling rate is well below 2 % of a period (7°); a larger "delay" is a model error.
MAX_DELAY_FRACTION = 0.02


class Family(Protocol):
    """A base model with its library of candidate effects."""

    kind: str
    base_params: tuple[ParamSpec, ...]
    candidates: dict[str, Candidate]

    input_name: str
    output_name: str
    input_unit: str
    output_unit: str

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

    def slope(self, p: dict[str, float], d: Prepared) -> np.ndarray | None: ...

    def implausible(self, name: str, p: dict[str, float], d: Prepared) -> str | None: ...

    def regime(self, p: dict[str, float], d: Prepared) -> str | None: ...
