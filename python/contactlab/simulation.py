"""One protocol for every model that turns a sampled input into a response (issue 32).

Four kinds of model simulate: the diagnosis's :class:`~contactlab.diagnose.ExtendedModel`
(output for an input ``u``), the normal-contact models
:class:`~contactlab.normal.KelvinVoigt` and :class:`~contactlab.normal.NonlinearContact`
(displacement for a pressure ``p``), a :class:`~contactlab.structure.Structure` and an
:class:`~contactlab.structure.IdentifiedModel` (response to a ``force`` or a ``base`` motion).
Each has ``simulate(t, <input>, ...)``: the sample times first, then the input sampled at
them, then keyword options of its own. :class:`Simulator` names that shape, so a function
can take "any model" (``isinstance(model, Simulator)`` at run time, or a type hint), and
:func:`simulate` calls it with the input given by name or position.

The results are typed objects with one shape, :class:`SimulatedResponse`: the sample times
``t``, the main ``response`` (δ of a normal model, ``x`` of a structure, the measured output
of a diagnosis model), and the solver's ``success``, ``status`` and ``message``. The normal
models' :class:`~contactlab.normal.OdeResult` and the structures'
:class:`~contactlab.structure.SimulationResult` have it themselves; :func:`simulate_response`
returns it for every model (a model that returns a bare array gets a :class:`Response`).

>>> from contactlab.normal import KelvinVoigt
>>> isinstance(KelvinVoigt(k=1e12, psi=0.2, omega=1.0), Simulator)
True
>>> isinstance(object(), Simulator)
False
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

from .errors import InputError

if TYPE_CHECKING:
    import numpy as np

__all__ = ["Response", "SimulatedResponse", "Simulator", "simulate", "simulate_response"]


@runtime_checkable
class Simulator(Protocol):
    """A model with ``simulate(t, *inputs, **options)``: the response to inputs sampled at
    the times ``t`` (SI units). The return value is the model's own: an array (diagnosis
    models) or a result object with the response as an attribute (``OdeResult.delta``,
    ``SimulationResult.x``)."""

    def simulate(self, t: Any, *inputs: Any, **options: Any) -> Any:
        """The response to ``inputs`` sampled at ``t``."""
        ...


def simulate(model: Any, t: Any, *inputs: Any, **options: Any) -> Any:
    """Run ``model.simulate(t, *inputs, **options)`` after checking that it is a simulator.

    Parameters
    ----------
    model : Simulator
        Any of the package's simulating models (see the module documentation).
    t : array_like
        Sample times (s).
    *inputs, **options
        The input(s) sampled at ``t`` and the model's own keyword options.

    Returns
    -------
    object
        What the model's ``simulate`` returns.

    Raises
    ------
    InputError
        When ``model`` has no ``simulate`` method.
    """
    if not isinstance(model, Simulator):
        raise InputError(f"{type(model).__name__} is not a simulator: it has no simulate(t, ...)")
    return model.simulate(t, *inputs, **options)


@runtime_checkable
class SimulatedResponse(Protocol):
    """The typed result of a simulation: times, the main response and the solver's verdict.

    ``t`` holds the samples reached (shorter than asked when ``success`` is False),
    ``response`` the model's main output at them (an array of ``len(t)`` rows), ``status`` 0
    on success.
    """

    t: np.ndarray
    success: bool
    status: int
    message: str

    @property
    def response(self) -> np.ndarray:
        """The main output at ``t``."""
        ...


@dataclass(frozen=True)
class Response:
    """A :class:`SimulatedResponse` for a model whose ``simulate`` returns a bare array.

    Attributes
    ----------
    t : ndarray
        Sample times (s).
    response : ndarray
        The model's output at ``t``.
    success, status, message
        Always ``True``, ``0`` and ``""``: such a model either returns every sample or raises.
    """

    t: np.ndarray
    response: np.ndarray
    success: bool = True
    status: int = 0
    message: str = ""


def simulate_response(model: Any, t: Any, *inputs: Any, **options: Any) -> SimulatedResponse:
    """Run :func:`simulate` and return its result as a :class:`SimulatedResponse`.

    Parameters
    ----------
    model : Simulator
        Any of the package's simulating models.
    t : array_like
        Sample times (s).
    *inputs, **options
        The input(s) sampled at ``t`` and the model's own keyword options.

    Returns
    -------
    SimulatedResponse
        The model's own result object where it has that shape (``OdeResult``,
        ``SimulationResult``), else a :class:`Response` around the returned array.

    Raises
    ------
    InputError
        When ``model`` has no ``simulate`` method.
    """
    import numpy as np  # the protocol itself loads no numpy

    out = simulate(model, t, *inputs, **options)
    if isinstance(out, SimulatedResponse):
        return out
    return Response(np.asarray(t, dtype=float), np.asarray(out))
