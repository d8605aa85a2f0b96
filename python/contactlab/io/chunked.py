"""Reading a long recording chunk by chunk, in bounded memory.

:func:`read_chunks` opens a recording like :func:`contactlab.io.read_recording` (same column
guessing, units, ``kind``, ``fs``) and yields it as consecutive :class:`Recording` chunks of at
most ``chunk_size`` samples, SI inside, each with ``meta["offset"]`` (index of its first
sample) and ``meta["ranges"]`` (each channel's smallest and largest value in the chunk, SI).
Only one chunk of the needed channels is in memory at a time:

- HDF5 and MAT v7.3: datasets read by slices (h5py);
- TDMS: channels read by ``offset``/``length`` (npTDMS streaming mode: only the segments
  holding the slice are touched);
- CSV/text: blocks of lines parsed with ``numpy.loadtxt``;
- MAT v4-v7 (scipy) has no partial reads: the file is read whole, then handed out in chunks.

Every chunk is checked as the whole-file readers check a file, and errors carry the same
messages (file, column, row: the 1-based line for text, the 0-based sample index otherwise):
non-finite values, time going back or repeating (also across chunk boundaries) and gaps
(steps above 1.5 times the first chunk's median step).
"""

from __future__ import annotations

import itertools
import math
import os
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .. import _core
from ..errors import InputError
from .recording import (
    RESAMPLE_MAX_GAP,
    Recording,
    RecordingError,
    at_sample,
    check_equal_lengths,
    check_finite,
    check_time,
    real_values,
    resolve_columns,
    step_of_rate,
    unit_factor,
    user_rate,
)
from .sniff import content_format, format_of

#: default samples per chunk (8 MiB per channel)
DEFAULT_CHUNK = 1 << 20

#: ``alloc(n, names)``: the arrays a chunk of ``n`` samples is written into, one per name
#: (``"t"`` and each channel)
Alloc = Callable[[int, list[str]], dict[str, np.ndarray]]


@dataclass
class ChunkedRecording:
    """A recording read chunk by chunk; iterate it for :class:`Recording` chunks.

    Attributes
    ----------
    source : str
        The file.
    kind : str or None
        ``"tangential"`` or ``"normal"``.
    units : dict
        SI unit of each channel.
    columns : dict
        Canonical channel name to the name in the file.
    n_samples : int or None
        Number of samples when the format tells without reading (None for text files).
    meta : dict
        Format, file units, channels whose unit was assumed SI.
    """

    source: str
    kind: str | None
    units: dict[str, str]
    columns: dict[str, str]
    n_samples: int | None
    meta: dict[str, Any]
    _open: Callable[[], Iterator[Recording]] = field(repr=False)
    _open_into: Callable[[Alloc, bool], Iterator[Recording]] | None = field(
        default=None, repr=False
    )
    #: ``(t0, dt)`` when the time axis is made from a sampling interval: sample ``i`` is at
    #: ``t0 + dt * i`` (``contactlab._core.fill_time``), else None (a time column)
    time_step: tuple[float, float] | None = None
    #: the reader checks every chunk as the whole-file reader checks a recording: channels
    #: finite (``meta["ranges"]`` their exact extremes), time axis finite and increasing
    checked: bool = False

    def __iter__(self) -> Iterator[Recording]:
        return self._open()

    def chunks_into(self, alloc: Alloc, *, time_axis: bool = True) -> Iterator[Recording]:
        """The chunks, with the time axis and each channel (SI) written into the arrays that
        ``alloc(n, names)`` returns for a chunk of ``n`` samples: a dict of each of ``names``
        (``"t"`` and the channels) to a writable contiguous float64 array of ``n`` samples,
        which become the chunk's arrays. HDF5 datasets stored as plain float64 are read
        straight into them (no array allocated per chunk, no copy); other data is copied.
        ``alloc`` is called for a chunk only once the previous chunk has been taken from the
        iterator.

        ``time_axis=False``, for a caller that makes the axis from :attr:`time_step` itself:
        where the reader would make it from the sampling interval (:attr:`time_step` not
        None), it is checked (its last stamps finite and increasing) but not written, and
        the chunks' ``t`` holds whatever ``alloc`` left in its array (do not read it). A
        time column is written as always."""
        if self._open_into is not None:
            yield from self._open_into(alloc, time_axis)
            return
        for c in self._open():
            out = alloc(len(c), ["t", *c.data])
            np.copyto(out["t"], c.t)
            data = {}
            for k, v in c.data.items():
                np.copyto(out[k], v)
                data[k] = out[k]
            yield Recording(out["t"], data, c.units, c.source, c.meta)


