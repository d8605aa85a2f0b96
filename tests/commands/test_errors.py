"""CLI bad input and interruption: non-zero exit, a message naming what is wrong, and no
partial outputs (the output folder is left exactly as it was)."""

from __future__ import annotations

import os

import pytest

import contactlab.studies.study as study_mod
from contactlab.cli import main


def _snapshot(d):
    return sorted(
        (str(p.relative_to(d)), p.read_bytes() if p.is_file() else None) for p in d.rglob("*")
    )


@pytest.fixture
def outdir(tmp_path):
    d = tmp_path / "out"
    d.mkdir()
    (d / "keep.txt").write_text("user file")
    (d / "report.html").write_text("previous report")
    return d


def test_no_verb_prints_help(capsys):
    assert main([]) == 2
    assert "analyze" in capsys.readouterr().out


def test_analyze_missing_file(tmp_path, outdir, capsys):
    before = _snapshot(outdir)
    code = main(["analyze", str(tmp_path / "nope.csv"), "--model", "tangential",
                 "--report", str(outdir), "--json", str(outdir / "r.json")])  # fmt: skip
    assert code == 1
    err = capsys.readouterr().err
    assert "contactlab analyze: error:" in err and "nope.csv" in err
    assert _snapshot(outdir) == before


def test_analyze_bad_model_is_usage_error(tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["analyze", "x.csv", "--model", "sideways"])
    assert exc.value.code == 2
    assert "invalid choice" in capsys.readouterr().err


def test_study_bad_manifest_names_row_and_column(tmp_path, outdir, capsys):
    (tmp_path / "a.csv").write_text("t,x,F\n")
    m = tmp_path / "m.csv"
    m.write_text("file,normal_load [N]\na.csv,50\na.csv,fifty\n")
    before = _snapshot(outdir)
    assert main(["study", str(m), "--report", str(outdir)]) == 1
    err = capsys.readouterr().err
    assert "row 3" in err and "normal_load" in err and "'fifty' is not a number" in err
    assert _snapshot(outdir) == before


def test_study_missing_manifest(tmp_path, outdir, capsys):
    assert main(["study", str(tmp_path / "none.csv"), "--report", str(outdir)]) == 1
    assert "does not exist" in capsys.readouterr().err


def test_study_ctrl_c_leaves_report_dir_as_it_was(tmp_path, outdir, monkeypatch, capsys):
    for n in ("Al-Al_W50N_A10um.csv", "Al-Al_W100N_A10um.csv"):
        (tmp_path / n).write_text("t,x,F\n")
    calls = []

    def interrupted(entry, **_):
        calls.append(entry.name)
        raise KeyboardInterrupt

    monkeypatch.setattr(study_mod, "analyze_entry", interrupted)
    before = _snapshot(outdir)
    # in this process (--workers 0), so that the patched function is the one called
    code = main(
        ["study", str(tmp_path), "--report", str(outdir), "--no-progress", "--workers", "0"]
    )
    assert code == 130
    assert "interrupted" in capsys.readouterr().err
    assert calls == ["Al-Al_W100N_A10um.csv"]  # sorted: stopped at the first
    assert _snapshot(outdir) == before
    assert not any(n.endswith(".part") for n in os.listdir(outdir))


def test_study_folder_without_recordings(tmp_path, outdir, capsys):
    empty = tmp_path / "empty"
    empty.mkdir()
    assert main(["study", str(empty), "--report", str(outdir)]) == 1
    assert "holds no recordings" in capsys.readouterr().err


def test_keep_going_survives_an_unexpected_error(tmp_path, monkeypatch):
    for n in ("Al-Al_W50N_A10um.csv", "Al-Al_W100N_A10um.csv"):
        (tmp_path / n).write_text("t,x,F\n")

    def broken(entry, **_):
        raise ZeroDivisionError("boom")

    monkeypatch.setattr(study_mod, "analyze_entry", broken)
    res = study_mod.run_study(tmp_path, progress=False, keep_going=True)
    assert [r.error.split(": ", 1)[1] for r in res.failures] == [
        "unexpected ZeroDivisionError: boom"
    ] * 2
    with pytest.raises(ZeroDivisionError):  # without keep_going a bug stays a bug
        study_mod.run_study(tmp_path, progress=False)


def test_unnamed_columns_hint_names_the_flags(tmp_path, capsys):
    """A CSV whose columns say nothing of their kind (the friction frame's): the message
    names the command line's flags as well as the Python keywords."""
    f = tmp_path / "frame.csv"
    f.write_text("t_s,top_mm,base_mm\n0,0,0\n0.004,0.1,0.2\n0.008,0.2,0.3\n")
    assert main(["track", str(f)]) == 1
    err = capsys.readouterr().err
    assert "frame.csv" in err and "--model" in err and "--columns 'x=" in err
    assert main(["analyze", str(f), "--model", "tangential"]) == 1
    err = capsys.readouterr().err
    assert "no column for 'x'" in err and "--columns 'x=your column'" in err
    g = tmp_path / "not.csv"
    g.write_text("disp_m,force_N\n0,0\n1e-6,1\n2e-6,3\n")
    assert main(["track", str(g)]) == 1
    assert "--fs or --columns 't=" in capsys.readouterr().err


def test_json_that_is_the_input_is_refused(tmp_path, capsys):
    """`--json` naming the recording itself would replace it with the result."""
    from contactlab.io import write_recording
    from contactlab.synthetic.tangential import synthetic_recording

    p = tmp_path / "in.csv"
    write_recording(p, synthetic_recording(h0=40.0, ac=4e4, amplitude=20e-6, n_cycles=6, seed=3))
    before = p.read_bytes()
    for argv in (["track", str(p), "--every", "3cycles"], ["analyze", str(p), "--model",
                 "tangential"], ["diagnose", str(p), "--model", "tangential"]):  # fmt: skip
        assert main([*argv, "--json", str(p)]) == 1
        err = capsys.readouterr().err
        assert "is the input" in err and "--json" in err
        assert p.read_bytes() == before


def test_keep_going_with_nothing_analysed_writes_nothing(tmp_path, outdir, capsys):
    bad = [tmp_path / "a.csv", tmp_path / "b.csv"]
    for b in bad:
        b.write_text("t [s],x [m],F [N]\n0,0,abc\n")
    (outdir / "r.json").write_text("previous")
    before = _snapshot(outdir)
    code = main(["analyze", *map(str, bad), "--model", "tangential", "--keep-going",
                 "--report", str(outdir), "--json", str(outdir / "r.json")])  # fmt: skip
    assert code == 1
    err = capsys.readouterr().err
    assert "none of the 2 recordings could be analysed" in err
    assert _snapshot(outdir) == before


def test_quantity_flags_refuse_infinity(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["track", "x.csv", "--fs", "1e400"])
    assert exc.value.code == 2 and "finite" in capsys.readouterr().err
