"""``contactlab track FILE --every 100cycles [--json OUT] [--report DIR]``: a long recording
window by window.

Reads the recording in chunks (memory bounded by one chunk and one window, whatever its
length), analyses every window of N cycles or T seconds as ``analyze`` does (tangential: h0,
ac or h0·ac, energy analytic and numeric, c_e·ω, k_local, k_global, amplitude, offset, with
standard errors; normal: E_d, ψ, k_tan, k_sec, polynomials) and the loop energy of every
cycle; writes them as JSON and as a report with each quantity plotted against time or cycle
count.
"""

from __future__ import annotations

import argparse
import math
import sys
from typing import Any

from ..errors import InputError
from .common import (
    add_frame_flags,
    add_pressure_flags,
    add_progress_flags,
    add_reader_flags,
    add_workers_flag,
    check_output_targets,
    describe,
    frame_option,
    infer_model,
    made_by,
    normal_options,
    parse_columns,
    process_pool,
    quantity,
    window_threads,
    wrap_warning,
    wrapped,
    write_json,
)

_SHOW = {
    "tangential": [
        ("h0", "N", 1.0),
        ("ac", "1/m", 1.0),
        ("h0_ac", "N/m", 1.0),
        ("energy_per_cycle", "J", 1.0),
        ("amplitude", "um", 1e6),
    ],
    "normal": [("E_d", "J/m^2", 1.0), ("psi", "", 1.0), ("k_tan", "Pa/m", 1.0)],
}


def _handler(args: argparse.Namespace) -> int:
    from ..studies.tracking import parse_every, track, track_json

    check_output_targets(json_out=args.json, report=args.report, inputs=[args.file])
    parse_every(args.every)  # a bad --every fails before the file is opened
    say = sys.stderr if args.json == "-" else sys.stdout
    frame = frame_option(args)  # before the file is read: it has no force column
    note = None
    if frame is None:
        args.model, note = infer_model(args.file, args.model, parse_columns(args.columns), args.fs)
    options = _options(args)
    if args.delay is not None:
        if options is not None:  # a normal recording's options
            raise InputError(f"{args.file}: --delay is for tangential recordings")
        options = {"delay": args.delay}
    threads = None
    if args.workers is None:
        threads = window_threads() if args.threads is None else args.threads
        if threads < 0:
            raise InputError(f"--threads must be >= 0, got {threads}")
    elif args.threads is not None:
        raise InputError("--threads is for helper threads; --workers runs processes instead")
    source, rebuilt = args.file, None
    if frame is not None:
        # the force is reconstructed from the whole record (derivatives, smoothing): the
        # frame's displacements are read whole, then tracked window by window
        from ..tangential import read_frame
        from ..tangential.frame import describe_reconstruction

        fr = read_frame(
            args.file, frame["M"], frame["C"], frame["K"], x=frame["x"], y=frame["y"], fs=args.fs
        )
        source = fr.recording(args.file)
        rebuilt = fr.to_dict()
        print(f"{args.file}: friction frame: {describe_reconstruction(rebuilt)}", file=say)
    print(
        wrapped(f"tracking {args.file} every {args.every}" + (f"; {note}" if note else "")),
        file=say,
        flush=True,
    )
    bar = None
    if args.progress or (args.progress is None and sys.stderr.isatty()):
        from tqdm.auto import tqdm

        bar = tqdm(desc="windows", unit="win", file=sys.stderr)
    try:
        with process_pool(args.workers) as ex:
            res = track(
                source,
                args.every,
                kind="tangential" if frame is not None else args.model,
                columns=parse_columns(args.columns),
                fs=None if frame is not None else args.fs,
                chunk_size=args.chunk_size,
                executor=ex,
                threads=threads,
                options=options,
                callback=(lambda _row: bar.update(1)) if bar is not None else None,
                resample=args.resample,
            )
    finally:
        if bar is not None:
            bar.close()
    from .._malloc import release_freed_memory

    release_freed_memory()  # the windows' arrays, before the JSON and the figures are made
    if rebuilt is not None:
        res.meta["frame_reconstruction"] = rebuilt
    comb = res.combined()
    if not any(k.endswith("_stderr") for k in comb):
        failed = [r for r in res.rows if r.get("error")]
        why = f" ({failed[0]['error']})" if failed else ""
        raise InputError(
            f"{res.source}: none of the {len(res.rows)} windows could be analysed{why}; "
            "nothing written"
        )
    _print_summary(res, comb, say)
    doc = track_json(res) if args.json else None  # rendered before anything is written
    if args.report:
        _write_report(args, res, frame, say)
    if args.json:
        p = write_json(args.json, doc)
        if str(p) != "-":
            print(f"wrote {p}", file=say)
    return 0


