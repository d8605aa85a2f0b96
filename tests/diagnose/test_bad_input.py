"""``contactlab diagnose`` on bad input: one error line, exit 1 (2 for a bad flag value), no
traceback, and the outputs of an earlier run left exactly as they were."""

from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest

import contactlab
from contactlab.cli import main

HEADER = "t [s],x [m],F [N]"


def _tangential(n_cycles: int = 12, per_cycle: int = 100, seed: int = 7) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = np.arange(n_cycles * per_cycle) / (2.0 * per_cycle)  # 2 Hz
    x = 4e-4 * np.sin(2 * np.pi * 2.0 * t)
    F = contactlab.Masing(h0=40, ac=4e4).force(x) + 0.2 * rng.standard_normal(t.size)
    return np.column_stack([t, x, F])


def _write(path, cols: np.ndarray, header: str = HEADER):
    np.savetxt(path, cols, delimiter=",", header=header, comments="", fmt="%.17g")
    return path


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """A tangential recording and its diagnosis (computed once: the output tests reuse it)."""
    path = _write(tmp_path_factory.mktemp("rec") / "tan.csv", _tangential())
    rec = contactlab.io.read_recording(path, kind="tangential")
    return path, contactlab.diagnose(rec, model="tangential", max_effects=1)


@pytest.fixture
def quick(recorded, monkeypatch):
    """``contactlab diagnose`` returning the precomputed diagnosis (the CLI's own reading,
    rendering and writing still run)."""
    path, report = recorded
    monkeypatch.setattr(contactlab.diagnose, "diagnose", lambda *a, **k: report)
    return path


def _one_error_line(capsys, code: int = 1) -> str:
    err = capsys.readouterr().err
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("contactlab diagnose: error: ")
    return lines[0]


def _usage_error(capsys, argv: list[str]) -> str:
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return err.strip().splitlines()[-1]


def test_declared_but_unwritten_hdf5_is_refused_before_it_is_read_whole(tmp_path, capsys):
    h5py = pytest.importorskip("h5py")
    path = tmp_path / "empty.h5"
    with h5py.File(path, "w") as f:
        for name, unit in (("t", "s"), ("x", "m"), ("F", "N")):
            d = f.create_dataset(name, shape=(10**9,), dtype="f8", chunks=(65536,))
            d.attrs["unit"] = unit
    assert main(["diagnose", "--model", "tangential", str(path)]) == 1
    line = _one_error_line(capsys)
    assert str(path) in line and "stores 0 bytes" in line
    assert "declares" in line and "none of it was written" in line


def test_failing_report_leaves_the_previous_json(quick, tmp_path, capsys, monkeypatch):
    import contactlab.report

    prev = tmp_path / "prev.json"
    prev.write_text("PREV", encoding="utf-8")

    def refuse(directory, files):
        raise PermissionError(13, "Permission denied", str(directory))

    monkeypatch.setattr(contactlab.report, "commit_outputs", refuse)
    argv = ["diagnose", "--model", "tangential", str(quick), "--json", str(prev),
            "--report", str(tmp_path / "rep")]  # fmt: skip
    assert main(argv) == 1
    assert "Permission denied" in _one_error_line(capsys)
    assert prev.read_text(encoding="utf-8") == "PREV"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["prev.json"]  # no temporary left


def test_interrupt_while_rendering_writes_nothing(quick, tmp_path, capsys, monkeypatch):
    import contactlab.report.diagnosis as html

    prev = tmp_path / "prev.json"
    prev.write_text("PREV", encoding="utf-8")
    (tmp_path / "rep").mkdir()

    def interrupted(report, **_kw):  # intro= carries the report's Made by line
        raise KeyboardInterrupt

    monkeypatch.setattr(html, "report_files", interrupted)
    argv = ["diagnose", "--model", "tangential", str(quick), "--json", str(prev),
            "--report", str(tmp_path / "rep")]  # fmt: skip
    assert main(argv) == 130
    assert "Traceback" not in capsys.readouterr().err
    assert prev.read_text(encoding="utf-8") == "PREV"
    assert list((tmp_path / "rep").iterdir()) == []


