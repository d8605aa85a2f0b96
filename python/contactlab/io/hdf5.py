"""HDF5 recordings (h5py, optional extra ``io``).

Each channel is a 1-D dataset anywhere in the file, found by its name (the last path
component) or by its full path; its unit is the dataset attribute ``unit`` or ``units``. The time
is a dataset (``t``, ``time``) or, failing that, a sampling interval ``dt``/``wf_increment`` or a
rate ``fs``/``sampling_rate`` as an attribute of a data dataset or of the file. Only the needed
datasets are read.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from .._io_atomic import atomic_path
from ..errors import InputError
from .recording import (
    Recording,
    RecordingError,
    check_equal_lengths,
    finish,
    real_values,
    resolve_columns,
    time_from_interval,
)


def import_h5py() -> Any:
    """The h5py module (an optional dependency; HDF5 and MATLAB v7.3 readers need it)."""
    try:
        import h5py
    except ImportError:  # pragma: no cover - depends on the installation
        raise InputError("reading HDF5 files needs h5py: pip install 'contactlab[io]'") from None
    return h5py


def text_value(v: Any) -> str:
    """An HDF5 attribute or dataset as text: bytes, one-element string arrays, MATLAB chars."""
    if isinstance(v, bytes):
        return v.decode("utf-8", "replace")
    if isinstance(v, np.ndarray):
        if v.dtype.kind in "SO" and v.size == 1:
            return text_value(v.reshape(-1)[0])
        if v.dtype.kind in "ui":  # MATLAB char arrays: uint16 code points
            return "".join(chr(int(c)) for c in v.reshape(-1))
    return str(v)


def datasets(f: Any) -> dict[str, Any]:
    """Every numeric dataset: by full path (no leading slash) and by its last name."""
    h5py = import_h5py()
    out: dict[str, Any] = {}

    def visit(name: str, obj: Any) -> None:
        if isinstance(obj, h5py.Dataset) and obj.dtype.kind in "fiub":
            out[name] = obj

    f.visititems(visit)
    short: dict[str, Any] = {}
    for name, obj in out.items():
        short.setdefault(name.rsplit("/", 1)[-1], obj)
    return {**short, **out}


def vector(ds: Any, *, file: str, column: str) -> np.ndarray:
    """A dataset as a 1-D float64 array (MATLAB row/column vectors are flattened)."""
    shape = ds.shape
    if len([s for s in shape if s != 1]) > 1:
        raise RecordingError(
            f"dataset has shape {shape}; a channel must be a vector", file=file, column=column
        )
    return real_values(ds[()], file=file, column=column).reshape(-1)


def unit_attr(ds: Any) -> str | None:
    for key in ("unit", "units", "unit_string", "Unit"):
        if key in ds.attrs:
            u = text_value(ds.attrs[key]).strip()
            return u or None
    return None


def _dt_attr(objs: list[Any]) -> float | None:
    for obj in objs:
        for key in ("dt", "wf_increment", "sampling_interval"):
            if key in obj.attrs:
                return float(np.asarray(obj.attrs[key]).reshape(-1)[0])
        for key in ("fs", "sampling_rate", "sample_rate"):
            if key in obj.attrs:
                return 1.0 / float(np.asarray(obj.attrs[key]).reshape(-1)[0])
    return None


def hdf5_layout(
    f: Any, *, columns: dict[str, str] | None, kind: str | None, file: str
) -> tuple[str | None, dict[str, str], dict[str, Any], dict[str, str | None], float | None]:
    """What a reader needs before touching the data: ``(kind, mapping, datasets, units, dt)``;
    ``dt`` is the sampling interval from the attributes (None when absent or a ``t`` exists)."""
    dsets = datasets(f)
    names = [n for n in dsets if not n.startswith("#")]
    kind, mapping = resolve_columns(names, columns=columns, kind=kind, file=file)
    units = {c: unit_attr(dsets[n]) for c, n in mapping.items()}
    dt = None
    if "t" not in mapping:
        dt = _dt_attr([dsets[n] for n in mapping.values()] + [f])
    return kind, mapping, dsets, units, dt


def read_hdf5(
    path: str | Path,
    *,
    columns: dict[str, str] | None = None,
    kind: str | None = None,
    fs: float | None = None,
) -> Recording:
    """Read an HDF5 recording; see :func:`contactlab.io.read_recording`.

    Rows in errors are 0-based sample indices.
    """
    h5py = import_h5py()
    path = Path(path)
    file = str(path)
    try:
        f = h5py.File(path, "r")
    except OSError as exc:
        raise RecordingError(f"not a readable HDF5 file ({exc})", file=file) from None
    with f:
        kind, mapping, dsets, units, dt = hdf5_layout(f, columns=columns, kind=kind, file=file)
        raw = {c: vector(dsets[n], file=file, column=n) for c, n in mapping.items()}
        check_equal_lengths(raw, mapping, file=file)
        t_fallback = None
        if "t" not in raw and fs is None and dt is not None:
            n = next(iter(raw.values())).size
            t_fallback = time_from_interval(dt, n, file=file)
        return finish(
            raw,
            mapping,
            units,
            kind=kind,
            file=file,
            fs=fs,
            t_fallback=t_fallback,
            meta={"format": "hdf5"},
        )


def write_hdf5(path: str | Path, rec: Recording, **_: Any) -> Path:
    """Write ``rec`` as HDF5: datasets ``t`` and one per channel, each with a ``unit``
    attribute; the recording's ``source`` and ``kind`` as file attributes."""
    h5py = import_h5py()
    with atomic_path(path) as tmp:
        with h5py.File(tmp, "w") as f:
            f.create_dataset("t", data=rec.t).attrs["unit"] = "s"
            for k, v in rec.data.items():
                f.create_dataset(k, data=v).attrs["unit"] = rec.units[k]
            f.attrs["source"] = rec.source
            if rec.kind:
                f.attrs["kind"] = rec.kind
    return Path(path)
