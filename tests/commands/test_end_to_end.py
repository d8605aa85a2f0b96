"""Regressions for defects a demanding user hit end to end (CLI, readers, outputs, report).

Each test here failed before its fix; the docstring says what the user saw.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

import numpy as np
import pytest

import contactlab
from contactlab import cli
from contactlab.commands.common import write_json
from contactlab.data import data_dir
from contactlab.io import Recording, RecordingError, read_recording, write_recording
from contactlab.report import Column, table_html

TANG = data_dir() / "tangential" / "Al-Al_W109N_A10um.csv"


def _mode(p: Path) -> int:
    return stat.S_IMODE(p.stat().st_mode)


def default_mode() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def _short_csv(path: Path, rows: list[str], header: str = "t [ms],x [um],F [N]") -> Path:
    path.write_text(header + "\n" + "\n".join(rows) + ("\n" if rows else ""))
    return path


# --- outputs: permissions ---------------------------------------------------------------------


def test_atomic_outputs_get_ordinary_permissions(tmp_path):
    """JSON and recordings written by contactlab were 0600 (mkstemp's mode), unreadable for
    anyone else sharing the results folder."""
    p = write_json(str(tmp_path / "a.json"), "{}\n")
    assert _mode(p) == default_mode()
    rec = Recording(np.arange(4) * 1e-3, {"x": np.zeros(4), "F": np.ones(4)}, {"x": "m", "F": "N"})
    q = write_recording(tmp_path / "r.csv", rec)
    assert _mode(q) == default_mode()


def test_atomic_outputs_keep_the_mode_of_the_file_they_replace(tmp_path):
    p = tmp_path / "a.json"
    p.write_text("old")
    os.chmod(p, 0o640)
    write_json(str(p), "new")
    assert p.read_text() == "new" and _mode(p) == 0o640


# --- readers: messages ------------------------------------------------------------------------


def test_unsorted_time_message_has_plain_numbers_with_unit(tmp_path):
    """The message read 'time stamp np.float64(0.002) is unsorted'."""
    f = _short_csv(tmp_path / "u.csv", ["0,0,0", "1,1,1", "3,2,2", "2,3,3", "4,4,4"])
    with pytest.raises(RecordingError) as ei:
        read_recording(f)
    msg = str(ei.value)
    assert "np.float64" not in msg
    assert "0.002 s is unsorted" in msg and "previous is 0.003 s" in msg
    assert "(line 5 of" in msg and "'t [ms]'" in msg


def test_nan_cell_message_has_plain_numbers(tmp_path):
    f = _short_csv(tmp_path / "n.csv", ["0,0,0", "1,nan,1", "2,2,2"])
    with pytest.raises(
        RecordingError, match=r"'x \[um\]', sample 1 \(line 3 of n.csv\): value nan is not"
    ) as ei:
        read_recording(f)
    assert "np.float64" not in str(ei.value)


def test_header_only_csv_is_an_error_not_a_numpy_warning(tmp_path):
    """numpy's 'input contained no data' UserWarning escaped before the error (and under
    ``-W error`` replaced it)."""
    f = _short_csv(tmp_path / "h.csv", [])
    with pytest.raises(RecordingError, match="header but no data rows"):
        read_recording(f)


# --- Python API: complex input ----------------------------------------------------------------


@pytest.mark.parametrize("x", [np.array([0.0, 1e-6j]), [0.0, 1e-6 + 0j], 1e-6j])
def test_complex_input_is_rejected_not_truncated(x):
    """Complex arrays were cast to their real part with only a ComplexWarning."""
    m = contactlab.Masing(40.0, 4e4)
    with pytest.raises(contactlab.InputError, match="complex"):
        m.force(x)
    with pytest.raises(contactlab.InputError, match="complex"):
        m.local_stiffness(x)


# --- CLI: output targets and folders ----------------------------------------------------------


def _run(capsys, *argv):
    rc = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return rc, out, err


def test_analyze_a_folder_says_folder(tmp_path, capsys):
    """A folder given to ``analyze`` was reported as 'no such file'."""
    d = tmp_path / "recordings"
    d.mkdir()
    rc, _, err = _run(capsys, "analyze", d, "--model", "tangential")
    assert rc == 1 and "is a folder" in err and "Traceback" not in err


def test_report_target_that_is_a_file_fails_cleanly_before_analysis(tmp_path, capsys):
    """``--report FILE`` ended in a NotADirectoryError traceback naming a temporary file,
    after the whole analysis had run."""
    rep = tmp_path / "out"
    rep.write_text("keep me")
    js = tmp_path / "fit.json"
    rc, _, err = _run(capsys, "analyze", TANG, "--model", "tangential", "--json", js,
                      "--report", rep, "--no-progress")  # fmt: skip
    assert rc == 1
    assert "--report" in err and "not a folder" in err and "Traceback" not in err
    assert rep.read_text() == "keep me" and not js.exists()
    assert "h0 =" not in err  # refused before the analysis ran


def test_json_target_that_is_a_folder_leaves_no_report(tmp_path, capsys):
    """``--json DIR`` failed only after report.html had been written: a partial output."""
    js = tmp_path / "j"
    js.mkdir()
    rep = tmp_path / "rep"
    rc, _, err = _run(capsys, "study", data_dir() / "normal", "--json", js, "--report", rep,
                      "--no-progress")  # fmt: skip
    assert rc == 1 and "--json" in err and "is a folder" in err
    assert not rep.exists() and list(js.iterdir()) == []


def test_os_errors_are_one_line_not_a_traceback(tmp_path, capsys, monkeypatch):
    """Any OSError from the file system (permissions, full disk) gave a traceback."""
    from contactlab.commands import analyze

    def boom(*_a, **_k):
        raise PermissionError(13, "Permission denied", str(tmp_path / "fit.json"))

    monkeypatch.setattr(analyze, "write_json", boom)
    rc, _, err = _run(capsys, "analyze", TANG, "--model", "tangential", "--json",
                      tmp_path / "fit.json", "--no-progress")  # fmt: skip
    assert rc == 1
    assert "error: Permission denied: " in err and "fit.json" in err
    assert "Traceback" not in err


# --- report: value ± uncertainty --------------------------------------------------------------


@pytest.mark.parametrize(
    "v, s, text",
    [
        (5.764e-14, 0.00068, "0.00000 ± 0.00068"),  # was '5.764e-14 ± 0.00068'
        (-1e-9, 0.0012, "0.0000 ± 0.0012"),  # no '-0.0000'
        (2.66912, 0.00084, "2.66912 ± 0.00084"),  # was '2.669 ± 0.00084'
        (45.7789, 0.0463, "45.779 ± 0.046"),
        (40.0, 0.25, "40.00 ± 0.25"),
        (1588123.0, 840.0, "(1.58812 ± 0.00084)e+06"),
        (1.0e-12, 3.0e-14, "(1.000 ± 0.030)e-12"),
        (3.0, 0.0, "3 ± 0"),
    ],
)
def test_format_measurement(v, s, text):
    from contactlab.report import format_measurement

    assert format_measurement(v, s) == text


def test_table_cells_round_value_to_its_uncertainty():
    html = table_html([{"E": 5.764e-20, "E_se": 6.8e-10}], [Column("E", "E", "µJ", 1e6, "E_se")])
    assert "0.00000 ± 0.00068" in html.replace("\u00a0", " ") and "e-14" not in html


# --- readers: complex channels, corrupt TDMS ---------------------------------------------------


def test_complex_channels_are_rejected_by_the_binary_readers(tmp_path):
    """A complex .mat variable or TDMS channel lost its imaginary part with a ComplexWarning."""
    import scipy.io
    from nptdms import ChannelObject, TdmsWriter

    t = np.arange(50) * 1e-3
    scipy.io.savemat(tmp_path / "c.mat", {"t": t, "x": t + 1j, "F": t})
    with pytest.raises(RecordingError, match=r"c\.mat, column 'x': complex values"):
        read_recording(tmp_path / "c.mat")
    props = {"wf_increment": 1e-3}
    with TdmsWriter(tmp_path / "c.tdms") as w:
        w.write_segment([ChannelObject("g", "x", t + 1j, properties=props),
                         ChannelObject("g", "F", t, properties=props)])  # fmt: skip
    with pytest.raises(RecordingError, match=r"c\.tdms, column 'x': complex values"):
        read_recording(tmp_path / "c.tdms")


def test_corrupt_tdms_leaves_no_open_file(tmp_path, caplog):
    """npTDMS leaked its file handle on a corrupt file (ResourceWarning at garbage collection)."""
    import gc
    import warnings

    p = tmp_path / "bad.tdms"
    p.write_bytes(b"TDSm" + b"\x00" * 60)
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        with pytest.raises(RecordingError, match="not a readable TDMS file"):
            read_recording(p)
        gc.collect()
    assert not [w for w in seen if issubclass(w.category, ResourceWarning)]


def test_normal_json_gives_units_of_the_paper_b_coefficients(tmp_path, capsys):
    """``b1_paper`` .. ``b4_paper`` (MPa/µm units) were in the JSON without a unit, beside
    ``b1`` .. ``b4`` in SI: nothing told a reader that they differ by powers of 10⁶."""
    import json

    js = tmp_path / "n.json"
    f = data_dir() / "normal" / "C45-C45_p0-1MPa_pa-0.4MPa.mat"
    rc, _, _ = _run(capsys, "analyze", f, "--model", "normal", "--json", js, "--no-progress")
    assert rc == 0
    units = json.loads(js.read_text())["units"]
    assert units["b1_paper"] == "µm⁻¹·MPa⁻²" and units["b4_paper"] == "MPa/µm"
    assert units["b1"] == "1/(m·Pa^2)"


# --- CLI: quantities with units ---------------------------------------------------------------


def test_cli_quantities_check_sign_and_dimension(capsys):
    """``--fs -5`` was accepted silently, ``--amplitude 5N`` became 5 m, ``--fs 10kHz`` was an
    unknown unit, and argparse replaced every reason with 'invalid quantity in Hz value'."""
    from contactlab.commands.common import quantity

    assert quantity("m")("20um") == 2e-05  # exact, not 1.9999999999999998e-05
    assert quantity("Hz", positive=True)("10kHz") == 1e4
    assert quantity("1/m")("40/mm") == 4e4
    assert quantity("1/s")("2rad/s") == 2.0
    for argv, reason in [
        (["analyze", "x.csv", "--model", "tangential", "--fs", "-5"], "'-5': must be > 0"),
        (["analyze", "x.csv", "--model", "tangential", "--fs", "5N"], "N is not a unit"),
        (["simulate", "tangential", "x.csv", "--amplitude", "5N"], "N is not a unit"),
        (["simulate", "normal", "x.csv", "--omega", "1Hz"], "Hz is not a unit"),  # 2π
        (["simulate", "tangential", "x.csv", "--h0", "40lbs"], "unknown unit 'lbs'"),
    ]:
        with pytest.raises(SystemExit) as ei:
            cli.main(argv)
        assert ei.value.code == 2
        assert reason in capsys.readouterr().err


def test_columns_without_units_are_warned_about(tmp_path, capsys):
    """A header ``t,x,F`` with x written in µm gave 'amplitude = 1e+07 um' and no warning."""
    import json

    lines = TANG.read_text().splitlines()
    rows = [f"{float(r.split(',')[0]) / 1e3!r},{r.split(',', 1)[1]}" for r in lines[1:]]
    f = _short_csv(tmp_path / "nounits.csv", rows, header="t,x,F")
    js = tmp_path / "fit.json"
    rc, _, err = _run(capsys, "analyze", f, "--model", "tangential", "--json", js, "--no-progress")
    assert rc == 0
    assert "warning: no unit in the file for x, F, t: taken as SI (t in s, x in m, F in N)" in err
    assert json.loads(js.read_text())["warnings"][0].startswith("no unit in the file for x, F")


def test_report_shows_the_uncertainty_of_the_numeric_loop_energy():
    """'E numeric' showed -0.0003019 µJ bare for a tiny steel loop: a negative energy with
    nothing to say it is (-0.3 ± 1.3) nJ, i.e. zero within its uncertainty."""
    from contactlab.report.study_report import TANGENTIAL_COLUMNS

    row = {"energy_per_cycle_numeric": -3.0188e-10, "energy_per_cycle_numeric_stderr": 1.27e-9}
    html = table_html([row], [c for c in TANGENTIAL_COLUMNS if "numeric" in c.key])
    assert "-0.0003 ± 0.0013" in html.replace("\u00a0", " ")


def test_os_error_names_the_output_not_its_temporary():
    """'Is a directory: /tmp/.fit.json.h3a5bx85.part' named a file the user never asked for."""
    from contactlab.cli import os_error_text

    e = IsADirectoryError(21, "Is a directory", "/d/.fit.json.h3a5bx85.part", "/d/fit.json")
    assert os_error_text(e) == "Is a directory: /d/fit.json"
    e = NotADirectoryError(20, "Not a directory", "/d/afile/.report.html.k2_j4x9.part")
    assert os_error_text(e) == "Not a directory: /d/afile/report.html"


def test_polynomial_coefficients_get_their_own_units_in_the_table():
    """Every column poly_load_0..4 of study_normal.csv was headed
    '[Pa; ascending powers of delta in m]' and k_s_delta_0..3 '[Pa/m; ...]', a description
    rather than a unit, and wrong for all but one coefficient."""
    from contactlab.studies.manifest import entry_from_file
    from contactlab.studies.study import analyze_entry

    f = data_dir() / "normal" / "C45-C45_p0-1MPa_pa-0.4MPa.mat"
    r = analyze_entry(entry_from_file(f, kind="normal"))
    assert [r.units[f"poly_load_{i}"] for i in range(5)] == [
        "Pa", "Pa/m", "Pa/m^2", "Pa/m^3", "Pa/m^4"]  # fmt: skip
    assert [r.units[f"k_s_delta_{i}"] for i in range(4)] == [
        "Pa/m", "Pa/m^2", "Pa/m^3", "Pa/m^4"]  # fmt: skip
    header = r.units["poly_centre_1"]
    assert ";" not in header


def test_latin1_csv_from_windows_acquisition_software(tmp_path):
    """A header ``Zeit [ms],Weg [µm],Kraft [N]`` or a comment ``# Prüfstand 2`` written in a
    Windows code page failed with 'cannot be parsed as numbers'."""
    body = "\n".join(f"{i},{i % 7 - 3},{0.5 * (i % 7)}" for i in range(30))
    f = tmp_path / "messung.csv"
    f.write_bytes(("# Prüfstand 2\nZeit [ms],Weg [µm],Kraft [N]\n" + body + "\n").encode("cp1252"))
    rec = read_recording(f)
    assert rec.meta["encoding"] == "latin-1" and rec.meta["comments"] == ["Prüfstand 2"]
    assert rec["x"][0] == -3e-6 and rec.t[1] == 1e-3 and rec.kind == "tangential"


def test_normal_analysis_of_a_dead_displacement_sensor():
    """A constant delta gave 'parameter x = 0 is invalid: all abscissae are zero'."""
    from contactlab.normal import analyze_loop

    t = np.linspace(0.0, 20 * np.pi, 2561)
    with pytest.raises(contactlab.InputError, match=r"delta is constant \(0 m\)"):
        analyze_loop(t, 1e6 + 4e5 * np.sin(t), np.zeros_like(t))


# --- study manifests --------------------------------------------------------------------------


def _manifest(tmp_path: Path, text: str) -> Path:
    src = data_dir() / "normal" / "C45-C45_p0-1MPa_pa-0.4MPa.mat"
    (tmp_path / "n.mat").write_bytes(src.read_bytes())
    m = tmp_path / "manifest.csv"
    m.write_text(text, encoding="utf-8")
    return m


def test_manifest_saved_by_a_european_spreadsheet(tmp_path):
    """A ';'-separated manifest with decimal commas (Excel in de/fr/it/... locales) failed
    with "no 'file' column in ['file;kind;...']"."""
    from contactlab.studies.manifest import read_manifest

    m = _manifest(tmp_path, "file;kind;p0 [MPa];pa [MPa]\nn.mat;normal;1,5;0,4\n")
    (e,) = read_manifest(m)
    assert e.kind == "normal" and e.tags["p0"] == 1.5e6 and e.tags["pa"] == 4e5


def test_manifest_listing_a_file_twice_is_refused(tmp_path):
    """A duplicated row was analysed twice: counted twice in every trend, one figure lost."""
    from contactlab.studies.manifest import read_manifest

    m = _manifest(tmp_path, "file,kind\nn.mat,normal\n./n.mat,normal\n")
    with pytest.raises(contactlab.InputError, match=r"row 3, column 'file': ./n.mat is listed "
                       r"already in row 2"):  # fmt: skip
        read_manifest(m)


# --- Masing: the linear limit -----------------------------------------------------------------


@pytest.mark.parametrize("h0", [1e8, 1e150, 1e160, 1e250])
def test_loop_energy_in_the_linear_limit_is_not_nan(h0):
    """With h0·ac fixed and ac → 0 (where fits of nearly linear loops go), loop_energy gave
    0.0 near h0 = 1e150 and NaN from h0 = 1e155 on: h0/ac overflowed while (ac·A)³ underflowed."""
    k0, A = 1e6, 2.5e-7
    m = contactlab.Masing(h0, k0 / h0)
    want = 2.0 / 3.0 * k0 * (m.ac * A) * A * A  # cubic law, exact to O(ac·A)
    assert m.loop_energy(A) == pytest.approx(want, rel=1e-9)
    assert m.equivalent_damping(A) == pytest.approx(want / (np.pi * A * A), rel=1e-9)


def test_analyze_the_same_file_twice_is_refused(capsys):
    """``analyze a.csv a.csv`` (a shell glob overlap) analysed and reported it twice."""
    rc, _, err = _run(capsys, "analyze", TANG, str(TANG), "--model", "tangential")
    assert rc == 1 and "given twice" in err


def test_python_dash_m_contactlab():
    """``python -m contactlab`` failed: 'No module named contactlab.__main__'."""
    import subprocess
    import sys

    r = subprocess.run([sys.executable, "-m", "contactlab", "--version"], capture_output=True,
                       text=True, timeout=60)  # fmt: skip
    assert r.returncode == 0 and r.stdout.startswith("contactlab ")


def test_diagnose_cli_names_the_file_when_the_recording_is_too_short(tmp_path, capsys):
    from contactlab.cli import main
    from contactlab.io import write_recording
    from contactlab.synthetic.tangential import synthetic_recording

    rec = synthetic_recording(h0=40.0, ac=4e4, amplitude=20e-6, n_cycles=2, fs=400.0, seed=2)
    path = tmp_path / "short_run.csv"
    write_recording(path, rec)
    out = tmp_path / "out.json"
    assert main(["diagnose", str(path), "--model", "tangential", "--json", str(out)]) == 1
    err = capsys.readouterr().err
    assert "short_run.csv" in err and "cycles" in err
    assert not out.exists()