def _print_summary(res: Any, comb: dict, say: Any) -> None:
    """The tracked record's windows, cycles and samples, each combined quantity with its
    error and how it was combined, the resampling and the notes."""
    print(
        f"{res.source}: {len(res.rows)} window{'s' if len(res.rows) != 1 else ''}, "
        f"{comb.get('n_cycles', 0)} cycles, {res.meta['n_samples']} samples",
        file=say,
    )
    for key, unit, f in _SHOW[res.kind]:
        if key in comb:
            birge = comb.get(f"{key}_birge")
            how = f"pooled; Birge ratio {birge:.2g}" if birge is not None else "mean of the windows"
            err = comb.get(f"{key}_stderr")
            pm = f" ± {err * f:.2g}" if err is not None and math.isfinite(err) else ""
            if not pm:
                how += "; one window: no error from their scatter"
            print(
                f"  {key} = {comb[key] * f:.5g}{pm}{' ' + unit if unit else ''} ({how})", file=say
            )
    if res.meta.get("resampled"):
        from ..io.recording import describe_resampling

        print(wrapped(f"  {describe_resampling(res.meta['resampled'])}"), file=say)
    for note in res.notes(comb):
        print(wrap_warning(str(note)), file=sys.stderr)


def _write_report(args: argparse.Namespace, res: Any, frame: Any, say: Any) -> None:
    """The HTML report of a tracked record, written all or nothing into ``--report``."""
    import matplotlib

    matplotlib.use("Agg")
    from ..report import commit_outputs
    from ..report.track_report import build_track_report, track_files

    cmd = made_by(
        args,
        "track",
        args.file,
        "--every",
        args.every,
        "--report",
        args.report,
        *(["--frame", args.frame] if frame else []),
        *(["--frame-x", args.frame_x] if args.frame_x else []),
        *(["--frame-y", args.frame_y] if args.frame_y else []),
    )
    rep = build_track_report(
        res, f"contactlab track: {args.file}", against=args.against, intro=f"Made by: {cmd}"
    )
    for p in commit_outputs(args.report, track_files(res, rep)):
        if p.suffix == ".html":
            print(f"wrote {p}", file=say)


def _options(args: argparse.Namespace) -> dict | None:
    """The per-window analysis options of a normal recording: ``--p0``/``--pa``, else the
    file-name tags (``p0-0.5MPa``), and ω from a ``frequency`` tag, as ``analyze`` uses them;
    ``None`` for a tangential recording (where ``--p0``/``--pa`` are refused)."""
    from ..io import read_chunks
    from ..studies.manifest import entry_from_file

    if getattr(args, "frame", None) is not None:  # a frame gives a tangential recording
        if args.p0 is not None or args.pa is not None:
            raise InputError(f"{args.file}: --p0/--pa are for normal-contact recordings")
        return None
    kind = (
        args.model or read_chunks(args.file, columns=parse_columns(args.columns), fs=args.fs).kind
    )
    if kind != "normal":
        if args.p0 is not None or args.pa is not None:
            raise InputError(f"{args.file}: --p0/--pa are for normal-contact recordings")
        return None
    entry = entry_from_file(args.file, kind="normal")
    return normal_options(entry, {"p0": args.p0, "pa": args.pa})


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "track",
        help="fitted quantities window by window along a long recording (bounded memory)",
        description=describe(__doc__),
    )
    p.add_argument("file", metavar="FILE", help="recording (.csv .tdms .h5 .mat)")
    p.add_argument(
        "--every",
        default="100cycles",
        help="window length: '100cycles' or a time, '10s' (default 100cycles)",
    )
    add_reader_flags(p)
    p.add_argument(
        "--json",
        metavar="OUT",
        help="write windows, pooled result and per-cycle energies as JSON (SI; '-' = stdout)",
    )
    p.add_argument("--report", metavar="DIR", help="write report.html, figures and tables here")
    p.add_argument(
        "--against", choices=("time", "cycle"), default="time", help="x axis of the plots"
    )
    p.add_argument(
        "--chunk-size",
        type=int,
        default=1 << 18,
        metavar="N",
        help="samples read at a time (default 262144, as contactlab.track)",
    )
    p.add_argument(
        "--delay",
        type=quantity("s"),
        default=None,
        help="tangential: a known delay of the force behind the displacement (e.g. 1.1ms), "
        "corrected in every window before its analysis (as analyze --delay)",
    )
    add_frame_flags(p)
    add_pressure_flags(p)
    add_workers_flag(p, "windows")
    p.add_argument(
        "--threads",
        type=int,
        default=None,
        metavar="N",
        help="without --workers: analyse windows on N helper threads while reading on "
        "(default: one per core, at most 2, none while every core is busy, as analyze; 0: "
        "each window before reading on)",
    )
    add_progress_flags(p)
    p.set_defaults(handler=_handler)
