"""MATLAB channels inside a struct (``save(file, 'data')`` with ``data.x``, ``data.F``) are
read, for MAT v5 (scipy) and v7.3 (h5py), named ``data.x`` (and ``x`` when unambiguous); they
were refused with a hint to ``save(file, '-struct', 'data')``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import scipy.io

from contactlab.io import RecordingError, read_chunks, read_recording

h5py = pytest.importorskip("h5py")

N = 600
T = np.arange(N) * 1e-3
X = 1e-5 * np.sin(np.linspace(0, 12 * np.pi, N))


def _v5(path: Path, **variables: object) -> Path:
    scipy.io.savemat(path, variables)
    return path


def _v73(path: Path, structs: dict[str, dict[str, np.ndarray]], **top: np.ndarray) -> Path:
    with h5py.File(path, "w", userblock_size=512) as f:
        for name, fields in structs.items():
            g = f.create_group(name)
            g.attrs["MATLAB_class"] = np.bytes_("struct")
            for k, v in fields.items():
                d = g.create_dataset(k, data=np.asarray(v).reshape(-1, 1))
                d.attrs["MATLAB_class"] = np.bytes_("double")
        for k, v in top.items():
            d = f.create_dataset(k, data=v.reshape(1, -1))
            d.attrs["MATLAB_class"] = np.bytes_("double")
    with open(path, "r+b") as fh:
        fh.write(b"MATLAB 7.3 MAT-file".ljust(128, b" "))
    return path


def _both(tmp_path: Path, structs: dict[str, dict[str, np.ndarray]], **top: np.ndarray):
    yield _v5(tmp_path / "s5.mat", **structs, **top)
    yield _v73(tmp_path / "s73.mat", structs, **top)


def test_struct_fields_are_read(tmp_path: Path) -> None:
    for p in _both(tmp_path, {"data": {"t": T, "x": X, "F": 1e6 * X}}):
        rec = read_recording(p)
        assert rec.meta["columns"] == {"x": "data.x", "F": "data.F", "t": "data.t"}, p
        np.testing.assert_array_equal(rec["x"], X)
        np.testing.assert_array_equal(rec["F"], 1e6 * X)
        np.testing.assert_array_equal(rec.t, T)
        asked = read_recording(p, columns={"x": "data.x", "F": "data.F"})
        np.testing.assert_array_equal(asked["F"], 1e6 * X)
        plain = read_recording(p, columns={"x": "x", "F": "F"})
        np.testing.assert_array_equal(plain["x"], X)
        chunks = read_chunks(p, chunk_size=256)
        assert chunks.columns == rec.meta["columns"]
        np.testing.assert_array_equal(np.concatenate([c["x"] for c in chunks]), X)


def test_audit_example_files() -> None:
    root = Path("/work/s27/audit1/rec")
    if not (root / "M5_struct.mat").exists():
        pytest.skip("audit files not here")
    for name in ("M5_struct.mat", "M73_row_struct.mat"):
        rec = read_recording(root / name)
        assert rec.kind == "tangential" and len(rec) == 20000


def test_ambiguous_field_needs_the_full_name(tmp_path: Path) -> None:
    """``x`` in two structs (or beside a variable ``x``): the plain name is not offered."""
    structs = {"a": {"x": X, "F": X}, "b": {"x": 2 * X, "F": 2 * X}}
    for p in _both(tmp_path, structs, t=T):
        with pytest.raises(RecordingError) as e:
            read_recording(p, kind="tangential")
        assert "'a.x'" in str(e.value) and "'b.x'" in str(e.value)
        rec = read_recording(p, columns={"x": "b.x", "F": "b.F"})
        np.testing.assert_array_equal(rec["x"], 2 * X)
        with pytest.raises(RecordingError, match=r"column 'x' .*not found"):
            read_recording(p, columns={"x": "x", "F": "a.F"})


def test_variable_wins_over_field(tmp_path: Path) -> None:
    for p in _both(tmp_path, {"data": {"x": 3 * X}}, t=T, x=X, F=X):
        rec = read_recording(p)
        assert rec.meta["columns"]["x"] == "x"
        np.testing.assert_array_equal(rec["x"], X)


def test_unusable_field_still_named(tmp_path: Path) -> None:
    p = _v5(tmp_path / "txt.mat", data={"t": T, "x": X, "F": "not numbers"})
    with pytest.raises(RecordingError, match=r"'data.F' is text: a channel must hold real"):
        read_recording(p, kind="tangential")
