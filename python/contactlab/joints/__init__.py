"""Joint laws driven by displacement, ``x(t) -> F(t)``, with exact non-local memory.

See :mod:`contactlab.joints.laws` for the laws, their conventions and the registry
:data:`LAWS`.
"""

from __future__ import annotations

from .laws import (
    LAWS,
    Backlash,
    BoucWen,
    Dahl,
    GeneralizedMaxwellSlip,
    Iwan,
    Jenkins,
    JointLaw,
    JointOperator,
    KelvinVoigt,
    LuGre,
    MasingLaw,
    MaxwellSlip,
    Parallel,
    ParamSpec,
    Segalman,
    Series,
)

__all__ = [
    "LAWS",
    "Backlash",
    "BoucWen",
    "Dahl",
    "GeneralizedMaxwellSlip",
    "Iwan",
    "Jenkins",
    "JointLaw",
    "JointOperator",
    "KelvinVoigt",
    "LuGre",
    "MasingLaw",
    "MaxwellSlip",
    "Parallel",
    "ParamSpec",
    "Segalman",
    "Series",
]