class _Finisher:
    """Unit conversion and the checks of :func:`~contactlab.io.recording.finish`, applied
    chunk by chunk with the state they need across boundaries (the last time stamp, the
    reference step)."""

    def __init__(
        self,
        mapping: dict[str, str],
        file_units: dict[str, str | None],
        *,
        kind: str | None,
        file: str,
        fs: float | None,
        dt: float | None = None,
        t0: float = 0.0,
        row_of: Callable[[int], int] | None = None,
        meta: dict[str, Any] | None = None,
        resample: bool = False,
        time_axis: bool = True,
    ) -> None:
        self.mapping, self.kind, self.file = mapping, kind, file
        # a time axis made from the sampling interval written into ``out["t"]`` (False: only
        # checked; see ChunkedRecording.chunks_into)
        self.time_axis = time_axis
        # resampling onto the grid t0 + step·k: the grid's next index, the previous chunk's
        # last sample (interpolation across the boundary), what was bridged so far
        self.resample = resample and "t" in mapping
        self.grid_next = 0
        self.carry: tuple[float, dict[str, float]] | None = None
        self.bridged = {"largest_step": 0.0, "steps_bridged": 0, "n_read": 0}
        self.row_of = row_of  # a sample's line of a text file (None: binary)
        assumed: list[str] = []
        self.factors: dict[str, float] = {}
        self.units: dict[str, str] = {}
        for canon, col in mapping.items():
            f, si = unit_factor(canon, col, file_units.get(canon), file=file, assumed=assumed)
            self.factors[canon] = f
            if canon != "t":
                self.units[canon] = si
        self.dt = None
        self.dt_source = ""  # what the time step came from, for the messages
        if "t" not in mapping:
            if fs is not None:
                fs = user_rate(fs, file=file)
                self.dt = step_of_rate(fs, file=file, label="fs")
                self.dt_source = f"fs = {fs:g}"
            elif dt is not None:
                if not np.isfinite(dt) or dt <= 0:
                    raise RecordingError(
                        f"sampling interval {dt} is not a positive time step", file=file
                    )
                self.dt = float(dt)
                self.dt_source = f"sampling interval {self.dt:g} from start time {t0:g}"
            else:
                raise RecordingError(
                    "no time column and no sampling rate: pass fs= (Hz) or columns={'t': ...} "
                    "(command line: --fs or --columns 't=...')",
                    file=file,
                )
        self.t0 = t0
        self.tcol = mapping.get("t", "t")
        self.prev_t: float | None = None
        self.step: float | None = None
        m = dict(meta or {})
        m.setdefault("kind", kind)
        m["columns"] = dict(mapping)
        m["file_units"] = dict(file_units)
        if assumed:
            m["units_assumed_si"] = assumed
        self.meta = m

    @property
    def time_step(self) -> tuple[float, float] | None:
        """``(t0, dt)`` of a time axis made from the sampling interval, else None."""
        return None if self.dt is None else (float(self.t0), float(self.dt))

    def _check_time(self, t: np.ndarray, offset: int) -> None:
        """The whole-file reader's time checks, judged against the first chunk's median step
        and across the boundary with the previous chunk (with ``resample``: steps up to
        :data:`~contactlab.io.recording.RESAMPLE_MAX_GAP` grid steps allowed)."""
        col = self.tcol
        gap = RESAMPLE_MAX_GAP if self.resample else 1.5
        if self.prev_t is None:
            if t.size >= 2:
                self.step = float(np.median(np.diff(t)))
            check_time(
                t,
                file=self.file,
                column=col,
                row_of=self.row_of,
                step=self.step,
                offset=offset,
                max_gap=gap,
            )
            return
        if t.size:  # the boundary: the previous chunk's last stamp, then this one's first
            check_time(
                np.array([self.prev_t, t[0]]),
                file=self.file,
                column=col,
                row_of=self.row_of,
                step=self.step,
                offset=offset - 1,
                max_gap=gap,
            )
        if t.size >= 2:
            check_time(
                t,
                file=self.file,
                column=col,
                row_of=self.row_of,
                step=self.step,
                offset=offset,
                max_gap=gap,
            )

    def _resample(
        self, t: np.ndarray, data: dict[str, np.ndarray]
    ) -> tuple[np.ndarray, dict[str, np.ndarray], int]:
        """This chunk's part of the uniform grid (step: the first chunk's median step),
        interpolated from the chunk and the previous chunk's last sample; and the grid index
        of its first sample."""
        assert self.step is not None
        if self.carry is not None:
            tt = np.concatenate([[self.carry[0]], t])
            dd = {k: np.concatenate([[self.carry[1][k]], v]) for k, v in data.items()}
        else:
            tt, dd = t, data
            self.t_grid0 = float(t[0])
        if tt.size >= 2:
            steps = np.diff(tt)
            b = self.bridged
            b["largest_step"] = max(b["largest_step"], float(steps.max()))
            b["steps_bridged"] += int(np.count_nonzero(steps > 1.5 * self.step))
        self.bridged["n_read"] += int(t.size)
        first = self.grid_next
        k_last = int(np.floor((float(tt[-1]) - self.t_grid0) / self.step * (1 + 1e-12)))
        grid = self.t_grid0 + self.step * np.arange(first, k_last + 1, dtype=np.float64)
        out = {k: np.interp(grid, tt, v) for k, v in dd.items()}
        self.grid_next = k_last + 1
        self.carry = (float(t[-1]), {k: float(v[-1]) for k, v in data.items()})
        return grid, out, first

    def __call__(
        self,
        raw: dict[str, np.ndarray],
        offset: int,
        out: dict[str, np.ndarray] | None = None,
        scans: dict[str, list[Any]] | None = None,
    ) -> Recording:
        """The chunk of samples ``offset..`` from the file's values ``raw`` (by canonical
        name); with ``out`` (``"t"`` and each channel), the SI values are written there (a
        ``raw`` array that is its ``out`` array itself is converted in place). ``scans``:
        ``[all finite, smallest, largest]`` of a channel's ``raw`` values found as they were
        read (:meth:`~contactlab.io.hdf5.DirectRead.read`), taken for its check and range
        where the values are not converted."""
        check_equal_lengths(raw, self.mapping, file=self.file)
        n = next(iter(raw.values())).size
        if self.prev_t is None and n < 2:  # as the whole-file check of the time says
            raise RecordingError(f"only {n} sample(s)", file=self.file, column=self.tcol)

        data: dict[str, np.ndarray] = {}
        ranges: dict[str, tuple[float, float]] = {}
        t = None
        for canon, values in raw.items():
            col = self.mapping[canon]
            dest = None if out is None else out[canon]
            v = np.ascontiguousarray(values, dtype=np.float64)
            factor = self.factors[canon]
            if factor != 1.0:
                if dest is None:
                    with np.errstate(over="ignore", invalid="ignore"):
                        v = v * factor
                else:
                    if values is dest:  # read in place: the file's values for the messages
                        values = v = dest.copy()
                    with np.errstate(over="ignore", invalid="ignore"):
                        np.multiply(v, factor, out=dest)
                    v = dest
            elif dest is not None and values is not dest:
                np.copyto(dest, v)
                v = dest
            # the range in SI (the magnitude check and the cycle trigger of a streamed analysis
            # use it: meta["ranges"]) is the finiteness check too: numpy's min and max are NaN
            # when a value is, and ±inf when one is (or overflowed in the conversion)
            # (one pass of the core: finiteness, min and max; numpy took two passes)
            sc = None if scans is None else scans.get(canon)
            unconverted = factor == 1.0 and v is raw[canon]
            if sc is not None and sc[0] and sc[1] != 0.0 and sc[2] != 0.0 and unconverted:
                # scanned as read, and not converted: the same numbers (the extremes of
                # pieces are the extremes; a zero extreme, whose sign a pass's order could
                # pick, and anything not finite are scanned again below)
                finite, lo, hi = True, sc[1], sc[2]
            else:
                finite, lo, hi = _core.finite_min_max(v) if v.size else (True, math.inf, -math.inf)
            if not finite:
                # the whole-file reader's checks find the value and raise
                check_finite(values, file=self.file, column=col, row_of=self.row_of, offset=offset)
                i = int(np.argmax(~np.isfinite(v)))  # found by fuzzing (track): 1e306 kN in N
                raise RecordingError(
                    f"value {float(values[i])} overflows double precision when converted to SI",
                    file=self.file,
                    column=col,
                    **at_sample(i, self.row_of, offset),
                )
            if canon == "t":
                t = v
            else:
                data[canon] = v
                ranges[canon] = (lo, hi)
        if t is None:
            # a time axis made from the sampling interval is increasing and gap-free by
            # construction: nothing to check. One pass, bit for bit
            # t0 + dt * np.arange(offset, offset + n)
            assert self.dt is not None
            t = np.empty(n, dtype=np.float64) if out is None else out["t"]
            if out is None or self.time_axis:
                _core.fill_time(t, self.t0, self.dt, offset)
                last = t[-2:]
            else:  # the caller makes the axis: its last two stamps (fill_time is elementwise)
                last = np.empty(min(n, 2))
                _core.fill_time(last, self.t0, self.dt, offset + n - last.size)
            # found by audit (--fs 1e-308): a step so large that the axis overflows, or so
            # small against the start time that it stops increasing; the axis is monotonic,
            # so its last stamps tell
            if n and (not math.isfinite(last[-1]) or (n >= 2 and last[-1] <= last[-2])):
                raise RecordingError(
                    f"{self.dt_source} gives no increasing, finite time axis for "
                    f"{offset + n} samples",
                    file=self.file,
                )
        else:
            self._check_time(t, offset)
        if n:
            self.prev_t = float(t[-1])
        meta = dict(self.meta, offset=offset, ranges=ranges)
        if self.resample and n:
            t, data, meta["offset"] = self._resample(t, data)
            meta["ranges"] = {
                k: (float(v.min()), float(v.max())) for k, v in data.items() if v.size
            }
            # what was bridged so far (the last chunk's: the whole record's)
            meta["resampled"] = dict(
                self.bridged, step=self.step, resampled=True, n_samples=self.grid_next
            )
        return Recording(t, data, dict(self.units), self.file, meta)


