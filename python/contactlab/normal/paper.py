"""Konowalski (2009) reference values and the unit conversions between SI and the paper's units.

Everything in :mod:`contactlab.normal` works in SI (Pa, m, J/m², Pa/m). The paper prints
pressures in MPa and displacements in µm (so stiffness in MPa/µm and energy in MPa·µm = J/m²);
these helpers convert polynomial coefficients for display and for entering the paper's tables.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

#: Table 2 of the paper: loop curves p(δ) = a0 + a1 δ + … + a4 δ⁴, p in MPa, δ in µm
#: (p0 = 0.5 MPa, pa = 0.4 MPa, ω = 1 1/s), ascending coefficients.
TABLE2_MPA_UM: dict[str, tuple[float, ...]] = {
    "load": (0.01541, 1.33235, 1.49154, 2.28094, 1.57210),
    "centre": (0.0, 1.32596, 1.59811, 2.92127, 2.87416),
    "unload": (-0.01541, 1.31957, 1.70468, 3.56159, 4.17622),
}
TABLE2_P0 = 0.5e6  # Pa
TABLE2_PA = 0.4e6  # Pa
TABLE2_OMEGA = 1.0  # rad/s
#: The paper's linear-model inputs (section 5). PHYSICS.md §2 cautions that the Table 2 loop
#: does not reproduce them; they are kept only to rebuild the paper's comparison figures.
PAPER_K_TAN = 1.206e12  # Pa/m  (1.206 MPa/µm)
PAPER_PSI = 0.0887

MPA = 1e6
UM = 1e-6


def loop_poly_to_si(c: Sequence[float]) -> np.ndarray:
    """p(δ) coefficients from (MPa, µm) to (Pa, m): ``a_i · 1e6 · (1e6)^i``."""
    a = np.asarray(c, dtype=float)
    return a * MPA / UM ** np.arange(a.size)


def loop_poly_to_display(c: Sequence[float]) -> np.ndarray:
    """p(δ) coefficients from (Pa, m) to (MPa, µm), the inverse of :func:`loop_poly_to_si`."""
    a = np.asarray(c, dtype=float)
    return a / MPA * UM ** np.arange(a.size)


def ks_delta_to_display(c: Sequence[float]) -> np.ndarray:
    """k_s(δ) coefficients ``[a1, a2, …]`` (Pa/m, δ in m) to (MPa/µm, δ in µm)."""
    a = np.asarray(c, dtype=float)
    return a * UM / MPA * UM ** np.arange(a.size)


def ks_pressure_to_display(b: Sequence[float]) -> np.ndarray:
    """k_s(p) coefficients in eq. 16 order ``[b1, b2, b3, b4]`` (Pa/m, p in Pa) to
    (MPa/µm, p in MPa)."""
    a = np.asarray(b, dtype=float)
    powers = np.arange(a.size)[::-1]  # b1 multiplies p³ … b4 multiplies p⁰
    return a * UM / MPA * MPA**powers


def ks_pressure_to_si(b: Sequence[float]) -> np.ndarray:
    """Inverse of :func:`ks_pressure_to_display`."""
    a = np.asarray(b, dtype=float)
    powers = np.arange(a.size)[::-1]
    return a / (UM / MPA * MPA**powers)


def table2_si() -> dict[str, np.ndarray]:
    """Table 2 curves in SI (Pa as a polynomial of δ in m)."""
    return {k: loop_poly_to_si(v) for k, v in TABLE2_MPA_UM.items()}
