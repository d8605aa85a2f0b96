"""Studies over many recordings: one table of fitted parameters against load and amplitude.

Issue 4 ("Studies over many recordings"). Each recording of a study (tagged by a manifest or by
its file name, see :mod:`contactlab.studies.manifest`) is read, analysed — tangential recordings
with :func:`contactlab.tangential.analyze_tangential` (h0, ac, E per cycle analytic and numeric,
c_e·ω = E/(πA²), local and global stiffness, eqs. 8-19 of the tangential paper), normal ones
with :func:`contactlab.normal.analyze_loop` (E_d, ψ eqs. 3 and 7, k_tan eq. 4, k_sec eq. 5) and
the pressure-dependent stiffness of eq. 16 (b1..b4) — and becomes one row of a table in SI
with the uncertainties the analyses report. The table is written as CSV (units in the header
cells, ``h0 [N]``) and Parquet (units in the schema metadata); :mod:`contactlab.studies.plots`
draws the paper's plots from it.
"""

from __future__ import annotations

import csv
import functools
import html
import io
import json
import math
import os
import re
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ContactLabError, InputError
from .manifest import TAG_UNITS, StudyEntry, entry_from_file, read_manifest

KINDS = ("tangential", "normal")
SUPPORTED_EXTENSIONS = (".csv", ".tdms", ".h5", ".hdf5", ".mat")


@dataclass
class RecordingResult:
    """The analysis of one recording of a study and its table row (SI, flat scalars)."""

    entry: StudyEntry
    row: dict[str, Any]
    units: dict[str, str]
    analysis: Any = None
    recording: Any = None
    extra: dict[str, Any] = field(default_factory=dict)
    error: str | None = None

    @property
    def ok(self) -> bool:
        return self.error is None


# "Pa; ascending powers of delta in m" (a polynomial's coefficients, described in one string)
_POWERS = re.compile(
    r"^\s*([A-Za-z]+)(/([A-Za-z]+)(?:\^(\d+))?)?\s*; ascending powers of \S+ in (\w+)"
)


def coefficient_unit(unit: str, i: int) -> str:
    """Unit of coefficient ``i`` of a polynomial whose unit map says ``"Pa; ascending powers of
    delta in m"``: ``Pa``, ``Pa/m``, ``Pa/m^2``, ... (``"Pa/m; ..."`` starts at ``Pa/m``).
    Other strings are returned as they are."""
    m = _POWERS.match(unit)
    if m is None or (m.group(2) and m.group(3) != m.group(5)):
        return unit
    n = i + (int(m.group(4) or 1) if m.group(2) else 0)
    var = m.group(5)
    return m.group(1) if n == 0 else f"{m.group(1)}/{var}" if n == 1 else f"{m.group(1)}/{var}^{n}"


def flatten(d: Mapping[str, Any], units: Mapping[str, str]) -> tuple[dict, dict]:
    """Scalars as they are, short vectors as ``key_0, key_1, ...``; nested dicts dotted."""
    row: dict[str, Any] = {}
    out_units: dict[str, str] = {}
    for key, value in d.items():
        if key == "units":
            continue
        unit = units.get(key, "")
        if isinstance(value, Mapping):
            sub, sub_units = flatten(value, value.get("units", {}) or {})
            for k, v in sub.items():
                row[f"{key}.{k}"] = v
                if sub_units.get(k):
                    out_units[f"{key}.{k}"] = sub_units[k]
            continue
        if isinstance(value, (list, tuple, np.ndarray)):
            arr = np.asarray(value)
            if arr.ndim == 1 and arr.size <= 8 and arr.dtype.kind in "fiub":
                for i, v in enumerate(arr.tolist()):
                    row[f"{key}_{i}"] = float(v)
                    if isinstance(unit, (list, tuple)) and i < len(unit):
                        out_units[f"{key}_{i}"] = str(unit[i])
                    elif isinstance(unit, str) and unit:
                        out_units[f"{key}_{i}"] = coefficient_unit(unit, i)
            continue
        if isinstance(value, (np.floating, np.integer, np.bool_)):
            value = value.item()
        if value is None or isinstance(value, (bool, int, float, str)):
            row[key] = value
            if isinstance(unit, str) and unit:
                out_units[key] = unit
    return row, out_units


