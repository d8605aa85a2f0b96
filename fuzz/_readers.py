"""The reader targets' common body: bytes → a file of the format → ``read_recording``.

The input is the file's content, so a saved crash is the offending file itself. Options
(``kind``, ``columns``, ``fs``) are not fuzzed here: they are part of the content's meaning
(column names), and ``fs`` is tried both absent and given.
"""

from __future__ import annotations

import tempfile
from collections.abc import Callable
from pathlib import Path

from _harness import check, instrumented, recording_ok

with instrumented(("contactlab", "nptdms")):
    from contactlab.io import RecordingError, read_recording

_TMP = Path(tempfile.mkdtemp(prefix="contactlab-fuzz-"))


def reader_target(ext: str) -> Callable[[bytes], None]:
    path = _TMP / f"run_W50N{ext}"

    def one_input(data: bytes) -> None:
        path.write_bytes(data)
        for fs in (None, 1000.0):
            rec = check(lambda fs=fs: read_recording(path, fs=fs), expected=RecordingError)
            if rec is not None:
                recording_ok(rec, f"{ext} reader")

    return one_input
