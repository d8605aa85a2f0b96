"""Physical units of recorded channels and their conversion to SI.

Column names may carry their unit, as test rigs write them: ``x [um]``, ``F (N)``, ``p [MPa]``,
``t_ms``. :func:`split_name` separates name and unit; :func:`to_si` gives the factor to SI and
the dimension, so a channel in the wrong kind of unit (a force in mm) is caught.
"""

from __future__ import annotations

import re

from ..errors import InputError

# dimension -> SI unit
SI_UNITS = {
    "time": "s",
    "length": "m",
    "force": "N",
    "pressure": "Pa",
    "dimensionless": "",
    "frequency": "Hz",
    "rate": "1/s",
    "angular frequency": "rad/s",
    "inverse length": "1/m",
    "energy": "J",
    "stiffness": "N/m",
}

# The one unit table of the package (channel units of recordings here, tag units of study
# manifests in contactlab.studies.manifest): normalised spelling -> (factor to SI, dimension).
# Micro is written u, µ (micro sign U+00B5) or μ (Greek mu U+03BC); normalize() maps both to u.
_TABLE: dict[str, tuple[float, str]] = {}


def _add(dim: str, names: tuple[str, ...], factor: float) -> None:
    for n in names:
        _TABLE[normalize(n)] = (factor, dim)


def normalize(unit: str) -> str:
    return unit.strip().replace(" ", "").replace("µ", "u").replace("μ", "u").lower()


_add("time", ("s", "sec", "second", "seconds"), 1.0)
_add("time", ("ms", "msec", "millisecond", "milliseconds"), 1e-3)
_add("time", ("us", "usec", "microsecond", "microseconds"), 1e-6)
_add("time", ("ns",), 1e-9)
_add("time", ("min",), 60.0)
_add("length", ("m", "meter", "metre"), 1.0)
_add("length", ("mm", "millimeter", "millimetre"), 1e-3)
_add("length", ("um", "micron", "microns", "micrometer"), 1e-6)
_add("length", ("nm", "nanometer", "nanometre"), 1e-9)
# US customary units, exact by definition (international yard and pound, 1959): 1 in =
# 0.0254 m, 1 mil = 0.001 in, 1 lbf = 0.45359237 kg x 9.80665 m/s^2 (standard gravity),
# 1 kip = 1000 lbf, 1 psi = 1 lbf/in^2, 1 ksi = 1000 psi
_INCH = 0.0254
_LBF = 0.45359237 * 9.80665
_add("length", ("in", "inch", "inches"), _INCH)
_add("length", ("mil", "mils", "thou"), _INCH * 1e-3)
_add("force", ("n", "newton", "newtons"), 1.0)
_add("force", ("mn",), 1e-3)
_add("force", ("un",), 1e-6)
_add("force", ("lbf",), _LBF)
_add("force", ("kip", "kips", "klbf"), _LBF * 1e3)
_add("force", ("kn", "kilonewton"), 1e3)
_add("pressure", ("pa", "n/m2", "n/m^2", "n/m²"), 1.0)
_add("pressure", ("kpa",), 1e3)
_add("pressure", ("mpa", "n/mm2", "n/mm^2", "n/mm²"), 1e6)
_add("pressure", ("gpa",), 1e9)
_add("pressure", ("bar",), 1e5)
_add("pressure", ("mbar",), 1e2)
_add("pressure", ("psi", "lbf/in2", "lbf/in^2", "lbf/in²"), _LBF / _INCH**2)
_add("pressure", ("ksi",), _LBF / _INCH**2 * 1e3)
_add("dimensionless", ("", "-", "1"), 1.0)
_add("frequency", ("Hz",), 1.0)
_add("frequency", ("kHz",), 1e3)
_add("rate", ("1/s",), 1.0)
_add("angular frequency", ("rad/s",), 1.0)
_add("inverse length", ("1/m",), 1.0)
_add("inverse length", ("1/mm",), 1e3)
_add("inverse length", ("1/um",), 1e6)
_add("energy", ("J",), 1.0)
_add("energy", ("mJ",), 1e-3)
_add("energy", ("uJ",), 1e-6)
_add("stiffness", ("N/m",), 1.0)
_add("stiffness", ("N/mm",), 1e3)
_add("stiffness", ("N/um",), 1e6)
_add("stiffness", ("kN/mm",), 1e6)
_add("stiffness", ("lbf/in",), _LBF / _INCH)

