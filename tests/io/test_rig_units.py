"""Units the rigs write (issue 31): uN, mN, kN, lbf, kip, in, mil, ms, psi, bar, N/mm²,
against the exact conversion factors of their definitions."""

from __future__ import annotations

import numpy as np
import pytest

from contactlab.errors import InputError
from contactlab.io import read_recording, split_name, to_si
from contactlab.studies.manifest import unit_factor

# exact by definition (NIST SP 811, appendix B): 1 lbf = 4.4482216152605 N,
# 1 in = 0.0254 m, 1 psi = 6894.757293168361 Pa (lbf / in²)
LBF = 4.4482216152605
INCH = 0.0254


@pytest.mark.parametrize(
    ("unit", "factor", "dim"),
    [
        ("uN", 1e-6, "force"), ("µN", 1e-6, "force"), ("μN", 1e-6, "force"),
        ("mN", 1e-3, "force"), ("kN", 1e3, "force"), ("lbf", LBF, "force"),
        ("kip", 1e3 * LBF, "force"), ("kips", 1e3 * LBF, "force"),
        ("in", INCH, "length"), ("inch", INCH, "length"), ("mil", INCH / 1000, "length"),
        ("ms", 1e-3, "time"), ("psi", LBF / INCH**2, "pressure"), ("bar", 1e5, "pressure"),
        ("N/mm²", 1e6, "pressure"), ("N/mm2", 1e6, "pressure"), ("N/mm^2", 1e6, "pressure"),
        ("ksi", 1e3 * LBF / INCH**2, "pressure"), ("lbf/in", LBF / INCH, "stiffness"),
    ],
)  # fmt: skip
def test_rig_units_have_their_exact_factors(unit, factor, dim):
    f, d = to_si(unit)
    assert d == dim
    assert f == pytest.approx(factor, rel=1e-15)
    assert unit_factor(unit, "here") == f  # the CLI's quantities and manifests read alike


def test_psi_against_its_published_value():
    # 1 psi = 6.894757293168361 kPa (NIST SP 811 B.9, exact to the digits shown)
    assert to_si("psi")[0] == pytest.approx(6894.757293168361, rel=1e-15)
    assert to_si("kip")[0] == pytest.approx(4448.2216152605, rel=1e-15)


@pytest.mark.parametrize("unit", ["MN", "Mbar"])
def test_mega_prefixed_stays_unknown(unit):
    with pytest.raises(InputError, match="unknown unit"):
        to_si(unit)


def test_a_suffix_in_is_not_inches():
    # ``F_in`` (an input force) keeps its name; the bracket form is read as written
    assert split_name("F_in") == ("F_in", None)
    assert split_name("x [in]") == ("x", "in")
    assert split_name("x_mil") == ("x", "mil")


def test_a_recording_in_us_units_reads_in_si(tmp_path):
    p = tmp_path / "rig.csv"
    p.write_text("t [ms],x [mil],F [lbf]\n0,0,0\n1,1,2\n2,2,4\n")
    rec = read_recording(p)
    np.testing.assert_allclose(rec.t, [0, 1e-3, 2e-3], rtol=1e-15)
    np.testing.assert_allclose(rec["x"], [0, 2.54e-5, 5.08e-5], rtol=1e-15)
    np.testing.assert_allclose(rec["F"], [0, 2 * LBF, 4 * LBF], rtol=1e-15)
    p2 = tmp_path / "press.csv"
    p2.write_text("t [s],p [psi],delta [in]\n0,100,0.001\n1,110,0.002\n")
    rec2 = read_recording(p2)
    np.testing.assert_allclose(rec2["p"], [100 * LBF / INCH**2, 110 * LBF / INCH**2])
    assert rec2.kind == "normal"
