"""Fuzz target: ``contactlab track FILE --every N --json OUT`` (chunked reading, windows) on
random-but-plausible recordings (see _signals.py), with random chunk sizes and windows.

Invariants: exit 0 or 1 with one clear line, no file written on failure; on success the
JSON's windows carry numbers, not NaN.
"""

from __future__ import annotations

import json
import math
import shutil
import tempfile
from pathlib import Path

from _harness import Bytes, InvariantViolation, instrumented, main

with instrumented(("contactlab",)):
    from _signals import build, run_cli

    import contactlab.cli  # noqa: F401

TARGET = "track"
_DIR = Path(tempfile.mkdtemp(prefix="contactlab-fuzz-track-"))


def one_input(data: bytes) -> None:
    b = Bytes(data)
    kind, text = build(b)
    every = b.choice(("2cycles", "1cycles", "auto", "0.5s", "3cycles", "0cycles", "-1s"))
    chunk = b.choice((64, 500, 4096, 100_000))
    src = _DIR / "run_W50N.csv"
    src.write_text(text)
    out = _DIR / "out"
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir()
    js = out / "track.json"
    argv = ["track", str(src), "--model", kind, f"--every={every}", "--chunk-size", str(chunk),
            "--json", str(js), "--no-progress"]  # fmt: skip
    doc = run_cli(argv, out, js, ())
    if doc is None:
        return
    for w in doc.get("windows", []):
        for k, v in w.items():
            if isinstance(v, float) and not math.isfinite(v):
                raise InvariantViolation(f"window value {k} = {v}")
    json.dumps(doc, allow_nan=False)


if __name__ == "__main__":
    main(one_input)
