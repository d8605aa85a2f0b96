"""Tracking a joint over a long recording: the fitted quantities window by window.

An endurance, fretting or wear test runs for 10⁴..10⁶ cycles, and the question is how the
joint changes. :func:`track` reads the recording in chunks (:func:`contactlab.io.read_chunks`)
and cuts it into windows of N cycles or T seconds (cut at upward crossings of the drive, so
every window holds whole cycles), analyses each window as the whole-recording analyses do and
keeps only the results:

- tangential windows: :func:`contactlab.tangential.window.analyze_window` (the numbers of
  :func:`~contactlab.tangential.analyze_tangential`, the samples folded once in Rust) — h0,
  ac (None where the analysis finds them not separately identifiable; ``h0_ac`` always),
  energy per cycle
  analytic and numeric, c_e·ω (eq. 17), k_local0 (eq. 18), k_global (eq. 19), amplitude and
  force offset, each with its standard error;
- normal windows: :func:`contactlab.normal.analyze_loop` — E_d (with its standard error from
  the cycle-to-cycle scatter), ψ (eq. 7), ψ_KV (eq. 3), k_tan (eq. 4), k_sec (eq. 5) and the
  loading, unloading and centre polynomials of eq. 1;
- every cycle of the record (:mod:`.cycles`): loop energy ∮F dx, amplitude, offset.

Memory holds one chunk and one window, whatever the length of the record.
:meth:`TrackResult.combined` pools the windows (weights by window size, the error widened by
the Birge ratio when the windows scatter more than their errors say): the whole-record result of a
streamed analysis.
"""

from __future__ import annotations

import contextlib
import functools
import math
from collections import deque
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .._options import as_dict
from .._physical import MAX_MAGNITUDE
from ..errors import ContactLabError, ContactLabWarning, InputError
from ..io import Recording, read_chunks
from .cycles import CYCLE_UNITS, CycleState, block_cycles, trigger_levels
from .track_cuts import WindowCuts
from .track_result import (  # noqa: F401  (the constants and TrackResult, re-exported)
    _EVERY,
    AUTO_WINDOW,
    BIRGE_NOTE,
    CYCLE_SEGMENT,
    MAX_WINDOW,
    MIN_CYCLES,
    NORMAL_QUANTITIES,
    TANGENTIAL_QUANTITIES,
    TRACK_CHUNK,
    TrackResult,
    _as_float,
    _finite,
    parse_every,
    track_json,
)

#: options of ``analyze_tangential`` the one-pass window analysis
#: (:func:`contactlab.tangential.window.analyze_window`) takes; others (``on="signal"``,
#: ``history``) take the whole-window analysis
_WINDOW_OPTIONS = frozenset(
    (
        "force_sign",
        "n_points",
        "rel_threshold",
        "min_cycles",
        "max_rel_stderr",
        "fit_offset",
        "fit_x0",
        "fit_amplitude",
        "detrend",
        "initial",
        "delay",
    )
)


class _WindowSamples:
    """A window of a recording sampled every ``dt`` from ``t0`` whose time axis is made when
    its analysis starts (:meth:`recording`, on the helper thread or worker): a window waiting
    for a helper holds its channels only, 8 bytes a sample less, and the reader does not fill
    the axis. The axis is :func:`contactlab._core.fill_time`'s, bit for bit the one
    :meth:`_Windows.take` made before. ``scanned``: each channel's ``(min, max)`` when the
    reader checked every sample finite and the axis finite (``ChunkedRecording.checked``),
    else None (:func:`contactlab.tangential.window.analyze_window`'s ``scanned``)."""

    __slots__ = ("data", "meta", "scanned", "source", "start", "time_step", "units")

    def __init__(
        self,
        data: dict[str, np.ndarray],
        units: dict[str, str],
        source: str,
        meta: dict[str, Any],
        time_step: tuple[float, float],
        start: int,
        scanned: dict[str, tuple[float, float]] | None = None,
    ) -> None:
        self.data, self.units, self.source, self.meta = data, units, source, meta
        self.time_step, self.start, self.scanned = time_step, start, scanned

    def __getstate__(self) -> tuple[Any, ...]:
        return tuple(getattr(self, k) for k in self.__slots__)

    def __setstate__(self, state: tuple[Any, ...]) -> None:
        for k, v in zip(self.__slots__, state, strict=True):
            setattr(self, k, v)

    def __len__(self) -> int:
        return len(next(iter(self.data.values())))

    def time(self, i: int) -> float:
        """The time of sample ``i`` of the window (that of :meth:`recording`'s axis)."""
        return _step_time(self.time_step, self.start + i)

    def recording(self) -> Recording:
        from .. import _core

        t = np.empty(len(self))
        _core.fill_time(t, self.time_step[0], self.time_step[1], self.start)
        return Recording(t, self.data, self.units, self.source, self.meta)