# Case is ignored ("Pa", "pa", "MPA" are the same; all-caps headers such as "MM" or "MS" mean
# mm and ms; "m" is metre, minute is "min") except where the capital could be a real mega
# unit: "MN" (meganewton), "MJ" (megajoule) and "Mbar" are unknown rather than read as mN,
# mJ and mbar, 10^9 times too small.
_MILLI = {"mn", "mj", "mbar"}
#: units not taken from a ``name_unit`` suffix: ``F_in`` is more often an input force than a
#: force in inches (``F [in]`` and ``F / in`` are read as written)
_NO_SUFFIX = {"in"}


class UnknownUnitError(InputError):
    """A unit string that contactlab does not know."""


def known_units() -> list[str]:
    """Every unit string accepted (case-insensitive)."""
    return sorted(_TABLE)


def lookup(unit: str) -> tuple[float, str] | None:
    """``(factor to SI, dimension)`` of ``unit``, or None when it is not known."""
    key = normalize(unit)
    if key in _MILLI and not unit.strip().startswith("m"):
        return None
    return _TABLE.get(key)


def to_si(unit: str, *, where: str = "") -> tuple[float, str]:
    """Factor that converts values in ``unit`` to SI, and the unit's dimension.

    Raises
    ------
    UnknownUnitError
        Naming the unit and ``where`` it was found.

    Examples
    --------
    >>> to_si("um")
    (1e-06, 'length')
    >>> to_si("MPa")
    (1000000.0, 'pressure')
    """
    hit = lookup(unit)
    if hit is None:
        loc = f" in {where}" if where else ""
        raise UnknownUnitError(
            f"unknown unit {unit!r}{loc}; known units: s, ms, us, m, mm, um, nm, in, mil, N, "
            "mN, uN, kN, lbf, kip, Pa, kPa, MPa, GPa, bar, psi, ksi, N/mm2 (µ may be written u)"
        )
    return hit


_BRACKET = re.compile(r"^\s*(?P<name>.*?)\s*[\[(](?P<unit>[^\])]*)[\])]\s*$")
_SLASH = re.compile(r"^\s*(?P<name>[^/]+?)\s*/\s*(?P<unit>[A-Za-zµμ][A-Za-z0-9µμ/^²]*)\s*$")
_SUFFIX = re.compile(r"^(?P<name>.+?)_(?P<unit>[A-Za-zµμ]+)$")


def split_name(column: str) -> tuple[str, str | None]:
    """Split ``"x [um]"``, ``"x (um)"``, ``"x / um"`` or ``"x_um"`` into ``("x", "um")``.

    A bracketed unit is returned even when unknown (so that it can be reported); the slash and
    underscore forms are recognised only with a known unit (``"F_tan"`` stays a plain name).

    Examples
    --------
    >>> split_name("t [ms]")
    ('t', 'ms')
    >>> split_name("force")
    ('force', None)
    >>> split_name("x_um")
    ('x', 'um')
    """
    m = _BRACKET.match(column)
    if m and m.group("name"):
        return m.group("name"), m.group("unit").strip()
    for rx in (_SLASH, _SUFFIX):
        m = rx.match(column)
        if rx is _SUFFIX and m and normalize(m.group("unit")) in _NO_SUFFIX:
            continue
        if m and lookup(m.group("unit")) is not None:
            return m.group("name").strip(), m.group("unit")
    return column.strip(), None
