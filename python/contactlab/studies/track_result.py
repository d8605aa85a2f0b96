"""The result of :func:`contactlab.studies.tracking.track`: the quantities per window of a
long recording and per cycle over the whole record, their units, the pooled whole-record
values (:meth:`TrackResult.combined`, weights by window size, the error widened by the Birge
ratio when the windows scatter more than their errors say), tables and JSON."""

from __future__ import annotations

import csv
import io
import math
import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._json import dumps, jsonable
from ..errors import InputError
from ..io.units import UnknownUnitError, to_si
from .cycles import CYCLE_UNITS
from .pooled import pool

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


def _finite(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _as_float(v: Any) -> float:
    return float(v) if _finite(v) else float("nan")


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


def track_json(result: TrackResult, *, cycles: bool = True) -> str:
    """The result as JSON text (NaN → null; each per-cycle array on one line)."""
    doc = result.to_dict(cycles=False)
    if cycles:  # the arrays as they are: jsonable converts numbers at numpy's speed
        doc["cycles"] = dict(result.cycles)
    return dumps(jsonable(doc), indent=1) + "\n"
