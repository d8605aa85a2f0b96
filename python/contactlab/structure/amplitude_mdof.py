"""Amplitude-dependent frequency and damping of each mode of a structure with joints
(equivalent linearisation, several DOFs).

At a modal amplitude ``a`` (the displacement amplitude of the mode's reference DOF, the
largest component of the linearised mode shape) the structure vibrates as ``a φ sin ωt`` with
``φ`` the mode shape scaled to ``φ[ref] = 1``. Each joint ``j`` then sees the relative
displacement amplitude ``A_j = a |b_jᵀ φ|`` (``b_j = e_dof − e_dof2``) and acts as its
equivalent stiffness ``k_eq,j(A_j)`` (first harmonic of its quasi-static loop, as in
:func:`~contactlab.structure.amplitude.amplitude_dependence`), which changes the mode
shape; the mode shape and the ``k_eq`` are iterated to a fixed point:

    K_eq = K + Σ_j k_eq,j(A_j) b_j b_jᵀ,     K_eq φ = ω² M φ.

The damping ratio is the energy dissipated per cycle over ``4π`` times the maximum strain
energy, viscous part included:

    ζ = (π ω a² φᵀ C φ + Σ_j E_j(A_j)) / (4π · ½ a² φᵀ K_eq φ),

which for one DOF is the single-DOF function's ``c / (2 m ω) + E / (2π k_tot A²)``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.linalg

from .._moved import forward
from ..errors import ConvergenceError, InputError
from .model import Structure


@dataclass
class ModalAmplitudeDependence:
    """One mode's frequency and damping ratio against its amplitude.

    Attributes
    ----------
    mode : int
        Mode index (ascending linearised frequency).
    ref_dof : int
        The DOF whose displacement amplitude is ``amplitude``.
    amplitude : ndarray (na,)
        Displacement amplitude of ``ref_dof`` [m].
    frequency_hz, damping_ratio : ndarray (na,)
    shapes : ndarray (na, n)
        Equivalent-linear mode shape at each amplitude (``shape[ref_dof] = 1``).
    joint_amplitude, k_eq, energy : ndarray (na, n_joints)
        Each joint's relative-displacement amplitude [m], equivalent stiffness [N/m] and
        energy dissipated per cycle [J].
    viscous_energy : ndarray (na,)
        Energy ``C`` dissipates per cycle [J].
    iterations : ndarray (na,) of int
        Fixed-point iterations of mode shape and ``k_eq``.
    """

    mode: int
    ref_dof: int
    amplitude: np.ndarray
    frequency_hz: np.ndarray
    damping_ratio: np.ndarray
    shapes: np.ndarray
    joint_amplitude: np.ndarray
    k_eq: np.ndarray
    energy: np.ndarray
    viscous_energy: np.ndarray
    iterations: np.ndarray = field(default_factory=lambda: np.zeros(0, int))

    def to_dict(self) -> dict[str, Any]:
        return {
            "mode": self.mode,
            "ref_dof": self.ref_dof,
            "amplitude": self.amplitude.tolist(),
            "frequency_hz": self.frequency_hz.tolist(),
            "damping_ratio": self.damping_ratio.tolist(),
            "shapes": self.shapes.tolist(),
            "joint_amplitude": self.joint_amplitude.tolist(),
            "k_eq": self.k_eq.tolist(),
            "energy": self.energy.tolist(),
            "viscous_energy": self.viscous_energy.tolist(),
            "iterations": self.iterations.tolist(),
            "units": {
                "amplitude": "m",
                "frequency_hz": "Hz",
                "joint_amplitude": "m",
                "k_eq": "N/m",
                "energy": "J",
                "viscous_energy": "J",
            },
        }


class _JointTable:
    """``k_eq`` and loop energy of one joint at an amplitude (quasi-static loop by the core,
    remembered per amplitude)."""

    def __init__(self, joint: Any) -> None:
        self.joint = joint
        self.k0 = float(joint.initial_stiffness)
        self.cache: dict[float, tuple[float, float]] = {}

    def __call__(self, amp: float) -> tuple[float, float]:
        if amp <= 0.0:
            return self.k0, 0.0
        key = float(f"{amp:.10g}")
        if key not in self.cache:
            from .amplitude import joint_loop, loop_keq_energy

            s = Structure(1.0, 0.0, 0.0)
            s.add_joint(self.joint.kind, 0, None, **self.joint.params, **self.joint.arrays)
            _, keq, energy = loop_keq_energy(*joint_loop(s, key))
            self.cache[key] = (keq, energy)
        return self.cache[key]


def _direction(j: Any, n: int) -> np.ndarray:
    b = np.zeros(n)
    b[j.dof] = 1.0
    if j.dof2 is not None:
        b[j.dof2] = -1.0
    return b


def modal_amplitude_dependence(
    structure: Structure,
    amplitudes: Any,
    mode: int = 0,
    *,
    ref_dof: int | None = None,
    tol: float = 1e-9,
    max_iter: int = 200,
) -> ModalAmplitudeDependence:
    """Frequency [Hz] and damping ratio of mode ``mode`` versus its amplitude [m].

    Parameters
    ----------
    structure : Structure
        Any number of DOFs, any joints except Kelvin-Voigt (rate-dependent: put its ``k``
        and ``c`` into the structure).
    amplitudes : array_like
        Displacement amplitudes of ``ref_dof`` [m].
    mode : int
        Mode index, ascending in linearised (virgin-state) frequency.
    ref_dof : int, optional
        The DOF the amplitude refers to (default: the largest component of the linearised
        mode shape).

    Examples
    --------
    >>> s = Structure([[1.0, 0.0], [0.0, 0.5]], [[3.0, -1.0], [-1.0, 1.0]],
    ...               [[6e3, -2e3], [-2e3, 2e3]])
    >>> _ = s.add_joint("jenkins", 0, None, k=2e3, fs=1.0)
    >>> ad = modal_amplitude_dependence(s, [1e-5, 1e-1], mode=0)
    >>> [round(float(f), 3) for f in ad.frequency_hz]  # stuck joint → joint slipping
    [8.015, 7.12]
    """
    from .amplitude import checked_amplitudes

    a = checked_amplitudes(structure, amplitudes, "modal_amplitude_dependence")
    n = structure.n
    mode = int(mode)
    if not 0 <= mode < n:
        raise InputError(f"mode = {mode} is outside 0..{n - 1}")
    M, C, K = structure.M, structure.C, structure.K
    joints = structure.joints
    B = [_direction(j, n) for j in joints]
    tables = [_JointTable(j) for j in joints]
    k_lin = K + sum(
        (t.k0 * np.outer(b, b) for t, b in zip(tables, B, strict=True)), np.zeros((n, n))
    )
    phi0 = _mode(M, k_lin, mode, None)[1]
    if ref_dof is None:
        ref_dof = int(np.argmax(np.abs(phi0)))
    elif not 0 <= int(ref_dof) < n:
        raise InputError(f"ref_dof = {ref_dof} is outside 0..{n - 1}")
    ref = int(ref_dof)
    if abs(phi0[ref]) < 1e-9 * np.max(np.abs(phi0)):
        raise InputError(f"DOF {ref} does not move in mode {mode}: choose another ref_dof")
    nj, na = len(joints), a.size
    out = {k: np.zeros((na, nj)) for k in ("A", "keq", "E")}
    freq, zeta, ev = np.zeros(na), np.zeros(na), np.zeros(na)
    shapes, iters = np.zeros((na, n)), np.zeros(na, int)
    phi = phi0 / phi0[ref]
    for i, ai in enumerate(a):
        w2 = np.nan
        for it in range(1, max_iter + 1):
            A = np.array([ai * abs(float(b @ phi)) for b in B])
            ke = np.array([tb(float(x))[0] for tb, x in zip(tables, A, strict=True)])
            Keq = K + sum(
                (k * np.outer(b, b) for k, b in zip(ke, B, strict=True)), np.zeros((n, n))
            )
            w2_new, phi_new = _mode(M, Keq, mode, phi)
            phi_new = phi_new / phi_new[ref]
            change = float(np.max(np.abs(phi_new - phi))) + abs(w2_new - w2) / w2_new
            relax = 1.0 if it <= 30 else 0.5  # a slow or cycling fixed point: damp it
            phi = phi + relax * (phi_new - phi)
            w2 = w2_new
            if change < tol:
                break
        else:
            raise ConvergenceError(
                f"mode {mode} at amplitude {ai:g} m: mode shape and equivalent stiffness did "
                f"not settle in {max_iter} iterations (last change {change:.3g})"
            )
        A = np.array([ai * abs(float(b @ phi)) for b in B])
        vals = [tb(float(x)) for tb, x in zip(tables, A, strict=True)]
        ke = np.array([v[0] for v in vals])
        E = np.array([v[1] for v in vals])
        Keq = K + sum((k * np.outer(b, b) for k, b in zip(ke, B, strict=True)), np.zeros((n, n)))
        w = float(np.sqrt(w2))
        x = ai * phi
        e_visc = float(np.pi * w * (x @ C @ x))
        strain = 0.5 * float(x @ Keq @ x)
        freq[i], zeta[i], ev[i] = w / (2 * np.pi), (e_visc + E.sum()) / (4 * np.pi * strain), e_visc
        shapes[i], iters[i] = phi, it
        out["A"][i], out["keq"][i], out["E"][i] = A, ke, E
    return ModalAmplitudeDependence(
        mode=mode,
        ref_dof=ref,
        amplitude=a.copy(),
        frequency_hz=freq,
        damping_ratio=zeta,
        shapes=shapes,
        joint_amplitude=out["A"],
        k_eq=out["keq"],
        energy=out["E"],
        viscous_energy=ev,
        iterations=iters,
    )


def _mode(M: np.ndarray, K: np.ndarray, mode: int, prev: np.ndarray | None) -> tuple[float, Any]:
    """``(ω², φ)`` of mode ``mode`` (by index, or the one most like ``prev``: modes may
    swap order as the joints soften)."""
    try:
        w2, phi = scipy.linalg.eigh(K, M)
    except np.linalg.LinAlgError as exc:
        raise InputError(f"M must be symmetric positive definite: {exc}") from None
    i = mode
    if prev is not None:
        mac = (prev @ M @ phi) ** 2 / np.einsum("ij,ik,kj->j", phi, M, phi)
        i = int(np.argmax(mac))
    if not w2[i] > 0:
        raise InputError(
            f"the equivalent stiffness is not positive definite in mode {mode} "
            f"(ω² = {w2[i]:.4g}): a rigid-body mode once the joints slip"
        )
    return float(w2[i]), phi[:, i]


@dataclass
class PhaseResonance:
    """A mode's frequency and damping ratio measured on a periodic steady state (stepped
    sine at phase resonance): ``amplitude`` of the reference DOF [m], ``frequency_hz``,
    ``damping_ratio`` (input work per cycle / (4π · max kinetic energy)), ``force``
    amplitude vector [N] and the first-harmonic response ``response`` (complex, per DOF)."""

    mode: int
    ref_dof: int
    amplitude: float
    frequency_hz: float
    damping_ratio: float
    force: np.ndarray
    response: np.ndarray
    runs: int


def phase_resonance(
    structure: Structure,
    amplitude: float,
    mode: int = 0,
    *,
    samples_per_period: int = 256,
    rel_tol: float = 1e-6,
) -> PhaseResonance:
    """Phase resonance of ``mode`` by periodic steady-state simulation (stepped sine).

    The force ``F0 M φ sin ωt`` (``φ``: the equivalent-linear mode shape at ``amplitude``,
    ``F0`` from its predicted damping so that the reference DOF reaches about
    ``amplitude``) is applied, and ``ω`` is adjusted by bisection until the reference DOF's
    first harmonic is in quadrature with the force. Then the frequency is the mode's natural
    frequency at the response amplitude, and the damping ratio is the work of the force over
    one period divided by ``4π`` times the maximum kinetic energy ``½ ω² xᵀ M x`` of the
    first harmonic (equal to the maximum strain energy at resonance). This measures what
    :func:`modal_amplitude_dependence` predicts, from the time integration alone.
    """
    ad = modal_amplitude_dependence(structure, [amplitude], mode=mode)
    phi, ref = ad.shapes[0], ad.ref_dof
    f0, z0 = float(ad.frequency_hz[0]), float(ad.damping_ratio[0])
    if not z0 > 0:
        raise InputError("phase_resonance needs a damped mode (ζ > 0 predicted)")
    p = structure.M @ phi * (2.0 * z0 * (2 * np.pi * f0) ** 2 * float(amplitude))
    npp = int(samples_per_period)
    if npp < 16:
        raise InputError(f"samples_per_period must be >= 16, got {npp}")
    phase = np.exp(-2j * np.pi * np.arange(npp) / npp)
    runs = 0

    def run(f: float) -> tuple[np.ndarray, Any]:
        nonlocal runs
        runs += 1
        t = np.arange(npp) / (npp * f)
        r = structure.simulate(
            t,
            force=np.outer(np.sin(2 * np.pi * f * t), p),
            periodic=True,
            periodic_tol=1e-7,
            max_periods=1024,
            substeps=1,  # fixed steps, as the resonance search was calibrated with
        )
        if not r.success:
            raise ConvergenceError(f"phase_resonance at {f:.6g} Hz: {r.message}")
        x = np.asarray(r.x).reshape(npp, -1)
        return 2.0 * (phase @ x) / npp, r  # x ≈ Re(X e^{iωt})

    def in_phase(f: float) -> float:
        return float(-run(f)[0][ref].imag)  # the part of x_ref along sin ωt (the force)

    # bracket between the neighbouring modes (of the equivalent-linear structure): the phase
    # of x_ref turns through every resonance on the way
    keq = structure.K + sum(
        (
            k * np.outer(bj, bj)
            for k, bj in zip(
                ad.k_eq[0], [_direction(j, structure.n) for j in structure.joints], strict=True
            )
        ),
        np.zeros_like(structure.K),
    )
    fr = np.sqrt(np.abs(scipy.linalg.eigh(keq, structure.M, eigvals_only=True))) / (2 * np.pi)
    i0 = int(np.argmin(np.abs(fr - f0)))
    lo = max(0.5 * f0, float(np.sqrt(fr[i0 - 1] * f0)) if i0 > 0 else 0.0)
    hi = min(1.5 * f0, float(np.sqrt(fr[i0 + 1] * f0)) if i0 + 1 < fr.size else np.inf)
    g_lo, g_hi = in_phase(lo), in_phase(hi)
    if not g_lo * g_hi < 0:
        raise ConvergenceError(
            f"phase_resonance: no phase resonance of mode {mode} between {lo:.4g} and {hi:.4g} Hz"
        )
    while hi - lo > rel_tol * f0:
        mid = 0.5 * (lo + hi)
        g = in_phase(mid)
        if g * g_lo > 0:
            lo, g_lo = mid, g
        else:
            hi = mid
    f = 0.5 * (lo + hi)
    X, r = run(f)
    w = 2 * np.pi * f
    xa = (X * np.conj(X[ref]) / abs(X[ref])).real
    # the force's work over one period: the rectangle rule is exact to rounding for the
    # periodic integrand's harmonics below npp / 2
    v = np.asarray(r.v).reshape(npp, -1)
    work = float(np.sum(np.sin(w * r.t) * (v @ p))) / (npp * f)
    zeta = work / (4 * np.pi * 0.5 * w * w * float(xa @ structure.M @ xa))
    return PhaseResonance(mode, ref, float(abs(X[ref])), f, zeta, p, X, runs)


# moved to the report layer (issue 32): the old names warn and forward
__getattr__ = forward(
    __name__, {"plot_modal_amplitude_dependence": "contactlab.report.structure_plots"}
)
