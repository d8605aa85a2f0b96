"""NumPy recordings (.npy plain and structured, .npz named arrays): whole-file and chunked
readers give the same SI recording; bad arrays are refused with a sentence (issue 31)."""

from __future__ import annotations

import numpy as np
import pytest

from contactlab.io import read_chunks, read_recording, write_recording
from contactlab.io.recording import RecordingError

N = 200


def _channels():
    t = np.arange(N) * 1e-3
    x = 20e-6 * np.sin(2 * np.pi * 10 * t)
    F = 40 * np.tanh(x / 5e-6)
    return t, x, F


def _chunked(path, **kw):
    parts = list(read_chunks(path, chunk_size=64, **kw))
    t = np.concatenate([p.t for p in parts])
    return t, {k: np.concatenate([p[k] for p in parts]) for k in parts[0].data}


def test_plain_2d_is_t_x_F_in_si(tmp_path):
    t, x, F = _channels()
    p = tmp_path / "run.npy"
    np.save(p, np.column_stack([t, x, F]))
    rec = read_recording(p)
    assert rec.kind == "tangential"
    np.testing.assert_array_equal(rec["x"], x)
    np.testing.assert_array_equal(rec["F"], F)
    assert rec.meta["column_order"].startswith("by position")
    assert rec.meta["units_assumed_si"]  # a plain array has no units: said so
    tc, dc = _chunked(p)
    np.testing.assert_array_equal(tc, rec.t)
    np.testing.assert_array_equal(dc["F"], F)


def test_channels_in_rows_are_transposed(tmp_path):
    t, x, F = _channels()
    p = tmp_path / "rows.npy"
    np.save(p, np.vstack([t, x, F]))  # 3 x N
    np.testing.assert_array_equal(read_recording(p)["x"], x)


def test_plain_normal_order_and_two_columns(tmp_path):
    t, x, F = _channels()
    p = tmp_path / "n.npy"
    np.save(p, np.column_stack([t, 1e6 + F, x]))
    rec = read_recording(p, kind="normal")
    np.testing.assert_array_equal(rec["p"], 1e6 + F)
    np.testing.assert_array_equal(rec["delta"], x)
    p2 = tmp_path / "two.npy"
    np.save(p2, np.column_stack([x, F]))
    with pytest.raises(RecordingError, match="no time column"):
        read_recording(p2)
    rec2 = read_recording(p2, fs=1000.0)
    np.testing.assert_allclose(rec2.t, t, rtol=0, atol=1e-15)


def test_other_widths_need_columns_by_position(tmp_path):
    t, x, F = _channels()
    p = tmp_path / "four.npy"
    np.save(p, np.column_stack([t, np.zeros(N), x, F]))
    with pytest.raises(RecordingError, match=r"--columns t=0,x=1,F=2"):
        read_recording(p)
    rec = read_recording(p, columns={"t": "0", "x": "2", "F": "3"})
    np.testing.assert_array_equal(rec["F"], F)
    _tc, dc = _chunked(p, columns={"t": "0", "x": "2", "F": "3"})
    np.testing.assert_array_equal(dc["x"], x)


def test_structured_array_with_units(tmp_path):
    t, x, F = _channels()
    a = np.empty(N, dtype=[("time [ms]", "f8"), ("disp [um]", "f8"), ("force [mN]", "f4")])
    a["time [ms]"], a["disp [um]"], a["force [mN]"] = t * 1e3, x * 1e6, F * 1e3
    p = tmp_path / "s.npy"
    np.save(p, a)
    rec = read_recording(p)
    np.testing.assert_allclose(rec.t, t, rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(rec["x"], x, rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(rec["F"], F, rtol=1e-6)  # float32 on disk
    _tc, dc = _chunked(p)
    np.testing.assert_array_equal(dc["x"], rec["x"])


def test_npz_named_arrays_and_fs(tmp_path):
    t, x, F = _channels()
    p = tmp_path / "r.npz"
    np.savez(p, **{"x [um]": x * 1e6, "F [N]": F, "fs [kHz]": np.array(1.0)})
    rec = read_recording(p)
    np.testing.assert_allclose(rec["x"], x, rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(rec.t, t, rtol=0, atol=1e-15)
    tc, dc = _chunked(p)
    np.testing.assert_array_equal(dc["F"], F)
    np.testing.assert_array_equal(tc, rec.t)


def test_npz_round_trip_through_the_writer(tmp_path):
    t, x, F = _channels()
    rec = read_recording(_write_csv(tmp_path, t, x, F))
    for name in ("w.npz", "w.npy"):
        back = read_recording(write_recording(tmp_path / name, rec))
        np.testing.assert_array_equal(back.t, rec.t)
        np.testing.assert_array_equal(back["F"], rec["F"])
        assert back.units == rec.units


def _write_csv(tmp_path, t, x, F):
    p = tmp_path / "src.csv"
    p.write_text("t [s],x [m],F [N]\n" + "".join(f"{a:.17g},{b:.17g},{c:.17g}\n" for a, b, c in
                                                   zip(t, x, F, strict=True)))  # fmt: skip
    return p


@pytest.mark.parametrize(
    ("make", "match"),
    [
        (lambda p: np.save(p, np.array([1, "a", None], dtype=object), allow_pickle=True),
         "Python objects"),
        (lambda p: np.save(p, np.arange(5.0)), "1-D array holds one channel"),
        (lambda p: np.save(p, np.zeros((4, 5, 6))), "shape"),
        (lambda p: p.write_bytes(b"\x93NUMPY\x01\x00garbage"), "not a readable NumPy file"),
        (lambda p: np.save(p, np.column_stack([[0, 1, 1], [0, 1, 2], [0, 1, 2]])),
         "duplicated"),
        (lambda p: np.save(p, np.column_stack([[0, 1, 2], [0, np.nan, 2], [0, 1, 2]])),
         "not a finite number"),
    ],
)  # fmt: skip
def test_bad_arrays_are_refused_with_a_sentence(tmp_path, make, match):
    p = tmp_path / "bad.npy"
    make(p)
    with pytest.raises(RecordingError, match=match):
        read_recording(p)
    with pytest.raises(RecordingError, match=match):
        list(read_chunks(p, chunk_size=2))


def test_npz_without_channels_and_text_named_npy(tmp_path):
    p = tmp_path / "e.npz"
    np.savez(p, a=np.zeros((3, 3, 3)), b=np.zeros((2, 2, 2)))
    with pytest.raises(RecordingError, match="no 1-D array"):
        read_recording(p)
    q = tmp_path / "text.npy"
    q.write_text("t,x,F\n0,0,0\n")
    with pytest.raises(RecordingError, match="content is a text"):
        read_recording(q)
