"""Reading errors word a sample alike in every format: the 0-based sample index, and for a
text file its line too ("sample 1 (line 3 of run.csv)"); CSV said "row 3" (a line), the
binary formats "row 1" (an index)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from contactlab.io import Recording, RecordingError, read_chunks, read_recording, write_recording


@pytest.mark.parametrize("ext", ["csv", "h5", "mat"])
def test_sample_named_alike(tmp_path: Path, ext: str) -> None:
    t = np.arange(50) * 1e-3
    x = np.sin(t * 100)
    x[17] = np.nan
    p = tmp_path / f"run.{ext}"
    write_recording(p, Recording(t, {"x": x, "F": x}, {"x": "m", "F": "N"}))
    for read in (read_recording, lambda q: list(read_chunks(q, chunk_size=8))):
        with pytest.raises(RecordingError) as e:
            read(p)
        msg, err = str(e.value), e.value
        assert err.sample == 17
        if ext == "csv":
            assert "sample 17 (line 19 of run.csv): value nan" in msg, msg
            assert err.line == 19 and err.row == 19
        else:
            assert "sample 17: value nan" in msg and "line" not in msg, msg
            assert err.line is None and err.row == 17
