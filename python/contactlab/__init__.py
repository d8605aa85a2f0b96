"""contactlab: hysteresis of contact joints in machine structures.

Tangential contact (Masing friction hysteresis), normal contact (Konowalski's loops and
models), fitting, reports and model-discrepancy diagnosis. See README.md.
"""

from __future__ import annotations

# `contactlab.diagnose` is the subpackage, made callable: `contactlab.diagnose(recording,
# model=...)` runs the workflow while `contactlab.diagnose.<module>` imports keep working.
from . import diagnose, normal
from .errors import ContactLabError, ContactLabWarning, ConvergenceError, InputError
from .fitting import FitResult, Parameter, least_squares_fit
from .io import Recording, RecordingError, read_recording, write_recording
from .masing import CycleTable, Masing, MasingOperator, cycle_energies, force_many, loop_area
from .tangential import TangentialAnalysis, analyze_tangential

__version__ = "0.1.0"

__all__ = [
    "ContactLabError",
    "ContactLabWarning",
    "ConvergenceError",
    "CycleTable",
    "FitResult",
    "InputError",
    "Masing",
    "MasingOperator",
    "Parameter",
    "Recording",
    "RecordingError",
    "TangentialAnalysis",
    "__version__",
    "analyze_tangential",
    "cycle_energies",
    "diagnose",
    "force_many",
    "least_squares_fit",
    "loop_area",
    "normal",
    "read_recording",
    "write_recording",
]
