"""CLI success paths: simulate → analyze (JSON in SI with units, report), study, demo.

Runs ``contactlab.cli.main([...])`` in temporary folders on small synthetic recordings."""

from __future__ import annotations

import csv
import io
import json
import math
from html.parser import HTMLParser

import pytest

from contactlab.cli import main

TANGENTIAL_KEYS = (
    "h0", "ac", "h0_stderr", "ac_stderr", "amplitude", "energy_per_cycle",
    "energy_per_cycle_numeric", "equivalent_damping", "k_local0", "k_global",
)  # fmt: skip
NORMAL_KEYS = ("E_d", "E_pu", "E_pd", "psi", "psi_kv", "k_tan", "k_sec", "poly_load",
               "poly_unload", "poly_centre", "delta_max", "delta_min")  # fmt: skip


@pytest.fixture(scope="module")
def tangential_file(tmp_path_factory):
    d = tmp_path_factory.mktemp("sim")
    path = d / "Al-Al_W100N_A20um.csv"
    code = main(["simulate", "tangential", str(path), "--h0", "40", "--ac", "4e4",
                 "--amplitude", "20um", "--cycles", "4", "--fs", "400", "--noise", "0.005",
                 "--seed", "3"])  # fmt: skip
    assert code == 0 and path.is_file()
    return path


@pytest.fixture(scope="module")
def normal_file(tmp_path_factory):
    d = tmp_path_factory.mktemp("simn")
    path = d / "C45_p0-0.5MPa_pa-0.4MPa.mat"
    code = main(["simulate", "normal", str(path), "--p0", "0.5MPa", "--pa", "0.4MPa", "--omega",
                 "1", "--cycles", "3", "--samples-per-cycle", "300", "--seed", "1"])  # fmt: skip
    assert code == 0 and path.is_file()
    return path


def test_analyze_tangential_json_is_si_with_units(tangential_file, tmp_path, capsys):
    out = tmp_path / "fit.json"
    assert main(["analyze", str(tangential_file), "--model", "tangential", "--json", str(out)]) == 0
    assert "h0 = " in capsys.readouterr().out
    d = json.loads(out.read_text())
    for k in TANGENTIAL_KEYS:
        assert k in d, k
        assert isinstance(d[k], float) and math.isfinite(d[k]), k
    assert d["units"]["h0"] == "N" and d["units"]["ac"] == "1/m"
    assert d["units"]["amplitude"] == "m" and d["units"]["energy_per_cycle"] == "J"
    # SI values: h0 in N, ac in 1/m, amplitude in m (not µm), tags from the file name
    assert d["h0"] == pytest.approx(40.0, rel=0.05)
    assert d["ac"] == pytest.approx(4e4, rel=0.05)
    assert d["amplitude"] == pytest.approx(20e-6, rel=0.02)
    assert d["normal_load"] == 100.0 and d["units"]["normal_load"] == "N"
    assert d["energy_per_cycle_numeric"] == pytest.approx(d["energy_per_cycle"], rel=0.05)
    assert d["model"] == "tangential" and d["file"].endswith(".csv")


def test_analyze_report_is_written(tangential_file, tmp_path):
    rep = tmp_path / "rep"
    assert (
        main(["analyze", str(tangential_file), "--model", "tangential", "--report", str(rep)]) == 0
    )
    html = (rep / "report.html").read_text(encoding="utf-8")
    imgs = []

    class P(HTMLParser):
        def handle_starttag(self, tag, attrs):
            if tag == "img":
                imgs.append(dict(attrs)["src"])

    P().feed(html)
    assert imgs and all(s.startswith("data:image/png;base64,") for s in imgs)
    assert len(list((rep / "figures").glob("*.png"))) == len(imgs)
    assert (rep / "study_tangential.csv").is_file() and (rep / "study_tangential.parquet").is_file()


def test_analyze_normal_json(normal_file, tmp_path):
    out = tmp_path / "n.json"
    assert main(["analyze", str(normal_file), "--model", "normal", "--json", str(out)]) == 0
    d = json.loads(out.read_text())
    for k in NORMAL_KEYS:
        assert k in d, k
    assert len(d["poly_load"]) == 5 and len(d["poly_centre"]) == 5
    assert 0 < d["delta_max"] < 1e-4 and -1e-4 < d["delta_min"] < 0  # metres
    assert d["units"]["delta_max"] == "m"
    assert 0 < d["psi"] < 1
    assert d["k_tan"] > 1e11  # Pa/m (≈ 1 MPa/µm = 1e12 Pa/m)
    # eq. 16 for this test: k_s at p = 0 (b4) is the tangent stiffness at equilibrium
    assert d["b4"] == pytest.approx(d["k_tan"], rel=0.02)
    assert d["b4_paper"] == pytest.approx(d["k_tan"] * 1e-12, rel=0.02)
    assert d["units"]["b4"] == "Pa/m" and d["units"]["k_tan"] == "Pa/m"
    assert 0 < d["E_d_stderr"] < 0.1 * d["E_d"]