def _renamed(exc: ContactLabError, entry: StudyEntry) -> ContactLabError:
    """The same error type with the file named (errors from readers usually name it already)."""
    msg = _with_source(exc, entry)
    if msg == str(exc):
        return exc
    try:
        return type(exc)(msg)
    except TypeError:  # an error class with a different constructor
        return InputError(msg) if isinstance(exc, InputError) else ContactLabError(msg)


def _with_source(exc: BaseException, entry: StudyEntry) -> str:
    msg = str(exc)
    return msg if entry.path.name in msg else f"{entry.path}: {msg}"


_FIT_STATS = ("chisqr", "redchi", "aic", "bic", "success", "nfev", "ndata", "nvarys")


def tangential_row(d: Mapping[str, Any]) -> dict[str, Any]:
    """Table row of a tangential analysis' ``to_dict()``: identifiability as a flag plus the
    evidence, fit statistics (not the covariance matrix), warnings joined into one text."""
    out = {k: v for k, v in d.items() if k not in ("identifiable", "fit", "warnings", "source")}
    ident = d.get("identifiable")
    if isinstance(ident, Mapping):
        out["identifiable"] = bool(ident.get("h0")) and bool(ident.get("ac"))
        for k in ("ac_times_amplitude", "correlation_h0_ac", "rel_stderr_h0_ac"):
            if k in ident:
                out[k] = ident[k]
        out["identifiability"] = ident.get("message", "")
    elif ident is not None:
        out["identifiable"] = bool(ident)
    fit = d.get("fit")
    if isinstance(fit, Mapping):
        for k in _FIT_STATS:
            if k in fit:
                out[f"fit_{k}"] = fit[k]
    out["warnings"] = " | ".join(str(w) for w in d.get("warnings", []) or [])
    return out


def analyze_entry(
    entry: StudyEntry,
    *,
    tangential_options: Mapping[str, Any] | None = None,
    normal_options: Mapping[str, Any] | None = None,
) -> RecordingResult:
    """Read and analyse one recording; its row holds the tags, then the analysis outputs."""
    from ..io import read_recording

    frame = None
    if entry.frame is not None:
        from ..tangential import read_frame

        if entry.kind != "tangential":
            raise InputError(
                f"{entry.path}: a friction frame gives a tangential recording "
                f"(x, F), not a {entry.kind} one"
            )
        f = entry.frame
        frame = read_frame(
            entry.path, f["M"], f["C"], f["K"], x=f.get("x"), y=f.get("y"), fs=entry.fs
        )
        rec = frame.recording(str(entry.path))
        rec.meta.update(columns=frame.columns, file_units=frame.file_units)
        cols, funits = frame.columns or {}, frame.file_units or {}
        assumed_frame = [cols[k] for k in ("x", "y") if k in cols and not funits.get(k)]
        if assumed_frame:
            rec.meta["units_assumed_si"] = assumed_frame
    else:
        rec = read_recording(
            entry.path, columns=entry.columns, kind=entry.kind, fs=entry.fs, resample=entry.resample
        )
    from ..io.checks import check_recording_glitches

    check_recording_glitches(rec)  # a sensor glitch is refused, as diagnose refuses it
    base = {"file": entry.path.name, "kind": entry.kind, **entry.tags}
    # provenance: what was read (a units-assumed-SI note matters when a file has no units)
    base["format"] = entry.path.suffix.lower().lstrip(".")
    base["n_samples"] = len(rec.t)
    base["fs"] = float(rec.fs)
    assumed = (rec.meta or {}).get("units_assumed_si")
    base["units_assumed_si"] = ", ".join(map(str, assumed)) if assumed else ""
    units = {k: TAG_UNITS[k] for k in entry.tags if k in TAG_UNITS}
    units.update(entry.units)
    units["fs"] = "Hz"
    if entry.kind == "tangential":
        from ..tangential import analyze_tangential

        opts = {"warn": False, **dict(tangential_options or {})}  # warnings go in the table
        analysis = analyze_tangential(rec, **opts)
        d = tangential_row(analysis.to_dict())
        row, u = flatten(d, d.get("units", {}) or {})
        extra: dict[str, Any] = {}
        if "N" in rec.data:  # a recorded normal force: μ = F/N on the sliding plateau
            from ..tangential.friction import sliding_friction

            sf = sliding_friction(rec.t, rec["x"], rec["F"], rec["N"])
            row.update(sf.to_dict())
            extra.update(sf.to_dict())
            u.update(sf.units, mu_up="1", mu_down="1")
        if frame is not None:  # the reconstruction's figures: JSON object, table columns
            fd = frame.to_dict()
            extra["frame_reconstruction"] = fd
            for k in ("window", "window_s", "force_noise", "noise_x", "noise_y"):
                row[f"frame_{k}"] = fd[k]
                u[f"frame_{k}"] = fd["units"][k]  # type: ignore[index]
    else:
        from .normal import analyze_normal_recording

        analysis, d, extra = analyze_normal_recording(rec, entry, **dict(normal_options or {}))
        row, u = flatten(d, d.get("units", {}) or {})
    units.update(u)
    base.update(row)
    resampled = (rec.meta or {}).get("resampled")
    if resampled:
        from ..io.recording import describe_resampling

        base["resampled_largest_gap"] = float(resampled["largest_step"])
        units["resampled_largest_gap"] = "s"
        note = describe_resampling(resampled)
        ws = [note, *(w for w in str(base.get("warnings") or "").split(" | ") if w)]
        base["warnings"] = " | ".join(ws)
        extra = {**extra, "warnings": ws}
    if assumed:
        # A header without units is the commonest way to get metres where µm were meant:
        # say so beside the results (terminal, JSON, report), not only in a provenance column.
        si = ", ".join(["t in s"] + [f"{k} in {v}" for k, v in rec.units.items()])
        note = (
            f"no unit in the file for {', '.join(map(str, assumed))}: taken as SI ({si}); "
            "if that is wrong, put the unit in the name, e.g. 'x [um]'"
        )
        ws = [note, *(w for w in str(base.get("warnings") or "").split(" | ") if w)]
        base["warnings"] = " | ".join(ws)
        extra = {**extra, "warnings": ws}
    return RecordingResult(entry, base, units, analysis=analysis, recording=rec, extra=extra)


