"""Issue 31: ``contactlab identify`` shows a progress bar on stderr for a run longer than a
second (with --progress, or on a terminal), prints the fitted parameters with their errors at
the end, and its report's "Made by" line repeats the run, ``--fs`` included."""

from __future__ import annotations

import re
from types import SimpleNamespace

import numpy as np
import pytest

from contactlab.cli import main
from contactlab.commands import structure as structure_cmd
from contactlab.fitting import Parameter
from contactlab.structure import Structure


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    """400 samples at 500 Hz of a linear oscillator (m 1 kg, c 2 N s/m, k 4 kN/m) under a
    multisine force, no time column (the sampling rate comes from --fs)."""
    rng = np.random.default_rng(3101)
    fs, n = 500.0, 400
    t = np.arange(n) / fs
    u = sum(np.sin(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi)) for f in np.arange(3, 60, 0.5))
    u = 6.0 * u / np.std(u)
    y = Structure(1.0, 2.0, 4e3).simulate(t, force=u, substeps=4).x
    y = y + 0.01 * np.std(y) * rng.standard_normal(n)
    path = tmp_path_factory.mktemp("identify") / "rec.csv"
    path.write_text("u_force_N,y_disp_mm\n" + "\n".join(
        f"{a:.9g},{1e3 * b:.9g}" for a, b in zip(u, y, strict=True)))  # fmt: skip
    return path


def test_parameters_progress_and_made_by(record, tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(structure_cmd, "PROGRESS_DELAY", 0.0)  # the bar of a long run, now
    rep = tmp_path / "rep"
    argv = ["identify", str(record), "--joint", "linear", "--fs", "500Hz", "--substeps", "2",
            "--report", str(rep), "--progress"]  # fmt: skip
    assert main(argv) == 0
    out, err = capsys.readouterr()
    # the fitted parameters, each with its error and unit, after the summary line
    lines = out.splitlines()
    assert lines[0].startswith("linear: RMS output error")
    assert "fitted parameters" in lines[1]
    params = {m.group(1): m.group(2) for ln in lines[2:]
              if (m := re.match(r"\s+(\w+)\s+= (.*)$", ln))}  # fmt: skip
    assert set(params) >= {"m", "c", "k", "x0", "v0"}
    assert all("±" in v for v in params.values()), params
    assert params["k"].endswith("N/m") and params["m"].endswith("kg")
    assert "nan" not in out.lower()
    # the progress bar counts the simulations on stderr
    assert re.search(r"identify: (starts|fit|errors): *\d+sim", err), err
    # the report repeats the run, --fs included
    html = (rep / "report.html").read_text()
    made = re.search(r"Made by: ([^<]*)", html).group(1)
    assert "--fs 500Hz" in made and "--substeps 2" in made and "--joint linear" in made


def test_no_bar_off_a_terminal_without_progress(record, capsys, monkeypatch):
    monkeypatch.setattr(structure_cmd, "PROGRESS_DELAY", 0.0)
    assert main(["identify", str(record), "--joint", "linear", "--fs", "500Hz",
                 "--substeps", "1"]) == 0  # fmt: skip
    assert "sim" not in capsys.readouterr().err


def test_parameter_lines_say_not_identifiable():
    fit = SimpleNamespace(params={
        "k": Parameter("k", 4012.0, stderr=21.0, unit="N/m", identifiable=True),
        "fs": Parameter("fs", 2.0, stderr=None, unit="N", identifiable=False,
                        note="not identifiable: the joint never slips"),
        "m": Parameter("m", 1.5, vary=False, unit="kg"),
        "kj": Parameter("kj", 3e3, stderr=float("nan"), unit="N/m"),
        "c": Parameter("c", 0.02, stderr=47.4, unit="N s/m"),
    })  # fmt: skip
    text = structure_cmd.parameter_lines(fit)
    assert "k  = 4012 ± 21 N/m" in text
    assert "fs = 2 N (not identifiable: the joint never slips)" in text
    assert "m  = 1.5 kg (held fixed)" in text
    assert "kj = 3000 N/m (not identifiable: no finite standard error)" in text
    assert "c  = 0.02 N s/m (not identifiable: standard error 47, over 1000 % of the value)" in text
    assert "nan" not in text
