"""Which way the force channel counts, decided by physics: a passive joint dissipates.

Over every closed cycle the work done on a passive contact is positive, ``∮ F dx > 0``
(PHYSICS.md §1: the Masing loop is traversed so that its area ``E(A)`` is positive; a
Coulomb rectangle has ``∮ F dx = 4 h0 A``). A load cell that counts the other way gives a
negative area. The sign of the signed loop area over the complete cycles therefore fixes the
orientation — unlike the correlation of F with x, which is ≈ 0 for the nearly rectangular
loops of gross sliding.

The area is trusted when it exceeds three times its noise error: for white noise σF on the
force and σx on the displacement, the polygon area ``½ Σ (F_i + F_{i+1}) Δx_i`` has the
standard error ``sqrt(σF² Σ Δx² + σx² Σ ΔF²)`` (each term linear in the noise; σ from the
second differences, robust scale). When the loop is too thin for that (a nearly elastic
contact, ``ac·A ≪ 1``), a passive contact is still a positive stiffness: the sign of the
correlation of F with x decides, if it is significant (``|r| > 3/√n``). Otherwise the sign
is kept as recorded and the reason says so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..masing import loop_area
from .preprocess import find_reversals

#: number of standard errors the loop area (or the correlation) must exceed to decide
SIGNIFICANCE = 3.0


@dataclass(frozen=True)
class Orientation:
    """``sign`` (+1 or -1: analyse ``sign·F``), how it was decided (``reason``), the signed
    loop area of the complete cycles as recorded (J) and its noise error."""

    sign: int
    reason: str
    loop_area: float
    loop_area_stderr: float
    by: str  # "loop area", "stiffness", "user", "default"


def noise_sigma(v: np.ndarray) -> float:
    """White-noise standard deviation from second differences (``var(Δ²v) = 6σ²``, MAD)."""
    d2 = np.diff(v, 2)
    if d2.size < 10:
        return 0.0
    return 1.4826 * float(np.median(np.abs(d2 - np.median(d2)))) / math.sqrt(6.0)


def signed_area(x: np.ndarray, F: np.ndarray, t: np.ndarray | None) -> tuple[float, float]:
    """``∮ F dx`` over the complete cycles (first to last peak; the whole record when there
    is no complete cycle) and its noise standard error."""
    a, b = 0, x.size
    try:
        rev = find_reversals(x, t)
        if rev.peaks.size >= 2:
            a, b = int(rev.peaks[0]), int(rev.peaks[-1]) + 1
    except InputError:
        pass
    xs, Fs = x[a:b], F[a:b]
    area = float(loop_area(xs, Fs)) if xs.size >= 3 else 0.0
    sF, sx = noise_sigma(F), noise_sigma(x)
    err = math.sqrt(
        sF**2 * float(np.sum(np.diff(xs) ** 2)) + sx**2 * float(np.sum(np.diff(Fs) ** 2))
    )
    return area, err


def parse_force_sign(force_sign: object) -> int | None:
    """``"auto"``/None → None; ``+1``/``-1`` (int or text) → that sign."""
    if force_sign is None or (isinstance(force_sign, str) and force_sign.strip() == "auto"):
        return None
    try:
        s = int(str(force_sign).strip())
    except ValueError:
        s = 0
    if s not in (1, -1) or isinstance(force_sign, bool):
        raise InputError(f"force_sign must be 'auto', +1 or -1, got {force_sign!r}")
    return s


def orient(
    x: np.ndarray,
    F: np.ndarray,
    t: np.ndarray | None = None,
    *,
    force_sign: object = "auto",
) -> Orientation:
    """Decide the force sign of a tangential recording (see the module docstring).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.linspace(0, 4, 4001); x = np.sin(2 * np.pi * t)
    >>> F = -np.sign(np.cos(2 * np.pi * t))      # a Coulomb loop counted the wrong way
    >>> o = orient(x, F, t); o.sign, o.by
    (-1, 'loop area')
    """
    area, err = signed_area(x, F, t)
    fixed = parse_force_sign(force_sign)
    if fixed is not None:
        note = ""
        if abs(area) > SIGNIFICANCE * err and np.sign(area) != fixed:
            note = (
                f"; with this sign the loop area is {fixed * area:.3g} J < 0, which a passive "
                "joint cannot produce"
            )
        return Orientation(
            fixed, f"force sign {fixed:+d} given by the user{note}", area, err, "user"
        )
    if area != 0 and abs(area) > SIGNIFICANCE * err:
        sign = 1 if area > 0 else -1
        what = (
            "as recorded" if sign > 0 else "after inverting F (the load cell counts the other way)"
        )
        reason = (
            f"a passive joint dissipates (∮F dx > 0): the signed loop area is {area:.4g} J "
            f"± {err:.2g} J, so the force is analysed {what}"
        )
        return Orientation(sign, reason, area, err, "loop area")
    xc = x - x.mean()
    Fc = F - F.mean()
    den = math.sqrt(float(xc @ xc) * float(Fc @ Fc))
    r = float(xc @ Fc) / den if den > 0 else 0.0
    if abs(r) > SIGNIFICANCE / math.sqrt(max(x.size, 1)):
        sign = 1 if r > 0 else -1
        reason = (
            f"the loop area ({area:.3g} ± {err:.2g} J) is within its noise; a passive contact is "
            f"a positive stiffness and F correlates with x (r = {r:+.3f}), so the force is "
            f"analysed {'as recorded' if sign > 0 else 'after inverting F'}"
        )
        return Orientation(sign, reason, area, err, "stiffness")
    reason = (
        f"neither the loop area ({area:.3g} ± {err:.2g} J) nor the correlation of F with x "
        f"(r = {r:+.3f}) decides the force sign: kept as recorded"
    )
    return Orientation(1, reason, area, err, "default")


__all__ = ["Orientation", "noise_sigma", "orient", "parse_force_sign", "signed_area"]
