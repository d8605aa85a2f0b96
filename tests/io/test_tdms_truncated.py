"""A TDMS file cut inside a segment's lead-in or metadata is named as truncated, with where
(it said 'columns are []', as if the file had no channel of that name)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("nptdms")

from contactlab.io import Recording, RecordingError, read_chunks, read_recording, write_recording


def _tdms(tmp_path: Path, segments: int = 1) -> bytes:
    import nptdms

    path = tmp_path / "whole.tdms"
    with nptdms.TdmsWriter(path) as w:
        for k in range(segments):
            x = np.sin(np.arange(200) / 10.0) * 1e-5 + k
            w.write_segment(
                [
                    nptdms.ChannelObject("g", "x", x, properties={"unit_string": "m",
                                                                "wf_increment": 1e-3}),
                    nptdms.ChannelObject("g", "F", 3 * x, properties={"unit_string": "N",
                                                                    "wf_increment": 1e-3}),
                ]
            )  # fmt: skip
    return path.read_bytes()


def _raw_offset(b: bytes, at: int = 0) -> int:
    return int.from_bytes(b[at + 20 : at + 28], "little")


@pytest.mark.parametrize("cut", [10, 27, 28, 40, 60, 100, -1])
def test_cut_in_first_segment_metadata(tmp_path: Path, cut: int) -> None:
    b = _tdms(tmp_path)
    meta_end = 28 + _raw_offset(b)
    cut = meta_end - 1 if cut == -1 else cut
    assert cut < meta_end
    p = tmp_path / "cut.tdms"
    p.write_bytes(b[:cut])
    where = "lead-in of segment 1" if cut < 28 else "inside the metadata of segment 1"
    for read in (read_recording, read_chunks):
        with pytest.raises(RecordingError) as e:
            read(p, kind="tangential")
        msg = str(e.value)
        assert "not a readable TDMS file (damaged: truncated" in msg, msg
        assert f"ends at byte {cut}" in msg and where in msg, msg
        assert "columns are" not in msg


def test_cut_in_later_segment_metadata(tmp_path: Path) -> None:
    b = _tdms(tmp_path, segments=2)
    second = 28 + int.from_bytes(b[12:20], "little")
    p = tmp_path / "cut.tdms"
    p.write_bytes(b[: second + 40])
    with pytest.raises(RecordingError, match="inside the metadata of segment 2"):
        read_recording(p, kind="tangential")


def test_whole_file_still_reads(tmp_path: Path) -> None:
    p = tmp_path / "ok.tdms"
    write_recording(p, Recording(np.arange(50) * 1e-3, {"x": np.ones(50), "F": np.ones(50)},
                                 {"x": "m", "F": "N"}))  # fmt: skip
    assert len(read_recording(p)) == 50
    p.write_bytes(_tdms(tmp_path, segments=3))
    assert len(read_recording(p)) == 600
