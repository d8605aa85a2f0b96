"""Checks that run CalculiX on the exported joint characteristics.

- :func:`check_normal`: static pressure ramp on the two-block model carrying the exported
  pressure–overclosure table. The (overclosure, pressure) pairs CalculiX reports must lie on
  the exported curve, and the top displacement must equal the analytic series combination of
  the two blocks and the joint, ``2·p·H/E + u_joint(p)``.
- :func:`check_tangential`: cyclic shear at given amplitudes under a constant normal load with
  the exported ``*FRICTION`` (elastic Coulomb). Its loop is bilinear, so the dissipated energy
  per cycle must be Jenkins' ``4·F_s·(A − F_s/k)`` (F_s = μW, k = λ·A_c); the report puts the
  fitted Masing energy at the same amplitude beside it — the FE friction law is not the
  fitted contact, and the user must see by how much.
- :func:`check_dynamics`: first natural frequency of a pinned beam whose tip rests on the
  exported joint spring, CalculiX ``*FREQUENCY`` against ``contactlab.structure``'s
  ``Structure(M, C, K).modes()`` of the same beam (Hermite elements, the joint spring and
  dashpot as a Kelvin–Voigt joint) and the Euler–Bernoulli closed form
  ``EI β³ (sin βL coth βL − cos βL) = 2 k sin βL`` (ω = β² √(EI/m)).

All models are built in mm-N-s (mm, N, s, t; MPa) from the file text the exporter writes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.optimize import brentq

from ..errors import InputError
from ..masing import Masing
from .ccx import run_ccx
from .characteristics import JointCharacteristics, joint_characteristics
from .models import Beam, Block, beam_deck, two_block_deck
from .units import unit_system
from .writers import render

_MM = unit_system("mm-N-s")


def interaction_lines(text: str) -> list[str]:
    """The exported keyword lines that belong inside ``*SURFACE INTERACTION`` (no header)."""
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.startswith("**")]
    if lines and lines[0].upper().startswith("*SURFACE INTERACTION"):
        lines = lines[1:]
    out = []
    for ln in lines:
        if ln.upper().startswith(("*SPRING", "*DASHPOT")):
            break
        out.append(ln)
    return out


def _joint_lines(text: str) -> list[str]:
    """The exported ``*SPRING``/``*DASHPOT`` cards, blank data lines kept."""
    lines = text.splitlines()
    start = next((i for i, ln in enumerate(lines) if ln.upper().startswith("*SPRING")), None)
    if start is None:
        raise InputError("the export holds no *SPRING card (give an amplitude and frequency)")
    return [ln for ln in lines[start:] if not ln.startswith("**")]


@dataclass
class NormalCheck:
    """Result of :func:`check_normal` (model units mm, MPa)."""

    pressure: np.ndarray
    overclosure: np.ndarray
    table_pressure_error: float  # max |p_FE − p_table(u_FE)| / table pressure range
    poly_error: float  # max |p_table − p_fit| / range on the table's measured rows
    top_displacement: np.ndarray
    analytic_displacement: np.ndarray
    compliance_error: float  # max relative error of the top displacement
    block_share: float  # the blocks' part of the analytic top displacement at the last step
    seconds: float
    notes: list[str] = field(default_factory=list)

    def report(self) -> str:
        return (
            f"normal check (CalculiX, {self.seconds:.2f} s, {self.pressure.size} increments): "
            f"contact pressure vs exported curve max error {100 * self.table_pressure_error:.3g}"
            f"% of range; table vs fitted loading branch {100 * self.poly_error:.3g}% of range; "
            f"top displacement vs series 2pH/E + u_joint(p) (blocks' share "
            f"{100 * self.block_share:.0f}%): max {100 * self.compliance_error:.3g}%"
        )

    def to_dict(self) -> dict[str, Any]:
        return {
            "table_pressure_error": self.table_pressure_error,
            "poly_error": self.poly_error,
            "compliance_error": self.compliance_error,
            "block_share": self.block_share,
            "seconds": self.seconds,
            "increments": int(self.pressure.size),
        }


def check_normal(
    result: dict[str, Any], *, block: Block | None = None, increments: int = 20, points: int = 25
) -> NormalCheck:
    """Run the two-block pressure ramp with the table exported from ``result`` (normal).

    By default the blocks (steel, 10 mm × 10 mm) are made as tall as it takes for their
    compliance to equal the joint's at the top of the ramp.
    """
    jc = joint_characteristics(result, points=points)
    if jc.table is None:
        raise InputError("check_normal needs a normal-contact result")
    text = render(jc, "calculix", _MM)
    inter = interaction_lines(text)
    inter = [ln for ln in inter if not ln.upper().startswith("*CONTACT DAMPING")]
    inter = inter[: 1 + len(jc.table)]  # static check: the table alone (damping needs velocity)
    tab = np.array([[float(v) for v in ln.split(",")] for ln in inter[1:]])
    p_top = 0.98 * float(tab[-1, 0])  # stay inside the table (constant beyond it in CalculiX)
    if block is None:
        # blocks as compliant as the joint at the top of the ramp: the series sum is tested
        # with both terms of the same size
        u_top = float(np.interp(p_top, tab[:, 0], tab[:, 1]))
        block = Block(height=u_top * 210000.0 / (2 * p_top))
    b = block
    run = run_ccx(two_block_deck(b, inter, mode="normal", pressure=p_top, increments=increments))
    t, cstr = run.dat.series("contact stress")
    _, cdis = run.dat.series("relative contact displacement")
    _, u = run.dat.series("displacements", "NTOP")
    if t.size != increments:
        raise InputError(f"CalculiX printed {t.size} increments, expected {increments}")
    p_fe = np.array([float(np.mean(c[:, 1])) for c in cstr])
    u_fe = np.array([float(np.mean(np.abs(c[:, 1]))) for c in cdis])
    rng = float(tab[-1, 0] - tab[0, 0])
    err_tab = float(np.max(np.abs(p_fe - np.interp(u_fe, tab[:, 1], tab[:, 0]))) / rng)
    # The table against the fitted polynomial it came from, between its measured rows.
    coeffs = [float(c) for c in result["poly_load"]]
    p0 = float(result["p0"])
    uu = np.linspace(tab[1, 1], tab[-1, 1], 400)
    d_at_zero = float(result["delta_max"]) * 1e3 - tab[-1, 1]  # δ (mm) where the table's u = 0
    p_fit = (p0 + np.polynomial.polynomial.polyval((uu + d_at_zero) * 1e-3, coeffs)) * 1e-6
    err_poly = float(np.max(np.abs(np.interp(uu, tab[:, 1], tab[:, 0]) - p_fit)) / rng)
    top = np.array([-float(np.mean(d[:, 3])) for d in u])
    p_applied = p_top * t
    analytic = 2 * p_applied * b.height / b.E + np.interp(p_applied, tab[:, 0], tab[:, 1])
    comp = float(np.max(np.abs(top - analytic) / analytic))
    share = float(2 * p_top * b.height / b.E / analytic[-1])
    return NormalCheck(
        p_fe, u_fe, err_tab, err_poly, top, analytic, comp, share, run.seconds, jc.notes
    )


@dataclass
class TangentialCheck:
    """Result of :func:`check_tangential` (SI in the table of :meth:`rows`)."""

    amplitudes: list[float]  # m
    energy_fe: list[float]  # J
    energy_jenkins: list[float]  # J
    energy_masing: list[float]  # J
    slip_force: float  # N
    stiffness: float  # N/m
    seconds: float
    loops: list[tuple[np.ndarray, np.ndarray]] = field(default_factory=list, repr=False)

    @property
    def errors(self) -> list[float]:
        return [abs(f - j) / j for f, j in zip(self.energy_fe, self.energy_jenkins, strict=True)]

    def report(self) -> str:
        lines = [
            f"tangential check (CalculiX elastic Coulomb, {self.seconds:.2f} s): "
            f"F_s = μW = {self.slip_force:.5g} N, k = λ·A_c = {self.stiffness:.5g} N/m",
            f"{'A [um]':>8} {'E_FE [J]':>12} {'E_Jenkins [J]':>14} {'error':>8} "
            f"{'E_Masing [J]':>13} {'Masing/FE':>10}",
        ]
        for a, f, j, m, e in zip(
            self.amplitudes,
            self.energy_fe,
            self.energy_jenkins,
            self.energy_masing,
            self.errors,
            strict=True,
        ):
            lines.append(
                f"{a * 1e6:8.4g} {f:12.5g} {j:14.5g} {100 * e:7.3g}% {m:13.5g} {m / f:10.3g}"
            )
        lines.append(
            "the FE law (bilinear, Jenkins) and the fitted Masing contact dissipate "
            "different energies: Masing/FE is the factor the FE model misses"
        )
        return "\n".join(lines)

    def to_dict(self) -> dict[str, Any]:
        return {
            "amplitudes": self.amplitudes,
            "energy_fe": self.energy_fe,
            "energy_jenkins": self.energy_jenkins,
            "energy_masing": self.energy_masing,
            "errors": self.errors,
            "seconds": self.seconds,
        }


def loop_energy(x: np.ndarray, f: np.ndarray) -> float:
    """Area of the closed polygon (x, f) (shoelace), the energy of one cycle."""
    return 0.5 * abs(float(np.dot(x, np.roll(f, -1)) - np.dot(f, np.roll(x, -1))))


def check_tangential(
    result: dict[str, Any],
    *,
    area: float,
    normal_load: float,
    amplitudes: tuple[float, ...] | None = None,
    increment: float = 0.1,
) -> TangentialCheck:
    """Cyclic shear of the two-block model with the exported ``*FRICTION`` (SI arguments).

    ``area`` (m²) sets the blocks' footprint; ``amplitudes`` (m) default to 2 and 4 times the
    elastic slip F_s/k = 1/ac; ``increment`` is the largest solver step as a fraction of a
    quarter cycle (0.1: the loop energy is within 0.1 % of the 0.025 result).
    """
    jc = joint_characteristics(result, area=area, normal_load=normal_load)
    text = render(jc, "calculix", _MM)
    friction = interaction_lines(text)
    mu, lam = (float(v) for v in friction[-1].split(","))  # as written: μ, λ in N/mm³
    side = math.sqrt(area) * 1e3  # mm
    b = Block(size=side, height=side / 2, n=2, m=1, nu=0.0)
    fs, k = mu * normal_load, lam * b.area  # N, N/mm
    amps_mm = [a * 1e3 for a in amplitudes] if amplitudes else [2 * fs / k, 4 * fs / k]
    inter = ["*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR", f"{100 * lam:.9g}", *friction]
    deck = two_block_deck(
        b,
        inter,
        mode="shear",
        pressure=normal_load / b.area,
        amplitudes=amps_mm,
        cycles=1,
        increment=increment,
    )
    run = run_ccx(deck)
    t_rf, rf = run.dat.series("total force", "NB")
    t_u, u = run.dat.series("displacements", "NTOP")
    period = 5.0
    e_fe, e_j, e_m, loops = [], [], [], []
    model = Masing(float(result["h0"]), float(result["ac"]))
    for j, a in enumerate(amps_mm):
        tau = t_rf - 1.0 - j * period
        sel = (tau >= 1.0 - 1e-6) & (tau <= period + 1e-6)  # the cycle A → −A → A
        x = np.array([float(np.mean(d[:, 1])) for d, s in zip(u, sel, strict=True) if s])
        f = np.array([float(r[0, 0]) for r, s in zip(rf, sel, strict=True) if s])
        if x.size < 20:
            raise InputError(f"CalculiX printed only {x.size} points of the cycle at A = {a} mm")
        loops.append((x * 1e-3, f))
        e_fe.append(loop_energy(x, f) * 1e-3)  # N·mm → J
        e_j.append(4 * fs * (a - fs / k) * 1e-3)
        e_m.append(float(model.loop_energy(a * 1e-3)))
    if not np.allclose(t_u, t_rf):
        raise InputError("CalculiX printed forces and displacements at different times")
    return TangentialCheck(
        [a * 1e-3 for a in amps_mm], e_fe, e_j, e_m, fs, k * 1e3, run.seconds, loops
    )


@dataclass
class DynamicsCheck:
    """Result of :func:`check_dynamics`: CalculiX's first frequency against the reference
    (``contactlab.structure`` when installed, else the closed form), both references kept."""

    frequency_fe: float  # Hz
    frequency_reference: float  # Hz
    reference: str
    spring: float  # N/m
    beam: Beam
    seconds: float
    frequency_closed_form: float = math.nan  # Hz
    damping_ratio: float = math.nan  # structure's modal ζ of mode 1 with the joint dashpot

    @property
    def error(self) -> float:
        return abs(self.frequency_fe - self.frequency_reference) / self.frequency_reference

    def report(self) -> str:
        b = self.beam
        ratio = self.spring * 1e-3 * b.length**3 / b.EI
        return (
            f"dynamics check (CalculiX *FREQUENCY, {self.seconds:.2f} s): beam "
            f"{b.length:.4g} mm × {b.side:.3g} mm square, joint spring {self.spring:.5g} N/m "
            f"(kL³/EI = {ratio:.3g}): f1 = {self.frequency_fe:.6g} Hz vs {self.reference} "
            f"{self.frequency_reference:.6g} Hz, error {100 * self.error:.3g}% (closed form "
            f"{self.frequency_closed_form:.6g} Hz; modal damping ratio with the joint "
            f"dashpot {self.damping_ratio:.3g})"
        )

    def to_dict(self) -> dict[str, Any]:
        return {
            "frequency_fe": self.frequency_fe,
            "frequency_reference": self.frequency_reference,
            "reference": self.reference,
            "error": self.error,
            "frequency_closed_form": self.frequency_closed_form,
            "damping_ratio": self.damping_ratio,
            "spring": self.spring,
            "seconds": self.seconds,
        }


def structure_beam_modes(beam: Beam, k: float, c: float, n: int = 40) -> Any:
    """Modes of the same beam from :class:`contactlab.structure.Structure` (SI).

    Euler–Bernoulli Hermite elements (consistent mass), deflection held at x = 0, the joint as
    a Kelvin–Voigt joint (``k`` N/m, ``c`` N·s/m) from the tip deflection to ground. Raises
    ImportError when ``contactlab.structure`` is not installed.
    """
    from ..structure import Structure

    L, EI = beam.length * 1e-3, beam.EI * 1e-6  # mm → m, N·mm² → N·m²
    m = beam.mass_per_length * 1e6  # t/mm → kg/m
    h = L / n
    ke = (
        EI
        / h**3
        * np.array(
            [
                [12, 6 * h, -12, 6 * h],
                [6 * h, 4 * h * h, -6 * h, 2 * h * h],
                [-12, -6 * h, 12, -6 * h],
                [6 * h, 2 * h * h, -6 * h, 4 * h * h],
            ]
        )
    )
    q = h * h
    me = (
        m
        * h
        / 420
        * np.array(
            [
                [156, 22 * h, 54, -13 * h],
                [22 * h, 4 * q, 13 * h, -3 * q],
                [54, 13 * h, 156, -22 * h],
                [-13 * h, -3 * q, -22 * h, 4 * q],
            ]
        )
    )
    size = 2 * (n + 1)
    K, M = np.zeros((size, size)), np.zeros((size, size))
    for e in range(n):
        s = slice(2 * e, 2 * e + 4)
        K[s, s] += ke
        M[s, s] += me
    keep = np.arange(1, size)  # deflection at x = 0 held
    st = Structure(M[np.ix_(keep, keep)], np.zeros((size - 1, size - 1)), K[np.ix_(keep, keep)])
    st.add_joint("kelvin_voigt", 2 * n - 1, k=k, c=c)  # tip deflection (index 2n before cut)
    return st.modes()


def pinned_spring_beam_frequency(beam: Beam, k: float) -> float:
    """First natural frequency (Hz) of a pinned Euler–Bernoulli beam with a tip spring ``k``.

    Units as the beam's (mm, N, t: k in N/mm). The root lies in (0, π/L): between the rigid
    rotation on a soft spring and the pinned–pinned beam.
    """
    L, EI = beam.length, beam.EI

    def g(x: float) -> float:
        beta = x / L
        return EI * beta**3 * (math.sin(x) / math.tanh(x) - math.cos(x)) - 2 * k * math.sin(x)

    x = brentq(g, 1e-9, math.pi, xtol=1e-14)
    beta = x / L
    return beta**2 * math.sqrt(EI / beam.mass_per_length) / (2 * math.pi)


def check_dynamics(
    result: dict[str, Any],
    *,
    area: float,
    normal_load: float,
    amplitude: float,
    frequency: float,
    n: int = 40,
) -> DynamicsCheck:
    """Beam on the exported joint spring k_global(A): CalculiX vs the closed form.

    The beam is sized so that the spring matters (kL³/EI = 40, slenderness L/side = 40).
    """
    jc: JointCharacteristics = joint_characteristics(
        result, area=area, normal_load=normal_load, amplitude=amplitude, frequency=frequency
    )
    text = render(jc, "calculix", _MM)
    joint = _joint_lines(text)
    k = float(joint[joint.index("*SPRING, ELSET=JOINT_SPRING") + 2])  # N/mm as written
    E = 210000.0
    L = 12 * 40**3 * k / E
    beam = Beam(length=L, side=L / 40, n=n, E=E)
    run = run_ccx(beam_deck(beam, joint, modes=3))
    if run.dat.eigen is None or run.dat.eigen.size == 0:
        raise InputError("CalculiX printed no eigenvalues")
    f_fe = float(run.dat.eigen[0, 3])
    f_closed = pinned_spring_beam_frequency(beam, k)
    c = float(joint[joint.index("*DASHPOT, ELSET=JOINT_DASHPOT") + 2])  # N·s/mm as written
    try:
        md = structure_beam_modes(beam, k * 1e3, c * 1e3, n=n)
    except ImportError:
        return DynamicsCheck(
            f_fe, f_closed, "Euler–Bernoulli closed form", k * 1e3, beam, run.seconds, f_closed
        )
    return DynamicsCheck(
        f_fe,
        float(md.frequency_hz[0]),
        "contactlab.structure modes()",
        k * 1e3,
        beam,
        run.seconds,
        f_closed,
        float(md.damping_ratio[0]),
    )