def _step_time(time_step: tuple[float, float], g: int) -> float:
    """The time of global sample ``g`` of an axis sampled every ``dt`` from ``t0``
    (``time_step``): :func:`contactlab._core.fill_time`'s, bit for bit."""
    from .. import _core

    one = np.empty(1)
    _core.fill_time(one, time_step[0], time_step[1], g)
    return float(one[0])


def _window_recording(rec: Recording | _WindowSamples) -> Recording:
    return rec.recording() if isinstance(rec, _WindowSamples) else rec


def _time_bounds(rec: Recording | _WindowSamples) -> tuple[float, float]:
    """The first and last sample times of a window."""
    if isinstance(rec, _WindowSamples):
        return rec.time(0), rec.time(len(rec) - 1)
    return float(rec.t[0]), float(rec.t[-1])


def _glitch_checked(
    always: bool,
) -> Callable[[Callable[..., tuple[dict, dict]]], Callable[..., tuple[dict, dict]]]:
    """Windows checked for a sensor glitch (a few samples orders of magnitude out,
    :func:`contactlab.diagnose._inputs.check_glitches`): a glitch fails the window, named
    with its sample counted in the file. Normal windows are ``always`` checked (their
    analysis drops a cycle it cannot use without a word); tangential ones when their
    analysis failed or warned (a glitch in either channel makes the fit warn or fail; the
    check would cost 2 ms of a 10⁶-sample window's 85 ms on the 1e8 bench)."""
    return functools.partial(_with_glitch_check, always=always)


def _with_glitch_check(
    fn: Callable[..., tuple[dict, dict]], *, always: bool
) -> Callable[..., tuple[dict, dict]]:
    @functools.wraps(fn)
    def run(rec: Recording | _WindowSamples, *args: Any, **kwargs: Any) -> tuple[dict, dict]:
        # (imported where a check runs: a clean tangential window never needs it)
        try:
            row, units = fn(rec, *args, **kwargs)
        except ContactLabError as exc:
            from ..io.checks import check_recording_glitches

            w = _window_recording(rec)
            try:
                check_recording_glitches(w, offset=int((w.meta or {}).get("offset", 0)))
            except InputError as glitch:
                raise glitch from exc
            raise
        if always or row.get("warnings"):
            from ..io.checks import check_recording_glitches

            w = _window_recording(rec)
            check_recording_glitches(w, offset=int((w.meta or {}).get("offset", 0)))
        return row, units

    return run


@_glitch_checked(always=False)
def _tangential_window(
    rec: Recording | _WindowSamples, options: Mapping[str, Any], keep_doc: bool = False
) -> tuple[dict, dict]:
    from ..tangential import analyze_tangential
    from ..tangential.window import analyze_window

    scanned: dict[str, tuple[float, float]] | None = None
    time_step: tuple[float, float, int] | None = None
    if isinstance(rec, _WindowSamples):
        # (the axis recording() makes: fill_time's from the window's first global sample)
        scanned, time_step = rec.scanned, (*rec.time_step, rec.start)
    rec = _window_recording(rec)

    opts = {k: v for k, v in options.items() if k != "warn"}
    if opts.get("on", "averaged") == "averaged" and opts.get("history", "steady") == "steady":
        opts.pop("on", None)
        opts.pop("history", None)
    if "invert_force" in opts:
        inv = opts.pop("invert_force")
        if inv is not None:
            opts["force_sign"] = -1 if inv else 1
    if set(opts) <= _WINDOW_OPTIONS:
        # (the rows keep no per-cycle mean of the detrended window: not computed)
        res = analyze_window(rec, period_means=False, scanned=scanned, time_step=time_step, **opts)
    else:
        res = analyze_tangential(rec, **{"warn": False, **dict(options)})
    d = res.to_dict()
    row: dict[str, Any] = {}
    for q in TANGENTIAL_QUANTITIES:
        row[q] = d.get(q)
        row[f"{q}_stderr"] = d.get(f"{q}_stderr")
    row["identifiable"] = bool(res.identifiable)
    row["n_cycles"] = d.get("n_cycles")
    row["warnings"] = " | ".join(res.warnings)
    units = {k: v for k, v in d.get("units", {}).items() if k in row}
    if keep_doc:
        row["_doc"] = d
    return row, units


