"""One unit table for recordings and study manifests (issue 13)."""

from __future__ import annotations

import pytest

from contactlab.errors import InputError
from contactlab.io import UnknownUnitError, known_units, to_si
from contactlab.io.units import SI_UNITS
from contactlab.studies.manifest import read_manifest, si_unit, unit_factor


@pytest.mark.parametrize("unit", known_units())
def test_manifest_and_recordings_read_every_unit_alike(unit):
    factor, dim = to_si(unit)
    assert unit_factor(unit, "here") == factor
    assert si_unit(unit) == SI_UNITS[dim]


@pytest.mark.parametrize(
    ("unit", "factor", "si"),
    [
        ("um", 1e-6, "m"), ("µm", 1e-6, "m"), ("μm", 1e-6, "m"), ("MPa", 1e6, "Pa"),
        ("Hz", 1.0, "Hz"), ("kHz", 1e3, "Hz"), ("1/s", 1.0, "1/s"), ("rad/s", 1.0, "rad/s"),
        ("1/um", 1e6, "1/m"), ("uJ", 1e-6, "J"), ("N/um", 1e6, "N/m"), ("-", 1.0, ""),
        ("mN", 1e-3, "N"), ("ms", 1e-3, "s"),
    ],
)  # fmt: skip
def test_manifest_units_kept_their_meaning(unit, factor, si):
    assert unit_factor(unit, "here") == factor
    assert si_unit(unit) == si


@pytest.mark.parametrize("unit", ["MN", "MJ", " MN "])
def test_mega_is_not_read_as_milli(unit):
    """Case-folding "MN" gave millinewton in recordings: 10^9 too small, silently."""
    with pytest.raises(UnknownUnitError, match=repr(unit)):
        to_si(unit)
    with pytest.raises(InputError, match=rf"col 2: unknown unit {unit!r}"):
        unit_factor(unit, "col 2")


@pytest.mark.parametrize(
    ("unit", "factor"), [("MM", 1e-3), ("MS", 1e-3), ("KN", 1e3), ("MPA", 1e6)]
)
def test_all_caps_headers_keep_their_meaning(unit, factor):
    assert to_si(unit)[0] == factor
    assert unit_factor(unit, "here") == factor


def test_manifest_header_in_a_recording_unit_spelling(tmp_path):
    (tmp_path / "a.csv").write_text("t,x,F\n0,0,0\n")
    (tmp_path / "m.csv").write_text("file,normal_load [kn],amplitude [micron]\na.csv,0.05,10\n")
    (entry,) = read_manifest(tmp_path / "m.csv")
    assert entry.tags["normal_load"] == pytest.approx(50.0)
    assert entry.tags["amplitude_nominal"] == pytest.approx(1e-5)
    assert entry.units == {"normal_load": "N", "amplitude_nominal": "m"}
