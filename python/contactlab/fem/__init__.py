"""Joint characteristics for finite-element models, checked by running CalculiX.

From a ``contactlab analyze --json`` result: the normal joint as a pressure–overclosure table,
contact stiffness and damping per unit area; the tangential joint as a friction coefficient and
stick slope (elastic Coulomb), and amplitude-dependent spring/dashpot values for dynamics
(:func:`joint_characteristics`, :func:`render`, ``contactlab export``). Model builders
(:mod:`.models`), a CalculiX runner and ``.dat`` parser (:mod:`.ccx`) and the solver checks
(:mod:`.checks`) close the loop.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from .units import FORMATS, SYSTEMS, UnitSystem, unit_system

if TYPE_CHECKING:
    from .ccx import SolverError
    from .characteristics import (
        JointCharacteristics,
        NotIdentifiableError,
        Value,
        joint_characteristics,
        load_result,
    )
    from .writers import render, write

# The names below load on first use (PEP 562): the command line's parser imports
# `contactlab.fem.units` for `export --units`, which must not pull numpy, the Masing operator
# and the CalculiX helpers into every `contactlab --help`.
_LAZY = {
    "SolverError": "ccx",
    "JointCharacteristics": "characteristics",
    "NotIdentifiableError": "characteristics",
    "Value": "characteristics",
    "joint_characteristics": "characteristics",
    "load_result": "characteristics",
    "render": "writers",
    "write": "writers",
}


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value  # later look-ups skip __getattr__
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


__all__ = [
    "FORMATS",
    "SYSTEMS",
    "JointCharacteristics",
    "NotIdentifiableError",
    "SolverError",
    "UnitSystem",
    "Value",
    "joint_characteristics",
    "load_result",
    "render",
    "unit_system",
    "write",
]
