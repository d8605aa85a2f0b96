"""``series_compliance``: the rig's compliance ``C_s`` in series with the contact."""

from __future__ import annotations

import numpy as np

from ....masing import Masing
from ..._family import ParamSpec
from .._base import EffectModel, register

_SERIES_POINTS = 400


def series_backbone(h0: float, ac: float, C_s: float, x_max: float) -> tuple[np.ndarray, ...]:
    """Virgin curve of a Masing element in series with compliance ``C_s``, as points.

    ``x(u) = u + C_s f(u)`` against ``f(u)``, ``u`` from 0 to ``3 x_max`` on a grid that is
    dense where the curve bends.
    """
    s = np.linspace(0.0, 1.0, _SERIES_POINTS)
    u = 3.0 * x_max * s * s
    f = h0 * -np.expm1(-ac * u)
    return u + C_s * f, f


@register
class SeriesCompliance(EffectModel):
    name = "series_compliance"
    kind = "tangential"
    params = (ParamSpec("C_s", "m/N", 0.0, 0.0, np.inf, "C"),)
    description = "measured displacement includes rig compliance C_s·F"
    physics = (
        "The displacement sensor sits behind a compliant part of the rig: x = x_c + C_s h. "
        "A spring in series with a Masing element is a Masing element with the virgin curve "
        "x(u) = u + C_s f(u) against f(u): the loops' turns soften, the plateaus stay."
    )
    stage = "core"
    order = 3
    size_param = "C_s"

    def apply(self, core, p, ctx):
        xmax = float(np.max(np.abs(ctx.xm))) or 1.0
        bx, bf = series_backbone(p["h0"], p["ac"], max(p["C_s"], 0.0), xmax)
        return Masing.from_backbone(bx, bf)

    def derived(self, p, se, **more):
        if p["C_s"] > 0:
            return {"k_s": 1.0 / p["C_s"]}, {"k_s": se["C_s"] / p["C_s"] ** 2}
        return {}, {}

    def argument(self, d, p):
        k0 = p.get("h0", np.nan) * p.get("ac", np.nan)
        return (
            f"a series stiffness 1/C_s = {1 / max(p['C_s'], 1e-300):.4g} N/m against the "
            f"contact's initial stiffness h0·ac = {k0:.4g} N/m: the rig's compliance"
        )
