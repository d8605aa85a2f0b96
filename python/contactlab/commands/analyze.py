"""``contactlab analyze FILE [FILE ...] [--model tangential|normal] [--json OUT] [--report DIR]``.

Reads each recording (CSV/TDMS/HDF5/MAT, SI inside), runs the tangential analysis (Masing fit,
energy analytic and numeric, c_e·ω, stiffness; the tangential paper's eqs. 1-19) or the normal
one (Konowalski's eqs. 1-7 and 16), prints a summary, and optionally writes JSON (SI values and
a ``units`` map) and an HTML report. Tags (material, load, amplitude, p0, pa) are read from
the file names as in :mod:`contactlab.studies.manifest`.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from ..errors import InputError
from .common import (
    FORCE_SIGN_CHOICES,
    add_frame_flags,
    add_pressure_flags,
    add_progress_flags,
    add_reader_flags,
    check_output_targets,
    default_workers,
    describe,
    force_sign,
    frame_option,
    infer_model,
    json_document,
    json_text,
    made_by,
    normal_options,
    parse_columns,
    process_pool,
    quantity,
    recording_json,
    refuse_if_none_analysed,
    window_threads,
    wrap_warning,
    wrapped,
    write_json,
    write_report,
)

_SUMMARY = {
    "tangential": [
        ("h0", "N", 1.0),
        ("ac", "1/m", 1.0),
        ("h0_ac", "N/m", 1.0),
        ("amplitude", "um", 1e6),
        ("energy_per_cycle", "J", 1.0),
        ("equivalent_damping", "N/m", 1.0),
        ("k_local0", "N/m", 1.0),
        ("k_global", "N/m", 1.0),
        ("mu", "", 1.0),
        ("normal_load", "N", 1.0),
    ],
    "normal": [
        ("E_d", "J/m^2", 1.0),
        ("psi", "", 1.0),
        ("psi_kv", "", 1.0),
        ("k_tan", "Pa/m", 1.0),
        ("k_sec", "Pa/m", 1.0),
    ],
}


#: width the console's summary lines and warnings are wrapped to
WIDTH = 100


def summary_lines(head: str, row: dict, kind: str, tail: str = "", width: int = WIDTH) -> str:
    """``head: key = value ± error unit; ...`` (then ``tail``) packed into lines of at most
    ``width`` characters, continuation lines indented, never breaking inside a quantity."""
    parts = [p for p in _summary_line(row, kind).split("; ") if p]
    if tail:
        parts.append(tail)
    lines: list[str] = []
    cur, fresh = f"{head}:", True
    for part in parts:
        if not fresh and len(cur) + 2 + len(part) > width:
            lines.append(cur + ";")
            cur, fresh = "  ", True
        cur += (" " if fresh else "; ") + part
        fresh = False
    lines.append(cur)
    return "\n".join(lines)


def _summary_line(row: dict, kind: str) -> str:
    parts = []
    for key, unit, f in _SUMMARY[kind]:
        v = row.get(key)
        if isinstance(v, float):
            s = row.get(f"{key}_stderr")
            pm = f" ± {abs(s) * f:.2g}" if isinstance(s, float) else ""
            parts.append(f"{key} = {v * f:.5g}{pm} {unit}".rstrip())
    if kind == "tangential" and row.get("force_sign") in (1, -1):
        parts.append(f"force sign {row['force_sign']:+d}")
    return "; ".join(parts)


def _streamed(
    args: argparse.Namespace, entries: list, columns: dict | None, topts: dict, nopts: dict
) -> int:
    """``--stream``: each file read in chunks, analysed window by window and pooled
    (:func:`contactlab.studies.track`); memory bounded whatever the length."""
    from .. import __version__
    from ..errors import ContactLabError
    from ..io.recording import RecordingError
    from ..studies.tracking import parse_every, track

    parse_every(args.every)
    if args.report and len(entries) > 1:
        raise InputError("--stream --report takes one file (or use `contactlab track` per file)")
    say = sys.stderr if args.json == "-" else sys.stdout
    docs, failures, last = [], [], None
    with process_pool(args.workers or None) as ex:
        for e in entries:
            try:
                res = track(
                    e.path,
                    args.every,
                    kind=args.model,
                    columns=columns,
                    fs=args.fs,
                    executor=ex,
                    resample=args.resample,
                    options=topts if e.kind == "tangential" else normal_options(e, nopts),
                )
                if res.rows and all(r.get("error") for r in res.rows):
                    raise RecordingError(
                        "no window of the streamed analysis could be analysed: "
                        + "; ".join(sorted({str(r["error"]) for r in res.rows})),
                        file=str(e.path),
                    )
            except ContactLabError as exc:
                if not args.keep_going:
                    raise
                failures.append({"file": str(e.path), "error": str(exc)})
                print(f"{e.path}: FAILED: {exc}", file=sys.stderr)
                continue
            last = res
            if res.meta.get("resampled"):
                from ..io.recording import describe_resampling

                print(wrapped(f"{e.path}: {describe_resampling(res.meta['resampled'])}"), file=say)
            full = res.to_dict(cycles=False)
            comb = full["combined"]
            print(
                summary_lines(
                    str(e.path),
                    comb,
                    args.model,
                    f"(streamed: {len(res.rows)} windows, {comb.get('n_cycles', 0)} cycles)",
                ),
                file=say,
            )
            units = {k: u for k, u in full["units"].items() if k in comb}
            docs.append(
                {
                    "file": str(e.path),
                    "model": args.model,
                    **e.tags,
                    "streamed": True,
                    "every": res.every,
                    "n_samples": res.meta["n_samples"],
                    "n_windows": len(res.rows),
                    **comb,
                    "units": units,
                }
            )
    refuse_if_none_analysed(len(docs), failures)
    doc: dict = (
        {**docs[0], "contactlab_version": __version__}
        if len(docs) == 1 and not failures
        else {"contactlab_version": __version__, "recordings": docs, "failures": failures}
    )
    text = json_text(doc) if args.json else None
    if args.report and last is not None:
        import matplotlib

        matplotlib.use("Agg")
        from ..report import commit_outputs
        from ..report.track_report import build_track_report, track_files

        cmd = made_by(
            args,
            "analyze",
            *args.files,
            "--model",
            args.model,
            "--stream",
            "--every",
            args.every,
            "--report",
            args.report,
        )
        rep = build_track_report(
            last, f"contactlab analyze --stream: {last.source}", intro=f"Made by: {cmd}"
        )
        for p in commit_outputs(args.report, track_files(last, rep)):
            if p.suffix == ".html":
                print(f"wrote {p}", file=say)
    if args.json:
        p = write_json(args.json, text)
        if str(p) != "-":
            print(f"wrote {p}", file=say)
    return 1 if failures else 0


def _n_samples(path: Path, columns: dict | None, fs: float | None, kind: str) -> int:
    """Samples of a recording without reading it (HDF5, MAT v7.3, TDMS), or an estimate from
    the size of a text file (16 bytes a row at least); 0 when the file cannot be opened that
    way (the whole-file reader then reports what is wrong with it)."""
    from ..errors import ContactLabError
    from ..io import read_chunks

    try:
        n = read_chunks(path, columns=columns, kind=kind, fs=fs).n_samples
    except (ContactLabError, OSError, ValueError):
        return 0
    return int(n) if n is not None else path.stat().st_size // 16


def _auto_streamed(
    args: argparse.Namespace, entry: object, columns: dict | None, opts: dict, ex: object
) -> dict:
    """A long recording analysed window by window in bounded memory and pooled into the
    whole-file document (:mod:`contactlab.studies.pooled`)."""
    from ..io.recording import RecordingError
    from ..studies.pooled import STREAM_ABOVE, pooled_document, pooled_normal_document
    from ..studies.tracking import track

    path = entry.path  # type: ignore[attr-defined]
    kind = entry.kind  # type: ignore[attr-defined]
    res = track(
        path,
        "auto",
        kind=kind,
        columns=columns,
        fs=args.fs,
        executor=ex,
        resample=getattr(args, "resample", False),
        options=opts,
        keep_documents=True,
        threads=window_threads(),
        # the document pools the windows' documents; the per-cycle table is drawn only in
        # a report (the crossings that cut the windows are found either way)
        cycles=bool(args.report),
    )
    if not res.window_docs:
        errors = "; ".join(str(r.get("error")) for r in res.rows if r.get("error"))
        raise RecordingError(
            f"no window of the streamed analysis could be fitted: {errors}", file=str(path)
        )
    n = res.meta["n_samples"]
    reason = (
        f"{n} samples > {STREAM_ABOVE}: analysed in {len(res.rows)} windows of whole cycles "
        f"(every={res.every}) read in chunks, memory bounded; the windows pooled "
        "(--whole analyses the file in memory)"
    )
    pooled = pooled_document if kind == "tangential" else pooled_normal_document
    doc = pooled(res.window_docs, reason=reason)
    doc.update(n_samples=n, n_windows=len(res.rows), every=res.every)
    failed = [r for r in res.rows if r.get("error")]
    if failed:
        doc["warnings"] = [*doc["warnings"], *(str(r["error"]) for r in failed)]
    doc = {"file": str(path), "model": kind, **entry.tags, **doc}  # type: ignore[attr-defined]
    doc["_track"] = res
    from .._malloc import release_freed_memory

    release_freed_memory()  # the windows' arrays, before a report's figures are drawn
    return doc


def _handler(args: argparse.Namespace) -> int:
    from ..studies.manifest import entry_from_file

    frame = frame_option(args)
    columns = parse_columns(args.columns)
    check_output_targets(json_out=args.json, report=args.report, inputs=args.files)
    if args.workers is not None and args.workers < 0:
        raise InputError(f"--workers must be >= 0 (0: serially), got {args.workers}")
    if frame is not None and args.stream:
        raise InputError("--frame reconstructs the force from the whole record: drop --stream")
    say = sys.stderr if args.json == "-" else sys.stdout
    if frame is not None and args.model is None:
        args.model = "tangential"  # a frame's displacements give a tangential recording
    if args.model is None:
        kinds = {}
        for f in args.files:
            if Path(f).is_file():
                kinds[f], note = infer_model(f, None, columns, args.fs)
                print(wrapped(f"{f}: {note}"), file=say)
        if len(set(kinds.values())) > 1:
            raise InputError(
                "the files are of different kinds ("
                + ", ".join(f"{f}: {k}" for f, k in kinds.items())
                + "): analyse them separately, or give --model"
            )
        args.model = next(iter(kinds.values()), "tangential")
    entries = []
    for f in args.files:
        if Path(f).is_dir():
            raise InputError(f"{f}: is a folder, not a recording file (use `contactlab study`)")
        if not Path(f).is_file():
            raise InputError(f"{f}: no such file")
        if any(Path(f).resolve() == e.path.resolve() for e in entries):
            raise InputError(f"{f}: given twice (it would be analysed and counted twice)")
        e = entry_from_file(f, kind=args.model)
        e.columns, e.fs, e.frame, e.resample = columns, args.fs, frame, args.resample
        entries.append(e)
    if args.delay is not None and args.model != "tangential":
        raise InputError("--delay is for tangential recordings (force against displacement)")
    # the flags parsed into the typed options (issue 32); the library takes them as dicts too
    from .._options import as_dict
    from ..tangential.options import Options as TangentialOptions

    topts = as_dict(TangentialOptions(force_sign=args.force_sign, delay=args.delay))
    # as_dict keeps the settings given: none given is {} without importing the normal
    # analysis (12-18 ms of CPU of a tangential run's start-up on this project's VM)
    nopts: dict[str, Any] = {}
    if args.p0 is not None or args.pa is not None:
        from ..normal.options import Options as NormalOptions

        nopts = as_dict(NormalOptions(p0=args.p0, pa=args.pa))
    if args.stream:
        return _streamed(args, entries, columns, topts, nopts)
    big: set[int] = set()
    if not args.whole and frame is None:  # a frame is reconstructed whole
        from ..studies.pooled import STREAM_ABOVE

        big = {
            i
            for i, e in enumerate(entries)
            if _n_samples(e.path, columns, args.fs, e.kind) > STREAM_ABOVE
        }
    if big and args.report and len(entries) > 1:
        raise InputError(
            "--report with several files, some too long to analyse in memory: use "
            "`contactlab analyze FILE --report DIR` per long file (or --whole)"
        )
    if big:
        return _with_long(args, entries, big, columns, topts, nopts)
    # several files: one process per core (--workers N sets it), the report's figures too
    workers = args.workers or None  # 0: serially
    if args.workers is None and len(entries) >= _POOL_FROM:
        workers = default_workers()
    with process_pool(workers, auto=args.workers is None) as ex:
        return _in_memory(args, entries, frame, topts, nopts, ex)


#: ``--delay``'s help (analyze; track and diagnose say it shorter)
DELAY_HELP = (
    "tangential: a known delay of the force channel behind the displacement (e.g. 1.1ms; "
    "negative: the force leads), corrected before the analysis by shifting the force (the "
    "samples left without force data are dropped). Any delay left is estimated "
    "(channel_delay in the JSON) and named in a warning when it matters"
)

#: files from which ``analyze`` (not streamed) uses a process per core by default
_POOL_FROM = 4


def _in_memory(
    args: argparse.Namespace, entries: list, frame: Any, topts: dict, nopts: dict, ex: Any
) -> int:
    """``analyze`` of recordings read whole: on ``ex`` (a process pool) or serially."""
    from ..studies.study import run_study

    result = run_study(
        entries,
        progress=args.progress,
        keep_going=args.keep_going,
        tangential_options=topts,
        normal_options=nopts,
        executor=ex,
        keep_recordings=True,
    )
    # With --json -, stdout carries the JSON alone; everything else goes to stderr.
    say = sys.stderr if args.json == "-" else sys.stdout
    for r in result.results:
        if r.ok:
            rebuilt = (r.extra or {}).get("frame_reconstruction")
            if rebuilt:
                from ..tangential.frame import describe_reconstruction

                print(
                    f"{r.entry.path}: friction frame: {describe_reconstruction(rebuilt)}", file=say
                )
            print(summary_lines(str(r.entry.path), r.row, r.entry.kind), file=say)
            if r.row.get("warnings"):
                for w in str(r.row["warnings"]).split(" | "):
                    print(wrap_warning(str(w)), file=sys.stderr)
            if args.verbose and hasattr(r.analysis, "report"):
                print(r.analysis.report(), file=say)
        else:
            print(f"{r.entry.path}: FAILED: {r.error}", file=sys.stderr)
    refuse_if_none_analysed(
        sum(r.ok for r in result.results), [str(r.error) for r in result.failures]
    )
    doc = json_text(json_document(result)) if args.json else None
    if args.report:
        title = f"contactlab analyze ({args.model}, {len(entries)} recording(s))"
        cmd = made_by(
            args,
            "analyze",
            *args.files,
            "--model",
            args.model,
            *(["--columns", args.columns] if args.columns else []),
            *(["--frame", args.frame] if frame else []),
            *(["--frame-x", args.frame_x] if args.frame_x else []),
            *(["--frame-y", args.frame_y] if args.frame_y else []),
            "--report",
            args.report,
        )
        paths = write_report(
            args.report,
            result,
            title,
            study_plots=len(entries) > 1,
            progress=args.progress,
            command=cmd,
            executor=ex,
        )
        for p in paths:
            if p.suffix == ".html":
                print(f"wrote {p}", file=say)
    if args.json:
        p = write_json(args.json, doc)
        if str(p) != "-":
            print(f"wrote {p}", file=say)
    return 1 if result.failures else 0


def _with_long(
    args: argparse.Namespace,
    entries: list,
    big: set[int],
    columns: dict | None,
    topts: dict,
    nopts: dict,
) -> int:
    """``analyze`` when some recordings are longer than ``STREAM_ABOVE`` samples: those
    streamed and pooled (same JSON keys, plus ``streamed``/``streamed_reason``), the others
    analysed whole."""
    from .. import __version__
    from ..errors import ContactLabError

    say = sys.stderr if args.json == "-" else sys.stdout
    small = [e for i, e in enumerate(entries) if i not in big]
    result = None
    if small:  # (the study module imported only then: 14-16 ms of a long file's start-up)
        from ..studies.study import run_study

        result = run_study(
            small,
            progress=args.progress,
            keep_going=args.keep_going,
            tangential_options=topts,
            normal_options=nopts,
        )

    by_path = {}
    failures = []
    if result is not None:
        for r in result.results:
            if r.ok:
                by_path[str(r.entry.path)] = recording_json(r)
                print(summary_lines(str(r.entry.path), r.row, r.entry.kind), file=say)
            else:
                failures.append({"file": str(r.entry.path), "error": r.error})
                print(f"{r.entry.path}: FAILED: {r.error}", file=sys.stderr)
    last = None
    with process_pool(args.workers or None) as ex:
        for i in sorted(big):
            e = entries[i]
            try:
                opts = topts if e.kind == "tangential" else normal_options(e, nopts)
                doc = _auto_streamed(args, e, columns, opts, ex)
            except ContactLabError as exc:
                if not args.keep_going:
                    raise
                failures.append({"file": str(e.path), "error": str(exc)})
                print(f"{e.path}: FAILED: {exc}", file=sys.stderr)
                continue
            last = doc.pop("_track")
            by_path[str(e.path)] = doc
            print(
                summary_lines(
                    str(e.path),
                    doc,
                    e.kind,
                    f"(streamed: {doc['n_samples']} samples in {doc['n_windows']} windows)",
                ),
                file=say,
            )
            for w in doc["warnings"]:
                print(wrap_warning(str(w)), file=sys.stderr)
    recs = [by_path[str(e.path)] for e in entries if str(e.path) in by_path]
    refuse_if_none_analysed(len(recs), failures)
    doc_all: dict = (
        {**recs[0], "contactlab_version": __version__}
        if len(recs) == 1 and not failures
        else {"contactlab_version": __version__, "recordings": recs, "failures": failures}
    )
    text = json_text(doc_all) if args.json else None
    if args.report and last is not None:
        import matplotlib

        matplotlib.use("Agg")
        from ..report import commit_outputs
        from ..report.track_report import build_track_report, track_files

        cmd = made_by(args, "analyze", *args.files, "--model", args.model, "--report", args.report)
        rep = build_track_report(
            last, f"contactlab analyze (streamed): {last.source}", intro=f"Made by: {cmd}"
        )
        for p in commit_outputs(args.report, track_files(last, rep)):
            if p.suffix == ".html":
                print(f"wrote {p}", file=say)
    if args.json:
        p = write_json(args.json, text)
        if str(p) != "-":
            print(f"wrote {p}", file=say)
    return 1 if failures else 0


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "analyze",
        help="analyse recordings (tangential Masing fit or normal-contact loop)",
        description=describe(__doc__),
    )
    p.add_argument("files", nargs="+", metavar="FILE", help="recordings (.csv .tdms .h5 .mat)")
    add_reader_flags(p)
    p.add_argument("--json", metavar="OUT", help="write results as JSON (SI; '-' = stdout)")
    p.add_argument("--report", metavar="DIR", help="write report.html, figures and tables here")
    p.add_argument(
        "--force-sign",
        type=force_sign,
        choices=FORCE_SIGN_CHOICES,
        default="auto",
        help="tangential: analyse F (+1) or -F (-1); auto (default): the sign that makes the "
        "loop area ∮F dx positive (a passive joint dissipates)",
    )
    p.add_argument("--delay", type=quantity("s"), default=None, help=DELAY_HELP)
    add_pressure_flags(p)
    add_frame_flags(p)
    p.add_argument(
        "--keep-going",
        action="store_true",
        help="skip recordings that fail (exit code 1) instead of stopping",
    )
    p.add_argument("-v", "--verbose", action="store_true", help="print each fit report")
    p.add_argument(
        "--stream",
        action="store_true",
        help="long files: read in chunks, analyse windows (--every) and pool them; "
        "memory stays bounded whatever the length",
    )
    p.add_argument(
        "--whole",
        action="store_true",
        help="recordings longer than 2^19 samples (tangential or normal) are streamed and "
        "pooled automatically (memory bounded, JSON says 'streamed'); --whole reads them into "
        "memory",
    )
    p.add_argument(
        "--every", default="auto", help="window of --stream: 'auto' (default), '200cycles' or '10s'"
    )
    p.add_argument(
        "--workers",
        type=int,
        default=None,
        metavar="N",
        help="analyse the recordings (four or more files: one process per core by "
        "default) or the windows of --stream in N processes (0: in this "
        "process)",
    )
    add_progress_flags(p)
    p.set_defaults(handler=_handler)
