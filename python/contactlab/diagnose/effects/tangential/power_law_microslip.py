"""``power_law_microslip``: an Iwan element with Segalman's power-law slip-force density."""

from __future__ import annotations

import numpy as np

from ..._family import ParamSpec
from .._base import EffectModel, Plausibility, register

_POINTS = 600


def segalman_constants(F_S: float, K_T: float, chi: float, beta: float) -> tuple[float, ...]:
    """``(phi_max, R, S)`` of Segalman's density ``ρ(φ) = R φ^χ`` on ``0 < φ < φ_max`` plus
    ``S δ(φ - φ_max)``, from the joint's macroslip force ``F_S``, its initial stiffness
    ``K_T``, the exponent ``χ`` and the ratio ``β`` of the delta's to the power law's share
    of the stiffness (Segalman 2005, eqs. 8-11)."""
    c = (chi + 1.0) / (chi + 2.0)
    phi = F_S * (1.0 + beta) / (K_T * (beta + c))
    R = F_S * (chi + 1.0) / (phi ** (chi + 2.0) * (beta + c))
    S = (F_S / phi) * (beta / (beta + c))
    return phi, R, S


def segalman_virgin(u: np.ndarray, F_S: float, K_T: float, chi: float, beta: float) -> np.ndarray:
    """Virgin curve of the Segalman Iwan element: for ``|u| < φ_max``
    ``K_T u - R |u|^(χ+2) sgn(u) / ((χ+1)(χ+2))``, beyond it ``F_S sgn(u)`` (macroslip).

    Its small-amplitude loops dissipate ``∝ A^(3+χ)`` (Masing's rule with this curve)."""
    phi, R, _ = segalman_constants(F_S, K_T, chi, beta)
    a = np.minimum(np.abs(u), phi)
    f = K_T * a - R * a ** (chi + 2.0) / ((chi + 1.0) * (chi + 2.0))
    return np.sign(u) * f


def dissipation_exponent(chi: float) -> float:
    """Exponent of the dissipation per cycle against amplitude in microslip: ``3 + χ``."""
    return 3.0 + chi


@register
class PowerLawMicroslip(EffectModel):
    name = "power_law_microslip"
    kind = "tangential"
    params = (
        ParamSpec("chi", "-", np.nan, -0.95, -0.02, "one"),
        ParamSpec("beta", "-", np.nan, 0.0, 50.0, "one"),
    )
    description = (
        "Iwan element with Segalman's power-law slip-force density (F_S = h0, K_T = h0·ac, "
        "exponent chi, delta share beta): microslip dissipation ∝ A^(3+chi)"
    )
    physics = (
        "A bolted or clamped interface slips patch by patch: an Iwan array of Jenkins "
        "elements whose slip forces follow Segalman's density R φ^χ up to φ_max plus a "
        "share S at φ_max. Its virgin curve K_T u - R u^(χ+2)/((χ+1)(χ+2)) (macroslip F_S "
        "beyond φ_max) gives loops whose dissipation per cycle grows as A^(3+χ), "
        "-1 < χ < 0 (the exponential element's grows as A^3)."
    )
    stage = "element"
    order = 15
    size_param = "chi"

    def start(self, p, d, residual, family=None):
        return {"chi": -0.5, "beta": 0.5}

    def apply(self, core, p, ctx):
        from ....masing import Masing

        F_S, K_T = p["h0"], p["h0"] * p["ac"]
        chi, beta = p["chi"], max(p["beta"], 0.0)
        if not (F_S > 0 and K_T > 0 and np.isfinite(K_T) and -1.0 < chi < 0.0):
            return Masing(p["h0"], p["ac"]).force(ctx.xm)  # (the element's own refusal)
        phi, _, _ = segalman_constants(F_S, K_T, chi, beta)
        s = np.linspace(0.0, 1.0, _POINTS)
        u = phi * s**2  # dense near the origin, where the power law bends
        u = np.r_[u, phi * (1.0 + 1e-9), 3.0 * max(float(np.max(np.abs(ctx.xm))), phi)]
        f = segalman_virgin(u, F_S, K_T, chi, beta)
        f[-2:] = F_S * (1.0 - np.array([1e-12, 1e-11]))  # (strictly increasing points)
        f[-1] = F_S * (1.0 - 1e-12) if f[-1] <= f[-2] else f[-1]
        f = np.maximum.accumulate(f)
        keep = np.r_[True, np.diff(f) > 0]
        return Masing.from_backbone(u[keep], f[keep]).force(ctx.xm)

    def plausible(self, d, p):
        base = super().plausible(d, p)
        if not base.ok:
            return base
        if not -1.0 < p["chi"] < 0.0:
            return Plausibility(False, f"χ = {p['chi']:.3g} is outside -1 < χ < 0")
        return base

    def argument(self, d, p):
        return (
            f"χ = {p['chi']:.3g}: the microslip dissipation grows as A^{3 + p['chi']:.2f} "
            f"(the exponential element's as A^3), with F_S = {p['h0']:.4g} N and K_T = "
            f"{p['h0'] * p['ac']:.4g} N/m: an Iwan interface slipping patch by patch"
        )
