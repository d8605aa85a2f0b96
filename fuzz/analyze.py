"""Fuzz target: ``contactlab analyze FILE --model tangential|normal --json OUT`` on
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

TARGET = "analyze"
_DIR = Path(tempfile.mkdtemp(prefix="contactlab-fuzz-analyze-"))
# h0 and ac are None by design when the loop does not identify them apart; h0_ac always is
REQUIRED = {"tangential": ("h0_ac", "energy_per_cycle"), "normal": ("E_d", "psi", "k_tan")}


def one_input(data: bytes) -> None:
    kind, text = build(Bytes(data))
    src = _DIR / "run_W50N.csv"
    src.write_text(text)
    out = _DIR / "out"
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir()
    run_cli(["analyze", str(src), "--model", kind, "--json", str(out / "fit.json"),
             "--no-progress"], out, out / "fit.json", REQUIRED[kind])  # fmt: skip


if __name__ == "__main__":
    main(one_input)
