"""Amplitude-dependent natural frequency and damping ratio of an SDOF structure with joints
(equivalent linearisation on the joint's backbone; first-harmonic balance).

For a joint displacement ``d = A sin θ`` the joint's first harmonic gives an equivalent
stiffness ``k_eq(A) = (1/(π A)) ∮ F sin θ dθ`` and the loop energy ``E(A) = ∮ F dd``. The
structure then behaves, at amplitude A, like ``m, k + k_eq, c + E/(π ω A²)``:

    f_n(A) = sqrt((k + k_eq) / m) / 2π,
    ζ(A)   = c / (2 m ω_n) + E / (2π (k + k_eq) A²).

The joint loop is computed by the Rust core, the joint driven quasi-statically (a stiff,
overdamped tie to a slowly moving base), so every joint law is handled the same way.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .._arrays import as_1d
from .._moved import forward
from ..errors import InputError
from .model import Structure


@dataclass
class AmplitudeDependence:
    """``frequency_hz`` and ``damping_ratio`` at joint-displacement amplitudes ``amplitude``
    [m], with the joint's ``k_eq`` [N/m] and loop energy ``energy`` [J]."""

    amplitude: np.ndarray
    frequency_hz: np.ndarray
    damping_ratio: np.ndarray
    k_eq: np.ndarray
    energy: np.ndarray

    def to_dict(self) -> dict[str, Any]:
        return {
            "amplitude": self.amplitude.tolist(),
            "frequency_hz": self.frequency_hz.tolist(),
            "damping_ratio": self.damping_ratio.tolist(),
            "k_eq": self.k_eq.tolist(),
            "energy": self.energy.tolist(),
            "units": {"amplitude": "m", "frequency_hz": "Hz", "k_eq": "N/m", "energy": "J"},
        }


def joint_loop(structure: Structure, amplitude: float, n: int = 2000) -> tuple[np.ndarray, ...]:
    """One steady quasi-static cycle ``(d, F)`` of the SDOF structure's joints (summed) at
    joint-displacement amplitude ``amplitude`` (after two run-in cycles)."""
    k0 = sum(abs(j.initial_stiffness) for j in structure.joints) + abs(float(structure.K[0, 0]))
    k_tie = 1e5 * max(k0, 1e-300)
    m = 1e-6
    drive = Structure(m, 3.0 * np.sqrt(k_tie * m), k_tie)
    for j in structure.joints:
        drive.add_joint(j.kind, 0, None, **j.params, **j.arrays)
    t = np.linspace(0.0, 3.0, 3 * n + 1)
    y = amplitude * np.sin(2 * np.pi * t)
    # fixed steps: the tie is stiff (its mode far beyond the sample rate), which the
    # A-stable trapezoidal rule steps over and error control would resolve at great cost
    yd = 2 * np.pi * amplitude * np.cos(2 * np.pi * t)
    r = drive.simulate(t, base=y, base_velocity=yd, substeps=1)
    if not r.success:
        raise InputError(f"joint loop at amplitude {amplitude:g} m failed: {r.message}")
    d = r.x[-n - 1 :]
    F = r.joint_force[-n - 1 :].sum(axis=1)
    return t[-n - 1 :], d, F


def loop_keq_energy(t: np.ndarray, d: np.ndarray, F: np.ndarray) -> tuple[float, float, float]:
    """``(A, k_eq, E)`` of one cycle of :func:`joint_loop`: half the displacement range, the
    first-harmonic equivalent stiffness ``(1/(π A)) ∮ F sin θ dθ`` and the loop energy
    ``∮ F dd``."""
    th = 2 * np.pi * (t - t[0])
    A = 0.5 * float(d.max() - d.min())
    return A, float(np.trapezoid(F * np.sin(th), th) / (np.pi * A)), float(np.trapezoid(F, d))


def checked_amplitudes(structure: Structure, amplitudes: Any, who: str) -> np.ndarray:
    """The amplitudes as a positive 1-D array; a rate-dependent (Kelvin-Voigt) joint refused."""
    if any(j.kind == "kelvin_voigt" for j in structure.joints):
        raise InputError(
            f"{who}: a Kelvin-Voigt joint is rate-dependent; add its k and c to "
            "the structure instead"
        )
    a = as_1d(amplitudes, "amplitudes")
    if np.any(a <= 0):
        raise InputError("amplitudes must be > 0")
    return a


def amplitude_dependence(structure: Structure, amplitudes: Any) -> AmplitudeDependence:
    """Natural frequency [Hz] and damping ratio of an SDOF structure versus amplitude [m].

    Examples
    --------
    >>> s = Structure(1.0, 0.5, 1000.0)
    >>> _ = s.add_joint("jenkins", 0, k=1000.0, fs=1.0)
    >>> ad = amplitude_dependence(s, [1e-4, 1e-2])
    >>> [round(float(f), 3) for f in ad.frequency_hz]  # stuck: √(2000); slipping: → √(1000)
    [7.118, 5.162]
    """
    if structure.n != 1:
        raise InputError("amplitude_dependence needs a single-DOF structure")
    a = checked_amplitudes(structure, amplitudes, "amplitude_dependence")
    m, c, k = float(structure.M[0, 0]), float(structure.C[0, 0]), float(structure.K[0, 0])
    keq = np.empty(a.size)
    energy = np.empty(a.size)
    amp = np.empty(a.size)
    for i, ai in enumerate(a):
        t, d, F = joint_loop(structure, float(ai)) if structure.joints else (None, None, None)
        if d is None:
            keq[i], energy[i], amp[i] = 0.0, 0.0, ai
            continue
        amp[i], keq[i], energy[i] = loop_keq_energy(t, d, F)
    ktot = k + keq
    if np.any(ktot <= 0):
        raise InputError("the equivalent stiffness is not positive at some amplitude")
    wn = np.sqrt(ktot / m)
    zeta = c / (2 * m * wn) + energy / (2 * np.pi * ktot * amp**2)
    return AmplitudeDependence(amp, wn / (2 * np.pi), zeta, keq, energy)


# moved to the report layer (issue 32): the old names warn and forward
__getattr__ = forward(__name__, {"plot_amplitude_dependence": "contactlab.report.structure_plots"})