@dataclass
class StudyResult:
    """All analysed recordings of a study, with tables per kind."""

    results: list[RecordingResult]

    def of_kind(self, kind: str) -> list[RecordingResult]:
        return [r for r in self.results if r.entry.kind == kind]

    @property
    def failures(self) -> list[RecordingResult]:
        return [r for r in self.results if not r.ok]

    def table(self, kind: str) -> list[dict[str, Any]]:
        """Rows (dicts, SI) of every successfully analysed recording of ``kind``."""
        return [r.row for r in self.of_kind(kind) if r.ok]

    def units(self, kind: str) -> dict[str, str]:
        out: dict[str, str] = {}
        for r in self.of_kind(kind):
            out.update(r.units)
        return out

    def columns(self, kind: str) -> list[str]:
        cols: list[str] = []
        for row in self.table(kind):
            cols.extend(k for k in row if k not in cols)
        return cols

    def to_csv(self, kind: str) -> str:
        """The table as CSV text; header cells carry SI units in brackets (``h0 [N]``)."""
        cols, units = self.columns(kind), self.units(kind)
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow([f"{c} [{units[c]}]" if units.get(c) else c for c in cols])
        for row in self.table(kind):
            w.writerow([_csv_cell(row.get(c)) for c in cols])
        return buf.getvalue()

    def to_parquet(self, kind: str) -> bytes:
        """The table as Parquet bytes (pyarrow); units in the schema metadata ``units``."""
        try:
            import pyarrow as pa
            import pyarrow.parquet as pq
        except ImportError:  # pragma: no cover - pyarrow is in the `io` extra
            raise InputError(
                "writing Parquet needs pyarrow: pip install 'contactlab[io]'"
            ) from None
        cols, rows = self.columns(kind), self.table(kind)
        arrays = {}
        for c in cols:
            values = [row.get(c) for row in rows]
            if all(v is None or isinstance(v, str) for v in values):
                arrays[c] = pa.array(values, type=pa.string())
            elif all(v is None or isinstance(v, bool) for v in values):
                arrays[c] = pa.array(values, type=pa.bool_())
            else:
                arrays[c] = pa.array(
                    [None if v is None else float(v) for v in values], type=pa.float64()
                )
        table = pa.table(arrays)
        meta = {b"units": json.dumps(self.units(kind)).encode()}
        table = table.replace_schema_metadata(meta)
        buf = io.BytesIO()
        pq.write_table(table, buf)
        return buf.getvalue()

    def _repr_html_(self) -> str:
        """Summary tables in notebooks (the full report: ``report.study_report``)."""
        from .._html import table_html
        from .columns import NORMAL_COLUMNS, TANGENTIAL_COLUMNS

        parts = []
        for kind, cols in (("tangential", TANGENTIAL_COLUMNS), ("normal", NORMAL_COLUMNS)):
            rows = self.table(kind)
            if rows:
                present = [c for c in cols if any(c.key in r for r in rows)]
                parts.append(table_html(rows, present, f"{kind}: {len(rows)} recording(s)"))
        for r in self.failures:
            parts.append(f"<p>failed: {html.escape(str(r.error))}</p>")
        return "".join(parts) or "<p>empty study</p>"

    def __repr__(self) -> str:
        n = {k: len(self.table(k)) for k in KINDS}
        return (
            f"StudyResult({n['tangential']} tangential, {n['normal']} normal, "
            f"{len(self.failures)} failed)"
        )

    def table_files(self, stem: str = "study") -> dict[str, bytes]:
        """``<stem>_<kind>.csv`` and ``.parquet`` for each kind present."""
        out: dict[str, bytes] = {}
        for kind in KINDS:
            if self.table(kind):
                out[f"{stem}_{kind}.csv"] = self.to_csv(kind).encode("utf-8")
                out[f"{stem}_{kind}.parquet"] = self.to_parquet(kind)
        return out


