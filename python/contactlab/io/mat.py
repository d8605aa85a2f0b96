"""MATLAB .mat recordings: v4-v7 through ``scipy.io``, v7.3 (HDF5 inside) through h5py.

Each channel is a vector variable, or a vector field of a scalar struct variable (saved as
``save(file, 'data')`` with ``data.x``, ``data.F``): such a channel is named ``data.x``, and
also ``x`` when no variable and no other struct has that name. Units, in order of
preference: a struct variable ``units`` with one text field per channel, a text variable
``<name>_unit``, or the name itself (``x_um``; see :func:`contactlab.io.units.split_name`).
Only the needed variables are read (``variable_names=`` for scipy, lazy datasets for v7.3).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import scipy.io

from .._io_atomic import atomic_path
from .hdf5 import h5_guard, import_h5py, open_hdf5, text_value, vector
from .mat5check import check_mat5
from .recording import (
    Recording,
    RecordingError,
    check_equal_lengths,
    finish,
    metadata_scalar,
    real_values,
    resolve_columns,
    step_of_rate,
    time_from_interval,
)
from .sniff import content_format
from .units import split_name


def _mat_text(v: Any) -> str | None:
    a = np.asarray(v)
    if a.dtype.kind in "US":
        s = "".join(str(c) for c in a.reshape(-1)).strip()
        return s or None
    if a.dtype == object and a.size == 1:
        return _mat_text(a.reshape(-1)[0])
    return None


def struct_names(top: list[str], fields: dict[str, list[str]]) -> tuple[list[str], dict[str, str]]:
    """The channel names a file offers and the full name of each: ``top`` (variables) and
    ``struct.field`` for each struct's vector fields (``fields``: struct to its fields), plus
    the bare field name where it is unambiguous (no variable of that name, one struct with
    it). Returns ``(names, full)``, ``full`` mapping each short name to ``struct.field``."""
    full_names = [f"{st}.{f}" for st, fs in fields.items() for f in fs]
    count: dict[str, int] = {}
    for fs in fields.values():
        for f in fs:
            count[f] = count.get(f, 0) + 1
    short = {
        f: f"{st}.{f}" for st, fs in fields.items() for f in fs if count[f] == 1 and f not in top
    }
    return [*top, *short, *full_names], short


def _v5_struct_fields(
    path: Path, info: list[Any], unusable: dict[str, str], file: str
) -> dict[str, np.ndarray]:
    """The vector fields of the file's scalar struct variables (but ``units``), as
    ``{"struct.field": values}``; a struct array or a field that is no numeric vector goes
    into ``unusable``."""
    structs = [n for n, shape, cls in info if cls == "struct" and n != "units"]
    if not structs:
        return {}
    d = scipy.io.loadmat(path, variable_names=structs, squeeze_me=True)
    out: dict[str, np.ndarray] = {}
    for st in structs:
        v = np.asarray(d.get(st))
        if v.dtype.names is None:
            continue
        if v.size != 1:
            unusable[st] = f"a MATLAB struct array ({v.size} elements)"
            continue
        rec = v.reshape(-1)[0]
        for f in v.dtype.names:
            a = np.asarray(rec[f])
            if a.dtype == object and a.size == 1:
                a = np.asarray(a.reshape(-1)[0])
            if a.dtype.kind in "fiu" and a.ndim <= 2:
                out[f"{st}.{f}"] = a
            else:
                what = {"U": "text", "S": "text", "c": "complex", "b": "logical"}.get(
                    a.dtype.kind, "a MATLAB struct" if a.dtype.names else "not numeric"
                )
                unusable[f"{st}.{f}"] = what
        unusable.pop(st, None)
    return out


def _read_v5(path: Path, file: str, columns: Any, kind: Any) -> tuple[Any, ...]:
    with open(path, "rb") as fh:
        v4 = 0 in fh.read(4)  # scipy's test: a v4 file has a zero among its first 4 bytes
    if not v4:
        # scipy's compiled v5 parser crashes the process on some damaged files: check first
        check_mat5(path, file=file)
    try:
        info = scipy.io.whosmat(path)
    except Exception as exc:
        raise RecordingError(f"not a readable MATLAB file ({exc})", file=file) from None
    numeric = [n for n, _shape, cls in info if cls in ("double", "single") or "int" in cls]
    unusable = {n: f"a MATLAB {cls}" for n, _shape, cls in info if n not in numeric}
    fields = _v5_struct_fields(path, info, unusable, file)
    by_struct: dict[str, list[str]] = {}
    for full in fields:
        st, f = full.split(".", 1)
        by_struct.setdefault(st, []).append(f)
    available, short = struct_names(numeric, by_struct)
    kind, mapping = resolve_columns(
        available, columns=columns, kind=kind, file=file, unusable=unusable
    )
    mapping = {c: short.get(n, n) for c, n in mapping.items()}
    names = {n for n in mapping.values() if n not in fields}
    extra = [n for n, _s, _c in info if n == "units" or n in {f"{m}_unit" for m in names}]
    extra += [n for n, _s, _c in info if n in ("dt", "fs")]
    d = scipy.io.loadmat(path, variable_names=[*names, *extra], squeeze_me=True)
    d.update(fields)
    raw = {}
    for c, n in mapping.items():
        a = real_values(d[n], file=file, column=n)
        if a.ndim > 1 and len([k for k in a.shape if k != 1]) > 1:
            raise RecordingError(
                f"variable has shape {a.shape}; a channel must be a vector", file=file, column=n
            )
        raw[c] = a.reshape(-1)
    units: dict[str, str | None] = {}
    ustruct = d.get("units")
    for c, n in mapping.items():
        u = None
        leaf = n.rsplit(".", 1)[-1]
        if ustruct is not None and getattr(ustruct, "dtype", None) is not None:
            if ustruct.dtype.names and leaf in ustruct.dtype.names:
                u = _mat_text(ustruct[leaf])
        if u is None and f"{n}_unit" in d:
            u = _mat_text(d[f"{n}_unit"])
        if u is None:
            u = split_name(leaf)[1]
        units[c] = u
    dt = _dt_of(d, file)
    return kind, mapping, raw, units, dt


def _dt_of(d: Any, file: str) -> float | None:
    """The sampling interval from a variable ``dt`` or ``fs`` of ``d`` (a dict of scipy's
    values or an open v7.3 file), checked; None when there is neither."""
    for key, kind in (("dt", "step"), ("fs", "rate")):
        if key in d:
            v = d[key]
            if hasattr(v, "attrs") and hasattr(v, "shape"):  # a v7.3 dataset
                v = np.empty(0) if v.attrs.get("MATLAB_empty", 0) else v[()]
            label = f"variable {key!r}"
            x = metadata_scalar(v, file=file, label=label, kind=kind)
            return x if kind == "step" else step_of_rate(x, file=file, label=label)
    return None


def _v73_text(f: Any, path: str, *, file: str, column: str) -> str | None:
    """The text of the v7.3 dataset at ``path`` (a unit); anything else is refused."""
    h5py = import_h5py()
    obj = f[path]
    if not isinstance(obj, h5py.Dataset):
        raise RecordingError(
            f"the unit {path!r} is a {type(obj).__name__.lower()}, not text",
            file=file,
            column=column,
        )
    return text_value(obj[()]).strip() or None


def v73_layout(
    f: Any, *, columns: Any, kind: Any, file: str
) -> tuple[str | None, dict[str, str], dict[str, str | None], float | None]:
    """``(kind, mapping, units, dt)`` of an open MAT v7.3 file, without reading the data."""
    with h5_guard(file):
        return _v73_layout(f, columns=columns, kind=kind, file=file)


def _v73_layout(
    f: Any, *, columns: Any, kind: Any, file: str
) -> tuple[str | None, dict[str, str], dict[str, str | None], float | None]:
    h5py = import_h5py()
    numeric = [
        n
        for n, obj in f.items()
        if isinstance(n, str)  # a damaged name table can yield bytes (found by fuzzing)
        and isinstance(obj, h5py.Dataset)
        and text_value(obj.attrs.get("MATLAB_class", b"double")) in ("double", "single")
    ]
    structs = {
        n: "a MATLAB struct"
        for n, obj in f.items()
        if isinstance(n, str)
        and n != "units"
        and isinstance(obj, h5py.Group)
        and text_value(obj.attrs.get("MATLAB_class", b"")) == "struct"
    }
    by_struct: dict[str, list[str]] = {}
    for st in list(structs):
        for fn, obj in f[st].items():
            if not isinstance(fn, str):
                continue
            cls = text_value(obj.attrs.get("MATLAB_class", b""))
            if isinstance(obj, h5py.Dataset) and cls in ("double", "single"):
                by_struct.setdefault(st, []).append(fn)
            else:
                structs[f"{st}.{fn}"] = f"a MATLAB {cls or type(obj).__name__.lower()}"
        del structs[st]  # its fields are listed (read, or named as unusable)
    available, short = struct_names(numeric, by_struct)
    kind, mapping = resolve_columns(
        available, columns=columns, kind=kind, file=file, unusable=structs
    )
    mapping = {c: short.get(n, n) for c, n in mapping.items()}
    units: dict[str, str | None] = {}
    for c, n in mapping.items():
        u = None
        leaf = n.rsplit(".", 1)[-1]
        if "units" in f and isinstance(f["units"], h5py.Group) and leaf in f["units"]:
            u = _v73_text(f, f"units/{leaf}", file=file, column=n)
        if u is None and "." not in n and f"{n}_unit" in f:
            u = _v73_text(f, f"{n}_unit", file=file, column=n)
        if u is None:
            u = split_name(leaf)[1]
        units[c] = u
    return kind, mapping, units, _dt_of(f, file)


def v73_dataset(f: Any, name: str) -> Any:
    """The dataset of channel ``name`` of an open v7.3 file: a variable, or ``struct.field``
    (MATLAB names hold neither ``.`` nor ``/``)."""
    return f[name.replace(".", "/")]


def _read_v73(path: Path, file: str, columns: Any, kind: Any) -> tuple[Any, ...]:
    with open_hdf5(path, file=file) as f:
        kind, mapping, units, dt = v73_layout(f, columns=columns, kind=kind, file=file)
        with h5_guard(file):
            raw = {c: vector(v73_dataset(f, n), file=file, column=n) for c, n in mapping.items()}
    return kind, mapping, raw, units, dt


def read_mat(
    path: str | Path,
    *,
    columns: dict[str, str] | None = None,
    kind: str | None = None,
    fs: float | None = None,
    resample: bool = False,
) -> Recording:
    """Read a MATLAB recording (v4-v7 or v7.3); see :func:`contactlab.io.read_recording`.

    Rows in errors are 0-based sample indices.
    """
    path = Path(path)
    file = str(path)
    v73 = content_format(path) == "mat73"
    reader = _read_v73 if v73 else _read_v5
    kind, mapping, raw, units, dt = reader(path, file, columns, kind)
    check_equal_lengths(raw, mapping, file=file, what="variables")
    t_fallback = None
    if "t" not in raw and fs is None and dt is not None:
        n = next(iter(raw.values())).size
        t_fallback = time_from_interval(dt, n, file=file, name="sampling interval dt =")
    return finish(
        raw,
        mapping,
        units,
        kind=kind,
        file=file,
        fs=fs,
        resample=resample,
        t_fallback=t_fallback,
        meta={"format": "mat73" if v73 else "mat"},
    )


_MAT73_HEADER = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created by: contactlab HDF5 schema 1.00 ."


def write_mat(path: str | Path, rec: Recording, *, version: str = "5", **_: Any) -> Path:
    """Write ``rec`` as a MATLAB file: column vectors ``t`` and one per channel, plus a struct
    ``units``. ``version="5"`` (scipy, default) or ``"7.3"`` (HDF5 with the MATLAB header and
    ``MATLAB_class`` attributes, as MATLAB writes it)."""
    if version not in ("5", "7.3"):
        raise RecordingError(f"MAT version must be '5' or '7.3', got {version!r}", file=str(path))
    units = {"t": "s", **rec.units}
    with atomic_path(path) as tmp:
        if version == "5":
            d: dict[str, Any] = {"t": rec.t.reshape(-1, 1)}
            d.update({k: v.reshape(-1, 1) for k, v in rec.data.items()})
            d["units"] = {k: u for k, u in units.items()}
            with open(tmp, "wb") as fh:
                scipy.io.savemat(fh, d, format="5", oned_as="column")
        else:
            h5py = import_h5py()
            with h5py.File(tmp, "w", userblock_size=512) as f:
                for k, v in {"t": rec.t, **rec.data}.items():
                    ds = f.create_dataset(k, data=v.reshape(1, -1))
                    ds.attrs["MATLAB_class"] = np.bytes_("double")
                g = f.create_group("units")
                g.attrs["MATLAB_class"] = np.bytes_("struct")
                for k, u in units.items():
                    ds = g.create_dataset(k, data=np.array([[ord(c)] for c in u], np.uint16))
                    ds.attrs["MATLAB_class"] = np.bytes_("char")
            with open(tmp, "r+b") as fh:
                fh.write(_MAT73_HEADER.ljust(116, b" ")[:116])
                fh.write(b"\x00" * 8)  # subsystem data offset
                fh.write(b"\x00\x02")  # version 0x0200
                fh.write(b"IM")  # endian indicator
    return Path(path)
