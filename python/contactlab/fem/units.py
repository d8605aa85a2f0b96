"""Unit systems for exported joint characteristics.

An FE model must be in one consistent system; ``mm-N-s`` and ``mm-t-s`` are the same system
(1 N = 1 t·mm/s²) named by force or by mass, so both give pressures in MPa (N/mm²).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import InputError

#: dimension → (exponents of length, force, time), used to convert from SI
DIMENSIONS: dict[str, tuple[int, int, int]] = {
    "1": (0, 0, 0),
    "length": (1, 0, 0),
    "force": (0, 1, 0),
    "energy": (1, 1, 0),
    "pressure": (-2, 1, 0),
    "stiffness": (-1, 1, 0),
    "damping": (-1, 1, 1),
    "stiffness_per_area": (-3, 1, 0),
    "damping_per_area": (-3, 1, 1),
    "area": (2, 0, 0),
}

_LABELS = {
    "SI": {
        "1": "1",
        "length": "m",
        "force": "N",
        "energy": "J",
        "pressure": "Pa",
        "stiffness": "N/m",
        "damping": "N·s/m",
        "stiffness_per_area": "Pa/m",
        "damping_per_area": "Pa·s/m",
        "area": "m^2",
    },
    "mm": {
        "1": "1",
        "length": "mm",
        "force": "N",
        "energy": "N·mm",
        "pressure": "MPa",
        "stiffness": "N/mm",
        "damping": "N·s/mm",
        "stiffness_per_area": "MPa/mm",
        "damping_per_area": "MPa·s/mm",
        "area": "mm^2",
    },
}


@dataclass(frozen=True)
class UnitSystem:
    """A consistent unit system: ``length`` metres per unit length (force N, time s)."""

    name: str
    length: float

    def factor(self, dim: str) -> float:
        """Multiply an SI value of dimension ``dim`` by this to get it in this system."""
        e_len = DIMENSIONS[dim][0]
        return float(self.length ** (-e_len))

    def label(self, dim: str) -> str:
        return _LABELS["SI" if self.length == 1.0 else "mm"][dim]

    def describe(self) -> str:
        if self.length == 1.0:
            return "SI: m, N, s, kg (pressure Pa)"
        return f"{self.name}: mm, N, s, t (pressure MPa = N/mm^2)"


#: the export's file formats (:func:`contactlab.fem.writers.render`); here, beside the unit
#: systems, so that the command line's parser offers both without importing the writers
FORMATS = ("calculix", "abaqus", "ansys", "csv", "json")

SYSTEMS = {
    "SI": UnitSystem("SI", 1.0),
    "mm-N-s": UnitSystem("mm-N-s", 1e-3),
    "mm-t-s": UnitSystem("mm-t-s", 1e-3),
}


def unit_system(name: str) -> UnitSystem:
    """The unit system called ``name`` (``SI``, ``mm-N-s``, ``mm-t-s``; case-insensitive)."""
    for k, v in SYSTEMS.items():
        if k.lower() == str(name).lower():
            return v
    raise InputError(f"unknown unit system {name!r}; choose one of {', '.join(SYSTEMS)}")
