"""--resample: non-uniform time stamps onto a uniform grid, the largest bridged gap reported,
real gaps (over 4 grid steps) still refused; the same by the whole-file and chunked readers."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from contactlab.cli import main
from contactlab.io import read_chunks, read_recording
from contactlab.io.recording import RESAMPLE_MAX_GAP, RecordingError, resample_uniform


def _times(n=600, doubled=(50, 51, 300, 301, 302)):
    """5 ms steps, some 10 ms (the sample between them dropped)."""
    t = np.arange(n) * 5e-3
    keep = np.ones(n, bool)
    keep[list(doubled)[::2]] = False
    return t[keep]


def _write(path, t):
    x = 1e-4 * np.sin(2 * np.pi * t)
    F = 2.0 * np.cos(2 * np.pi * t)
    path.write_text("t [s],x [m],F [N]\n" + "".join(f"{a:.17g},{b:.17g},{c:.17g}\n" for a, b, c
                                                    in zip(t, x, F, strict=True)))  # fmt: skip


def test_non_uniform_is_refused_with_the_way_forward(tmp_path):
    p = tmp_path / "nu.csv"
    _write(p, _times())
    with pytest.raises(RecordingError, match="--resample"):
        read_recording(p)


def test_resample_bridges_and_reports_the_largest_gap(tmp_path):
    p = tmp_path / "nu.csv"
    t = _times()
    _write(p, t)
    rec = read_recording(p, resample=True)
    info = rec.meta["resampled"]
    assert info["largest_step"] == pytest.approx(0.010, rel=1e-9)
    assert info["steps_bridged"] == 3
    assert info["step"] == pytest.approx(0.005, rel=1e-12)
    np.testing.assert_allclose(np.diff(rec.t), 0.005, rtol=1e-9)
    assert len(rec) == 600  # the full grid: the dropped samples are back
    # linear interpolation: exact on the samples read, and between them the chord
    np.testing.assert_allclose(rec["x"], np.interp(rec.t, t, 1e-4 * np.sin(2 * np.pi * t)))
    # chunked: the same grid and values, chunk boundaries included
    parts = list(read_chunks(p, chunk_size=97, resample=True))
    tc = np.concatenate([c.t for c in parts])
    np.testing.assert_allclose(tc, rec.t, rtol=0, atol=1e-12)
    np.testing.assert_allclose(np.concatenate([c["x"] for c in parts]), rec["x"], atol=1e-15)
    assert parts[-1].meta["resampled"]["largest_step"] == pytest.approx(0.010, rel=1e-9)


def test_a_real_gap_is_still_refused(tmp_path):
    t = np.arange(600) * 5e-3
    t = np.r_[t[:200], t[205:]]  # 6 steps missing: 30 ms > 4 x 5 ms
    p = tmp_path / "gap.csv"
    _write(p, t)
    for read in (lambda: read_recording(p, resample=True),
                 lambda: list(read_chunks(p, chunk_size=64, resample=True))):  # fmt: skip
        with pytest.raises(RecordingError, match="real gap"):
            read()


def test_uniform_record_is_not_touched():
    t = np.arange(50) * 1e-3
    tt, _d, info = resample_uniform(t, {"x": t**2}, file="f", column="t")
    assert tt is t and info["resampled"] is False


@settings(max_examples=40, deadline=None)
@given(st.lists(st.integers(1, int(RESAMPLE_MAX_GAP)), min_size=8, max_size=60))
def test_grid_covers_the_record_and_interpolates_lines_exactly(steps):
    """Property: whatever steps up to the limit, the grid has the median step, starts at the
    first stamp, ends within one step of the last, and a straight line stays exact."""
    t = np.cumsum([0, *steps]) * 1e-3
    tt, d, info = resample_uniform(t, {"x": 3.0 * t + 1.0}, file="f", column="t")
    assert tt[0] == t[0] and t[-1] - 1e-9 <= tt[-1] + info["step"] and tt[-1] <= t[-1] + 1e-12
    np.testing.assert_allclose(d["x"], 3.0 * tt + 1.0, rtol=1e-12)


def test_cli_resample_states_the_bridged_gap(tmp_path, capsys):
    p = tmp_path / "nu.csv"
    t = _times(4000, doubled=tuple(range(100, 3900, 97)))
    x = 2e-5 * np.sin(2 * np.pi * 2 * t)
    F = 10 * np.tanh(x / 1e-5)
    p.write_text("t [s],x [m],F [N]\n" + "".join(f"{a:.17g},{b:.17g},{c:.17g}\n" for a, b, c in
                                                 zip(t, x, F, strict=True)))  # fmt: skip
    assert main(["analyze", str(p), "--resample"]) == 0
    err = " ".join(capsys.readouterr().err.split())
    assert "largest gap bridged 0.01 s" in err


def test_track_and_stream_resample_and_say_so(tmp_path, capsys):
    p = tmp_path / "nu.csv"
    t = _times(4000, doubled=tuple(range(100, 3900, 97)))
    x = 2e-5 * np.sin(2 * np.pi * 2 * t)
    F = 10 * np.tanh(x / 1e-5)
    p.write_text("t [s],x [m],F [N]\n" + "".join(f"{a:.17g},{b:.17g},{c:.17g}\n" for a, b, c in
                                                 zip(t, x, F, strict=True)))  # fmt: skip
    assert main(["track", str(p), "--every", "10cycles", "--resample", "--no-progress"]) == 0
    assert "largest gap bridged 0.01 s" in " ".join(capsys.readouterr().out.split())
    assert main(["analyze", str(p), "--stream", "--every", "10cycles", "--resample"]) == 0
    assert "largest gap bridged 0.01 s" in " ".join(capsys.readouterr().out.split())
    assert main(["track", str(p), "--every", "10cycles", "--no-progress"]) == 1
    assert "--resample" in capsys.readouterr().err
