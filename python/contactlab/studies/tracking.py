"""Tracking a joint over a long recording: the fitted quantities window by window.

An endurance, fretting or wear test runs for 10⁴..10⁶ cycles, and the question is how the
joint changes. :func:`track` reads the recording in chunks (:func:`contactlab.io.read_chunks`)
and cuts it into windows of N cycles or T seconds (cut at upward crossings of the drive, so
every window holds whole cycles), analyses each window as the whole-recording analyses do and
keeps only the results:

- tangential windows: :func:`contactlab.tangential.analysis.analyze_window` (the numbers of
  :func:`~contactlab.tangential.analyze_tangential`, the samples folded once in Rust) — h0,
  ac (None where the analysis finds them not separately identifiable; ``h0_ac`` always),
  energy per cycle
  analytic and numeric, c_e·ω (eq. 17), k_local0 (eq. 18), k_global (eq. 19), amplitude and
  force offset, each with its standard error;
- normal windows: :func:`contactlab.normal.analyze_loop` — E_d (with its standard error from
  the cycle-to-cycle scatter), ψ (eq. 7), ψ_KV (eq. 3), k_tan (eq. 4), k_sec (eq. 5) and the
  loading, unloading and centre polynomials of eq. 1;
- every cycle of the record (:mod:`._cycles`): loop energy ∮F dx, amplitude, offset.

Memory holds one chunk and one window, whatever the length of the record.
:meth:`TrackResult.combined` pools the windows (weights by window size, the error widened by
the Birge ratio when the windows scatter more than their errors say): the whole-record result of a
streamed analysis.
"""

from __future__ import annotations

import contextlib
import csv
import functools
import io
import math
import re
from collections import deque
from collections.abc import Callable, Iterator, Mapping, Sequence
from concurrent.futures import FIRST_COMPLETED
from concurrent.futures import wait as futures_wait
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .._json import dumps, jsonable
from .._physical import MAX_MAGNITUDE
from ..errors import ContactLabError, ContactLabWarning, InputError
from ..io import Recording, read_chunks
from ..io.units import UnknownUnitError, to_si
from ._cycles import CycleState, block_cycles, trigger_levels
from .columns import CYCLE_UNITS
from .pooled import pool
from .study import coefficient_unit

#: tangential quantities tracked per window (each with ``*_stderr``)
TANGENTIAL_QUANTITIES = (
    "h0",
    "ac",
    "h0_ac",
    "energy_per_cycle",
    "energy_per_cycle_numeric",
    "equivalent_damping",
    "k_local0",
    "k_global",
    "amplitude",
    "offset",
)
#: normal quantities tracked per window (``E_d`` with ``E_d_stderr``)
NORMAL_QUANTITIES = ("E_d", "psi", "psi_kv", "k_tan", "k_sec", "delta_max", "delta_min", "p0", "pa")
#: fewest cycles in a window: N crossing-to-crossing cycles hold N - 1 complete peak-to-peak
#: cycles, and the window analyses average at least 2 of those
MIN_CYCLES = 3
#: default upper bound on a window's samples (one window is held in memory)
MAX_WINDOW = 2_000_000
#: samples per window for ``every="auto"``: the fit of a window costs about as much as folding
#: 10^5 samples (about 20 ms a window), so longer windows amortise it, but each window in
#: flight holds ~40 bytes a sample (t, x, F and the detrended x, F), and about 3.3 windows are
#: held at the peak (two analysed, one being cut out of the read chunks). On 1e8 samples with
#: two threads and :data:`TRACK_CHUNK` chunks: 2^20 peaked at 245-250 MB (2^19 at ~190 MB)
AUTO_WINDOW = 1 << 20
#: samples read at a time by :func:`track`: the rest of a chunk split between two windows is a
#: view that keeps the whole chunk alive until the next window is cut, so shorter chunks hold
#: less (1e8 samples, 2^20 windows: chunks of 2^20 peaked at 274 MB, 2^18 at 247 MB)
TRACK_CHUNK = 1 << 18
#: samples of the blocks whose drive's range sets the cycle trigger (:func:`_segments`): fixed
#: global sample ranges, so that the per-cycle table is the same whatever the chunk size
CYCLE_SEGMENT = TRACK_CHUNK