def test_analyze_several_files(tangential_file, tmp_path):
    other = tmp_path / "Al-Al_W50N_A20um.csv"
    code = main(["simulate", "tangential", str(other), "--h0", "20", "--ac", "5e4",
                 "--amplitude", "20um", "--cycles", "4", "--fs", "400", "--seed", "4",
                 "--offset", "0.3N", "--x-offset", "1um", "--adc-bits", "16"])  # fmt: skip
    assert code == 0
    out = tmp_path / "all.json"
    assert main(["analyze", str(tangential_file), str(other), "--model", "tangential",
                 "--json", str(out), "--no-progress"]) == 0  # fmt: skip
    d = json.loads(out.read_text())
    assert [r["normal_load"] for r in d["recordings"]] == [100.0, 50.0]
    assert d["failures"] == []


def test_analyze_bad_file_no_partial_outputs(tangential_file, tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text("t [s],x [um],force [N]\n0,0,0\n0.002,1,1\n0.001,2,2\n0.003,3,3\n")
    rep, js = tmp_path / "rep", tmp_path / "r.json"
    code = main(["analyze", str(tangential_file), str(bad), "--model", "tangential",
                 "--report", str(rep), "--json", str(js)])  # fmt: skip
    assert code == 1
    err = capsys.readouterr().err
    assert "bad.csv" in err and "sample 2 (line 4 of bad.csv)" in err
    assert not rep.exists() and not js.exists()


def test_analyze_keep_going_reports_failure(tangential_file, tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text("t [s],disp [um]\n0,0\n0.001,1\n")
    js = tmp_path / "r.json"
    code = main(["analyze", str(tangential_file), str(bad), "--model", "tangential",
                 "--json", str(js), "--keep-going"])  # fmt: skip
    assert code == 1
    d = json.loads(js.read_text())
    assert len(d["recordings"]) == 1 and "bad.csv" in d["failures"][0]["error"]


def test_study_manifest(tangential_file, normal_file, tmp_path):
    m = tmp_path / "manifest.csv"
    m.write_text(
        "file,kind,material,normal_load [N],amplitude [um],p0 [MPa],pa [MPa]\n"
        f"{tangential_file},tangential,Al/Al,100,20,,\n"
        f"{normal_file},normal,C45/C45,,,0.5,0.4\n"
    )
    rep = tmp_path / "study"
    assert main(["study", str(m), "--report", str(rep), "--no-progress"]) == 0
    t = (rep / "study_tangential.csv").read_text().splitlines()
    assert len(t) == 2 and "h0 [N]" in t[0].split(",")
    row = dict(zip(t[0].split(","), next(csv.reader([t[1]])), strict=True))
    assert float(row["fs [Hz]"]) == pytest.approx(400.0) and row["n_samples"] == "1600"
    assert row["format"] == "csv" and row["units_assumed_si"] == ""
    n = (rep / "study_normal.csv").read_text().splitlines()
    assert len(n) == 2 and "p0 [Pa]" in n[0].split(",")
    assert (rep / "report.html").stat().st_size > 10_000
    assert f"Made by: contactlab study {m} --report {rep}" in (rep / "report.html").read_text()


def test_simulate_bad_extension(tmp_path, capsys):
    assert main(["simulate", "tangential", str(tmp_path / "x.xlsx")]) == 1
    assert "x.xlsx" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_simulate_rejects_bad_quantity(tmp_path, capsys):
    with pytest.raises(SystemExit):
        main(["simulate", "tangential", str(tmp_path / "x.csv"), "--amplitude", "20 furlong"])
    assert "--amplitude" in capsys.readouterr().err


def test_demo_quick_end_to_end(tmp_path, capsys):
    out = tmp_path / "demo"
    assert main(["demo", "--out", str(out), "--quick", "--no-progress"]) == 0
    names = {p.name for p in out.iterdir()}
    assert {"loops.png", "amplitude_table.csv", "report.html", "figures"} <= names
    assert {"study_tangential.csv", "study_tangential.parquet", "study_normal.csv"} <= names
    html = (out / "report.html").read_text(encoding="utf-8")
    for mat in ("Al/Al", "PVC/steel", "steel/steel"):
        assert mat in html


def test_progress_bar_on_request(tangential_file, capsys):
    assert main(["analyze", str(tangential_file), "--model", "tangential", "--progress"]) == 0
    err = capsys.readouterr().err
    assert "analysing" in err and "1/1" in err
    assert main(["analyze", str(tangential_file), "--model", "tangential", "--no-progress"]) == 0
    assert "analysing" not in capsys.readouterr().err


def test_unidentifiable_loop_json_says_so(tmp_path):
    """The paper's steel case: a tiny loop; h0 and ac are null, h0·ac is given with its error."""
    from contactlab.data import data_dir

    f = data_dir() / "tangential" / "steel-steel_W225N_A0.25um.h5"
    out = tmp_path / "s.json"
    assert main(["analyze", str(f), "--model", "tangential", "--json", str(out)]) == 0
    text = out.read_text()
    assert "NaN" not in text and "Infinity" not in text  # strict JSON
    d = json.loads(text)
    assert d["h0"] is None and d["ac"] is None
    assert d["identifiable"]["h0"] is False
    assert any("NOT separately identifiable" in w for w in d["warnings"])
    assert d["h0_ac"] == pytest.approx(40.5 * 34668.1, rel=0.03)  # the truth in the manifest
    assert 0 < d["h0_ac_stderr"] < 0.02 * d["h0_ac"] and d["units"]["h0_ac"] == "N/m"


def test_study_json_and_tables_agree(tmp_path):
    from contactlab.data import data_dir

    files = sorted((data_dir() / "tangential").glob("PVC-steel_W30N_*"))
    m = tmp_path / "m.csv"
    m.write_text("file\n" + "".join(f"{f}\n" for f in files))
    rep, js = tmp_path / "r", tmp_path / "r.json"
    assert main(["study", str(m), "--report", str(rep), "--json", str(js), "--no-progress"]) == 0
    d = json.loads(js.read_text())
    assert [r["amplitude_nominal"] for r in d["recordings"]] == pytest.approx([1e-5, 2e-5, 4e-5])
    rows = list(csv.reader(io.StringIO((rep / "study_tangential.csv").read_text())))
    col = rows[0].index("h0 [N]")
    assert [float(r[col]) for r in rows[1:]] == [r["h0"] for r in d["recordings"]]


def test_json_to_stdout_is_pure_json(tangential_file, capsys):
    assert main(["analyze", str(tangential_file), "--model", "tangential", "--json", "-"]) == 0
    out = capsys.readouterr()
    d = json.loads(out.out)  # nothing but the JSON on stdout
    assert d["h0"] == pytest.approx(40.0, rel=0.05)
    assert "h0 = " in out.err  # the summary went to stderr


@pytest.mark.parametrize("ext", ["csv", "tdms", "h5", "mat"])
def test_simulate_analyze_round_trip_every_format(tmp_path, ext):
    """simulate → file → analyze recovers the parameters within 3 reported standard errors."""
    f = tmp_path / f"rt.{ext}"
    assert main(["simulate", "tangential", str(f), "--h0", "25", "--ac", "6e4", "--amplitude",
                 "15um", "--cycles", "5", "--fs", "300", "--noise", "0.01", "--offset", "0.4",
                 "--x-offset", "2um", "--seed", "11"]) == 0  # fmt: skip
    js = tmp_path / "rt.json"
    assert main(["analyze", str(f), "--model", "tangential", "--json", str(js)]) == 0
    d = json.loads(js.read_text())
    assert abs(d["h0"] - 25.0) < 3 * d["h0_stderr"]
    assert abs(d["ac"] - 6e4) < 3 * d["ac_stderr"]
    assert abs(d["amplitude"] - 15e-6) < 3 * d["amplitude_stderr"] + 1e-9


@pytest.mark.parametrize("model", ["nonlinear", "linear"])
def test_simulate_normal_models(tmp_path, model):
    f = tmp_path / f"n_{model}.h5"
    assert main(["simulate", "normal", str(f), "--cycles", "4", "--normal-model", model]) == 0
    js = tmp_path / "n.json"
    assert main(["analyze", str(f), "--model", "normal", "--json", str(js)]) == 0
    d = json.loads(js.read_text())
    if model == "linear":  # Kelvin-Voigt with the paper's inputs: k = 1.206 MPa/µm, ψ = 0.0887
        assert d["k_tan"] == pytest.approx(1.206e12, rel=0.03)
        assert d["psi"] == pytest.approx(0.0887, rel=0.1)
    else:
        assert d["k_tan"] > d["k_sec"] * 0.9
