"""Structures with hysteretic joints: simulate, find amplitude-dependent modal properties and
identify joints from input/response records (issue 10).

- :class:`Structure` (``M``, ``C``, ``K``) with :meth:`Structure.add_joint` (Masing,
  Jenkins, Iwan, Bouc-Wen, Kelvin-Voigt, nonlinear normal contact stiffness),
  :meth:`Structure.simulate` (Rust core: implicit Newmark with Newton on the joint forces) and
  :meth:`Structure.modes` (linearised natural frequencies, damping ratios, mode shapes).
"""

from __future__ import annotations

from .identify import IdentifiedModel, identify
from .joints import Joint, iwan_uniform, make_joint
from .modal import Modes, modes
from .model import SimulationResult, Structure

__all__ = [
    "IdentifiedModel",
    "Joint",
    "Modes",
    "SimulationResult",
    "Structure",
    "identify",
    "iwan_uniform",
    "make_joint",
    "modes",
]
