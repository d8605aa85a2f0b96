"""Chunked readers (contactlab.io.read_chunks): same data, same checks, same messages as the
whole-file readers, whatever the chunk size."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from contactlab import InputError
from contactlab.io import Recording, RecordingError, read_chunks, read_recording, write_recording

FORMATS = [("csv", {}), ("tdms", {}), ("h5", {}), ("mat", {}), ("mat", {"version": "7.3"})]


def _rec(n: int = 400, seed: int = 0) -> Recording:
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 1e-3
    x = 20e-6 * np.sin(2 * np.pi * 5 * t) + 1e-7 * rng.standard_normal(n)
    F = 30 * np.tanh(x / 10e-6) + 0.1 * rng.standard_normal(n)
    return Recording(t, {"x": x, "F": F}, {"x": "m", "F": "N"}, "synthetic")


def _joined(chunks: list[Recording]) -> dict[str, np.ndarray]:
    return {k: np.concatenate([c[k] for c in chunks]) for k in ("t", "x", "F")}


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> dict[str, object]:
    d = tmp_path_factory.mktemp("chunks")
    rec = _rec()
    out = {}
    for ext, opts in FORMATS:
        p = d / f"run{'73' if opts else ''}.{ext}"
        write_recording(p, rec, **opts)
        out[p.name] = p
    return out


@pytest.mark.parametrize("name", ["run.csv", "run.tdms", "run.h5", "run.mat", "run73.mat"])
def test_chunks_equal_whole_file(files: dict, name: str) -> None:
    p = files[name]
    whole = read_recording(p)
    cr = read_chunks(p, chunk_size=37)
    chunks = list(cr)
    assert all(len(c) <= 37 for c in chunks)
    assert [c.meta["offset"] for c in chunks] == list(range(0, len(whole), 37))
    j = _joined(chunks)
    for k in ("t", "x", "F"):
        np.testing.assert_array_equal(j[k], whole[k])
    assert cr.kind == "tangential" and cr.units == {"x": "m", "F": "N"}
    assert cr.n_samples in (None, len(whole))
    assert len(list(cr)) == len(chunks)  # iterable again


@settings(max_examples=15, deadline=None)
@given(size=st.integers(2, 500))
def test_any_chunk_size_reassembles(size: int) -> None:
    rec = _rec(n=301, seed=size)
    j = _joined(list(read_chunks(rec, chunk_size=size)))
    np.testing.assert_array_equal(j["x"], rec["x"])
    np.testing.assert_array_equal(j["t"], rec.t)


def _bad_csv(tmp_path, body_fn) -> object:
    rec = _rec(n=200)
    p = tmp_path / "bad.csv"
    write_recording(p, rec)
    lines = p.read_text().splitlines()
    body_fn(lines)
    p.write_text("\n".join(lines) + "\n")
    return p


@pytest.mark.parametrize(
    "edit",
    [
        lambda ls: ls.__setitem__(150, ls[150].replace(ls[150].split(",")[1], "nan", 1)),
        lambda ls: ls.__setitem__(150, ls[150].replace(ls[150].split(",")[2], "abc", 1)),
        lambda ls: ls.__setitem__(101, ls[99]),  # time goes back, across a 50-sample boundary
        lambda ls: ls.__delitem__(slice(120, 125)),  # gap
    ],
    ids=["nan", "text", "unsorted", "gap"],
)
def test_csv_errors_match_whole_reader(tmp_path, edit) -> None:
    p = _bad_csv(tmp_path, edit)
    with pytest.raises(RecordingError) as whole:
        read_recording(p)
    with pytest.raises(RecordingError) as chunked:
        list(read_chunks(p, chunk_size=50))
    assert str(chunked.value) == str(whole.value)
    assert chunked.value.row == whole.value.row and chunked.value.column == whole.value.column


@pytest.mark.parametrize("where", ["nan", "back"])
def test_hdf5_errors_match_whole_reader(tmp_path, where: str) -> None:
    rec = _rec(n=200)
    if where == "nan":
        rec.data["F"][133] = np.nan
    else:
        rec.t[100] = rec.t[98]
    p = tmp_path / "bad.h5"
    import h5py

    with h5py.File(p, "w") as f:  # write_recording would refuse nothing, but be explicit
        f["t"] = rec.t
        f["x"] = rec["x"]
        f["F"] = rec["F"]
    with pytest.raises(RecordingError) as whole:
        read_recording(p)
    with pytest.raises(RecordingError) as chunked:
        list(read_chunks(p, chunk_size=64))
    assert str(chunked.value) == str(whole.value)


def test_resolution_errors_are_immediate(tmp_path, files: dict) -> None:
    with pytest.raises(RecordingError, match="column 'nope'"):
        read_chunks(files["run.h5"], columns={"x": "nope"})
    with pytest.raises(InputError, match="chunk_size"):
        read_chunks(files["run.h5"], chunk_size=1)
    p = tmp_path / "junk.h5"
    p.write_bytes(b"not hdf5 at all")
    with pytest.raises(RecordingError, match=r"junk\.h5"):
        read_chunks(p)


@pytest.mark.parametrize(("ext", "opts"), [("tdms", {}), ("mat", {"version": "7.3"}), ("h5", {})])
def test_nan_named_alike_in_every_binary_format(tmp_path, ext, opts) -> None:
    rec = _rec(n=300)
    rec.data["F"][211] = np.nan
    p = tmp_path / f"bad.{ext}"
    write_recording(p, rec, **opts)
    with pytest.raises(RecordingError) as whole:
        read_recording(p)
    with pytest.raises(RecordingError) as chunked:
        list(read_chunks(p, chunk_size=50))
    assert str(chunked.value) == str(whole.value) and chunked.value.row == 211


@settings(max_examples=25, deadline=None)
@given(
    t0=st.floats(-1e6, 1e6, allow_nan=False),
    dt=st.floats(1e-9, 10.0),
    offset=st.integers(0, 2**52),
    n=st.integers(0, 40),
)
def test_time_axis_is_numpys_bit_for_bit(t0: float, dt: float, offset: int, n: int) -> None:
    from contactlab import _core

    t = np.empty(n)
    _core.fill_time(t, t0, dt, offset)
    want = t0 + dt * np.arange(offset, offset + n, dtype=np.float64)
    assert t.tobytes() == want.tobytes()


def test_chunks_of_a_sampled_file_carry_time_and_ranges(tmp_path) -> None:
    import h5py

    rec = _rec(n=1000, seed=3)
    p = tmp_path / "sampled.h5"
    with h5py.File(p, "w") as f:
        f["x"] = rec["x"] * 1e6  # µm: the chunks are converted to m
        f["x"].attrs["unit"] = "um"
        f["F"] = rec["F"]
        f.attrs["dt"] = 2.5e-4
    chunks = list(read_chunks(p, chunk_size=333))
    for c in chunks:
        a = c.meta["offset"]
        want_t = 2.5e-4 * np.arange(a, a + len(c), dtype=np.float64)
        assert c.t.tobytes() == want_t.tobytes()
        for k in ("x", "F"):
            assert c.meta["ranges"][k] == (float(c[k].min()), float(c[k].max()))
    np.testing.assert_allclose(_joined(chunks)["x"], rec["x"], rtol=1e-12)


@pytest.mark.parametrize(
    ("value", "unit", "message"),
    [
        (np.inf, None, "value inf is not a finite number"),
        (-np.inf, "kN", "value -inf is not a finite number"),
        (1e306, "kN", "value 1e+306 overflows double precision when converted to SI"),
    ],
)
def test_non_finite_and_overflow_named_with_their_row(tmp_path, value, unit, message) -> None:
    import h5py

    rec = _rec(n=300)
    F = rec["F"].copy()
    F[257] = value
    p = tmp_path / "bad.h5"
    with h5py.File(p, "w") as f:
        f["t"] = rec.t
        f["x"] = rec["x"]
        f["F"] = F
        if unit:
            f["F"].attrs["unit"] = unit
    with pytest.raises(RecordingError) as chunked:
        list(read_chunks(p, chunk_size=64))
    assert message in str(chunked.value) and chunked.value.row == 257
    assert chunked.value.column == "F"


def test_hdf5_datasets_libhdf5_must_decode_read_alike(tmp_path) -> None:
    """Only plain little-endian float64 is read from the file's bytes: compressed, shuffled,
    big-endian, float32 and integer datasets go through libhdf5, with the same samples."""
    import h5py

    rec = _rec(n=1000, seed=5)
    p = tmp_path / "mixed.h5"
    with h5py.File(p, "w") as f:
        f["t"] = rec.t.astype(">f8")
        f.create_dataset("x", data=rec["x"], chunks=(128,), compression="gzip", shuffle=True)
        f["F"] = rec["F"].astype(np.float32)
        f["F"].attrs["unit"] = "N"
    whole = read_recording(p)
    j = _joined(list(read_chunks(p, chunk_size=300)))
    for k in ("t", "x", "F"):
        assert j[k].tobytes() == whole[k].tobytes()
    with h5py.File(q := tmp_path / "ints.h5", "w") as f:
        f["x"] = np.arange(500, dtype=np.int32)
        f["F"] = np.arange(500, dtype="<f8")
        f.attrs["dt"] = 1e-3
    j = _joined(list(read_chunks(q, chunk_size=64)))
    np.testing.assert_array_equal(j["x"], np.arange(500))
    np.testing.assert_array_equal(j["F"], np.arange(500))


def test_chunks_into_without_the_time_axis(tmp_path):
    """``chunks_into(time_axis=False)`` of a sampled HDF5 file: the channels and checks of
    the written axis, the axis itself not written (the caller makes it)."""
    import h5py

    fs = 1000.0
    rec = _rec(1000, seed=31)
    with h5py.File(p := tmp_path / "sampled.h5", "w") as f:
        f.create_dataset("x", data=rec["x"], chunks=(128,)).attrs["unit"] = "m"
        f.create_dataset("F", data=rec["F"]).attrs["unit"] = "N"
    cr = read_chunks(p, chunk_size=300, fs=fs)
    assert cr.checked and cr.time_step == (0.0, 1 / fs)

    def alloc(m, names):
        return {k: np.full(m, np.nan) for k in names}

    made = list(cr.chunks_into(alloc))
    bare = list(cr.chunks_into(alloc, time_axis=False))
    offsets = [c.meta["offset"] for c in bare]
    assert offsets == [c.meta["offset"] for c in made] == [0, 300, 600, 900]
    for a, b in zip(made, bare, strict=True):
        assert np.isnan(b.t).all() and not np.isnan(a.t).any()
        assert a.meta["ranges"] == b.meta["ranges"]
        for k in ("x", "F"):
            assert a[k].tobytes() == b[k].tobytes()
    assert _joined(made)["t"].tobytes() == ((1 / fs) * np.arange(1000.0)).tobytes()
    assert _joined(bare)["x"].tobytes() == rec["x"].tobytes()
