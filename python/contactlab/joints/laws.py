"""Joint laws driven by displacement: ``F(t) = law(x(t))`` with exact non-local memory.

Every law shares one interface (:class:`JointLaw`):

- ``law.force(t, x, x0=0.0) -> F`` for a whole history (``t`` may be None for a
  rate-independent law), and ``op = law.operator(); op.push(t_chunk, x_chunk)`` for a
  recording streamed in chunks (chunked and one pass give the same forces);
- ``law.param_names``, ``law.params`` (dict), ``law.units``, ``law.bounds`` (dict of
  ``(lo, hi)``), ``law.vector`` and ``law.with_params(vector_or_dict)`` for fitters;
- bad parameters, non-finite samples and a time axis that does not strictly increase raise
  :class:`contactlab.InputError` naming the value.

Conventions: the operator starts relaxed (force 0, no history) at displacement ``x0``; the
path between samples is a straight line in time, so a rate-dependent law sees the velocity
``(x_n - x_{n-1}) / (t_n - t_{n-1})`` over each step and is integrated exactly along it (the
first sample is reached from ``x0`` quasi-statically: velocity 0 in the rate terms).
Rate-independent laws (Jenkins, Iwan, Segalman, Maxwell-slip, Dahl, Bouc-Wen, Masing) ignore
``t`` apart from checking it.

Laws (the registry :data:`LAWS` maps a lower-case name to the class):

========================  =====================================================================
``jenkins``               elastic-Coulomb: stiffness ``k`` in series with a slider ``fs``
``iwan``                  continuous Iwan model, uniform slip-force density up to ``fs_max``
``segalman``              Segalman's 4-parameter power-law Iwan model (J. Appl. Mech. 72, 2005)
``maxwell_slip``          ``N`` Jenkins elements in parallel (arrays ``k``, ``fs``)
``gms``                   generalised Maxwell-slip (Al-Bender, Lampaert & Swevers 2005)
``dahl``                  Dahl's law ``dF/dx = σ0 |1 - F/Fc sgn ẋ|^α``
``lugre``                 LuGre (bristle state, Stribeck curve, viscous term)
``bouc_wen``              Bouc-Wen in displacement-driven form
``kelvin_voigt``          ``F = k x + c ẋ``
``masing``                Masing's rules on an exponential (or any) virgin curve
``series``                laws in series (the force balance solved at every sample)
``parallel``              laws in parallel, plus a stiffness ``k`` and a viscous ``c``
``backlash``              a clearance ``gap`` in series with a law (a dead band)
========================  =====================================================================
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import InputError
from .composite_laws import Backlash, Parallel, Series
from .law_base import INF, REGISTRY, REGISTRY_HOOKS, JointLaw, JointOperator, ParamSpec
from .leaf_laws import (
    BoucWen,
    Dahl,
    GeneralizedMaxwellSlip,
    Iwan,
    Jenkins,
    KelvinVoigt,
    LuGre,
    MasingLaw,
    MaxwellSlip,
    Segalman,
)

__all__ = [
    "INF",
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
    "from_spec",
    "initial_stiffness",
]


def initial_stiffness(law: JointLaw) -> float:
    """Tangent stiffness of ``law`` from the relaxed state, N/m (0 behind an open gap)."""
    if isinstance(law, Iwan):
        return law.k
    if isinstance(law, Segalman):
        return law.K_T
    if isinstance(law, (Jenkins, KelvinVoigt)):
        return law.k
    if isinstance(law, (MaxwellSlip, GeneralizedMaxwellSlip)):
        return float(np.sum(law.k))
    if isinstance(law, (Dahl, LuGre)):
        return law.sigma0
    if isinstance(law, BoucWen):
        return law.alpha
    if isinstance(law, MasingLaw):
        return float(law.masing().local_stiffness(0.0))
    if isinstance(law, Parallel):
        return law.k + sum(x.initial_stiffness for x in law.laws)
    if isinstance(law, Series):
        ks = [x.initial_stiffness for x in law.laws]
        return 0.0 if min(ks) <= 0 else 1.0 / sum(1.0 / k for k in ks)
    if isinstance(law, Backlash):
        return law.laws[0].initial_stiffness if law.gap == 0 else 0.0
    raise InputError(f"{law.name}: no initial stiffness")  # pragma: no cover


def from_spec(spec: Any) -> JointLaw:
    """The law a :meth:`JointLaw.spec` describes.

    Parameters
    ----------
    spec : tuple
        ``(kind, params, children)`` (lists may be any sequences).

    Returns
    -------
    JointLaw
        A new law equal to the one the spec was taken from.
    """
    try:
        kind, params, children = spec
        p = [float(v) for v in params]
        kids = [from_spec(c) for c in children]
    except (TypeError, ValueError):
        raise InputError(f"a joint-law spec is (kind, params, children), got {spec!r}") from None
    cls = LAWS.get(str(kind))
    if cls is None:
        raise InputError(f"unknown joint law {kind!r}: use one of {', '.join(LAWS)}")
    if cls in (Series, Parallel, Backlash):
        if cls is Series:
            return Series(*kids)
        if cls is Parallel:
            if len(p) != 2:
                raise InputError(f"parallel takes 2 parameters (k, c), got {len(p)}")
            return Parallel(*kids, k=p[0], c=p[1])
        if len(p) != 1 or len(kids) != 1:
            raise InputError("backlash takes 1 parameter (gap) and 1 law")
        return Backlash(p[0], kids[0])
    if kids:
        raise InputError(f"{kind} takes no child laws")
    if cls is MaxwellSlip:
        n = len(p) // 2
        return MaxwellSlip(p[:n], p[n:])
    if cls is GeneralizedMaxwellSlip:
        n = (len(p) - 6) // 2
        if n < 1 or len(p) != 2 * n + 6:
            raise InputError(f"gms takes 2 n + 6 parameters, got {len(p)}")
        return GeneralizedMaxwellSlip(p[:n], p[n : 2 * n], *p[2 * n :])
    try:
        return cls(*p)
    except TypeError as exc:
        raise InputError(f"{kind}: {exc}") from None


#: Registry of the joint laws by name.
LAWS: dict[str, type[JointLaw]] = {
    "jenkins": Jenkins,
    "iwan": Iwan,
    "segalman": Segalman,
    "maxwell_slip": MaxwellSlip,
    "gms": GeneralizedMaxwellSlip,
    "dahl": Dahl,
    "lugre": LuGre,
    "bouc_wen": BoucWen,
    "kelvin_voigt": KelvinVoigt,
    "masing": MasingLaw,
    "series": Series,
    "parallel": Parallel,
    "backlash": Backlash,
}
REGISTRY.update(LAWS)
REGISTRY_HOOKS["initial_stiffness"] = initial_stiffness
