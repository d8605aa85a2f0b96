"""Fuzz target: ``contactlab identify FILE --joint J --excitation E --json OUT`` on
random-but-plausible and adversarial structure records (see _structures.py): every joint law,
force and base excitation, parameters over decades, short and degenerate records, constant,
extreme or swapped channels, and random options (mass, hold-out, substeps, periodic, --fs).

Invariants (see _harness.py): exit 0 or 1 with one clear line, no file written on failure,
and on success a finite training RMS error and a JSON without NaN.
"""

from __future__ import annotations

import json
import math
import shutil
import tempfile
from pathlib import Path

from _harness import Bytes, InvariantViolation, instrumented, main

with instrumented(("contactlab",)):
    from _signals import run_cli
    from _structures import JOINTS, record

    import contactlab.cli  # noqa: F401

TARGET = "identify"
_DIR = Path(tempfile.mkdtemp(prefix="contactlab-fuzz-identify-"))


def one_input(data: bytes) -> None:
    b = Bytes(data)
    joint = b.choice(JOINTS)
    exc = b.choice(("force", "force", "base"))
    text, true = record(b, joint, exc)
    if b.int(0, 7) == 0:  # no time column: --fs instead
        lines = text.splitlines()
        text = "\n".join(ln.split(",", 1)[1] for ln in lines) + "\n"
        fs_arg = [f"--fs={b.choice((1000.0, 0.0, -5.0, 200.0))!r}"]
    else:
        fs_arg = []
    src = _DIR / "rec.csv"
    src.write_text(text)
    out = _DIR / "out"
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir()
    js = out / "model.json"
    argv = ["identify", str(src), "--joint", joint, "--excitation", exc, "--json", str(js)]
    argv += fs_arg
    if exc == "base" or b.int(0, 3) == 0:
        # --opt=VALUE: a value like -inf is the option's, not a new option (argparse)
        argv += [f"--mass={b.choice((true['m'], true['m'] * b.float(0.5, 2.0), 0.0, -1.0))!r}"]
    if b.int(0, 3) == 0:
        argv += [f"--holdout={b.choice((0.2, 0.5, 0.95, -0.1, b.float(0.0, 0.9)))!r}"]
    if b.int(0, 3) == 0:
        argv += [f"--substeps={b.choice((1, 2, 0, -1, 16))}"]
    if b.int(0, 7) == 0:
        argv += ["--periodic"]
    if b.int(0, 15) == 0:
        argv += ["--report", str(out / "report")]
    doc = run_cli(argv, out, js, ())
    if doc is None:
        return
    rms = doc.get("summary", {}).get("rms_train")
    if not (rms is None or (isinstance(rms, (int, float)) and math.isfinite(rms))):
        raise InvariantViolation(f"identify succeeded with rms_train = {rms!r}")
    json.dumps(doc, allow_nan=False)  # NaN in a successful result (written as NaN) fails


if __name__ == "__main__":
    main(one_input)
