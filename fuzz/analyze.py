"""Fuzz target: ``contactlab analyze FILE --model tangential|normal --json OUT`` on
random-but-plausible recordings (see _signals.py): any units from nN/nm to kN/mm, noise,
drift, clipping, constant and 1e±300 channels.

Invariants: exit 0 or 1 with one clear line (no traceback), no file written on failure, and
on success the fitted quantities are numbers.
"""

from __future__ import annotations

import math
import shutil
import tempfile
from pathlib import Path

from _harness import Bytes, InvariantViolation, instrumented, main

with instrumented(("contactlab",)):
    from _signals import build, run_cli

    import contactlab.cli  # noqa: F401

TARGET = "analyze"
_DIR = Path(tempfile.mkdtemp(prefix="contactlab-fuzz-analyze-"))
# h0 and ac are None by design when the loop does not identify them apart; in gross sliding
# h0_ac is None too (only h0 and a lower bound of ac are identified): checked below
REQUIRED = {"tangential": ("energy_per_cycle",), "normal": ("E_d", "psi", "k_tan")}


def _finite(v: object) -> bool:
    return isinstance(v, (int, float)) and math.isfinite(v)


def one_input(data: bytes) -> None:
    kind, text = build(Bytes(data))
    src = _DIR / "run_W50N.csv"
    src.write_text(text)
    out = _DIR / "out"
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir()
    doc = run_cli(["analyze", str(src), "--model", kind, "--json", str(out / "fit.json"),
                   "--no-progress"], out, out / "fit.json", REQUIRED[kind])  # fmt: skip
    if doc is None or kind != "tangential":
        return
    for r in doc.get("recordings", [doc]):
        # what a success must give: h0·ac, or (gross sliding) h0 and the bound on ac
        bounded = _finite(r.get("h0")) and _finite(r.get("ac_lower_bound"))
        if not (_finite(r.get("h0_ac")) or bounded):
            raise InvariantViolation(
                f"success without h0_ac nor h0 + ac_lower_bound (regime {r.get('regime')!r})"
            )


if __name__ == "__main__":
    main(one_input)
