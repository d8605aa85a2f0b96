"""HDF5 values read from the file's bytes are scanned as each piece arrives
(``DirectRead.read(..., scan)``): the chunk's check and ranges are those of one pass over the
chunk (``_core.finite_min_max``, or numpy's min and max), whatever the pieces."""

from __future__ import annotations

import math

import numpy as np
import pytest

from contactlab import _core
from contactlab.io import RecordingError, read_chunks
from contactlab.io import hdf5 as hdf5_io


def _write(path, x: np.ndarray, F: np.ndarray) -> None:
    import h5py

    with h5py.File(path, "w") as f:
        f.create_dataset("x", data=x, chunks=(1000,))  # chunked: pieces of 1000
        f["F"] = F  # contiguous: one piece
        f.attrs["dt"] = 1e-3


def _signal(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    x = 1e-5 * np.sin(np.arange(n) * 0.01) + 1e-7 * rng.standard_normal(n)
    F = 30 * np.tanh(x / 1e-5) + rng.standard_normal(n)
    return x, F


@pytest.mark.parametrize("piece", [1, 37, 1000, 1 << 15])
@pytest.mark.parametrize("seed", [3, 11])
def test_scanned_pieces_give_the_one_pass_figures(tmp_path, monkeypatch, piece, seed):
    """Every chunk's ranges equal numpy's min and max of its values, bit for bit, for reads in
    pieces that do and do not line up with the file's chunks; the values are the file's."""
    import h5py

    monkeypatch.setattr(hdf5_io, "SCAN_PIECE", piece)
    x, F = _signal(5003, seed)
    _write(p := tmp_path / "r.h5", x, F)
    with h5py.File(p, "r") as f:
        assert all(hdf5_io.direct_read(f[k], p.stat().st_size) is not None for k in ("x", "F"))
    seen = 0
    for c in read_chunks(p, chunk_size=777):
        a = c.meta["offset"]
        for k, ref in (("x", x), ("F", F)):
            v = c[k]
            assert v.tobytes() == ref[a : a + v.size].tobytes()
            lo, hi = c.meta["ranges"][k]
            assert (lo.hex(), hi.hex()) == (float(v.min()).hex(), float(v.max()).hex())
        seen += len(c)
    assert seen == x.size


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_direct_read_scan_equals_the_kernel_on_the_whole_read(tmp_path, seed):
    """``scan`` after a read at any offset and length: the kernel's (finite, min, max) of the
    array read; a NaN in it leaves ``scan[0]`` False."""
    import h5py

    rng = np.random.default_rng(seed)
    x, F = _signal(4100, seed)
    if seed % 2:
        x[rng.integers(0, x.size)] = math.nan
    _write(p := tmp_path / "r.h5", x, F)
    import os

    with h5py.File(p, "r") as f:
        d = hdf5_io.direct_read(f["x"], p.stat().st_size)
    assert d is not None
    fd = os.open(p, os.O_RDONLY)
    try:
        for _ in range(20):
            a = int(rng.integers(0, x.size - 1))
            b = int(rng.integers(a + 1, x.size + 1))
            out = np.empty(b - a)
            scan = [True, math.inf, -math.inf]
            assert d.read(fd, a, out, scan)
            assert out.tobytes() == x[a:b].tobytes()
            finite, lo, hi = _core.finite_min_max(out)
            assert scan[0] is finite
            if finite:
                assert (scan[1], scan[2]) == (lo, hi)
    finally:
        os.close(fd)


def test_a_nan_read_in_pieces_is_reported_as_before(tmp_path, monkeypatch):
    """A NaN in a scanned channel is refused with the reader's message (its column and
    sample), whichever piece holds it; zero extremes are scanned again (the same ranges)."""
    monkeypatch.setattr(hdf5_io, "SCAN_PIECE", 64)
    x, F = _signal(3000, 5)
    F[2222] = math.nan
    _write(p := tmp_path / "nan.h5", x, F)
    with pytest.raises(RecordingError, match="2222"):
        list(read_chunks(p, chunk_size=1000))
    x2 = np.abs(x)
    x2[10] = 0.0  # the smallest value a zero
    F2 = -np.abs(F[:3000].copy())
    F2[np.isnan(F2)] = -1.0
    F2[77] = -0.0  # the largest a negative zero
    _write(q := tmp_path / "zero.h5", x2, F2)
    for c in read_chunks(q, chunk_size=1000):
        for k in ("x", "F"):
            lo, hi = c.meta["ranges"][k]
            assert (lo.hex(), hi.hex()) == tuple(
                float(v).hex() for v in _core.finite_min_max(c[k])[1:]
            )
