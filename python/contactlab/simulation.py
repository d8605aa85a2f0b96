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

>>> from contactlab.normal import KelvinVoigt
>>> isinstance(KelvinVoigt(k=1e12, psi=0.2, omega=1.0), Simulator)
True
>>> isinstance(object(), Simulator)
False
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

from .errors import InputError

__all__ = ["Simulator", "simulate"]


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
