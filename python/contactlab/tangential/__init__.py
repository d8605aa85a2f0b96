"""Tangential contact recordings ``(t, x, F)``: reversal detection, period averaging,
Masing fits with honest uncertainty and identifiability, derived quantities and plots.

Implements the analysis of *Experimental investigation of tangential contact stiffness and
equivalent damping* with the corrected formulas of PHYSICS.md §1.
"""

from __future__ import annotations

from .._moved import forward
from .analysis import analyze_tangential
from .frame import FrameForce, frame_friction_force, read_frame
from .options import Options
from .preprocess import AveragedLoop, CycleScatter, Reversals, average_loop, find_reversals
from .result import UNITS, TangentialAnalysis

__all__ = [
    "UNITS",
    "AveragedLoop",
    "CycleScatter",
    "FrameForce",
    "Options",
    "Reversals",
    "TangentialAnalysis",
    "analyze_tangential",
    "average_loop",
    "find_reversals",
    "frame_friction_force",
    "read_frame",
]

# moved to the report layer and to contactlab.synthetic (issue 32): the old names warn and forward
__getattr__ = forward(
    __name__,
    {
        "plot_loop": "contactlab.report.tangential",
        "plot_residuals": "contactlab.report.tangential",
        "synthetic_recording": "contactlab.synthetic.tangential",
    },
)
