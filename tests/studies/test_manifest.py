"""Manifest parsing and file-name tagging (contactlab.studies.manifest)."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from contactlab import InputError
from contactlab.studies.manifest import (
    entry_from_file,
    read_manifest,
    tags_from_filename,
    unit_factor,
)


@pytest.mark.parametrize(
    ("unit", "factor"),
    [("um", 1e-6), ("µm", 1e-6), ("μm", 1e-6), ("mm", 1e-3), ("MPa", 1e6), ("kN", 1e3),
     ("ms", 1e-3), ("N", 1.0), ("", 1.0)],
)  # fmt: skip
def test_unit_factor(unit, factor):
    assert unit_factor(unit, "here") == factor


def test_unknown_unit_names_where():
    with pytest.raises(InputError, match=r"col 3.*unknown unit 'furlong'"):
        unit_factor("furlong", "col 3")


def test_tags_from_filename():
    t = tags_from_filename("data/Al-Al_W109N_A12.5um_f1Hz.csv")
    assert t == {
        "material": "Al/Al",
        "normal_load": 109.0,
        "amplitude_nominal": pytest.approx(12.5e-6),
        "frequency": 1.0,
    }
    n = tags_from_filename("C45_p0-0.5MPa_pa-0.4MPa.mat")
    assert n["p0"] == pytest.approx(5e5) and n["pa"] == pytest.approx(4e5)
    assert entry_from_file("C45_p0-0.5MPa_pa-0.4MPa.mat").kind == "normal"
    assert entry_from_file("Al-Al_W50N_A10um.csv").kind == "tangential"
    # a token that looks like a tag but has no known unit is left alone
    assert "amplitude_nominal" not in tags_from_filename("x_A4paper.csv")


def _touch(d, *names):
    for n in names:
        (d / n).write_text("t,x,F\n")


def test_read_manifest(tmp_path):
    _touch(tmp_path, "a.csv", "Al-Al_W50N_A10um.csv", "n.mat")
    (tmp_path / "m.csv").write_text(
        "# a comment line\n"
        "file,kind,material,normal_load [kN],amplitude [um],p0 [MPa],operator,columns\n"
        "a.csv,tangential,PVC/steel,0.05,20,,Ann,x=disp;F=force\n"
        "Al-Al_W50N_A10um.csv,,,,,,,\n"
        "\n"
        "n.mat,normal,C45,,,0.5,Bob,\n"
    )
    es = read_manifest(tmp_path / "m.csv")
    assert [e.kind for e in es] == ["tangential", "tangential", "normal"]
    assert es[0].tags == {
        "material": "PVC/steel",
        "normal_load": pytest.approx(50.0),
        "amplitude_nominal": pytest.approx(20e-6),
        "operator": "Ann",
    }
    assert es[0].columns == {"x": "disp", "F": "force"}
    assert es[0].units == {"normal_load": "N", "amplitude_nominal": "m"}
    assert es[2].units == {"p0": "Pa"}
    assert es[1].tags["material"] == "Al/Al"  # from the file name
    assert es[1].tags["normal_load"] == 50.0
    assert es[2].tags["p0"] == pytest.approx(5e5)
    assert es[0].path == tmp_path / "a.csv"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("name,kind\nx.csv,tangential\n", r"row 1: no 'file' column"),
        ("file,normal_load [N]\na.csv,heavy\n", r"row 2, column 'normal_load': 'heavy' is not"),
        ("file,normal_load [stone]\na.csv,1\n", r"row 1, column 2 .*unknown unit 'stone'"),
        ("file\nmissing.csv\n", r"row 2, column 'file': .*missing.csv does not exist"),
        ("file,kind\na.csv,sideways\n", r"row 2, column 'kind': 'sideways'"),
        ("file\na.csv,1,2\n", r"row 2: 3 cells but 1 columns"),
        ("file\n", r"lists no recordings"),
        ("# only a comment\n", r"is empty"),
    ],
)
def test_manifest_errors_name_row_and_column(tmp_path, text, message):
    _touch(tmp_path, "a.csv")
    (tmp_path / "m.csv").write_text(text)
    with pytest.raises(InputError, match=message):
        read_manifest(tmp_path / "m.csv")


def test_manifest_missing_or_binary(tmp_path):
    with pytest.raises(InputError, match="does not exist"):
        read_manifest(tmp_path / "nope.csv")
    (tmp_path / "bin.csv").write_bytes(b"\xff\xfe\x00\x81garbage")
    with pytest.raises(InputError, match="not a UTF-8"):
        read_manifest(tmp_path / "bin.csv")


@settings(max_examples=60, deadline=None)
@given(
    material=st.from_regex(r"[A-Za-z][A-Za-z0-9]{0,6}(-[A-Za-z0-9]{1,6})?", fullmatch=True),
    load=st.floats(0.01, 1e4, allow_nan=False),
    amp_um=st.floats(1e-3, 1e3, allow_nan=False),
    p0_mpa=st.floats(0.01, 10, allow_nan=False),
)
def test_filename_tags_round_trip(material, load, amp_um, p0_mpa):
    name = f"{material}_W{load:.6g}N_A{amp_um:.6g}um_p0-{p0_mpa:.6g}MPa.csv"
    t = tags_from_filename(name)
    assert t["material"] == material.replace("-", "/")
    assert t["normal_load"] == pytest.approx(float(f"{load:.6g}"), rel=1e-12)
    assert t["amplitude_nominal"] == pytest.approx(float(f"{amp_um:.6g}") * 1e-6, rel=1e-12)
    assert t["p0"] == pytest.approx(float(f"{p0_mpa:.6g}") * 1e6, rel=1e-12)