def _check_chunk_size(chunk_size: int) -> int:
    try:
        c = int(chunk_size)
    except (TypeError, ValueError):
        raise InputError(f"chunk_size must be an integer, got {chunk_size!r}") from None
    if c < 2 or c != chunk_size:
        raise InputError(f"chunk_size must be an integer >= 2, got {chunk_size!r}")
    return c


def _slice(ds: Any, a: int, b: int, *, file: str, column: str) -> np.ndarray:
    """Samples ``a:b`` of a vector dataset (MATLAB stores vectors as 1×N or N×1)."""
    if ds.ndim <= 1:
        part = ds[a:b]
    else:
        axis = next((i for i, s in enumerate(ds.shape) if s != 1), 0)
        idx: list[Any] = [0] * ds.ndim
        idx[axis] = slice(a, b)
        part = ds[tuple(idx)]
    return real_values(part, file=file, column=column).reshape(-1)


def _vector_length(ds: Any, *, file: str, column: str) -> int:
    if len([s for s in ds.shape if s != 1]) > 1:
        raise RecordingError(
            f"dataset has shape {ds.shape}; a channel must be a vector", file=file, column=column
        )
    return int(np.prod(ds.shape, dtype=np.int64))


def _direct_reads(path: Path, dsets: dict[str, Any], mapping: dict[str, str], fmt: str) -> dict:
    """The channels (canonical name → :class:`~contactlab.io.hdf5.DirectRead`) whose samples
    are read from the file's bytes, each first checked against libhdf5 on its first samples."""
    from .hdf5 import direct_read

    if fmt != "hdf5":
        return {}
    size = path.stat().st_size
    out = {}
    fd = os.open(path, os.O_RDONLY)
    try:
        for c, m in mapping.items():
            d = direct_read(dsets[m], size)
            if d is None:
                continue
            k = min(64, int(dsets[m].shape[0]))
            mine = np.empty(k)
            if d.read(fd, 0, mine) and mine.tobytes() == np.asarray(dsets[m][:k]).tobytes():
                out[c] = d
    finally:
        os.close(fd)
    return out