def test_json_and_report_are_written_together(quick, tmp_path, capsys):
    out, rep = tmp_path / "out.json", tmp_path / "rep"
    argv = ["diagnose", "--model", "tangential", str(quick), "--json", str(out),
            "--report", str(rep)]  # fmt: skip
    assert main(argv) == 0
    assert json.loads(out.read_text(encoding="utf-8"))["model"] == "tangential"
    assert (rep / "diagnose.html").is_file() and (rep / "diagnose.json").is_file()
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".part")]


@pytest.mark.parametrize("noise", ["1e308", "1e6"])
def test_output_noise_beyond_the_channel_is_refused(recorded, capsys, noise):
    # the real workflow (not the precomputed diagnosis): it checks the declared noise
    path, _ = recorded
    argv = ["diagnose", "--model", "tangential", str(path), "--output-noise", noise]
    assert main(argv) == 1
    line = _one_error_line(capsys)
    assert str(path) in line and "--output-noise" in line and "swing" in line


@pytest.mark.parametrize("noise", ["nan", "inf", "-1", "0"])
def test_output_noise_must_be_a_finite_positive_number(quick, capsys, noise):
    argv = ["diagnose", "--model", "tangential", str(quick), "--output-noise", noise]
    assert "--output-noise" in _usage_error(capsys, argv)


def test_fs_takes_a_unit(quick, tmp_path, capsys):
    cols = _tangential()[:, 1:]
    path = _write(tmp_path / "no_t.csv", cols, header="x [m],F [N]")
    out = tmp_path / "d.json"
    argv = ["diagnose", "--model", "tangential", str(path), "--fs", "0.2kHz", "--json", str(out)]
    assert main(argv) == 0
    assert out.is_file()
    assert "--fs" in _usage_error(capsys, ["diagnose", "--model", "tangential", str(path),
                                           "--fs", "2000N"])  # fmt: skip


@pytest.mark.parametrize("value", ["nan", "-1", "2", "0", "x"])
def test_holdout_out_of_range_is_a_usage_error(quick, capsys, value):
    line = _usage_error(capsys, ["diagnose", str(quick), "--structure", "m.json",
                                 "--holdout", value])  # fmt: skip
    assert "--holdout" in line
    if value != "x":
        assert "[0.05, 0.5]" in line


@pytest.mark.parametrize("flag", [["--u", "x"], ["--y", "F"], ["--holdout", "0.3"]])
def test_structure_flags_without_structure_are_refused(quick, capsys, flag):
    assert main(["diagnose", "--model", "tangential", str(quick), *flag]) == 1
    line = _one_error_line(capsys)
    assert flag[0] in line and "--structure" in line


def test_normal_noise_variance_at_zero_stiffness_is_unbounded(monkeypatch):
    # a solver step onto the stiffness bound k = 0 divided by zero (the input noise through
    # a compliance 1/k): its limit, not a ZeroDivisionError
    from contactlab.diagnose import candidates_normal as cn

    f = np.linspace(0.1, 10.0, 50)
    monkeypatch.setattr(cn, "input_noise_spectrum", lambda d: (f, np.full(f.size, 1e6)))
    fam = cn.NormalFamily()
    d = SimpleNamespace(extra={"omega": 2 * np.pi}, dt=1e-3)
    p = {"k": 0.0, "psi": 0.1, "p0": 0.0}
    assert fam.noise_variance(p, (), d) == np.inf
    assert fam.noise_variance_bound(p, d) == np.inf
    p["k"] = 1e12
    assert 0.0 < fam.noise_variance(p, (), d) < fam.noise_variance_bound(p, d) * 1.0001


def test_long_threshold_is_the_streamed_verbs():
    from contactlab.commands import diagnose as d
    from contactlab.studies.pooled import STREAM_ABOVE

    assert d._LONG == STREAM_ABOVE
