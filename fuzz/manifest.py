"""Fuzz target: the study manifest (``contactlab.studies.manifest.read_manifest``).

The input is the manifest's bytes; the folder beside it holds ``tangential.csv`` and
``normal.mat`` so rows can name real files. Invariant: a list of entries (each naming an
existing file, a known kind) or a ``ContactLabError``; nothing else.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
from _harness import InvariantViolation, check, instrumented, main

with instrumented(("contactlab",)):
    from contactlab.io import Recording, write_recording
    from contactlab.studies.manifest import read_manifest

TARGET = "manifest"
_DIR = Path(tempfile.mkdtemp(prefix="contactlab-fuzz-manifest-"))
_t = np.arange(32) / 1000.0
write_recording(
    _DIR / "tangential.csv",
    Recording(_t, {"x": np.sin(_t), "F": np.cos(_t)}, {"x": "m", "F": "N"}),
)
write_recording(
    _DIR / "normal.mat",
    Recording(_t, {"p": 1 + np.sin(_t), "delta": np.cos(_t)}, {"p": "Pa", "delta": "m"}),
)
_PATH = _DIR / "manifest.csv"


def one_input(data: bytes) -> None:
    _PATH.write_bytes(data)
    entries = check(lambda: read_manifest(_PATH))
    if entries is None:
        return
    for e in entries:
        if not Path(e.path).is_file():
            raise InvariantViolation(f"manifest entry names a missing file {e.path}")


if __name__ == "__main__":
    main(one_input)