def _csv_cell(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, float):
        return "nan" if math.isnan(v) else repr(v)
    return str(v)


def _progress(
    iterable: Iterable[Any], progress: bool | None, desc: str, total: int | None = None
) -> Iterable[Any]:
    """tqdm.auto bar (a widget in notebooks, text in terminals); None = only on a terminal.

    A bar that would not show (``progress`` False, or None outside IPython with stderr not a
    terminal: tqdm's own ``disable=None`` rule) is the iterable itself, without importing
    tqdm: ``tqdm.auto`` imports asyncio, ssl and importlib.metadata, 30-40 % of the start-up
    CPU of ``contactlab analyze FILE > out`` of a short recording."""
    if progress is False or (progress is None and _not_a_terminal()):
        return iterable
    from tqdm.auto import tqdm

    return tqdm(
        iterable,
        desc=desc,
        unit="rec",
        total=total,
        disable=None if progress is None else not progress,
    )


def _not_a_terminal() -> bool:
    """True where tqdm with ``disable=None`` would show no bar: stderr (its default output)
    is not a terminal, outside IPython (a notebook's tqdm widget ignores ``disable=None``)."""
    import sys

    if "IPython" in sys.modules:
        return False
    isatty = getattr(sys.stderr, "isatty", None)
    if isatty is None:
        return False  # tqdm then leaves the bar on: let it decide
    try:
        return not isatty()
    except (ValueError, OSError):  # a closed stream
        return False


def collect_entries(source: str | os.PathLike[str] | Sequence[Any]) -> list[StudyEntry]:
    """Study entries from a manifest file, a folder (tags from file names) or a list."""
    if isinstance(source, (str, os.PathLike)):
        p = Path(source)
        if p.is_dir():
            files = sorted(
                f
                for f in p.rglob("*")
                if f.is_file()
                and f.suffix.lower() in SUPPORTED_EXTENSIONS
                and f.name.lower() != "manifest.csv"  # a manifest is not a recording
                and not f.name.startswith(".")  # hidden files, our own temporaries
            )
            if not files:
                raise InputError(f"folder {p} holds no recordings ({SUPPORTED_EXTENSIONS})")
            return [entry_from_file(f) for f in files]
        return read_manifest(p)
    return [e if isinstance(e, StudyEntry) else entry_from_file(e) for e in source]