def _h5_chunks(
    path: Path, fmt: str, *, columns: Any, kind: Any, fs: Any, chunk: int, resample: bool = False
) -> ChunkedRecording:
    from .hdf5 import h5_guard, hdf5_layout, import_h5py, open_hdf5

    h5py = import_h5py()
    file = str(path)

    def layout(f: Any) -> tuple[Any, ...]:
        if fmt == "mat73":
            from .mat import v73_dataset, v73_layout

            kind_, mapping, units, dt = v73_layout(f, columns=columns, kind=kind, file=file)
            dsets = {n: v73_dataset(f, n) for n in mapping.values()}
        else:
            kind_, mapping, dsets, units, dt = hdf5_layout(f, columns=columns, kind=kind, file=file)
        sizes = {n: _vector_length(dsets[n], file=file, column=n) for n in mapping.values()}
        if len(set(sizes.values())) > 1:
            what = "variables" if fmt == "mat73" else "channels"
            raise RecordingError(f"{what} differ in length: {sizes}", file=file)
        return kind_, mapping, dsets, units, dt, next(iter(sizes.values()))

    with open_hdf5(path, file=file) as f:  # refuses what makes libhdf5 hang
        kind_, mapping, _d, units, dt, n = layout(f)
    fin0 = _Finisher(mapping, units, kind=kind_, file=file, fs=fs, dt=dt, meta={"format": fmt})

    names = ["t", *(c for c in mapping if c != "t")]

    def gen(alloc: Alloc | None, time_axis: bool = True) -> Iterator[Recording]:
        fin = _Finisher(
            mapping,
            units,
            kind=kind_,
            file=file,
            fs=fs,
            dt=dt,
            meta={"format": fmt},
            resample=resample,
            time_axis=time_axis,
        )
        if resample:
            alloc = None  # a resampled chunk's length is not the samples read
        with h5_guard(file), h5py.File(path, "r") as f:
            if fmt == "mat73":
                from .mat import v73_dataset

                dsets = {n_: v73_dataset(f, n_) for n_ in mapping.values()}
            else:
                dsets = None
            if dsets is None:
                from .hdf5 import datasets

                alld = datasets(f)
                dsets = {n_: alld[n_] for n_ in mapping.values()}
            if n < 2:
                raw = {c: _slice(dsets[m], 0, n, file=file, column=m) for c, m in mapping.items()}
                yield fin(raw, 0, None if alloc is None else alloc(n, names))
                return
            direct = _direct_reads(path, dsets, mapping, fmt)
            fd = os.open(path, os.O_RDONLY) if direct else None
            try:
                for a in range(0, n, chunk):
                    b = min(a + chunk, n)
                    out = None if alloc is None else alloc(b - a, names)
                    raw = {}
                    scans: dict[str, list[Any]] = {}
                    for c, m in mapping.items():
                        d = direct.get(c)
                        if d is not None and fd is not None:
                            buf = np.empty(b - a) if out is None else out[c]
                            sc: list[Any] = [True, math.inf, -math.inf]
                            if d.read(fd, a, buf, sc):
                                raw[c] = buf
                                scans[c] = sc
                                continue
                        raw[c] = _slice(dsets[m], a, b, file=file, column=m)
                    yield fin(raw, a, out, scans)
            finally:
                if fd is not None:
                    os.close(fd)

    return ChunkedRecording(
        file,
        kind_,
        fin0.units,
        mapping,
        None if resample else n,
        fin0.meta,
        lambda: gen(None),
        None if resample else gen,
        fin0.time_step,
        checked=True,
    )


