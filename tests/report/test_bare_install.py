"""``--report`` on a bare install (no ``io`` extra): everything that can be written is, and
the run says which table it skipped and what to install (issue 8 item 5)."""

from __future__ import annotations

import builtins
import json

import pytest

from contactlab.cli import main
from contactlab.data import data_dir


@pytest.fixture
def no_pyarrow(monkeypatch):
    real_import = builtins.__import__

    def fake_import(name, *args, **kwargs):
        if name == "pyarrow" or name.startswith("pyarrow."):
            raise ImportError(f"No module named {name!r}")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", fake_import)


def test_analyze_report_without_pyarrow(no_pyarrow, tmp_path, capsys):
    f = data_dir() / "tangential" / "Al-Al_W50N_A10um.csv"
    out, js = tmp_path / "rep", tmp_path / "fit.json"
    code = main(["analyze", str(f), "--model", "tangential", "--report", str(out),
                 "--json", str(js)])  # fmt: skip
    assert code == 0
    err = capsys.readouterr().err
    assert "skipped study_tangential.parquet" in err and "pip install 'contactlab[io]'" in err
    assert json.loads(js.read_text())["h0"] > 0  # the JSON is written too
    names = {p.name for p in out.rglob("*") if p.is_file()}
    assert {"report.html", "study_tangential.csv"} <= names
    assert any(n.endswith(".png") for n in names)
    assert not any(n.endswith(".parquet") for n in names)


def test_with_pyarrow_the_parquet_table_is_written(tmp_path, capsys):
    pytest.importorskip("pyarrow")
    f = data_dir() / "tangential" / "Al-Al_W50N_A10um.csv"
    out = tmp_path / "rep"
    assert main(["analyze", str(f), "--model", "tangential", "--report", str(out)]) == 0
    assert (out / "study_tangential.parquet").is_file()
    assert "skipped" not in capsys.readouterr().err