@_glitch_checked(always=True)
def _normal_window(
    rec: Recording | _WindowSamples, options: Mapping[str, Any], keep_doc: bool = False
) -> tuple[dict, dict]:
    import warnings

    rec = _window_recording(rec)
    if int((rec.meta or {}).get("offset", 0)) > 0 and "discard_cycles" not in options:
        # a window after the first starts mid-record, at an upward crossing: no start-up
        # cycle to drop (dropping one left 3 of a 5-cycle window's 4 whole cycles)
        options = {**dict(options), "discard_cycles": 0}

    from ..normal import analyze_loop

    if keep_doc:
        # the document a whole-file analysis writes (eq. 16's b1..b4, E_d's error, ...):
        # that of a study's recording, the options (p0, pa, omega) given
        from .manifest import StudyEntry
        from .normal import analyze_normal_recording

        entry = StudyEntry(Path(rec.source or "window"), "normal")
        res, doc, extra = analyze_normal_recording(rec, entry, **dict(options))
        d = res.to_dict()
        row, units = _normal_row(d)
        row["warnings"] = " | ".join(extra["warnings"])
        row["_doc"] = {**doc, **extra}
        return row, units
    from .normal import loop_options

    opts = loop_options(rec["p"], {}, options)  # the tags are in options (analyze, track)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ContactLabWarning)
        res = analyze_loop(rec.t, rec["p"], rec["delta"], **opts)
    row, units = _normal_row(res.to_dict())
    row["warnings"] = " | ".join(
        str(w.message) for w in caught if issubclass(w.category, ContactLabWarning)
    )
    return row, units


def _normal_row(d: dict[str, Any]) -> tuple[dict, dict]:
    # (imported here: a tangential run does not need the study module, 5-7 ms of start-up)
    from .study import coefficient_unit

    du = d.get("units", {})
    row: dict[str, Any] = {}
    units: dict[str, str] = {}
    for q in NORMAL_QUANTITIES:
        row[q] = d.get(q)
        if q in du:
            units[q] = du[q]
    n, e_std = int(d.get("n_cycles") or 0), d.get("E_d_cycle_std")
    row["E_d_stderr"] = e_std / math.sqrt(n) if n > 1 and _finite(e_std) else None
    units["E_d_stderr"] = du.get("E_d", "J/m^2")
    for key in ("poly_load", "poly_unload", "poly_centre"):
        for i, c in enumerate(d.get(key) or []):
            row[f"{key}_{i}"] = float(c)
            units[f"{key}_{i}"] = coefficient_unit(du.get(key, ""), i)
    row["n_cycles"] = n
    return row, units