def _tdms_chunks(
    path: Path, *, columns: Any, kind: Any, fs: Any, chunk: int, resample: bool = False
) -> ChunkedRecording:
    from .tdms import (
        import_nptdms,
        quiet_nptdms,
        refuse_unread_tdms,
        tdms_lengths,
        tdms_time_step,
    )

    nptdms = import_nptdms()
    file = str(path)

    def open_tdms() -> tuple[Any, Any, dict[str, Any]]:
        fh = open(path, "rb")
        try:
            tf = nptdms.TdmsFile.open(fh)
        except Exception as exc:  # npTDMS raises plain ValueError/KeyError on corrupt files
            fh.close()
            raise RecordingError(f"not a readable TDMS file ({exc})", file=file) from None
        chans: dict[str, Any] = {}
        for g in tf.groups():
            for ch in g.channels():
                chans.setdefault(ch.name, ch)
                chans[f"{g.name}/{ch.name}"] = ch
        return fh, tf, chans

    with quiet_nptdms() as quiet:
        fh, tf, chans = open_tdms()
        with tf, fh:
            refuse_unread_tdms(path, chans, quiet, file=file)
            kind_, mapping = resolve_columns(list(chans), columns=columns, kind=kind, file=file)
            units: dict[str, str | None] = {}
            sizes = {}
            for canon, name in mapping.items():
                u = chans[name].properties.get("unit_string")
                units[canon] = str(u) if u not in (None, "") else None
                sizes[name] = len(chans[name])
            tdms_lengths(sizes, quiet, file=file)
            n = next(iter(sizes.values()))
            dt, t0 = None, 0.0
            if "t" not in mapping and fs is None:
                ref = chans[mapping[next(c for c in mapping if c != "t")]]
                dt, t0 = tdms_time_step(ref, file=file)
    fin0 = _Finisher(
        mapping, units, kind=kind_, file=file, fs=fs, dt=dt, t0=t0, meta={"format": "tdms"}
    )

    def gen() -> Iterator[Recording]:
        fin = _Finisher(
            mapping,
            units,
            kind=kind_,
            file=file,
            fs=fs,
            dt=dt,
            t0=t0,
            meta={"format": "tdms"},
            resample=resample,
        )
        with quiet_nptdms():
            fh, tf, chans = open_tdms()
        with tf, fh:
            for a in range(0, max(n, 1), chunk):
                length = min(chunk, n - a)
                with quiet_nptdms():
                    raw = {
                        c: real_values(chans[m].read_data(a, length), file=file, column=m)
                        for c, m in mapping.items()
                    }
                yield fin(raw, a)

    return ChunkedRecording(
        file,
        kind_,
        fin0.units,
        mapping,
        None if resample else n,
        fin0.meta,
        gen,
        time_step=fin0.time_step,
        checked=True,
    )


