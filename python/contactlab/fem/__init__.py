"""Joint characteristics for finite-element models, checked by running CalculiX.

From a ``contactlab analyze --json`` result: the normal joint as a pressure–overclosure table,
contact stiffness and damping per unit area; the tangential joint as a friction coefficient and
stick slope (elastic Coulomb), and amplitude-dependent spring/dashpot values for dynamics
(:func:`joint_characteristics`, :func:`render`, ``contactlab export``). Model builders
(:mod:`.models`), a CalculiX runner and ``.dat`` parser (:mod:`.ccx`) and the solver checks
(:mod:`.checks`) close the loop.
"""

from __future__ import annotations

from .ccx import SolverError
from .characteristics import (
    JointCharacteristics,
    NotIdentifiableError,
    Value,
    joint_characteristics,
    load_result,
)
from .units import SYSTEMS, UnitSystem, unit_system
from .writers import FORMATS, render, write

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
