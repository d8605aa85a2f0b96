"""NumPy recordings: ``.npy`` (one array) and ``.npz`` (named arrays), read without pickle.

How the channels are found:

- ``.npz``: each 1-D array is a channel, named by its key (with its unit, as a CSV header
  names it: ``"x [um]"``, ``"F [N]"``, or plain ``"x"`` in SI). A 0-d array named ``fs``
  (Hz) or ``dt`` (s) gives the time axis of a file without a ``t`` array. An ``.npz``
  holding a single 2-D or structured array is read as an ``.npy`` of that array.
- ``.npy`` structured array (``np.save(path, rec_array)``): each field is a channel, named
  by the field (units as above).
- ``.npy`` plain 2-D array: the columns have no names, only positions ``"0"``, ``"1"``, ...
  In SI, and without ``columns=`` their order is **t, x, F** (three columns; a tangential
  recording) or **t, p, delta** (``kind="normal"``); two columns are **x, F** (``p, delta``)
  and need ``fs=``. Any other layout is mapped by position: ``columns={"t": "0", "x": "2",
  "F": "3"}`` (command line: ``--columns t=0,x=2,F=3``). An array with fewer rows than
  columns (at most 16 rows) is taken as channels in rows and read transposed.

Arrays of objects are refused (they would need pickle, which can run code). ``.npy`` files
are memory-mapped: :func:`contactlab.io.read_chunks` reads them slice by slice.
"""

from __future__ import annotations

import zipfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np

from .._io_atomic import atomic_path
from .recording import (
    KIND_CHANNELS,
    Recording,
    RecordingError,
    check_equal_lengths,
    finish,
    metadata_scalar,
    real_values,
    resolve_columns,
    time_from_interval,
)
from .units import split_name

#: a plain 2-D array with more rows than this and fewer columns is channels-in-columns
_MAX_CHANNEL_ROWS = 16


def _load(path: Path, *, mmap: bool) -> Any:
    """``np.load`` without pickle; what numpy raises on a damaged or object file, worded."""
    file = str(path)
    try:
        return np.load(path, mmap_mode="r" if mmap else None, allow_pickle=False)
    except ValueError as exc:
        if "allow_pickle" in str(exc) or "Object arrays" in str(exc):
            raise RecordingError(
                "holds Python objects (a pickled array), which are not read (loading them could "
                "run code): save numbers, e.g. np.save(path, np.column_stack([t, x, F]))",
                file=file,
            ) from None
        raise RecordingError(f"not a readable NumPy file ({exc})", file=file) from None
    except (OSError, EOFError, zipfile.BadZipFile) as exc:
        raise RecordingError(f"not a readable NumPy file ({exc})", file=file) from None


def _columns_of(a: np.ndarray, *, file: str) -> tuple[dict[str, Any], bool]:
    """Channel name -> 1-D view of an ``.npy`` array, and whether the names are positions."""
    if a.dtype.names:
        out: dict[str, Any] = {}
        for name in a.dtype.names:
            sub = a[name]
            if sub.ndim != 1:
                raise RecordingError(
                    f"field of shape {sub.shape}: a channel must be one number per sample",
                    file=file,
                    column=name,
                )
            out[name] = sub
        return out, False
    if a.ndim == 2:
        rows = a.shape[0] < a.shape[1] and a.shape[0] <= _MAX_CHANNEL_ROWS
        cols = a if not rows else a.T
        return {str(j): cols[:, j] for j in range(cols.shape[1])}, True
    if a.ndim == 1:
        raise RecordingError(
            "a 1-D array holds one channel only: save a 2-D array with columns t, x, F (np.save("
            "path, np.column_stack([t, x, F]))), a structured array, or an .npz of named arrays "
            "(np.savez(path, t=t, x=x, F=F))",
            file=file,
        )
    raise RecordingError(
        f"array of shape {a.shape}: a recording is a 2-D array (samples x channels), a "
        "structured array or an .npz of named 1-D arrays",
        file=file,
    )


