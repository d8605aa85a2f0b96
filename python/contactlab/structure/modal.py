"""Modes of the linearised structure: natural frequencies, damping ratios, mode shapes.

The linearisation adds each joint's initial tangent stiffness (virgin state, d = 0) to K and
a Kelvin-Voigt joint's ``c`` to C. Undamped modes solve ``K φ = ω² M φ`` (mass-normalised
``φ``); the damping ratio of mode i is the modal projection ``ζ_i = φ_iᵀ C φ_i / (2 ω_i)``,
exact for classically (e.g. Rayleigh) damped structures; the damped frequencies
``|λ| sqrt(1 − ζ²)`` come from the state-space eigenvalues ``λ`` of the full ``(M, C, K)``, so
non-proportional damping is seen there.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg

from ..errors import InputError


@dataclass
class Modes:
    """Modal data of a linear(ised) structure, ascending in frequency.

    Attributes
    ----------
    frequency_hz : ndarray (m,)
        Undamped natural frequencies ``ω_i / 2π`` [Hz].
    damping_ratio : ndarray (m,)
        Modal damping ratios ``φ_iᵀ C φ_i / (2 ω_i)`` [-].
    shapes : ndarray (n, m)
        Mass-normalised mode shapes, one column per mode (``φᵀ M φ = I``), sign chosen so
        that the largest component is positive.
    damped_frequency_hz : ndarray (m,)
        Damped natural frequencies from the state-space eigenvalues [Hz] (NaN for an
        overdamped mode).
    state_damping_ratio : ndarray (m,)
        ``−Re λ / |λ|`` of the state-space eigenvalues (equal to ``damping_ratio`` for
        classical damping).
    """

    frequency_hz: np.ndarray
    damping_ratio: np.ndarray
    shapes: np.ndarray
    damped_frequency_hz: np.ndarray
    state_damping_ratio: np.ndarray

    def to_dict(self) -> dict[str, Any]:
        return {
            "frequency_hz": self.frequency_hz.tolist(),
            "damping_ratio": self.damping_ratio.tolist(),
            "shapes": self.shapes.tolist(),
            "damped_frequency_hz": [
                None if not np.isfinite(v) else float(v) for v in self.damped_frequency_hz
            ],
            "state_damping_ratio": self.state_damping_ratio.tolist(),
            "units": {"frequency_hz": "Hz", "damping_ratio": "1", "shapes": "1/sqrt(kg)"},
        }


def modes(M: np.ndarray, C: np.ndarray, K: np.ndarray) -> Modes:
    """Modes of ``M x'' + C x' + K x = 0`` (M symmetric positive definite, K symmetric).

    Examples
    --------
    >>> import numpy as np
    >>> md = modes(np.eye(1) * 2.0, np.eye(1) * 4.0, np.eye(1) * 800.0)
    >>> round(float(md.frequency_hz[0] * 2 * np.pi), 6), round(float(md.damping_ratio[0]), 6)
    (20.0, 0.05)
    """
    n = M.shape[0]
    try:
        w2, phi = scipy.linalg.eigh(K, M)
    except np.linalg.LinAlgError as exc:
        raise InputError(f"M must be symmetric positive definite: {exc}") from None
    if np.any(w2 <= 0):
        i = int(np.argmax(w2 <= 0))
        raise InputError(
            f"the linearised stiffness is not positive definite (mode {i}: ω² = {w2[i]:.6g});"
            " the structure has a rigid-body mode, add a ground spring or joint"
        )
    w = np.sqrt(w2)
    big = np.argmax(np.abs(phi), axis=0)
    phi = phi * np.sign(phi[big, np.arange(n)])
    zeta = np.einsum("ij,ik,kj->j", phi, C, phi) / (2.0 * w)
    # State-space eigenvalues, matched to the undamped modes by nearest |λ|.
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    lam = np.linalg.eigvals(A)
    osc = lam[lam.imag > 0]
    fd = np.full(n, np.nan)
    zs = np.full(n, np.nan)
    taken = np.zeros(osc.size, bool)
    for i in range(n):
        if not np.any(~taken):
            break
        d = np.where(taken, np.inf, np.abs(np.abs(osc) - w[i]))
        j = int(np.argmin(d))
        if np.isfinite(d[j]):
            taken[j] = True
            fd[i] = osc[j].imag / (2 * np.pi)
            zs[i] = -osc[j].real / abs(osc[j])
    for i in range(n):
        if not np.isfinite(zs[i]):
            zs[i] = 1.0 if zeta[i] >= 1.0 else zeta[i]
    return Modes(
        frequency_hz=w / (2 * np.pi),
        damping_ratio=zeta,
        shapes=phi,
        damped_frequency_hz=fd,
        state_damping_ratio=zs,
    )
