"""Normal contact of machined joints: loop analysis, Kelvin-Voigt and nonlinear models.

Implements Konowalski (2009), *Experimental research and modeling of normal contact stiffness
and contact damping of machined joint surfaces* (PHYSICS.md §2): loop polynomials (eq. 1),
energies and dissipation coefficients (eqs. 3, 7), stiffnesses (eqs. 4-6, 16), the linear
Kelvin-Voigt model (eqs. 8-15) and the nonlinear model (eq. 17), with the comparison of
models and measurement of the paper's Figs. 9-12.

SI units throughout (Pa, m, J/m², Pa/m); the paper's MPa and µm only for display.
"""

from __future__ import annotations

from ._paper import TABLE2_MPA_UM
from .compare import (
    Comparison,
    compare,
    plot_comparison,
    plot_displacement,
    plot_loops,
    plot_phase_portrait,
    plot_velocity,
)
from .loop import LoopResult, analyze_loop
from .models import KelvinVoigt, NonlinearContact, OdeResult
from .stiffness import PressureStiffnessFit, fit_pressure_stiffness
from .synthetic import synthetic_recording, table2_model, table2_psi

__all__ = [
    "TABLE2_MPA_UM",
    "Comparison",
    "KelvinVoigt",
    "LoopResult",
    "NonlinearContact",
    "OdeResult",
    "PressureStiffnessFit",
    "analyze_loop",
    "compare",
    "fit_pressure_stiffness",
    "plot_comparison",
    "plot_displacement",
    "plot_loops",
    "plot_phase_portrait",
    "plot_velocity",
    "synthetic_recording",
    "table2_model",
    "table2_psi",
]