def _study_task(
    entry: StudyEntry,
    *,
    tangential_options: Mapping[str, Any] | None,
    normal_options: Mapping[str, Any] | None,
    keep_going: bool,
    keep_recording: bool,
) -> RecordingResult:
    """One recording of a study, as run on a worker (module level: it must pickle)."""
    try:
        r = analyze_entry(
            entry, tangential_options=tangential_options, normal_options=normal_options
        )
    except ContactLabError as exc:
        if not keep_going:
            raise
        return RecordingResult(entry, {}, {}, error=_with_source(exc, entry))
    except Exception as exc:  # not a known bad input: a bug, or something unforeseen
        if not keep_going:
            raise
        # The user asked to go on: keep the rest of the study, name what happened.
        msg = f"{entry.path}: unexpected {type(exc).__name__}: {exc}"
        return RecordingResult(entry, {}, {}, error=msg)
    if not keep_recording:
        r.recording = None
    return r


def run_study(
    source: str | os.PathLike[str] | Sequence[Any],
    *,
    progress: bool | None = None,
    keep_going: bool = False,
    tangential_options: Mapping[str, Any] | None = None,
    normal_options: Mapping[str, Any] | None = None,
    callback: Callable[[RecordingResult], None] | None = None,
    executor: Any = None,
    keep_recordings: bool | None = None,
) -> StudyResult:
    """Analyse every recording of a study.

    Parameters
    ----------
    source : path or sequence
        A manifest CSV, a folder of recordings tagged by their names (searched recursively;
        files named ``manifest.csv`` and hidden files are skipped), or a list of
        :class:`~contactlab.studies.StudyEntry` / file paths.
    progress : bool or None
        Show a progress bar (``tqdm.auto``: a widget in notebooks); None shows it on a terminal.
    keep_going : bool
        If False (default) the first recording that cannot be read or analysed stops the study
        with its error (naming the file). If True it is recorded in ``failures`` and skipped
        (unexpected errors too, with their type, so one odd file does not cost a long study).
    tangential_options, normal_options : Options or mapping, optional
        Keyword arguments for the per-recording analyses: :class:`contactlab.tangential.Options`
        / :class:`contactlab.normal.Options` or dicts of the same names.
    callback : callable, optional
        Called with each :class:`RecordingResult` as it completes.
    executor : optional
        Run the recordings in parallel: a ``concurrent.futures`` executor (threads or
        processes) or a Dask ``distributed.Client`` (see :mod:`contactlab.studies.executor`).
        Results come in the order of the study and equal the serial run's; a bounded number
        of recordings is in flight at a time (:func:`contactlab.studies.ordered_map`).
    keep_recordings : bool, optional
        Keep each recording's samples in its result (``RecordingResult.recording``, drawn
        behind the normal loops of the report). Default: yes for a serial run, no with an
        executor, so that a study of thousands of files holds only the results.

    Returns
    -------
    StudyResult

    Examples
    --------
    >>> from contactlab.data import manifest_path
    >>> res = run_study(manifest_path(), progress=False)  # the bundled example study
    >>> res
    StudyResult(27 tangential, 5 normal, 0 failed)
    >>> row = res.table("tangential")[0]
    >>> row["material"], row["normal_load"], round(row["h0"], 1)  # SI: N, N
    ('Al/Al', 50.0, 21.0)
    """
    from .._options import as_dict
    from .executor import ordered_map

    tangential_options, normal_options = as_dict(tangential_options), as_dict(normal_options)
    entries = collect_entries(source)
    keep = executor is None if keep_recordings is None else bool(keep_recordings)
    task = functools.partial(
        _study_task,
        tangential_options=tangential_options,
        normal_options=normal_options,
        keep_going=keep_going,
        keep_recording=keep,
    )
    results: list[RecordingResult] = []
    done = ordered_map(task, entries, executor)
    try:
        for r in _progress(done, progress, "analysing", total=len(entries)):
            results.append(r)
            if callback is not None:
                callback(r)
    except ContactLabError as exc:
        new = _renamed(exc, entries[len(results)])
        if new is exc:
            raise
        raise new from exc
    return StudyResult(results)


__all__ = [
    "KINDS",
    "RecordingResult",
    "StudyResult",
    "analyze_entry",
    "collect_entries",
    "run_study",
]
