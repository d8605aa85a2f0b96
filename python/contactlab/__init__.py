"""contactlab: hysteresis of contact joints in machine structures.

Tangential contact (Masing friction hysteresis), normal contact (Konowalski's loops and
models), fitting, reports and model-discrepancy diagnosis. See README.md.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from ._version import __version__
from .errors import ContactLabError, ContactLabWarning, ConvergenceError, InputError

if TYPE_CHECKING:
    from . import diagnose, normal
    from .fitting import FitResult, Parameter, least_squares_fit
    from .io import Recording, RecordingError, read_recording, write_recording
    from .masing import (
        CycleTable,
        Masing,
        MasingOperator,
        cycle_energies,
        force_many,
        loop_area,
        loop_areas,
    )
    from .simulation import Simulator
    from .studies.tracking import TrackResult, track
    from .tangential import TangentialAnalysis, analyze_tangential

# Everything but the errors loads on first use (PEP 562): `import contactlab` stays cheap, and
# a user of the Masing operator does not pay for scipy.optimize or the diagnosis workflow.
# `contactlab.diagnose` is the subpackage, made callable: `contactlab.diagnose(recording,
# model=...)` runs the workflow while `contactlab.diagnose.<module>` imports keep working.
_SUBMODULES = {"diagnose", "normal"}
_LAZY = {
    "FitResult": "fitting",
    "Parameter": "fitting",
    "least_squares_fit": "fitting",
    "Recording": "io",
    "RecordingError": "io",
    "read_recording": "io",
    "write_recording": "io",
    "CycleTable": "masing",
    "Masing": "masing",
    "MasingOperator": "masing",
    "cycle_energies": "masing",
    "loop_area": "masing",
    "loop_areas": "masing",
    "force_many": "masing",
    "TangentialAnalysis": "tangential",
    "analyze_tangential": "tangential",
    "Simulator": "simulation",
    "TrackResult": "studies.tracking",
    "track": "studies.tracking",
}


def __getattr__(name: str) -> Any:
    if name in _SUBMODULES:
        return importlib.import_module(f".{name}", __name__)
    if name in _LAZY:
        value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value  # later look-ups skip __getattr__
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(__all__)


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
    "Simulator",
    "TangentialAnalysis",
    "TrackResult",
    "__version__",
    "analyze_tangential",
    "cycle_energies",
    "diagnose",
    "force_many",
    "least_squares_fit",
    "loop_area",
    "loop_areas",
    "normal",
    "read_recording",
    "track",
    "write_recording",
]