_EVERY = re.compile(r"^\s*([0-9]*\.?[0-9]+(?:[eE][-+]?\d+)?)\s*([A-Za-zµμ]*)\s*$")


def parse_every(every: str | float | int) -> tuple[str, float]:
    """``"100cycles"`` → ``("cycles", 100)``, ``"10s"``/``"2min"``/``"500 ms"`` →
    ``("time", seconds)``, ``"auto"`` → ``("auto", 0)`` (whole cycles, about
    :data:`AUTO_WINDOW` samples per window). A bare number counts cycles."""
    if isinstance(every, str) and every.strip().lower() == "auto":
        return "auto", 0.0
    if isinstance(every, (int, float)) and not isinstance(every, bool):
        text = f"{every}cycles"
    elif isinstance(every, str):
        text = every
    else:
        raise InputError(f"every must be e.g. '100cycles' or '10s', got {every!r}")
    m = _EVERY.match(text)
    if not m:
        raise InputError(f"every={every!r}: give a number and a unit, e.g. '100cycles' or '10s'")
    value, unit = float(m.group(1)), m.group(2).lower()
    if unit in ("", "cycle", "cycles", "cyc", "c"):
        if value < MIN_CYCLES or value != int(value):
            raise InputError(
                f"every={every!r}: a window needs a whole number >= {MIN_CYCLES} of cycles"
            )
        return "cycles", float(int(value))
    factors = {"min": 60.0, "h": 3600.0}
    if unit in factors:
        seconds = value * factors[unit]
    else:
        try:
            factor, dim = to_si(unit)
        except UnknownUnitError:
            dim, factor = "", 0.0
        if dim != "time":
            raise InputError(f"every={every!r}: {unit!r} is neither 'cycles' nor a time unit")
        seconds = value * factor
    if not (seconds > 0 and math.isfinite(seconds)):
        raise InputError(f"every={every!r}: a window must last a finite time > 0 s")
    return "time", seconds


#: a pooled quantity whose windows' Birge ratio exceeds this is noted (TrackResult.notes)
BIRGE_NOTE = 3.0

_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def _mean_std(a: np.ndarray) -> tuple[float, float]:
    """Mean and sample standard deviation (NaN for one value) computed on ``a / max|a|``,
    so that values near the double-precision limit do not overflow the squares."""
    big = float(np.max(np.abs(a))) if a.size else 0.0
    u = a / big if (big > 0 and math.isfinite(big)) else a
    k = big if (big > 0 and math.isfinite(big)) else 1.0
    return k * float(np.mean(u)), (k * float(np.std(u, ddof=1)) if a.size > 1 else math.nan)


