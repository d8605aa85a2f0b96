"""Bad numeric parameters of simulate/export and bad study-manifest cells: refused, clearly.

Usage errors (a flag's value out of range) exit 2 through argparse and name the flag and the
valid range; input errors exit 1 with one line ``contactlab VERB: error: ...``; nothing is
written and no traceback or numpy warning is shown.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from contactlab.cli import main


def _run(capsys: pytest.CaptureFixture[str], argv: list[str]) -> tuple[int, str]:
    try:
        rc = main(argv)
    except SystemExit as exc:  # argparse usage errors
        rc = exc.code if isinstance(exc.code, int) else 1
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert "RuntimeWarning" not in err
    return rc, err


def _last_line(err: str) -> str:
    return err.strip().splitlines()[-1]


# --- simulate --------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("model", "flag", "value", "says"),
    [
        ("tangential", "--noise", "nan", ">= 0"),
        ("tangential", "--noise", "-0.1", ">= 0"),
        ("tangential", "--drift", "inf", "finite"),
        ("tangential", "--drift", "nan", "finite"),
        ("tangential", "--amplitude", "1e400", "finite"),
        ("tangential", "--amplitude", "0", "> 0"),
        ("tangential", "--h0", "-40", "> 0"),
        ("tangential", "--ac", "0", "> 0"),
        ("tangential", "--offset", "1e999", "finite"),
        ("tangential", "--x-offset", "-1e999", "finite"),
        ("tangential", "--fs", "0", "> 0"),
        ("tangential", "--frequency", "1e400", "finite"),
        ("tangential", "--seed", "-1", ">= 0"),
        ("tangential", "--seed", "1.5", ">= 0"),
        ("tangential", "--cycles", "0", ">= 1"),
        ("tangential", "--cycles", "1e12", ">= 1"),
        ("tangential", "--adc-bits", "2", "4..32"),
        ("normal", "--p0", "-1", "> 0"),
        ("normal", "--pa", "1e400", "finite"),
        ("normal", "--omega", "0", "> 0"),
        ("normal", "--samples-per-cycle", "4", ">= 8"),
        ("normal", "--noise", "inf", ">= 0"),
    ],
)
def test_simulate_flag_out_of_range(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    model: str,
    flag: str,
    value: str,
    says: str,
) -> None:
    out = tmp_path / "s.csv"
    rc, err = _run(capsys, ["simulate", model, str(out), f"{flag}={value}"])
    assert rc == 2
    line = _last_line(err)
    assert line.startswith(f"contactlab simulate: error: argument {flag}")
    assert says in line
    assert not out.exists()


def test_simulate_too_many_samples(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "s.csv"
    rc, err = _run(capsys, ["simulate", "tangential", str(out), "--cycles", "100000000"])
    assert rc == 1
    assert len(err.strip().splitlines()) == 1
    assert err.startswith("contactlab simulate: error: --cycles")
    assert "20,000,000" in err
    assert not out.exists()


def test_simulate_overflow_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "s.csv"
    out.write_text("keep me\n")
    argv = ["simulate", "tangential", str(out), "--drift", "1e308", "--cycles", "1000"]
    rc, err = _run(capsys, argv)
    assert rc == 1
    assert len(err.strip().splitlines()) == 1
    assert "not finite" in err and "--drift" in err
    assert out.read_text() == "keep me\n"  # left as it was


def test_simulate_valid_values_still_work(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "s.csv"
    argv = ["simulate", "tangential", str(out), "--cycles", "2", "--seed", "3", "--drift",
            "-0.5", "--noise", "0", "--adc-bits", "16"]  # fmt: skip
    rc, _ = _run(capsys, argv)
    assert rc == 0
    rows = out.read_text().splitlines()[1:]
    assert rows and all(math.isfinite(float(c)) for r in rows for c in r.split(","))


# --- export ----------------------------------------------------------------------------------


def _normal_result(tmp_path: Path) -> Path:
    p0 = 0.5e6
    coeffs = [0.0] + [a * 1e6 / 1e-6**k for k, a in enumerate([3.0, 1.0, 1.0, 1.0], start=1)]
    doc = {
        "model": "normal",
        "p0": p0,
        "pa": 0.4e6,
        "delta_min": -0.1e-6,
        "delta_max": 0.3e-6,
        "poly_load": coeffs,
        "poly_centre": coeffs,
        "k_tan": coeffs[1],
        "psi": 0.1,
        "omega": 1.0,
        "E_d": 1e-3,
    }
    path = tmp_path / "nor_fit.json"
    path.write_text(json.dumps(doc))
    return path


@pytest.mark.parametrize("points", ["100000000", "10001", "0", "-3", "1", "2", "abc", "2.5"])
def test_export_points_out_of_range(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], points: str
) -> None:
    res, out = _normal_result(tmp_path), tmp_path / "j.inp"
    argv = ["export", str(res), "--format", "calculix", "-o", str(out), f"--points={points}"]
    rc, err = _run(capsys, argv)
    assert rc == 2
    line = _last_line(err)
    assert line.startswith("contactlab export: error: argument --points")
    assert "3..10000" in line
    assert not out.exists()


@pytest.mark.parametrize("points", ["3", "10000"])
def test_export_points_bounds_accepted(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], points: str
) -> None:
    res, out = _normal_result(tmp_path), tmp_path / "j.csv"
    argv = ["export", str(res), "--format", "csv", "-o", str(out), "--points", points]
    rc, _ = _run(capsys, argv)
    assert rc == 0 and out.exists()


def test_export_points_api() -> None:
    from contactlab.errors import InputError
    from contactlab.fem import joint_characteristics

    with pytest.raises(InputError, match=r"3\.\.10000"):
        joint_characteristics({"model": "normal"}, points=10**8)


@pytest.mark.parametrize(
    ("flag", "value"), [("--area", "1e400"), ("--normal-load", "1e400"), ("--amplitude", "inf")]
)
def test_export_quantity_not_finite(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], flag: str, value: str
) -> None:
    res, out = _normal_result(tmp_path), tmp_path / "j.inp"
    rc, err = _run(capsys, ["export", str(res), "--format", "abaqus", "-o", str(out),
                            f"{flag}={value}"])  # fmt: skip
    assert rc == 2
    assert _last_line(err).startswith(f"contactlab export: error: argument {flag}")
    assert not out.exists()


@pytest.mark.parametrize(
    ("doc", "says"),
    [
        ({"source": "t.csv", "kind": "tangential", "every": "5cycles", "windows": []},
         "is a track result"),
        ({"model": "tangential", "effects": [], "steps": [], "final_model": {}},
         "is a diagnose result"),
        ({"kind": "tangential", "h0": 40.0}, "no 'model' key"),
    ],
)  # fmt: skip
def test_export_refuses_other_json(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], doc: dict, says: str
) -> None:
    res, out = tmp_path / "r.json", tmp_path / "z.csv"
    res.write_text(json.dumps(doc))
    rc, err = _run(capsys, ["export", str(res), "--format", "csv", "-o", str(out)])
    assert rc == 1
    assert len(err.strip().splitlines()) == 1
    assert err.startswith("contactlab export: error: ")
    assert says in err and "contactlab analyze" in err
    assert "None" not in err
    assert not out.exists()


# --- study manifest --------------------------------------------------------------------------


def _manifest(tmp_path: Path, text: str) -> Path:
    for name in ("Al-Al_W50N_A20um.csv", "Al-Al_W100N_A20um.csv", "C45_p0-0.5MPa.csv"):
        (tmp_path / name).write_text("t [s],x [m],F [N]\n")  # never read: the manifest fails
    m = tmp_path / "m.csv"
    m.write_text(text)
    return m


@pytest.mark.parametrize(
    ("text", "says"),
    [
        ("file,kind,normal_load [N],amplitude [um]\n"
         "Al-Al_W50N_A20um.csv,tangential,nan,20\n", "row 2, column 3 ('normal_load [N]')"),
        ("file,kind,normal_load [N],amplitude [um]\n"
         "Al-Al_W50N_A20um.csv,tangential,50,20\n"
         "Al-Al_W100N_A20um.csv,tangential,inf,20\n", "row 3, column 3 ('normal_load [N]')"),
        ("file,kind,normal_load [N],amplitude [um]\n"
         "Al-Al_W50N_A20um.csv,tangential,1e400,20\n", "not a finite number"),
        ("file,kind,normal_load [m],amplitude [N]\n"
         "Al-Al_W50N_A20um.csv,tangential,50,20\n", "row 1, column 3 ('normal_load [m]')"),
        ("file,kind,normal_load [N],amplitude [N]\n"
         "Al-Al_W50N_A20um.csv,tangential,50,20\n", "is a unit of force, but amplitude"),
        ("file,kind,frequency [Pa]\nAl-Al_W50N_A20um.csv,tangential,1\n", "is a unit of pressure"),
        ("file,kind,p0 [MPa],pa [MPa]\nC45_p0-0.5MPa.csv,normal,-0.5,0.4\n",
         "column 3 ('p0 [MPa]'): '-0.5': p0 must be > 0"),
        ("file,kind,normal_load [N]\nAl-Al_W50N_A20um.csv,tangential,-50\n", "must be > 0"),
        ("file,kind,fs [Hz]\nAl-Al_W50N_A20um.csv,tangential,0\n", "fs must be > 0"),
    ],
)  # fmt: skip
def test_manifest_bad_cells(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str, says: str
) -> None:
    m = _manifest(tmp_path, text)
    rep = tmp_path / "rep"
    rc, err = _run(capsys, ["study", str(m), "--report", str(rep), "--workers", "0"])
    assert rc == 1
    assert len(err.strip().splitlines()) == 1
    assert err.startswith(f"contactlab study: error: manifest {m}")
    assert says in err
    assert not rep.exists()


def test_manifest_good_units_accepted(tmp_path: Path) -> None:
    from contactlab.studies.manifest import read_manifest

    m = _manifest(tmp_path, "file,kind,normal_load [kN],amplitude [mm],frequency [1/s]\n"
                            "Al-Al_W50N_A20um.csv,tangential,0.05,0.02,2\n")  # fmt: skip
    (e,) = read_manifest(m)
    assert e.tags["normal_load"] == 50.0
    assert e.tags["amplitude_nominal"] == 2e-05
    assert e.tags["frequency"] == 2.0
