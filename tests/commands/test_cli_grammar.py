"""One command-line grammar (issue 31): the model inferred alike by analyze, diagnose, track
and the Python diagnose, and said so; help texts; "Made by" lines that repeat the run; hints
in flags, not keyword arguments; lines of at most ~100 characters; one-line errors."""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np
import pytest

import contactlab
from contactlab.cli import cli_wording, join_negative_values, main
from contactlab.commands.structure import read_table
from contactlab.io import write_recording
from contactlab.synthetic.tangential import synthetic_recording

INFERRED = re.compile(r"model tangential, inferred from the columns x='x \[m\]', F='F \[N\]'")


@pytest.fixture
def rec_csv(tmp_path, monkeypatch):
    """A small tangential record, named relatively (short console lines)."""
    monkeypatch.chdir(tmp_path)
    rec = synthetic_recording(h0=40.0, ac=4e4, amplitude=20e-6, n_cycles=6, fs=400.0,
                              noise=0.01, seed=3)  # fmt: skip
    write_recording(tmp_path / "run.csv", rec)
    return "run.csv"


def test_model_inferred_alike_and_said(rec_csv, capsys):
    assert main(["analyze", rec_csv]) == 0
    assert INFERRED.search(capsys.readouterr().out)
    assert main(["track", rec_csv, "--every", "3cycles"]) == 0
    assert INFERRED.search(capsys.readouterr().out)
    assert main(["diagnose", rec_csv, "--max-effects", "0", "--report", "diag"]) == 0
    out = capsys.readouterr().out
    assert INFERRED.search(out)
    # diagnose's console output carries units, in lines of at most 100 characters
    assert "held-out RMS [N]" in out and re.search(r"noise RMS \(estimated .*\): \S+ N", out)
    assert max(len(s) for s in out.splitlines()) <= 100
    html = Path("diag/diagnose.html").read_text()
    assert "Made by: contactlab diagnose run.csv --max-effects 0 --report diag" in html
    assert "estimated from the data" in html  # as the console says it
    # given explicitly: no inference line
    assert main(["analyze", rec_csv, "--model", "tangential"]) == 0
    assert "inferred" not in capsys.readouterr().out


def test_python_diagnose_infers_the_model_as_the_cli_does():
    rec = synthetic_recording(h0=40.0, ac=4e4, amplitude=20e-6, n_cycles=6, fs=400.0,
                              noise=0.01, seed=4)  # fmt: skip
    report = contactlab.diagnose(rec, max_effects=0)
    assert report.model == "tangential" and report.model_inferred
    assert "inferred from the channels" in report.summary()
    with pytest.raises(contactlab.InputError, match="model="):
        contactlab.diagnose({"t": np.arange(5.0), "a": np.ones(5)})


def test_console_lines_fit_100_characters(rec_csv, capsys):
    assert main(["analyze", rec_csv, "--force-sign", "1"]) == 0
    both = capsys.readouterr()
    lines = (both.out + both.err).splitlines()
    assert lines and max(len(s) for s in lines) <= 100, max(lines, key=len)


def _help(capsys, *argv):
    with pytest.raises(SystemExit):
        main([*argv, "--help"])
    return capsys.readouterr().out


def test_help_texts(capsys):
    assert "bundled with contactlab" in _help(capsys, "demo")
    sim = _help(capsys, "simulate")
    assert "(default: 40.0)" in sim and "(default: 500.0)" in sim and "(default: None)" not in sim
    ana = _help(capsys, "analyze")
    assert "{auto,+1,-1}" in ana and "+1,-1,1}" not in ana
    for verb in ("analyze", "track", "diagnose"):
        h = _help(capsys, verb)
        for flag in ("--columns MAP", "--fs RATE", "--model {tangential,normal}", "--resample"):
            assert flag in h, (verb, flag)
    ident = _help(capsys, "identify")
    for flag in ("--fs RATE", "--json OUT", "--report DIR", "--u COLUMN"):
        assert flag in ident


def test_force_sign_1_is_plus_1(rec_csv, capsys):
    assert main(["analyze", rec_csv, "--force-sign", "1", "--model", "tangential"]) == 0
    assert "force sign +1" in capsys.readouterr().out


def test_negative_quantity_is_a_value_not_a_flag(tmp_path, capsys):
    assert join_negative_values(["export", "r.json", "--area", "-50cm2"]) == [
        "export", "r.json", "--area=-50cm2"]  # fmt: skip
    assert join_negative_values(["x", "--delay", "-.5ms"])[-1] == "--delay=-.5ms"
    with pytest.raises(SystemExit):
        main(["export", str(tmp_path / "r.json"), "--format", "csv", "--area", "-50cm2", "-o", "x"])
    err = capsys.readouterr().err
    assert "must be a finite area > 0" in err and "expected one argument" not in err


def test_made_by_repeats_the_run_with_every_flag(tmp_path, monkeypatch):
    """A file without a time column needs --fs: the report's line must carry it."""
    monkeypatch.chdir(tmp_path)
    rec = synthetic_recording(h0=40.0, ac=4e4, amplitude=20e-6, n_cycles=6, fs=400.0,
                              noise=0.01, seed=5)  # fmt: skip
    Path("nt.csv").write_text("x [um],F [N]\n" + "".join(
        f"{a * 1e6:.9g},{b:.9g}\n" for a, b in zip(rec["x"], rec["F"], strict=True)))  # fmt: skip
    argv = ["analyze", "nt.csv", "--fs", "400Hz", "--model", "tangential", "--report", "rep"]
    assert main(argv) == 0
    html = Path("rep/report.html").read_text()
    assert "Made by: contactlab analyze nt.csv --fs 400Hz --model tangential --report rep" in html


def test_error_hints_speak_flags(tmp_path, capsys):
    p = tmp_path / "odd.csv"
    p.write_text("a,b,c\n0,1,2\n1,2,3\n2,3,4\n")
    assert main(["analyze", str(p)]) == 1
    err = capsys.readouterr().err
    assert "--model" in err and "--columns" in err and "columns={" not in err
    assert (
        cli_wording("chunk_size must be an integer >= 2") == "--chunk-size must be an integer >= 2"
    )
    assert "max_effects" not in cli_wording("max_effects must be >= 0, got -1")


def test_export_of_a_binary_file_and_a_missing_structure_say_one_line(tmp_path, capsys):
    b = tmp_path / "rec.mat"
    b.write_bytes(bytes(range(256)) * 4)
    assert main(["export", str(b), "--format", "csv", "-o", str(tmp_path / "o.csv")]) == 1
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "a binary file" in err and "codec" not in err
    assert main(["simulate", "structure", str(tmp_path / "o.csv"), "--structure",
                 str(tmp_path / "missing.json"), "--input", str(b)]) == 1  # fmt: skip
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "no such file" in err and "Errno" not in err


def test_identify_reads_a_comment_line_with_commas(tmp_path):
    p = tmp_path / "rec.csv"
    p.write_text("# rig 2, run 7, 2026-11-28\n# operator: A, B\nt_s,u_N,y_mm\n0,1,2\n0.1,2,3\n")
    cols = read_table(str(p))
    assert list(cols) == ["t_s", "u_N", "y_mm"]
    np.testing.assert_allclose(cols["y_mm"], [2e-3, 3e-3])
    q = tmp_path / "hdr.csv"  # the header itself written as a comment
    q.write_text("# t_s,u_N,y_mm\n0,1,2\n0.1,2,3\n")
    assert list(read_table(str(q))) == ["t_s", "u_N", "y_mm"]
    assert os.path.basename(str(q)) == "hdr.csv"