def positional_columns(
    n_columns: int, kind: str | None, columns: dict[str, str] | None, *, file: str
) -> tuple[dict[str, str] | None, str | None]:
    """The documented order of a header-less array's columns: ``t, x, F`` (``t, p, delta``
    for ``kind="normal"``); two columns ``x, F``. Explicit ``columns`` win. Other widths
    without ``columns`` are a :class:`RecordingError` asking for them."""
    if columns:
        return columns, kind
    kind = kind or "tangential"
    if kind not in KIND_CHANNELS:
        return columns, kind
    chans = KIND_CHANNELS[kind]
    if n_columns == 3:
        return {"t": "0", chans[0]: "1", chans[1]: "2"}, kind
    if n_columns == 2:
        return {chans[0]: "0", chans[1]: "1"}, kind
    order = ", ".join(("t", *chans))
    raise RecordingError(
        f"a plain array of {n_columns} columns: its columns have no names, so the order "
        f"{order} (3 columns) or {', '.join(chans)} (2 columns) is assumed only for those "
        f"widths; name them by position: columns={{'t': '0', {chans[0]!r}: '1', "
        f"{chans[1]!r}: '2'}} (command line: --columns t=0,{chans[0]}=1,{chans[1]}=2)",
        file=file,
    )


def _table(path: Path, *, mmap: bool) -> tuple[dict[str, Any], dict[str, Any], bool, str, Any]:
    """``(channels, scalars, positional, format, handle)`` of an ``.npy``/``.npz`` file:
    1-D arrays by name, 0-d arrays by name (npz ``fs``/``dt``), whether the names are
    positions, ``"npy"``/``"npz"``, and the open NpzFile (to close) or None."""
    file = str(path)
    obj = _load(path, mmap=mmap)
    if isinstance(obj, np.ndarray):
        chans, positional = _columns_of(obj, file=file)
        return chans, {}, positional, "npy", None
    chans, scalars, others = {}, {}, {}
    try:
        for key in obj.files:
            a = obj[key]
            if a.ndim == 0:
                scalars[key] = a
            elif a.ndim == 1 or (a.ndim == 2 and 1 in a.shape and not a.dtype.names):
                chans[key] = a.reshape(-1)
            else:
                others[key] = a
    except ValueError as exc:  # an object array inside the archive
        obj.close()
        if "allow_pickle" in str(exc) or "Object arrays" in str(exc):
            raise RecordingError(
                "an array in the archive holds Python objects, which are not read (loading "
                "them could run code): save numbers",
                file=file,
            ) from None
        raise RecordingError(f"not a readable NumPy file ({exc})", file=file) from None
    if not chans and len(others) == 1:  # an .npz of one table
        (a,) = others.values()
        chans, positional = _columns_of(a, file=file)
        return chans, scalars, positional, "npz", obj
    if not chans:
        obj.close()
        raise RecordingError(
            f"no 1-D array in the archive (arrays: {sorted(obj.files)}); save one per channel: "
            "np.savez(path, t=t, x=x, F=F)",
            file=file,
        )
    return chans, scalars, False, "npz", obj


def _time_meta(scalars: dict[str, Any], *, file: str) -> tuple[float | None, float | None]:
    """``(fs, dt)`` stored in an ``.npz`` as 0-d arrays (either may be None)."""
    fs = dt = None
    for key, a in scalars.items():
        name, unit = split_name(key)
        if name.lower() in ("fs", "sampling_rate", "rate"):
            fs = metadata_scalar(a, file=file, label=f"array {key!r}", kind="rate")
            if unit:
                from .units import to_si

                fs *= to_si(unit, where=key)[0]
        elif name.lower() in ("dt", "step", "time_step"):
            dt = metadata_scalar(a, file=file, label=f"array {key!r}", kind="step")
            if unit:
                from .units import to_si

                dt *= to_si(unit, where=key)[0]
    return fs, dt


def layout(
    path: Path,
    *,
    columns: dict[str, str] | None,
    kind: str | None,
    fs: float | None,
    mmap: bool,
) -> tuple[
    str | None,
    dict[str, str],
    dict[str, Any],
    dict[str, str | None],
    float | None,
    dict[str, Any],
    Any,
]:
    """What both readers need: ``(kind, mapping, arrays, file_units, dt, meta, handle)``."""
    file = str(path)
    chans, scalars, positional, fmt, handle = _table(path, mmap=mmap)
    try:
        if positional:
            columns, kind = positional_columns(len(chans), kind, columns, file=file)
        kind, mapping = resolve_columns(list(chans), columns=columns, kind=kind, file=file)
        units = {c: split_name(mapping[c])[1] for c in mapping}
        file_fs, file_dt = _time_meta(scalars, file=file)
        if fs is not None:
            dt = None  # the caller's rate wins
        elif file_fs is not None:
            dt = 1.0 / file_fs
        else:
            dt = file_dt
        meta: dict[str, Any] = {"format": fmt}
        if positional:
            meta["column_order"] = "by position: " + ", ".join(f"{c}={mapping[c]}" for c in mapping)
        arrays = {c: chans[mapping[c]] for c in mapping}
        return kind, mapping, arrays, units, dt, meta, handle
    except BaseException:
        if handle is not None:
            handle.close()
        raise


