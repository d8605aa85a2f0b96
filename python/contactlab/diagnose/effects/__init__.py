"""Diagnosis effects as objects (issue 29 item 6).

Each candidate effect is one class in one file, ``effects/<kind>/<effect>.py``: its
parameters (name, unit, bounds, the value meaning "absent"), :meth:`~EffectModel.apply` (what
it does to the base model's input or prediction, at its stage of the composition),
:meth:`~EffectModel.plausible` (whether a fitted value is physical on a record, and the
argument in numbers) and :meth:`~EffectModel.detectable` (the smallest size the record would
reveal). A class decorated with :func:`register` is in its family's library: a new effect is
one new file.

>>> from contactlab.diagnose.effects import registry
>>> eff = registry("tangential")["channel_delay"]
>>> eff.params[0].name, eff.params[0].unit, eff.acts_through
('tau', 's', 'velocity')
"""

from ._base import (
    NORMAL_STAGES,
    TANGENTIAL_STAGES,
    EffectModel,
    ForceContext,
    Plausibility,
    ordered,
    register,
    registry,
)

__all__ = [
    "NORMAL_STAGES",
    "TANGENTIAL_STAGES",
    "EffectModel",
    "ForceContext",
    "Plausibility",
    "ordered",
    "register",
    "registry",
]