@dataclass
class TrackResult:
    """Quantities per window of a long recording, and per cycle over the whole record.

    Attributes
    ----------
    source : str
        The recording.
    kind : str
        ``"tangential"`` or ``"normal"``.
    every : str
        The window length asked for.
    rows : list of dict
        One per window: ``window``, ``t_start``, ``t_end``, ``t_mid`` (s), ``cycle_start``,
        ``cycle_end`` (complete cycles before the window's ends), ``n_samples``, then the
        analysis' quantities in SI with ``*_stderr``; ``error`` when a window could not be
        analysed.
    units : dict
        SI unit of every column.
    cycles : dict of str to ndarray
        Per cycle: ``start``, ``end`` (s), ``energy`` (J, or J/m² for normal),
        ``amplitude`` (m), ``offset`` (N or Pa).
    meta : dict
        Samples read, windows analysed, tail left out.
    """

    source: str
    kind: str
    every: str
    rows: list[dict[str, Any]]
    units: dict[str, str]
    cycles: dict[str, np.ndarray]
    meta: dict[str, Any] = field(default_factory=dict)
    #: each window's whole analysis document (``track(..., keep_documents=True)``)
    window_docs: list[dict[str, Any]] = field(default_factory=list, repr=False)

    @property
    def quantities(self) -> list[str]:
        """The tracked quantities present (those with a value in some window)."""
        names = TANGENTIAL_QUANTITIES if self.kind == "tangential" else NORMAL_QUANTITIES
        extra = [c for c in self.columns() if c.startswith("poly_") and "stderr" not in c]
        return [q for q in (*names, *extra) if any(_finite(r.get(q)) for r in self.rows)]

    def column(self, name: str) -> np.ndarray:
        """One column over the windows as floats (None → NaN)."""
        return np.array([_as_float(r.get(name)) for r in self.rows], dtype=float)

    def columns(self) -> list[str]:
        cols: list[str] = []
        for r in self.rows:
            cols.extend(k for k in r if k not in cols)
        return cols

    def combined(self) -> dict[str, Any]:
        """The windows pooled into one whole-record result.

        Each quantity with a standard error is the weighted mean over the windows that
        determine it (:func:`contactlab.studies.pooled.pool`: each window weighted by the
        error typical of its number of cycles, not by its own error, which is correlated with
        its value; a window whose own error is far above the typical one keeps its own); its
        ``*_stderr`` is ``1/sqrt(Σ w)`` times the Birge ratio ``sqrt(χ²/(n-1))`` when that
        exceeds 1 (windows scattering beyond their errors: the joint changed, or the errors
        are optimistic). ``*_birge`` gives the ratio. A quantity
        the window analysis gives no error for (ψ, k_tan, ... of normal loops) is the plain
        mean over the windows with the standard error of that mean.
        """
        out: dict[str, Any] = {"n_windows": len(self.rows)}
        sizes = self.column("n_cycles") if "n_cycles" in self.columns() else None
        for q in self.quantities:
            v, s = self.column(q), self.column(f"{q}_stderr")
            ok = np.isfinite(v) & np.isfinite(s) & (s > 0)
            if not ok.any():
                # no standard error per window: the mean of the windows and its error from
                # their scatter
                fin = v[np.isfinite(v)]
                if fin.size:
                    m, sd = _mean_std(fin)
                    out[q] = m
                    out[f"{q}_stderr"] = sd / math.sqrt(fin.size)
                continue
            mean, err, birge = pool(v, s, sizes)
            out[q] = mean
            out[f"{q}_stderr"] = err
            out[f"{q}_birge"] = birge
        e = self.cycles.get("energy")
        if e is not None and e.size:
            out["n_cycles"] = int(e.size)
            # energies of 1e160 J and more overflowed the squares (found by fuzz: track)
            out["cycle_energy_mean"], out["cycle_energy_std"] = _mean_std(e)
        return out

    def notes(self, combined: dict[str, Any] | None = None) -> list[str]:
        """What a reader of the pooled values must know, one line each: windows that could not
        be analysed, the windows' own warnings (each kind once, with how many windows gave
        it: the first window's text) and quantities whose windows scatter beyond their errors
        (Birge ratio above :data:`BIRGE_NOTE`: the pooled value is a weighted mean of values
        that changed, not a constant)."""
        comb = self.combined() if combined is None else combined
        n = len(self.rows)
        out: list[str] = []
        failed = [r for r in self.rows if r.get("error")]
        if failed:
            out.append(f"{len(failed)} of {n} windows could not be analysed ({failed[0]['error']})")
        kinds: dict[str, list[Any]] = {}  # a warning's text with its numbers blanked
        for r in self.rows:
            seen = set()
            for w in filter(None, str(r.get("warnings") or "").split(" | ")):
                key = _NUMBER.sub("#", w)
                if key in seen:
                    continue
                seen.add(key)
                kinds.setdefault(key, [0, r.get("window"), w])[0] += 1
        for count, window, text in kinds.values():
            out.append(f"{count} of {n} windows warn (window {window}: {text})")
        mode, size = parse_every(self.every)
        spans = [r["t_end"] - r["t_start"] for r in self.rows if "t_end" in r and "t_start" in r]
        if mode == "time" and spans and float(np.median(spans)) > 1.5 * size:
            out.append(
                f"windows of {self.every} hold at least {MIN_CYCLES} cycles: they last "
                f"{float(np.median(spans)):.3g} s (median), not {size:.3g} s"
            )
        spread = []
        for q in self.quantities:
            b = comb.get(f"{q}_birge")
            if b is not None and not b <= BIRGE_NOTE and n >= 3:  # NaN/inf: beyond any error
                spread.append(f"{q} {b:.3g}" if math.isfinite(b) else f"{q} (beyond any)")
        if spread:
            out.append(
                "the windows scatter beyond their standard errors (Birge ratio "
                + ", ".join(spread)
                + "): these change over the record (or the errors are optimistic); their "
                "pooled values are weighted means, not constants - see them against time"
            )
        return out

    def to_dict(self, *, cycles: bool = True) -> dict[str, Any]:
        """JSON-ready: ``windows`` (rows), ``combined``, ``notes`` (:meth:`notes`), ``cycles``
        (arrays), ``units``."""
        cu = CYCLE_UNITS[self.kind]
        comb = self.combined()
        units = dict(self.units)
        for k in list(comb):
            base = k.removesuffix("_stderr")
            if base in self.units:
                units.setdefault(k, self.units[base])
        d: dict[str, Any] = {
            "source": self.source,
            "kind": self.kind,
            "every": self.every,
            "windows": self.rows,
            "combined": comb,
            "notes": self.notes(comb),
            "units": units,
            "cycle_units": dict(cu),
            "meta": self.meta,
        }
        if cycles:
            d["cycles"] = {k: v.tolist() for k, v in self.cycles.items()}
        return d

    def to_csv(self) -> str:
        """The window table as CSV; header cells carry SI units (``h0 [N]``)."""
        cols = self.columns()
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow([f"{c} [{self.units[c]}]" if self.units.get(c) else c for c in cols])
        for r in self.rows:
            w.writerow(
                [
                    "" if r.get(c) is None else repr(r[c]) if isinstance(r[c], float) else str(r[c])
                    for c in cols
                ]
            )
        return buf.getvalue()

    def cycles_csv(self) -> str:
        """The per-cycle table as CSV (``cycle, start [s], end [s], energy [J], ...``)."""
        cu = CYCLE_UNITS[self.kind]
        names = list(self.cycles)
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(["cycle", *(f"{k} [{cu[k]}]" for k in names)])
        # the rows csv.writer wrote from [i + 1, repr(float(v)), ...] (numbers need no
        # quoting), joined at C speed: 1e5 cycles in 0.1 s instead of 1.4 s
        cols = [map(repr, np.asarray(self.cycles[k], dtype=float).tolist()) for k in names]
        n = self.cycles[names[0]].size if names else 0
        rows = map(",".join, zip(map(str, range(1, n + 1)), *cols, strict=True))
        for line in rows:
            buf.write(line)
            buf.write("\n")
        return buf.getvalue()

    def plot(self, name: str, *, against: str = "time", ax: Any = None) -> Any:
        """``name`` (with error bars when it has a standard error) against window mid time
        (``against="time"``) or cycle count (``"cycle"``); returns the axes.

        Deprecated (issue 32: studies return results, the report draws them): use
        :func:`contactlab.report.track_plots.plot_quantity`.
        """
        from .._moved import moved

        fn = moved(
            "contactlab.TrackResult", "plot", "contactlab.report.track_plots", "plot_quantity"
        )
        return fn(self, name, against=against, ax=ax)

    def __repr__(self) -> str:
        return (
            f"TrackResult({self.source!r}, {self.kind}, every={self.every!r}, "
            f"{len(self.rows)} windows, {self.cycles['energy'].size} cycles)"
        )