def read_npy(
    path: str | Path,
    *,
    columns: dict[str, str] | None = None,
    kind: str | None = None,
    fs: float | None = None,
    resample: bool = False,
) -> Recording:
    """Read an ``.npy`` or ``.npz`` recording; see :func:`contactlab.io.read_recording` and
    the module's description of the layouts.

    Examples
    --------
    >>> import tempfile, pathlib, numpy as np
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "run.npz"
    >>> t = np.arange(4) * 1e-3
    >>> np.savez(p, **{"t": t, "x [um]": [0, 1, 2, 3], "F [N]": [0, 2, 4, 6]})
    >>> rec = read_npy(p)
    >>> rec["x"].tolist(), rec.kind
    ([0.0, 1e-06, 2e-06, 3e-06], 'tangential')
    """
    path = Path(path)
    file = str(path)
    kind, mapping, arrays, units, dt, meta, handle = layout(
        path, columns=columns, kind=kind, fs=fs, mmap=False
    )
    try:
        raw = {
            c: real_values(a, file=file, column=mapping[c]).reshape(-1) for c, a in arrays.items()
        }
    finally:
        if handle is not None:
            handle.close()
    check_equal_lengths(raw, mapping, file=file)
    t_fallback = None
    if "t" not in raw and fs is None and dt is not None:
        t_fallback = time_from_interval(dt, next(iter(raw.values())).size, file=file)
    return finish(
        raw,
        mapping,
        units,
        kind=kind,
        file=file,
        fs=fs,
        t_fallback=t_fallback,
        meta=meta,
        resample=resample,
    )


def npy_chunk_source(
    path: Path, *, columns: dict[str, str] | None, kind: str | None, fs: float | None
) -> tuple[
    str | None,
    dict[str, str],
    dict[str, str | None],
    float | None,
    int,
    dict[str, Any],
    Callable[[int], Iterator[tuple[int, dict[str, np.ndarray]]]],
]:
    """An ``.npy`` opened memory-mapped for :func:`contactlab.io.read_chunks`: ``(kind,
    mapping, file_units, dt, n, meta, slices)``, where ``slices(chunk)`` yields ``(offset,
    {canonical: values})`` chunk by chunk (only those pages of the file are read)."""
    file = str(path)
    kind, mapping, arrays, units, dt, meta, handle = layout(
        path, columns=columns, kind=kind, fs=fs, mmap=True
    )
    if handle is not None:
        handle.close()
    sizes = {mapping[c]: int(a.shape[0]) for c, a in arrays.items()}
    if len(set(sizes.values())) > 1:
        raise RecordingError(f"channels differ in length: {sizes}", file=file)
    n = next(iter(sizes.values()))

    def slices(chunk: int) -> Iterator[tuple[int, dict[str, np.ndarray]]]:
        _k, _m, arrs, _u, _dt, _meta, h = layout(path, columns=columns, kind=kind, fs=fs, mmap=True)
        if h is not None:
            h.close()
        for a in range(0, max(n, 1), chunk):
            b = min(a + chunk, n)
            yield (
                a,
                {
                    c: real_values(np.array(v[a:b]), file=file, column=mapping[c])
                    for c, v in arrs.items()
                },
            )

    return kind, mapping, units, dt, n, meta, slices


def write_npy(path: str | Path, rec: Recording, **_: Any) -> Path:
    """Write ``rec`` as ``.npz`` (one array per channel, named with its SI unit: ``"t [s]"``,
    ``"x [m]"``) or ``.npy`` (a structured array with those field names), atomically."""
    cols = [("t", "s", rec.t)] + [(k, rec.units[k], v) for k, v in rec.data.items()]
    names = [f"{k} [{u}]" if u else k for k, u, _ in cols]
    with atomic_path(path) as tmp:
        if Path(path).suffix.lower() == ".npz":
            with open(tmp, "wb") as fh:
                np.savez(fh, **{n: v for n, (_, _, v) in zip(names, cols, strict=True)})
        else:
            a = np.empty(rec.t.size, dtype=[(n, np.float64) for n in names])
            for n, (_, _, v) in zip(names, cols, strict=True):
                a[n] = v
            with open(tmp, "wb") as fh:
                np.save(fh, a)
    return Path(path)
