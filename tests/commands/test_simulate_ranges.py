"""simulate refuses physically meaningless magnitudes (``--amplitude 1e30`` was accepted and
written): argparse exits 2 naming the flag, the value (SI) and the range; nothing written."""

from __future__ import annotations

from pathlib import Path

import pytest

from contactlab.cli import main
from contactlab.commands.simulate import RANGES


def _run(capsys: pytest.CaptureFixture[str], argv: list[str]) -> tuple[int, str]:
    try:
        rc = main(argv)
    except SystemExit as exc:
        rc = exc.code if isinstance(exc.code, int) else 1
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return rc, err


@pytest.mark.parametrize(
    ("model", "flag", "value", "says"),
    [
        (
            "tangential",
            "--amplitude",
            "1e30",
            "'1e30' = 1e+30 m: a displacement amplitude of a contact must be in 1e-09..1 m",
        ),
        ("tangential", "--amplitude", "1e-3nm", "1e-12 m"),
        ("tangential", "--h0", "1e20", "must be in 1e-06..1e+08 N"),
        ("tangential", "--ac", "1e15", "1e+15 1/m"),
        ("tangential", "--frequency", "1e9", "1e-06..1e+06 Hz"),
        ("tangential", "--fs", "1e12", "0.001..1e+09 Hz"),
        ("tangential", "--offset=-1e12", None, "within ±1e+08 N"),
        ("tangential", "--x-offset", "5", "within ±1 m"),
        ("tangential", "--noise", "1e6", "<= 10"),
        ("normal", "--p0", "1e15", "1..1e+10 Pa"),
        ("normal", "--pa", "1e20Pa", "1..1e+10 Pa"),
        ("normal", "--omega", "1e9", "1e-06..1e+07 1/s"),
    ],
)
def test_simulate_out_of_physical_range(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    model: str,
    flag: str,
    value: str | None,
    says: str,
) -> None:
    out = tmp_path / "s.csv"
    rc, err = _run(capsys, ["simulate", model, str(out), flag, *([value] if value else [])])
    assert rc == 2
    line = err.strip().splitlines()[-1]
    name = flag.split("=")[0]
    assert line.startswith(f"contactlab simulate: error: argument {name}: "), line
    assert says in line, line
    assert not out.exists()


@pytest.mark.parametrize("key", ["amplitude", "h0", "p0"])
def test_range_ends_are_accepted(tmp_path: Path, key: str) -> None:
    lo, hi, _ = RANGES[key]
    model = "tangential" if key in ("amplitude", "h0") else "normal"
    for v in (lo, hi):
        out = tmp_path / f"{key}{v:g}.csv"
        extra = ["--pa", "1"] if key == "p0" else []
        argv = ["simulate", model, str(out), f"--{key}", f"{v!r}", "--cycles", "1", *extra]
        assert main(argv) == 0, argv
        assert out.exists()
