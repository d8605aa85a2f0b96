"""CLI on bad recordings: exit code 1, a message naming file, column and row, nothing written."""

from __future__ import annotations

import numpy as np
import pytest

from contactlab.cli import main


def _good_csv(path, n_cycles=4.0, fs=200.0):
    t = np.arange(int(n_cycles * fs)) / fs
    x = 10.0 * np.sin(2 * np.pi * t)
    F = 20.0 * np.tanh(x / 8.0)
    rows = "\n".join(f"{a:.4f},{b:.4f},{c:.4f}" for a, b, c in zip(t, x, F, strict=True))
    path.write_text("t [s],x [um],F [N]\n" + rows + "\n")
    return path


@pytest.mark.parametrize(
    ("name", "content", "expect"),
    [
        ("unit.csv", "t [s],x [furlong],F [N]\n0,0,0\n0.1,1,1\n",
         ["unit.csv", "x [furlong]", "furlong"]),
        ("cell.csv", "t [s],x [um],F [N]\n0,0,0\n0.1,abc,1\n0.2,2,2\n",
         ["cell.csv", "sample 1 (line 3 of cell.csv)"]),
        ("dup.csv", "t [s],x [um],F [N]\n0,0,0\n0.1,1,1\n0.1,2,2\n0.2,3,3\n",
         ["dup.csv", "sample 2 (line 4 of dup.csv)"]),
        ("fake.h5", "t,x,F\n0,0,0\n", ["fake.h5"]),
        ("fake.mat", "not a MAT file at all", ["fake.mat"]),
        ("fake.tdms", "t,x,F\n", ["fake.tdms"]),
    ],
)  # fmt: skip
def test_bad_recording(tmp_path, capsys, name, content, expect):
    f = tmp_path / name
    f.write_text(content)
    rep, js = tmp_path / "rep", tmp_path / "out.json"
    code = main(["analyze", str(f), "--model", "tangential", "--report", str(rep),
                 "--json", str(js)])  # fmt: skip
    assert code == 1
    err = capsys.readouterr().err
    assert err.startswith("contactlab analyze: error:")
    for e in expect:
        assert e in err, (e, err)
    assert not rep.exists() and not js.exists()


def test_too_few_cycles(tmp_path, capsys):
    f = _good_csv(tmp_path / "short.csv", n_cycles=1.2)
    assert main(["analyze", str(f), "--model", "tangential"]) == 1
    err = capsys.readouterr().err
    assert "short.csv" in err and "cycle" in err


def test_wrong_model_names_missing_column(tmp_path, capsys):
    f = _good_csv(tmp_path / "tang.csv")
    assert main(["analyze", str(f), "--model", "normal"]) == 1
    err = capsys.readouterr().err
    assert "tang.csv" in err and "'p'" in err


def test_columns_option_maps_names(tmp_path):
    f = tmp_path / "renamed.csv"
    _good_csv(f)
    f.write_text(f.read_text().replace("x [um],F [N]", "LVDT1 [um],loadcell [N]", 1))
    assert main(["analyze", str(f), "--model", "tangential"]) == 1
    assert main(["analyze", str(f), "--model", "tangential", "--columns",
                 "x=LVDT1,F=loadcell"]) == 0  # fmt: skip
