"""Recordings of a joint as the fits and comparisons take them: time, displacement, force.

A record is a :class:`JointRecord` or anything that converts to one (:func:`as_record`): a
tuple ``(t, x, F)``, a mapping with keys ``t``, ``x``, ``F`` or a
:class:`contactlab.io.Recording` of a tangential test. Arrays are checked at the boundary:
float64, 1-D, finite, of one length, time strictly increasing; an error names the record and
the sample.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._arrays import as_1d
from ..errors import InputError


@dataclass
class JointRecord:
    """One test: time ``t`` [s], displacement ``x`` [m] and measured force ``F`` [N].

    Parameters
    ----------
    t, x, F : array
        Samples of one length; ``t`` strictly increasing. ``F`` may be None for a record
        that is only to be predicted.
    name : str
        Label in tables and reports.
    mask : array of bool, optional
        Samples a fit compares (the law still runs over the whole record, from its first
        sample, so that its memory is built up): e.g. everything after a run-in, or the
        first 25 cycles. Default: every sample.
    """

    t: np.ndarray
    x: np.ndarray
    F: np.ndarray | None = None
    name: str = ""
    mask: np.ndarray | None = None
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        who = f"record {self.name!r}" if self.name else "record"
        self.t = as_1d(self.t, f"{who}: t")
        self.x = as_1d(self.x, f"{who}: x")
        n = self.t.size
        if self.x.size != n:
            raise InputError(f"{who}: x has {self.x.size} samples, t has {n}")
        if self.F is not None:
            self.F = as_1d(self.F, f"{who}: F")
            if self.F.size != n:
                raise InputError(f"{who}: F has {self.F.size} samples, t has {n}")
        if n < 3:
            raise InputError(f"{who}: {n} samples; a joint record needs at least 3")
        dt = np.diff(self.t)
        if not np.all(dt > 0):
            i = int(np.argmax(~(dt > 0)))
            raise InputError(
                f"{who}: time must increase strictly; t[{i + 1}] = {self.t[i + 1]!r} follows "
                f"t[{i}] = {self.t[i]!r}"
            )
        if self.mask is not None:
            m = np.asarray(self.mask)
            if m.dtype != bool or m.shape != (n,):
                raise InputError(f"{who}: mask must be a boolean array of {n} samples")
            if not m.any():
                raise InputError(f"{who}: mask selects no sample")
            self.mask = np.ascontiguousarray(m)

    @property
    def n(self) -> int:
        return int(self.t.size)

    def selected(self) -> np.ndarray:
        """Indices of the samples a fit compares."""
        return np.arange(self.n) if self.mask is None else np.flatnonzero(self.mask)

    def require_force(self) -> np.ndarray:
        if self.F is None:
            raise InputError(f"record {self.name!r} has no measured force F")
        return self.F

    def window(self, start: int, stop: int, name: str | None = None) -> JointRecord:
        """Samples ``start:stop`` as a record of their own."""
        F = None if self.F is None else self.F[start:stop]
        m = None if self.mask is None else self.mask[start:stop]
        if m is not None and not m.any():
            m = None
        return JointRecord(self.t[start:stop], self.x[start:stop], F,
                           name if name is not None else self.name, m)  # fmt: skip


def _is_recording(obj: Any) -> bool:
    """A :class:`contactlab.io.Recording` (or alike: ``t`` and a mapping ``data``)."""
    return hasattr(obj, "t") and isinstance(getattr(obj, "data", None), Mapping)


def as_record(obj: Any, name: str | None = None, *, fs: float | None = None) -> JointRecord:
    """A :class:`JointRecord` from a record-like object.

    Accepted: a :class:`JointRecord`; a tuple ``(t, x, F)`` or ``(t, x)`` (``t`` may be None
    when ``fs`` is given); a mapping with ``t`` (or ``fs``), ``x`` and ``F``; a
    :class:`contactlab.io.Recording` with channels ``x`` and ``F``.
    """
    if isinstance(obj, JointRecord):
        if name is not None and not obj.name:
            obj.name = name
        return obj
    label = name or ""

    def time(t: Any, n: int, rate: float | None) -> Any:
        if t is not None:
            return t
        if rate is None or not (np.isfinite(rate) and rate > 0):
            raise InputError(f"record {label!r}: no time axis; give t or a sampling rate fs > 0")
        return np.arange(n) / float(rate)

    if isinstance(obj, tuple):
        if len(obj) not in (2, 3):
            raise InputError(f"record {label!r}: a tuple must be (t, x, F) or (t, x)")
        x = np.asarray(obj[1], dtype=float).reshape(-1)
        F = obj[2] if len(obj) == 3 else None
        F = None if F is None else np.asarray(F, dtype=float).reshape(-1)
        return JointRecord(time(obj[0], x.size, fs), x, F, label)
    if isinstance(obj, Mapping):
        if "x" not in obj:
            raise InputError(f"record {label!r}: no 'x' in the mapping")
        x = np.asarray(obj["x"], dtype=float).reshape(-1)
        F = obj.get("F")
        F = None if F is None else np.asarray(F, dtype=float).reshape(-1)
        rate = obj.get("fs", fs)
        return JointRecord(time(obj.get("t"), x.size, rate), x, F,
                           str(obj.get("name", label)), obj.get("mask"))  # fmt: skip
    if _is_recording(obj):
        data = obj.data
        if "x" not in data or "F" not in data:
            have = ", ".join(sorted(data))
            raise InputError(
                f"recording {getattr(obj, 'source', label)}: needs channels x and F (has "
                f"{have}); name them with columns={{'x': ..., 'F': ...}}"
            )
        src = getattr(obj, "source", None)
        return JointRecord(obj.t, data["x"], data["F"], label or (str(src) if src else ""))
    raise InputError(
        f"record {label!r}: expected a JointRecord, (t, x, F), a mapping or a Recording, got "
        f"{type(obj).__name__}"
    )


def as_records(
    records: Any, *, fs: float | None = None, names: Sequence[str] | None = None
) -> list[JointRecord]:
    """A list of records from one record-like object or a sequence of them."""

    def record_like(r: Any) -> bool:
        return isinstance(r, (JointRecord, tuple, Mapping)) or _is_recording(r)

    if isinstance(records, tuple) and not any(record_like(r) for r in records):
        seq = [records]  # (t, x, F)
    elif record_like(records) and not isinstance(records, tuple):
        seq = [records]
    elif isinstance(records, Sequence) and not isinstance(records, (str, bytes)):
        seq = list(records)
    else:
        raise InputError(f"records: expected a record or a list of records, got "
                         f"{type(records).__name__}")  # fmt: skip
    if not seq:
        raise InputError("records: the list is empty")
    if names is not None and len(names) != len(seq):
        raise InputError(f"records: {len(names)} names for {len(seq)} records")
    out = []
    for i, r in enumerate(seq):
        label = names[i] if names is not None else f"record {i}"
        rec = as_record(r, label, fs=fs)
        if not rec.name:
            rec.name = label
        out.append(rec)
    return out


#: the suffixes of one-quantity array files: displacement, force (and velocity, not read)
_NPY_ROLES = {"x": "x", "F": "F", "f": "F", "v": "v"}


def npy_single_quantity(path: Any) -> bool:
    """True when ``path`` is a ``.npy`` file holding one quantity: a 1-D array, or 2-D with
    one row or one column (as ``(1, N)``), which a joint record pairs with its sibling files
    (:func:`read_npy_pair`)."""
    from pathlib import Path

    p = Path(path)
    if p.suffix.lower() != ".npy" or not p.is_file():
        return False
    try:
        arr = np.load(p, mmap_mode="r", allow_pickle=False)
    except (OSError, ValueError):
        return False
    return arr.ndim == 1 or (arr.ndim == 2 and min(arr.shape) == 1)


def read_npy_pair(path: Any, fs: float | None) -> JointRecord:
    """The record of a test stored as one ``.npy`` file per quantity with no time column
    (``<stem>_x.npy`` displacement [m], ``<stem>_F.npy`` force [N], each of shape ``(N,)``,
    ``(1, N)`` or ``(N, 1)``), sampled at ``fs`` [Hz]: ``t = arange(N) / fs``.

    ``path`` is either file of the pair. Raises :class:`InputError` naming what is missing:
    the sampling rate, the partner file, a file name without the ``_x`` / ``_F`` suffix, or
    arrays of different lengths.
    """
    import re
    from pathlib import Path

    p = Path(path)
    m = re.fullmatch(r"(.+)_([xFfv])", p.stem)
    if m is None:
        raise InputError(
            f"{p}: a .npy file of one quantity with no time column; name the test's files "
            "<stem>_x.npy (displacement) and <stem>_F.npy (force) so that they are read as "
            "one recording, or store t, x, F as the columns of one array"
        )
    stem = m.group(1)
    files = {"x": p.with_name(f"{stem}_x.npy"), "F": p.with_name(f"{stem}_F.npy")}
    if not files["F"].is_file() and p.with_name(f"{stem}_f.npy").is_file():
        files["F"] = p.with_name(f"{stem}_f.npy")
    for role, f in files.items():
        if not f.is_file():
            what = "displacement" if role == "x" else "force"
            raise InputError(f"{p}: the {what} of this test, {f.name}, is not next to it")
    if fs is None:
        raise InputError(
            f"{p}: the arrays have no time column; give the sampling rate with --fs (Hz; a "
            "data folder's README states it)"
        )
    fs = float(fs)
    if not (np.isfinite(fs) and fs > 0):
        raise InputError(f"--fs must be a positive sampling rate in Hz, got {fs}")
    data = {}
    for role, f in files.items():
        arr = np.load(f, allow_pickle=False)
        if not (arr.ndim == 1 or (arr.ndim == 2 and min(arr.shape) == 1)):
            raise InputError(f"{f}: shape {arr.shape} is not one quantity ((N,), (1, N), (N, 1))")
        data[role] = np.asarray(arr, dtype=float).reshape(-1)
    if data["x"].size != data["F"].size:
        raise InputError(f"{stem}: {files['x'].name} has {data['x'].size} samples, "
                         f"{files['F'].name} has {data['F'].size}")  # fmt: skip
    t = np.arange(data["x"].size) / fs
    return JointRecord(t, data["x"], data["F"], stem)