def _csv_chunks(
    path: Path, *, columns: Any, kind: Any, fs: Any, chunk: int, resample: bool = False
) -> ChunkedRecording:
    from .csv import decimal_comma, line_of_sample, locate_bad_cell, read_header, sniff_encoding
    from .units import split_name

    file = str(path)
    enc = sniff_encoding(path)
    names, delim, header_line, comments = read_header(path, enc)
    if len(set(names)) != len(names):
        dup = next(n for n in names if names.count(n) > 1)
        raise RecordingError("column name appears twice in the header", file=file, column=dup)
    kind_, mapping = resolve_columns(names, columns=columns, kind=kind, file=file)
    canon = list(mapping)
    idx = [names.index(mapping[c]) for c in canon]
    first_data = header_line + 1
    comma = decimal_comma(path, delim, first_data, enc)
    units = {c: split_name(mapping[c])[1] for c in canon}
    meta = {
        "format": "csv",
        "comments": comments,
        "delimiter": delim or "whitespace",
        "decimal": "," if comma else ".",
        "encoding": enc,
    }

    def row_of(i: int) -> int:
        return line_of_sample(path, first_data, i, enc)

    fin0 = _Finisher(mapping, units, kind=kind_, file=file, fs=fs, row_of=row_of, meta=meta)

    def gen() -> Iterator[Recording]:
        fin = _Finisher(
            mapping,
            units,
            kind=kind_,
            file=file,
            fs=fs,
            row_of=row_of,
            meta=meta,
            resample=resample,
        )
        offset = 0
        with open(path, encoding=enc, errors="strict", newline="") as fh:
            try:
                for _ in itertools.islice(fh, first_data):
                    pass
                while True:
                    lines = list(itertools.islice(fh, chunk))
                    if not lines:
                        break
                    try:
                        with warnings.catch_warnings():
                            warnings.filterwarnings("ignore", message="loadtxt: input contained")
                            block = np.loadtxt(
                                lines,
                                delimiter=delim,
                                usecols=idx,
                                ndmin=2,
                                comments="#",
                                dtype=np.float64,
                                quotechar='"',
                                converters=(lambda v: float(v.replace(",", ".")))
                                if comma
                                else None,
                            )
                    except ValueError:
                        raise locate_bad_cell(
                            path, delim, first_data, idx, names, comma, enc
                        ) from None
                    if block.shape[0] == 0:
                        continue
                    raw = {c: np.ascontiguousarray(block[:, j]) for j, c in enumerate(canon)}
                    yield fin(raw, offset)
                    offset += block.shape[0]
            except UnicodeDecodeError as exc:
                raise RecordingError(
                    f"byte {exc.object[exc.start : exc.start + 1]!r} is not {enc} text; save "
                    "the file as UTF-8",
                    file=file,
                ) from None
        if offset == 0:
            raise RecordingError("header but no data rows", file=file)

    return ChunkedRecording(
        file,
        kind_,
        fin0.units,
        mapping,
        None,
        fin0.meta,
        gen,
        time_step=fin0.time_step,
        checked=True,
    )