def _finite(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _as_float(v: Any) -> float:
    return float(v) if _finite(v) else float("nan")


#: options of ``analyze_tangential`` the one-pass window analysis
#: (:func:`contactlab.tangential.analysis.analyze_window`) takes; others (``on="signal"``,
#: ``history``) take the whole-window analysis
_WINDOW_OPTIONS = frozenset(
    ("force_sign", "n_points", "rel_threshold", "min_cycles", "max_rel_stderr", "fit_offset",
     "fit_x0", "fit_amplitude", "detrend", "initial", "delay")
)  # fmt: skip


class _WindowSamples:
    """A window of a recording sampled every ``dt`` from ``t0`` whose time axis is made when
    its analysis starts (:meth:`recording`, on the helper thread or worker): a window waiting
    for a helper holds its channels only, 8 bytes a sample less, and the reader does not fill
    the axis. The axis is :func:`contactlab._core.fill_time`'s, bit for bit the one
    :meth:`_Windows.take` made before."""

    __slots__ = ("data", "meta", "source", "start", "time_step", "units")

    def __init__(
        self,
        data: dict[str, np.ndarray],
        units: dict[str, str],
        source: str,
        meta: dict[str, Any],
        time_step: tuple[float, float],
        start: int,
    ) -> None:
        self.data, self.units, self.source, self.meta = data, units, source, meta
        self.time_step, self.start = time_step, start

    def __getstate__(self) -> tuple[Any, ...]:
        return tuple(getattr(self, k) for k in self.__slots__)

    def __setstate__(self, state: tuple[Any, ...]) -> None:
        for k, v in zip(self.__slots__, state, strict=True):
            setattr(self, k, v)

    def __len__(self) -> int:
        return len(next(iter(self.data.values())))

    def time(self, i: int) -> float:
        """The time of sample ``i`` of the window (that of :meth:`recording`'s axis)."""
        from .. import _core

        one = np.empty(1)
        _core.fill_time(one, self.time_step[0], self.time_step[1], self.start + i)
        return float(one[0])

    def recording(self) -> Recording:
        from .. import _core

        t = np.empty(len(self))
        _core.fill_time(t, self.time_step[0], self.time_step[1], self.start)
        return Recording(t, self.data, self.units, self.source, self.meta)


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
        from ..io.checks import check_recording_glitches

        try:
            row, units = fn(rec, *args, **kwargs)
        except ContactLabError as exc:
            w = _window_recording(rec)
            try:
                check_recording_glitches(w, offset=int((w.meta or {}).get("offset", 0)))
            except InputError as glitch:
                raise glitch from exc
            raise
        if always or row.get("warnings"):
            w = _window_recording(rec)
            check_recording_glitches(w, offset=int((w.meta or {}).get("offset", 0)))
        return row, units

    return run


@_glitch_checked(always=False)
def _tangential_window(
    rec: Recording | _WindowSamples, options: Mapping[str, Any], keep_doc: bool = False
) -> tuple[dict, dict]:
    from ..tangential import analyze_tangential
    from ..tangential.analysis import analyze_window

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
        res = analyze_window(rec, **opts)
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
    is made for each window instead (bit for bit the chunks'), and each chunk's on its own.
    """

    def __init__(self, first_window: int, time_step: tuple[float, float] | None) -> None:
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
            out["t"] = np.empty(m)
        return out

    def add(self, rec: Recording) -> None:
        """The next ``len(rec)`` samples (written where :meth:`alloc` said) are read."""
        if self.proto is None:  # what the windows inherit (not the arrays: they would
            # keep the first window's array alive to the end)
            self.proto = (rec.units, rec.source, rec.meta)
        self.n += len(rec)

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
            rec = _WindowSamples(
                data, dict(units), source, dict(meta, offset=self.start), self.time_step, self.start
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
                piece = Recording(c.t[a:b], {k: v[a:b] for k, v in c.data.items()},
                                  c.units, c.source, meta)  # fmt: skip
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
    options : mapping, optional
        Keyword arguments of the per-window analysis (``analyze_tangential`` or
        ``normal.analyze_loop``).
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
            return _track(
                source, every, kind=kind, columns=columns, fs=fs, chunk_size=chunk_size,
                max_window=max_window, options=options, keep_going=keep_going,
                callback=callback, executor=pool, keep_documents=keep_documents,
                slots=n_threads + (2 if n_threads >= 2 else 1), resample=resample,
            )  # fmt: skip
    return _track(
        source, every, kind=kind, columns=columns, fs=fs, chunk_size=chunk_size,
        max_window=max_window, options=options, keep_going=keep_going, callback=callback,
        executor=executor, keep_documents=keep_documents, slots=None, resample=resample,
    )  # fmt: skip


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
) -> TrackResult:
    """:func:`track` on ``executor`` (None: serial); ``slots``: windows in flight at most
    (default two per worker)."""
    mode, size = parse_every(every)
    every_text = every if isinstance(every, str) else f"{every}cycles"
    if not (isinstance(max_window, int) and max_window >= 16):
        raise InputError(f"max_window must be an integer >= 16, got {max_window!r}")
    cr = read_chunks(source, chunk_size=chunk_size, columns=columns, kind=kind, fs=fs,
                     resample=resample)  # fmt: skip
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
    docs: list[dict[str, Any]] = []
    opts = dict(options or {})

    state = CycleState()
    cyc: dict[str, list[np.ndarray]] = {
        k: [] for k in ("start", "end", "energy", "amplitude", "offset")
    }
    rows: list[dict[str, Any]] = []
    units: dict[str, str] = {"t_start": "s", "t_end": "s", "t_mid": "s"}
    # the first window's array: sized for an "auto" window (or a chunk; it grows), at most
    # the recording
    first = AUTO_WINDOW if mode == "auto" else chunk_size
    buf = _Windows(
        first if cr.n_samples is None else max(min(first, cr.n_samples), 1), cr.time_step
    )
    n_cross = 0  # crossings so far
    cycles_at_start = 0  # complete cycles before the current window
    next_cross_target = int(size) if mode == "cycles" else None
    first_crossings: list[int] = []
    window_t0: float | None = None
    crossings_in_window = 0
    n_total = 0

    from .executor import n_workers

    in_flight: deque[tuple[dict[str, Any], Any]] = deque()
    limit = slots if slots is not None else 2 * n_workers(executor)
    dask = executor is not None and type(executor).__module__.split(".")[0] == "distributed"

    def collect(row: dict[str, Any], job: Any) -> None:
        try:
            values, u = job() if executor is None else job.result()
        except ContactLabError as exc:
            if not keep_going:
                raise
            values, u = {"error": f"window {row['window']}: {exc}"}, {}
        doc = values.pop("_doc", None)
        if doc is not None:
            docs.append(doc)
        row.update(values)
        units.update(u)
        if callback is not None:
            callback(row)

    def emit(stop: int, n_cycles_before_stop: int) -> None:
        nonlocal cycles_at_start
        rec = buf.take(stop)
        t_first, t_last = _time_bounds(rec)
        row: dict[str, Any] = {
            "window": len(rows) + 1,
            "t_start": t_first,
            "t_end": t_last,
            "t_mid": 0.5 * (t_first + t_last),
            "cycle_start": cycles_at_start,
            "cycle_end": n_cycles_before_stop,
            "n_samples": len(rec),
        }
        rows.append(row)
        cycles_at_start = n_cycles_before_stop
        if executor is None:
            collect(row, functools.partial(analyse, rec, opts))
            return
        fut = (
            executor.submit(analyse, rec, opts, pure=False)
            if dask
            else executor.submit(analyse, rec, opts)
        )
        in_flight.append((row, fut))
        if slots is not None:
            # our helper threads: a window holds its samples until its analysis is done, so
            # the limit counts the windows not done yet, and the reader goes on as soon as any
            # is (waiting for the oldest left a helper thread idle whenever a younger window
            # finished first: the two threads were busy 65 % of a run); finished windows are
            # collected in order
            busy = [f for _, f in in_flight if not f.done()]
            if len(busy) >= limit:
                futures_wait(busy, return_when=FIRST_COMPLETED)
            while in_flight and in_flight[0][1].done():
                collect(*in_flight.popleft())
            return
        while len(in_flight) >= limit:
            collect(*in_flight.popleft())

    try:
        for block, ranges in _segments(_noting(cr.chunks_into(buf.alloc), noted), CYCLE_SEGMENT):
            off = int(block.meta.get("offset", n_total))
            buf.add(block)
            n_total = off + len(block)
            levels = trigger_levels(*ranges[drive]) if ranges and len(block) else None
            got = block_cycles(
                block.t, block[loop_x], block[loop_F], block[drive], off, state, levels,
                cr.time_step,
            )  # fmt: skip
            for k in cyc:
                cyc[k].append(np.asarray(getattr(got, k), dtype=float))
            if window_t0 is None:
                window_t0 = float(block.t[0])
            if mode == "auto":
                first_crossings.extend(got.crossings[:64].tolist())
                if len(first_crossings) >= 3:
                    per_cycle = float(np.median(np.diff(first_crossings)))
                    size = float(max(MIN_CYCLES + 1, round(AUTO_WINDOW / per_cycle)))
                    mode, next_cross_target = "cycles", int(size)
            for g in got.crossings.tolist():
                n_cross += 1
                crossings_in_window += 1
                # complete cycles before crossing g: crossings so far minus the first one
                done = n_cross - 1
                if mode == "auto":
                    cut = False
                elif mode == "cycles":
                    assert next_cross_target is not None
                    cut = n_cross == next_cross_target + 1
                    if cut:
                        next_cross_target += int(size)
                else:
                    t_g = float(block.t[g - off])
                    cut = t_g - window_t0 >= size and crossings_in_window > MIN_CYCLES
                if cut:
                    emit(g, done)
                    window_t0 = float(block.t[g - off])
                    crossings_in_window = 1
            if buf.n > max_window:  # the open window (cut windows have left the buffer)
                raise InputError(
                    f"{cr.source}: a window of every={every_text!r} holds more than "
                    f"{max_window} samples; choose a shorter window (or raise max_window)"
                )
        # the tail: analysed when it holds MIN_CYCLES complete cycles
        tail = buf.n
        if tail and crossings_in_window > MIN_CYCLES:
            emit(n_total, max(n_cross - 1, 0))
            tail = 0
        while in_flight:
            collect(*in_flight.popleft())
    finally:
        for _row, fut in in_flight:
            fut.cancel()
    if not rows:
        raise InputError(
            f"{cr.source}: found {max(n_cross - 1, 0)} complete cycle(s) in {n_total} samples; "
            f"tracking needs windows of at least {MIN_CYCLES} cycles"
        )
    cycles = {k: (np.concatenate(v) if v else np.empty(0)) for k, v in cyc.items()}
    meta = {
        **noted,  # resampled: what --resample bridged (the last chunk's: the whole record's)
        "n_samples": n_total,
        "n_windows": len(rows),
        "tail_samples_left_out": tail,
        "chunk_size": chunk_size,
        "every_mode": mode,
        "every_value": size,
    }
    return TrackResult(cr.source, kind_, every_text, rows, units, cycles, meta, docs)


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


def track_json(result: TrackResult, *, cycles: bool = True) -> str:
    """The result as JSON text (NaN → null; each per-cycle array on one line)."""
    doc = result.to_dict(cycles=False)
    if cycles:  # the arrays as they are: jsonable converts numbers at numpy's speed
        doc["cycles"] = dict(result.cycles)
    return dumps(jsonable(doc), indent=1) + "\n"


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
