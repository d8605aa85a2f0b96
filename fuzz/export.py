"""Fuzz target: ``contactlab export RESULT.json --format F -o OUT`` on mutated analyze JSON
(seeds: what ``contactlab analyze --json`` writes for the bundled recordings).

The first byte picks the format and options; the rest is the JSON file. Invariants: exit 0,
1 or 3 (refused: not identified) with a clear line, no output written on failure.
"""

from __future__ import annotations

import contextlib
import io
import shutil
import tempfile
from pathlib import Path

from _harness import InvariantViolation, check, files_under, instrumented, main

with instrumented(("contactlab",)):
    from contactlab.cli import main as cli

TARGET = "export"
_DIR = Path(tempfile.mkdtemp(prefix="contactlab-fuzz-export-"))
_FORMATS = ("calculix", "abaqus", "ansys", "csv", "json")
_OPTIONS = ([], ["--units", "mm-N-s"], ["--area", "50cm2"],
            ["--amplitude", "10um", "--frequency", "5Hz", "--area", "1cm2"],
            ["--recording", "0"], ["--points", "7", "--units", "mm-t-s"])  # fmt: skip


def one_input(data: bytes) -> None:
    sel = data[0] if data else 0
    src = _DIR / "result.json"
    src.write_bytes(data[1:])
    out = _DIR / "out"
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir()
    fmt = _FORMATS[sel % len(_FORMATS)]
    opts = _OPTIONS[(sel // len(_FORMATS)) % len(_OPTIONS)]
    argv = ["export", str(src), "--format", fmt, "-o", str(out / f"joint.{fmt}"), *opts]
    sink = io.StringIO()
    with contextlib.redirect_stdout(sink), contextlib.redirect_stderr(sink):
        rc = check(lambda: cli(argv))
    if rc is None:
        raise InvariantViolation("a ContactLabError escaped the CLI's handler")
    if rc not in (0, 1, 3):
        raise InvariantViolation(f"exit code {rc}: {sink.getvalue()[-300:]}")
    if rc != 0 and files_under(out):
        raise InvariantViolation(f"failed export left {files_under(out)}")


if __name__ == "__main__":
    main(one_input)