def _npy_chunks(
    path: Path, *, columns: Any, kind: Any, fs: Any, chunk: int, resample: bool = False
) -> ChunkedRecording:
    """An ``.npy`` memory-mapped and read slice by slice (an ``.npz`` is read whole: its
    arrays are zip members)."""
    from .npy import npy_chunk_source, read_npy

    file = str(path)
    if content_format(path) == "npz":
        rec = read_npy(path, columns=columns, kind=kind, fs=fs, resample=resample)
        return _whole_chunks(rec, chunk)
    kind_, mapping, units, dt, n, meta, slices = npy_chunk_source(
        path, columns=columns, kind=kind, fs=fs
    )
    fin0 = _Finisher(mapping, units, kind=kind_, file=file, fs=fs, dt=dt, meta=meta)

    def gen() -> Iterator[Recording]:
        fin = _Finisher(
            mapping, units, kind=kind_, file=file, fs=fs, dt=dt, meta=meta, resample=resample
        )
        for a, raw in slices(chunk):
            yield fin(raw, a)

    return ChunkedRecording(
        file,
        kind_,
        fin0.units,
        mapping,
        None if resample else n,
        fin0.meta,
        gen,
        time_step=fin0.time_step,
        checked=True,
    )


def _whole_chunks(rec: Recording, chunk: int) -> ChunkedRecording:
    n = len(rec)
    # a recording made of a chunk carries that chunk's ranges: not those of these chunks
    meta = {k: v for k, v in rec.meta.items() if k != "ranges"}

    def gen() -> Iterator[Recording]:
        for a in range(0, n, chunk):
            b = min(a + chunk, n)
            data = {k: v[a:b] for k, v in rec.data.items()}
            yield Recording(rec.t[a:b], data, dict(rec.units), rec.source, dict(meta, offset=a))

    return ChunkedRecording(
        rec.source,
        rec.kind,
        dict(rec.units),
        dict(rec.meta.get("columns", {})),
        n,
        dict(rec.meta),
        gen,
    )


def read_chunks(
    path: str | Path | Recording,
    *,
    chunk_size: int = DEFAULT_CHUNK,
    columns: dict[str, str] | None = None,
    kind: str | None = None,
    fs: float | None = None,
    format: str | None = None,
    resample: bool = False,
) -> ChunkedRecording:
    """Open a recording for reading in chunks of at most ``chunk_size`` samples.

    Parameters are those of :func:`contactlab.io.read_recording`; a :class:`Recording` (already
    in memory) is handed out in chunks too. Column resolution and units are checked at once,
    the data as the chunks are read. With ``resample``, each chunk is interpolated onto the
    uniform grid of the first chunk's median step (chunks then hold about ``chunk_size``
    samples; ``meta["resampled"]`` of the last chunk tells the largest gap bridged).

    Returns
    -------
    ChunkedRecording
        Iterable (again and again) of :class:`Recording` chunks with ``meta["offset"]``.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "run.csv"
    >>> _ = p.write_text("t [ms],x [um],F [N]\\n" + "".join(f"{i},{i},0\\n" for i in range(5)))
    >>> [len(c) for c in read_chunks(p, chunk_size=2)]
    [2, 2, 1]
    """
    chunk = _check_chunk_size(chunk_size)
    if isinstance(path, Recording):
        return _whole_chunks(path, chunk)
    p = Path(path)
    fmt = format_of(p, format)
    opts = {"columns": columns, "kind": kind, "fs": fs, "chunk": chunk, "resample": resample}
    if fmt == "csv":
        return _csv_chunks(p, **opts)
    if fmt == "tdms":
        return _tdms_chunks(p, **opts)
    if fmt == "hdf5":
        return _h5_chunks(p, "hdf5", **opts)
    if fmt == "npy":
        return _npy_chunks(p, **opts)
    if content_format(p) == "mat73":
        return _h5_chunks(p, "mat73", **opts)
    from .mat import read_mat

    rec = read_mat(p, columns=columns, kind=kind, fs=fs, resample=resample)
    return _whole_chunks(rec, chunk)


__all__ = ["DEFAULT_CHUNK", "ChunkedRecording", "read_chunks"]
