"""Fuzz target: ``contactlab diagnose FILE --model tangential|normal --json OUT`` on
random-but-plausible recordings (see _signals.py): any units from nN/nm to kN/mm, noise,
drift, clipping, constant and 1e±300 channels.

Invariants: exit 0 or 1 with one clear line (no traceback), no file written on failure, and
on success the fitted quantities are numbers.
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

from _harness import Bytes, instrumented, main

with instrumented(("contactlab",)):
    from _signals import build, run_cli

    import contactlab.cli  # noqa: F401

TARGET = "diagnose"
_DIR = Path(tempfile.mkdtemp(prefix="contactlab-fuzz-diagnose-"))
REQUIRED: dict[str, tuple[str, ...]] = {"tangential": (), "normal": ()}


def one_input(data: bytes) -> None:
    kind, text = build(Bytes(data))
    src = _DIR / "run_W50N.csv"
    src.write_text(text)
    out = _DIR / "out"
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir()
    run_cli(["diagnose", str(src), "--model", kind, "--json", str(out / "fit.json"),
             "--max-effects", "2"], out, out / "fit.json", REQUIRED[kind])  # fmt: skip


if __name__ == "__main__":
    main(one_input)
