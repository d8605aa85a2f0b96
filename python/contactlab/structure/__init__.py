"""Structures with hysteretic joints: simulate, find amplitude-dependent modal properties and
identify joints from input/response records (issue 10).

- :class:`Structure` (``M``, ``C``, ``K``) with :meth:`Structure.add_joint` (Masing,
  Jenkins, Iwan, Bouc-Wen, Kelvin-Voigt, nonlinear normal contact stiffness),
  :meth:`Structure.simulate` (Rust core: implicit Newmark with Newton on the joint forces) and
  :meth:`Structure.modes` (linearised natural frequencies, damping ratios, mode shapes);
- :func:`identify` (one or several DOFs), :func:`modal_amplitude_dependence` (each mode's
  frequency and damping ratio against amplitude, equivalent linearisation) and
  :func:`phase_resonance` (the same measured on a periodic steady state).
"""

from __future__ import annotations

from .._moved import forward
from .amplitude_mdof import (
    ModalAmplitudeDependence,
    PhaseResonance,
    modal_amplitude_dependence,
    phase_resonance,
)
from .identify import IdentifiedModel, identify
from .joints import Joint, iwan_uniform, make_joint
from .modal import Modes, modes
from .model import SimulationResult, Structure

__all__ = [
    "IdentifiedModel",
    "Joint",
    "ModalAmplitudeDependence",
    "Modes",
    "PhaseResonance",
    "SimulationResult",
    "Structure",
    "identify",
    "iwan_uniform",
    "make_joint",
    "modal_amplitude_dependence",
    "modes",
    "phase_resonance",
]

# moved to the report layer (issue 32): the old names warn and forward
__getattr__ = forward(
    __name__, {"plot_modal_amplitude_dependence": "contactlab.report.structure_plots"}
)
