"""Joint laws driven by displacement, ``x(t) -> F(t)``, with exact non-local memory.

See :mod:`contactlab.joints.laws` for the laws, their conventions and the registry
:data:`LAWS`; :func:`fit` fits them to measured records and :func:`compare` scores their
predictions (:mod:`.fit`, :mod:`.compare`); :mod:`.amplitude` gives their amplitude-dependent
stiffness and damping and fits them to such tables and to stepped-sine responses.
"""

from __future__ import annotations

from .amplitude import (
    AmplitudeFit,
    EquivalentProperties,
    energy_per_cycle,
    equivalent_properties,
    fit_amplitude,
    secant_stiffness,
)
from .compare import Comparison, compare
from .fit import JointFit, fit, start_law
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
    from_spec,
)
from .records import JointRecord
from .stepped_sine import SteppedSineFit, Sweep, fit_stepped_sine

__all__ = [
    "LAWS",
    "AmplitudeFit",
    "Backlash",
    "BoucWen",
    "Comparison",
    "Dahl",
    "EquivalentProperties",
    "GeneralizedMaxwellSlip",
    "Iwan",
    "Jenkins",
    "JointFit",
    "JointLaw",
    "JointOperator",
    "JointRecord",
    "KelvinVoigt",
    "LuGre",
    "MasingLaw",
    "MaxwellSlip",
    "Parallel",
    "ParamSpec",
    "Segalman",
    "Series",
    "SteppedSineFit",
    "Sweep",
    "compare",
    "energy_per_cycle",
    "equivalent_properties",
    "fit",
    "fit_amplitude",
    "fit_stepped_sine",
    "from_spec",
    "secant_stiffness",
    "start_law",
]
