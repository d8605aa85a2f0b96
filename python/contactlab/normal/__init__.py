"""Normal contact of machined joints: loop analysis, Kelvin-Voigt and nonlinear models.

Implements Konowalski (2009), *Experimental research and modeling of normal contact stiffness
and contact damping of machined joint surfaces* (PHYSICS.md §2): loop polynomials (eq. 1),
energies and dissipation coefficients (eqs. 3, 7), stiffnesses (eqs. 4-6, 16), the linear
Kelvin-Voigt model (eqs. 8-15) and the nonlinear model (eq. 17), with the comparison of
models and measurement of the paper's Figs. 9-12.

SI units throughout (Pa, m, J/m², Pa/m); the paper's MPa and µm only for display.
"""

from __future__ import annotations

from .._moved import forward
from .compare import (
    Comparison,
    compare,
)
from .loop import LoopResult, analyze_loop
from .models import KelvinVoigt, NonlinearContact, OdeResult
from .options import Options
from .paper import TABLE2_MPA_UM
from .stiffness import PressureStiffnessFit, fit_pressure_stiffness

__all__ = [
    "TABLE2_MPA_UM",
    "Comparison",
    "KelvinVoigt",
    "LoopResult",
    "NonlinearContact",
    "OdeResult",
    "Options",
    "PressureStiffnessFit",
    "analyze_loop",
    "compare",
    "fit_pressure_stiffness",
]

# moved to the report layer and to contactlab.synthetic (issue 32): the old names warn and forward
__getattr__ = forward(
    __name__,
    {
        "plot_comparison": "contactlab.report.normal",
        "plot_displacement": "contactlab.report.normal",
        "plot_loops": "contactlab.report.normal",
        "plot_phase_portrait": "contactlab.report.normal",
        "plot_velocity": "contactlab.report.normal",
        "synthetic_recording": "contactlab.synthetic.normal",
        "table2_model": "contactlab.synthetic.normal",
        "table2_psi": "contactlab.synthetic.normal",
    },
)
