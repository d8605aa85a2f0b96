"""Model-discrepancy workflow: where model and measurement disagree, which effect is
missing, and how much the gap shrinks once it is added (issue 5).

>>> import contactlab
>>> from contactlab.synthetic.diagnosis import hidden_effect_recording
>>> report = contactlab.diagnose(hidden_effect_recording(["channel_delay"], seed=0))
>>> report.effect_names
['channel_delay']
"""

from __future__ import annotations

import sys
import types
from typing import TYPE_CHECKING, Any

from .._moved import moved
from .model import ExtendedModel
from .workflow import DiagnosisReport, Effect, Step, diagnose

if TYPE_CHECKING:
    from .structure import StructureDiagnosis, diagnose_structure

__all__ = [
    "DiagnosisReport",
    "Effect",
    "ExtendedModel",
    "Step",
    "StructureDiagnosis",
    "diagnose",
    "diagnose_structure",
]


def __getattr__(name: str) -> Any:
    """The structure diagnosis and the hidden-effect generator on first use: the first
    imports contactlab.structure and scipy.signal, half a second that a tangential or normal
    diagnosis does not need; the second three modules a diagnosis does not use."""
    if name in ("StructureDiagnosis", "diagnose_structure"):
        from . import structure

        return getattr(structure, name)
    if name in ("HiddenEffectRecording", "hidden_effect_recording"):  # moved (issue 32)
        return moved(__name__, name, "contactlab.synthetic.diagnosis")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


class _CallableModule(types.ModuleType):
    """``contactlab.diagnose(...)`` calls :func:`diagnose`; attributes are the subpackage's."""

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return diagnose(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