class _Windows:
    """The samples of the stream not yet handed to a window, by global sample index, in one
    array per channel (and ``t``, unless made from the sampling interval) that the reader
    writes the chunks into (:meth:`~contactlab.io.ChunkedRecording.chunks_into`): a window
    is a view of it, no copy.

    Windows cut one after the other share the array until the next might not fit in what is
    left of it; then a new one is started, sized for a window as long as the last plus a
    chunk, and the samples already read past the cut (less than a chunk) are copied over. A
    window that outgrows its array moves to one twice as long (rare: the first window, or one
    much longer than the last). A time axis made from the sampling interval (``time_step``)
    is made for each window instead (bit for bit the chunks'); the chunks' own axis is then
    not made (``chunks_into(time_axis=False)``: their ``t`` is one scratch array, unread).

    ``checked`` (the reader's ``ChunkedRecording.checked``): the blocks' ranges
    (:meth:`add`) are the exact extremes of samples found finite; a sampled window then
    carries its channels' ranges (``_WindowSamples.scanned``), from the blocks inside it
    and a scan of the parts of the blocks it cuts.
    """

    def __init__(
        self, first_window: int, time_step: tuple[float, float] | None, checked: bool = False
    ) -> None:
        self.arrays: dict[str, np.ndarray] = {}
        self.cap = 0
        self.head = 0  # index in the arrays of global sample self.start
        self.used = 0  # samples of the arrays handed to the reader
        self.start = 0  # global index of the first sample kept
        self.n = 0  # samples added and not yet in a window
        self.expect = max(int(first_window), 1)  # samples of the next window, about
        self.chunk = 0  # longest chunk read
        self.time_step = time_step
        self.proto: tuple[dict[str, str], str, dict[str, Any]] | None = None
        self.scratch_t = np.empty(0)  # the chunks' unread time axis (a sampled recording)
        # (global first sample, end, ranges or None) of the blocks added, not yet all in windows
        self.checked = checked and time_step is not None
        self.blocks: deque[tuple[int, int, dict[str, tuple[float, float]] | None]] = deque()

    def _move(self, cap: int, names: list[str]) -> None:
        rest = self.used - self.head
        new = {k: np.empty(cap) for k in names}
        for k, a in self.arrays.items():
            new[k][:rest] = a[self.head : self.used]
        self.arrays, self.cap, self.head, self.used = new, cap, 0, rest

    def alloc(self, m: int, names: list[str]) -> dict[str, np.ndarray]:
        """Room for the next chunk of ``m`` samples (``read_chunks``' ``alloc``)."""
        self.chunk = max(self.chunk, m)
        kept = [k for k in names if not (k == "t" and self.time_step is not None)]
        if self.arrays and list(self.arrays) != kept:
            raise InputError(f"the chunks' channels changed: {list(self.arrays)} -> {kept}")
        if self.used + m > self.cap:
            open_part = self.used - self.head
            self._move(max(self.expect + self.chunk, 2 * open_part + m), kept)
        a = self.used
        self.used += m
        out = {k: v[a : self.used] for k, v in self.arrays.items()}
        if "t" not in out:
            if self.scratch_t.size < m:
                self.scratch_t = np.empty(m)
            out["t"] = self.scratch_t[:m]
        return out

    def add(self, rec: Recording, ranges: dict[str, tuple[float, float]] | None = None) -> None:
        """The next ``len(rec)`` samples (written where :meth:`alloc` said) are read;
        ``ranges``: their channels' ``(min, max)``."""
        if self.proto is None:  # what the windows inherit (not the arrays: they would
            # keep the first window's array alive to the end)
            self.proto = (rec.units, rec.source, rec.meta)
        if self.checked:
            a = self.start + self.n
            self.blocks.append((a, a + len(rec), ranges))
        self.n += len(rec)

    def _ranges(self, stop: int, data: dict[str, np.ndarray]) -> dict | None:
        """The channels' ``(min, max)`` over the window ``[start, stop)`` (``data``: its
        arrays): the blocks' ranges, and the parts of blocks the window cuts scanned (min and
        max are exact: the same numbers as a scan of the window); None when a block's are
        not known."""
        from .. import _core

        lo = dict.fromkeys(data, math.inf)
        hi = dict.fromkeys(data, -math.inf)
        known = True
        blocks = self.blocks
        while blocks and blocks[0][0] < stop:
            a, b, r = blocks[0]
            if r is None or any(c not in r for c in data):
                known = False
            elif a >= self.start and b <= stop:
                for c in data:
                    lo[c], hi[c] = min(lo[c], r[c][0]), max(hi[c], r[c][1])
            else:
                i, j = max(a, self.start) - self.start, min(b, stop) - self.start
                for c, v in data.items():
                    if j > i:
                        _f, p, q = _core.finite_min_max(v[i:j])
                        lo[c], hi[c] = min(lo[c], p), max(hi[c], q)
            if b > stop:
                break
            blocks.popleft()
        if not known or not all(math.isfinite(lo[c]) and math.isfinite(hi[c]) for c in data):
            return None
        return {c: (lo[c], hi[c]) for c in data}

    def take(self, stop: int) -> Recording | _WindowSamples:
        """Samples ``[start, stop)`` as one recording (views); they leave the buffer. With a
        time axis made from the sampling interval, a :class:`_WindowSamples` whose axis is
        made when its analysis starts."""
        assert self.proto is not None
        k = stop - self.start
        a, b = self.head, self.head + k
        data = {c: v[a:b] for c, v in self.arrays.items() if c != "t"}
        units, source, meta = self.proto
        rec: Recording | _WindowSamples
        if self.time_step is None:
            t = self.arrays["t"][a:b]
            rec = Recording(t, data, dict(units), source, dict(meta, offset=self.start))
        else:
            scanned = self._ranges(stop, data) if self.checked else None
            rec = _WindowSamples(
                data,
                dict(units),
                source,
                dict(meta, offset=self.start),
                self.time_step,
                self.start,
                scanned,
            )
        self.head, self.start, self.n = b, stop, self.n - k
        self.expect = k + k // 256  # the next window's length, and some
        # room for the next window up to the end of the chunk it ends in (chunks start at
        # multiples of the chunk length): the chunk may run past the window's end
        c = max(self.chunk, 1)
        end = -(-(stop + max(self.expect, 4 * c)) // c) * c
        room = end - stop
        if self.head + room > self.cap:
            self._move(max(room, self.used - self.head + c), list(self.arrays))
        return rec


def _time_at(
    t: np.ndarray, off: int, g: int, time_step: tuple[float, float] | None = None
) -> float:
    """The time of global sample ``g`` in a block starting at global sample ``off`` (with
    ``time_step``, from the sampling interval: the block's ``t`` is not read)."""
    if time_step is not None:
        return _step_time(time_step, g)
    return float(t[g - off])


def _noting(chunks: Iterator[Recording], noted: dict[str, Any]) -> Iterator[Recording]:
    """The chunks as they come, keeping the last one's ``meta["resampled"]`` in ``noted``."""
    for c in chunks:
        if "resampled" in c.meta:
            noted["resampled"] = c.meta["resampled"]
        yield c


def _segments(
    chunks: Iterator[Recording], size: int
) -> Iterator[tuple[Recording, dict[str, tuple[float, float]]]]:
    """The chunks re-cut into blocks of the samples ``[k·size, (k+1)·size)`` (global
    indices; the last block holds what is left), each with its channels' ranges
    (``(min, max)``). The cycle trigger is judged on a block's range (:func:`block_cycles`),
    so the per-cycle table does not depend on the chunks the file is read in (a chunk of
    ``size`` samples at a multiple of it passes as it is: reading in chunks of ``size`` gives
    the blocks it always gave). Chunks of other lengths are cut (views) or joined (copied)."""
    from .. import _core

    buf: list[Recording] = []
    held = 0  # samples in buf
    ranges: dict[str, tuple[float, float]] = {}
    pos = 0  # global index of the next sample
    for c in chunks:
        # the reader's one pass found each channel's range (read_chunks: meta["ranges"]);
        # taken out of the meta, which the windows inherit
        got = c.meta.pop("ranges", None)
        if got is None or any(name not in got for name in c.data):
            got = {
                name: (float(v.min()), float(v.max())) if v.size else (math.inf, -math.inf)
                for name, v in c.data.items()
            }
        for name, v in c.data.items():  # found by fuzzing: 1e300 data overflowed windows
            lo, hi = got[name]
            if v.size and max(hi, -lo) > MAX_MAGNITUDE:
                i = int(np.argmax(np.abs(v)))
                raise InputError(
                    f"{c.source}: {name} reaches {float(v[i]):.3g} {c.units.get(name, '')} "
                    f"at sample {i + int(c.meta.get('offset', 0))}: beyond any physical value; "
                    "a unit mix-up or a corrupt file?"
                )
        off = int(c.meta.get("offset", pos))
        a, n = 0, len(c)
        while a < n:
            b = min(n, a + size - held)  # to the end of the current block, or of the chunk
            if a == 0 and b == n:
                piece, part = c, got
            else:
                meta = dict(c.meta, offset=off + a)
                piece = Recording(
                    c.t[a:b], {k: v[a:b] for k, v in c.data.items()}, c.units, c.source, meta
                )
                part = {k: _core.finite_min_max(v)[1:] for k, v in piece.data.items()}
            ranges = {
                k: (min(ranges[k][0], lo), max(ranges[k][1], hi)) if k in ranges else (lo, hi)
                for k, (lo, hi) in part.items()
            }
            buf.append(piece)
            held += b - a
            a = b
            if held == size:
                yield _join(buf), ranges
                buf, held, ranges = [], 0, {}
        pos = off + n
    if buf:
        yield _join(buf), ranges


def _join(parts: list[Recording]) -> Recording:
    if len(parts) == 1:
        return parts[0]
    first = parts[0]
    t = np.concatenate([p.t for p in parts])
    data = {c: np.concatenate([p.data[c] for p in parts]) for c in first.data}
    return Recording(t, data, dict(first.units), first.source, dict(first.meta))


def _one_blas_thread() -> Any:
    """BLAS limited to one thread while windows are analysed on helper threads (restored
    afterwards; a no-op without ``threadpoolctl``): the windows' least-squares problems are a
    few hundred rows, which threaded BLAS does not speed up, and its threads spin after each
    call on cores the helper threads and the reader already fill."""
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:  # optional at run time: only the speed depends on it
        return contextlib.nullcontext()
    return threadpool_limits(limits=1, user_api="blas")


def track(
    source: str | Path | Recording,
    every: str | float = "100cycles",
    *,
    kind: str | None = None,
    columns: dict[str, str] | None = None,
    fs: float | None = None,
    chunk_size: int = TRACK_CHUNK,
    max_window: int = MAX_WINDOW,
    options: Mapping[str, Any] | None = None,
    keep_going: bool = True,
    callback: Callable[[dict[str, Any]], None] | None = None,
    executor: Any = None,
    keep_documents: bool = False,
    threads: int | None = None,
    resample: bool = False,
    cycles: bool = True,
) -> TrackResult:
    """Fitted quantities of a long recording window by window, in bounded memory.

    Parameters
    ----------
    source : path or Recording
        A recording file (CSV/TDMS/HDF5/MAT, read in chunks) or a :class:`Recording`.
    every : str or number
        Window length: ``"100cycles"`` (a bare number counts cycles), or a time such as
        ``"10s"``, ``"500ms"``, ``"2min"``, or ``"auto"`` (whole cycles, about
        :data:`AUTO_WINDOW` samples). Windows are cut at upward crossings of the drive
        (``x`` or ``p``), so they hold whole cycles; the first also holds the lead-in before
        the first crossing, and a last, shorter window is analysed when it has >= 3 cycles.
    kind, columns, fs, resample
        As for :func:`contactlab.io.read_recording` (``resample``: a non-uniform time axis
        interpolated onto a uniform grid, chunk by chunk; see
        :func:`contactlab.io.read_chunks`).
    chunk_size : int
        Samples read at a time (default :data:`TRACK_CHUNK`).
    max_window : int
        Refuse windows longer than this many samples (one window is held in memory).
    options : Options or mapping, optional
        Keyword arguments of the per-window analysis (``analyze_tangential`` or
        ``normal.analyze_loop``): :class:`contactlab.tangential.Options` /
        :class:`contactlab.normal.Options` or a dict of the same names.
    keep_going : bool
        A window the analysis cannot fit gets a row with ``error`` (default) instead of
        stopping the run. Errors of the file itself always stop it.
    callback : callable, optional
        Called with each window's row as it completes (progress).
    executor : optional
        Analyse windows in parallel on a ``concurrent.futures`` executor or a Dask
        ``distributed.Client`` while the file is read on; at most two windows per worker are
        held. The rows equal those of a serial run.
    threads : int, optional
        Without ``executor``: analyse windows on this many helper threads while the next
        chunks are read and their cycles found (the Rust kernels release the GIL); default 1
        (``threads + 1`` windows in flight, ``threads + 2`` from two threads on, those
        waiting for a thread without their time axis: 2 threads peaked at 245-263 MB on 1e8
        samples with ``"auto"`` windows), 0 analyses each window before reading on. The rows
        are the same.
    keep_documents : bool
        Keep each window's whole analysis document (``TrackResult.window_docs``; what
        :func:`contactlab.studies.pooled.pooled_document` and
        :func:`~contactlab.studies.pooled.pooled_normal_document` pool).
    cycles : bool
        Compute the per-cycle table (``TrackResult.cycles``: energy, amplitude, offset of
        every cycle; default). False finds only the crossings the windows are cut at (the
        same windows and rows): ``cycles`` then holds empty arrays, and ``combined()`` has
        no ``cycle_energy_*`` (``analyze --json`` of a long file, which pools the window
        documents, skips the ∮ F dx of every sample so).

    Returns
    -------
    TrackResult

    Examples
    --------
    >>> from contactlab.synthetic.tangential import synthetic_recording
    >>> rec = synthetic_recording(h0=40.0, ac=4e4, amplitude=20e-6, n_cycles=12, fs=2000.0,
    ...                           noise=0.01, seed=2)
    >>> res = track(rec, every="4cycles")  # 10 complete cycles: 4 + 4, and a 2-cycle tail
    >>> len(res.rows), res.cycles["energy"].size, res.rows[-1]["cycle_end"]
    (2, 10, 8)
    >>> bool(abs(res.combined()["h0"] - 40.0) < 4 * res.combined()["h0_stderr"])
    True
    """
    options = as_dict(options)  # a contactlab.tangential/normal.Options or a dict
    settings: dict[str, Any] = {
        "kind": kind,
        "columns": columns,
        "fs": fs,
        "chunk_size": chunk_size,
        "max_window": max_window,
        "options": options,
        "keep_going": keep_going,
        "callback": callback,
        "keep_documents": keep_documents,
        "resample": resample,
        "cycles": cycles,
    }
    if executor is None and threads != 0:
        from concurrent.futures import ThreadPoolExecutor

        n_threads = 1 if threads is None else int(threads)
        if n_threads < 0:
            raise InputError(f"threads must be >= 0, got {threads!r}")
        with (
            ThreadPoolExecutor(n_threads, thread_name_prefix="contactlab-track") as pool,
            _one_blas_thread(),
        ):
            # each helper thread analyses one window while the next is read: n + 1 windows
            # in memory, those waiting without their time axis; n + 2 for two threads or more,
            # which together outpace the reader (with n + 1 they waited for it: 1e8 samples
            # on 2 threads, interleaved runs 4.43-5.15 s against 4.45-5.96 s, peak 245-263
            # against 240-255 MB); one thread is three times slower than the reader and
            # always has a window waiting. An executor given by the caller gets two per worker
            slots = n_threads + (2 if n_threads >= 2 else 1)
            return _track(source, every, **settings, executor=pool, slots=slots)
    return _track(source, every, **settings, executor=executor, slots=None)


def _track(
    source: str | Path | Recording,
    every: str | float,
    *,
    kind: str | None,
    columns: dict[str, str] | None,
    fs: float | None,
    chunk_size: int,
    max_window: int,
    options: Mapping[str, Any] | None,
    keep_going: bool,
    callback: Callable[[dict[str, Any]], None] | None,
    executor: Any,
    keep_documents: bool,
    slots: int | None,
    resample: bool = False,
    cycles: bool = True,
) -> TrackResult:
    """:func:`track` on ``executor`` (None: serial); ``slots``: windows in flight at most
    (default two per worker)."""
    mode, size = parse_every(every)
    every_text = every if isinstance(every, str) else f"{every}cycles"
    if not (isinstance(max_window, int) and max_window >= 16):
        raise InputError(f"max_window must be an integer >= 16, got {max_window!r}")
    cr = read_chunks(
        source, chunk_size=chunk_size, columns=columns, kind=kind, fs=fs, resample=resample
    )
    noted: dict[str, Any] = {}
    kind_ = cr.kind
    if kind_ not in ("tangential", "normal"):
        raise InputError(
            f"{cr.source}: cannot tell the kind of recording; pass kind= (command line: --model)"
        )
    loop_x, loop_F, drive = ("x", "F", "x") if kind_ == "tangential" else ("delta", "p", "p")
    analyse: Callable[..., tuple[dict, dict]] = functools.partial(
        _tangential_window if kind_ == "tangential" else _normal_window, keep_doc=keep_documents
    )
    state = CycleState()
    cyc: dict[str, list[np.ndarray]] = {
        k: [] for k in ("start", "end", "energy", "amplitude", "offset")
    }
    # the first window's array: sized for an "auto" window (or a chunk; it grows), at most
    # the recording
    first = AUTO_WINDOW if mode == "auto" else chunk_size
    buf = _Windows(
        first if cr.n_samples is None else max(min(first, cr.n_samples), 1),
        cr.time_step,
        cr.checked,
    )
    cuts = WindowCuts(mode, size, AUTO_WINDOW)  # (a module global: tests shrink it)
    out = _Dispatch(analyse, dict(options or {}), executor, slots, keep_going, callback, buf)
    n_total = 0
    try:
        # (a sampled recording's axis is made for each window: the reader does not make it)
        chunks = cr.chunks_into(buf.alloc, time_axis=False)
        for block, ranges in _segments(_noting(chunks, noted), CYCLE_SEGMENT):
            off = int(block.meta.get("offset", n_total))
            buf.add(block, ranges)
            n_total = off + len(block)
            levels = trigger_levels(*ranges[drive]) if ranges and len(block) else None
            got = block_cycles(
                block.t,
                block[loop_x],
                block[loop_F],
                block[drive],
                off,
                state,
                levels,
                cr.time_step,
                quantities=cycles,
                # (a checked reader refused any non-finite sample: not scanned again)
                finite=cr.checked,
            )
            for k in cyc:
                cyc[k].append(np.asarray(getattr(got, k), dtype=float))
            cuts.block(_time_at(block.t, off, off, cr.time_step), got.crossings)
            # (g, complete cycles before crossing g: crossings so far minus the first one)
            at = functools.partial(_time_at, block.t, off, time_step=cr.time_step)
            for g, n_before in cuts.cuts(got.crossings.tolist(), at):
                out.emit(g, n_before)
            if buf.n > max_window:  # the open window (cut windows have left the buffer)
                raise InputError(
                    f"{cr.source}: a window of every={every_text!r} holds more than "
                    f"{max_window} samples; choose a shorter window (or raise max_window)"
                )
        # the tail: analysed when it holds MIN_CYCLES complete cycles
        tail = buf.n
        if tail and cuts.crossings_in_window > MIN_CYCLES:
            out.emit(n_total, max(cuts.n_cross - 1, 0))
            tail = 0
        out.drain()
    finally:
        out.cancel()
    if not out.rows:
        raise InputError(
            f"{cr.source}: found {max(cuts.n_cross - 1, 0)} complete cycle(s) in {n_total} "
            f"samples; tracking needs windows of at least {MIN_CYCLES} cycles"
        )
    cycles = {k: (np.concatenate(v) if v else np.empty(0)) for k, v in cyc.items()}
    meta = {
        **noted,  # resampled: what --resample bridged (the last chunk's: the whole record's)
        "n_samples": n_total,
        "n_windows": len(out.rows),
        "tail_samples_left_out": tail,
        "chunk_size": chunk_size,
        "every_mode": cuts.mode,
        "every_value": cuts.size,
    }
    return TrackResult(cr.source, kind_, every_text, out.rows, out.units, cycles, meta, out.docs)


class _Dispatch:
    """The windows of :func:`track` to their analysis, serially or on ``executor`` with at
    most ``slots`` (default two per worker) in flight, and their rows in window order."""

    def __init__(
        self,
        analyse: Callable[..., tuple[dict, dict]],
        opts: dict[str, Any],
        executor: Any,
        slots: int | None,
        keep_going: bool,
        callback: Callable[[dict[str, Any]], None] | None,
        buf: _Windows,
    ) -> None:
        from .executor import n_workers

        self.analyse, self.opts, self.executor, self.slots = analyse, opts, executor, slots
        self.keep_going, self.callback, self.buf = keep_going, callback, buf
        self.rows: list[dict[str, Any]] = []
        self.units: dict[str, str] = {"t_start": "s", "t_end": "s", "t_mid": "s"}
        self.docs: list[dict[str, Any]] = []
        self.in_flight: deque[tuple[dict[str, Any], Any]] = deque()
        self.cycles_at_start = 0  # complete cycles before the current window
        self.limit = slots if slots is not None else 2 * n_workers(executor)
        module = type(executor).__module__.split(".")[0]
        self.dask = executor is not None and module == "distributed"

    def collect(self, row: dict[str, Any], job: Any) -> None:
        try:
            values, u = job() if self.executor is None else job.result()
        except ContactLabError as exc:
            if not self.keep_going:
                raise
            values, u = {"error": f"window {row['window']}: {exc}"}, {}
        doc = values.pop("_doc", None)
        if doc is not None:
            self.docs.append(doc)
        row.update(values)
        self.units.update(u)
        if self.callback is not None:
            self.callback(row)

    def emit(self, stop: int, n_cycles_before_stop: int) -> None:
        rec = self.buf.take(stop)
        t_first, t_last = _time_bounds(rec)
        row: dict[str, Any] = {
            "window": len(self.rows) + 1,
            "t_start": t_first,
            "t_end": t_last,
            "t_mid": 0.5 * (t_first + t_last),
            "cycle_start": self.cycles_at_start,
            "cycle_end": n_cycles_before_stop,
            "n_samples": len(rec),
        }
        self.rows.append(row)
        self.cycles_at_start = n_cycles_before_stop
        ex, in_flight = self.executor, self.in_flight
        if ex is None:
            self.collect(row, functools.partial(self.analyse, rec, self.opts))
            return
        fut = (
            ex.submit(self.analyse, rec, self.opts, pure=False)
            if self.dask
            else ex.submit(self.analyse, rec, self.opts)
        )
        in_flight.append((row, fut))
        if self.slots is not None:
            # our helper threads: a window holds its samples until its analysis is done, so
            # the limit counts the windows not done yet, and the reader goes on as soon as any
            # is (waiting for the oldest left a helper thread idle whenever a younger window
            # finished first: the two threads were busy 65 % of a run); finished windows are
            # collected in order
            busy = [f for _, f in in_flight if not f.done()]
            if len(busy) >= self.limit:
                # (imported here: a serial run needs no concurrent.futures, whose import
                # pulls in logging, ~5 % of a short streamed run's start-up)
                from concurrent.futures import FIRST_COMPLETED
                from concurrent.futures import wait as futures_wait

                futures_wait(busy, return_when=FIRST_COMPLETED)
            while in_flight and in_flight[0][1].done():
                self.collect(*in_flight.popleft())
            return
        while len(in_flight) >= self.limit:
            self.collect(*in_flight.popleft())

    def drain(self) -> None:
        while self.in_flight:
            self.collect(*self.in_flight.popleft())

    def cancel(self) -> None:
        for _row, fut in self.in_flight:
            fut.cancel()


def track_many(
    sources: Sequence[str | Path | Recording],
    every: str | float = "100cycles",
    *,
    executor: Any = None,
    **options: Any,
) -> Iterator[TrackResult]:
    """:func:`track` over many recordings, in order, optionally on ``executor`` (a
    ``concurrent.futures`` executor or a Dask ``distributed.Client``; see
    :mod:`contactlab.studies.executor`). A generator: each result can be saved and dropped
    before the next arrives, so thousands of long recordings fit in memory.

    ``options`` go to :func:`track`. Results equal those of a serial run.

    Examples
    --------
    >>> from concurrent.futures import ThreadPoolExecutor
    >>> from contactlab.synthetic.tangential import synthetic_recording
    >>> recs = [synthetic_recording(h0=40.0, ac=4e4, amplitude=20e-6, n_cycles=8, fs=1000.0,
    ...                             noise=0.01, seed=s) for s in (1, 2)]
    >>> with ThreadPoolExecutor(2) as ex:
    ...     [len(r.rows) for r in track_many(recs, "3cycles", executor=ex)]
    [2, 2]
    """
    from .executor import ordered_map

    parse_every(every)  # a bad window length fails before anything is submitted
    task = functools.partial(track, every=every, **options)
    yield from ordered_map(task, list(sources), executor)


__all__ = [
    "AUTO_WINDOW",
    "CYCLE_UNITS",
    "MAX_WINDOW",
    "MIN_CYCLES",
    "NORMAL_QUANTITIES",
    "TANGENTIAL_QUANTITIES",
    "TRACK_CHUNK",
    "TrackResult",
    "parse_every",
    "track",
    "track_json",
    "track_many",
]
