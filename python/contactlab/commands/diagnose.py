"""``contactlab diagnose FILE --model tangential|normal [--json OUT] [--report DIR]``, or
``contactlab diagnose FILE --structure MODEL.json [--json OUT]`` for an identified structure.

Reads the recording (any format :func:`contactlab.io.read_recording` knows), runs
:func:`contactlab.diagnose`, prints the findings and the gap-shrink table, and optionally
writes the JSON result and a self-contained HTML report. Outputs are written atomically.
"""

from __future__ import annotations

import argparse
from typing import Any

#: ``--holdout``: the range :func:`contactlab.diagnose.diagnose_structure` accepts, the default
HOLDOUT_RANGE = (0.05, 0.5)
HOLDOUT_DEFAULT = 0.25

#: the flags that only mean something with ``--structure``
_STRUCTURE_ONLY = (("u", "--u"), ("y", "--y"), ("holdout", "--holdout"))


def _holdout(text: str) -> float:
    """argparse ``type=`` of ``--holdout``: a fraction in :data:`HOLDOUT_RANGE`."""
    lo, hi = HOLDOUT_RANGE
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"--holdout {text!r}: not a number") from None
    if not lo <= v <= hi:  # (NaN fails it too)
        raise argparse.ArgumentTypeError(
            f"--holdout {text!r}: must be a fraction of the record in [{lo}, {hi}]"
        )
    return v


_holdout.__name__ = "fraction"


def add_parser(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "diagnose",
        help="find where model and measurement disagree and which effect is missing",
        description=(
            "Fit the base model to the recording, report where the residual lives, name the "
            "missing effect(s) from the candidate library by their error on held-out cycles, "
            "and show the gap shrink. Prints the findings and the gap-shrink table."
        ),
    )
    p.add_argument("file", metavar="FILE", help="recording (CSV, TDMS, HDF5, MAT)")
    from ..commands.common import add_reader_flags

    add_reader_flags(p)
    p.add_argument(
        "--structure",
        metavar="MODEL.json",
        help="diagnose a structure: this identified model (contactlab identify --json) is "
        "the base; FILE is a CSV with the input and response columns",
    )
    p.add_argument(
        "--u", metavar="COLUMN", help="with --structure: input column (force, or base displacement)"
    )
    p.add_argument(
        "--y", metavar="COLUMN", help="with --structure: response column (displacement of the mass)"
    )
    from ..commands.common import quantity

    p.add_argument(
        "--holdout",
        type=_holdout,
        default=None,
        help=f"with --structure: fraction of the record (at its end) no fit sees, in "
        f"[{HOLDOUT_RANGE[0]}, {HOLDOUT_RANGE[1]}] (default {HOLDOUT_DEFAULT})",
    )
    p.add_argument("--json", metavar="OUT", help="write the result as JSON to OUT")
    p.add_argument(
        "--report", metavar="DIR", help="write DIR/diagnose.html (+ figures/, diagnose.json)"
    )
    p.add_argument("--max-effects", type=int, default=3, help="stop after this many additions")
    from ..commands.common import add_frame_flags, add_pressure_flags, positive_number

    add_pressure_flags(p)
    add_frame_flags(p)
    p.add_argument(
        "--output-filter",
        metavar="KIND:WINDOW",
        help="tangential: the force channel went through this known smoothing, which every "
        "candidate's prediction then passes too: savgol:WINDOW[:ORDER] (Savitzky-Golay), "
        "mean:WINDOW (moving average) or frame:WINDOW (a frame reconstruction's); WINDOW an "
        "odd number of samples. With --frame: the reconstruction's own (default)",
    )
    p.add_argument(
        "--output-noise",
        metavar="N",
        type=positive_number("--output-noise"),
        help="the force channel's noise RMS in N when known (a smoothed channel's differences "
        "understate it); with --frame: the reconstruction's (default)",
    )
    p.add_argument(
        "--delay",
        type=quantity("s"),
        default=None,
        help="tangential: a known delay of the force behind the displacement (e.g. 1.1ms), "
        "corrected before the diagnosis (the force read that much later)",
    )
    from ..commands.common import FORCE_SIGN_CHOICES, force_sign

    p.add_argument(
        "--force-sign",
        type=force_sign,
        choices=FORCE_SIGN_CHOICES,
        default=None,
        help="tangential: diagnose F (+1) or -F (-1), as analyze takes it; auto: the sign that "
        "makes the loop area ∮F dx positive (a passive joint dissipates). Default: F as "
        "recorded (a loop that runs the wrong way is refused, naming this flag)",
    )
    p.set_defaults(handler=run)


def _suspect(path: str) -> bool:
    """Whether a file is too large for the memory available (a third of it): only those are
    probed in chunks first (0.1 s and 20 MB of a 1e6-sample diagnosis otherwise). A file
    declaring more samples than it stores is refused by the HDF5 reader itself."""
    from pathlib import Path

    try:
        size = Path(path).stat().st_size
    except OSError:
        return False  # the reader names it
    free = _available_memory()
    return free is not None and size * _COPIES > free


#: samples from which a recording counts as long (``contactlab.studies.pooled.STREAM_ABOVE``,
#: the streamed verbs' threshold; not imported from there: the studies package costs a
#: diagnosis 30 modules)
_LONG = 1 << 19


def _check_long(path: str, columns: dict | None, kind: str, fs: float | None) -> None:
    """Check a long recording's first chunk before it is read whole (as ``analyze`` and
    ``track`` read it in chunks), and refuse one whose arrays cannot fit in memory.

    The whole-file readers read every channel before they check it: an HDF5 file declaring
    a billion samples it never wrote would be read, and allocated, in full before its first
    repeated time stamp is found. Raises :class:`~contactlab.InputError` naming the file.
    """
    from pathlib import Path

    from ..errors import ContactLabError, InputError
    from ..io import read_chunks

    if not _suspect(path):
        return
    # a probe only: whatever it cannot open, the whole-file reader names (a damaged file,
    # a missing column), so nothing it raises is reported from here
    try:
        chunked = read_chunks(path, columns=columns, kind=kind, fs=fs)
        n = chunked.n_samples
    except Exception:
        return
    if n is None or n <= _LONG:
        return
    try:
        # a file smaller than one channel's samples declares more than it holds (unwritten
        # HDF5 chunks, or compression): its first chunk is checked before the whole is read
        # (0.03-0.05 s a file, skipped where the bytes are there)
        sparse = Path(path).stat().st_size < int(n) * 8
    except OSError:
        sparse = True
    chunks = iter(chunked) if sparse else iter(())
    try:
        next(chunks, None)  # the same checks and messages as the chunked verbs
    except ContactLabError:
        raise
    except Exception:
        return
    finally:
        close = getattr(chunks, "close", None)
        if close is not None:
            close()
    need = int(n) * (1 + len(chunked.units)) * 8 * _COPIES
    free = _available_memory()
    if free is not None and need > free:
        raise InputError(
            f"{Path(path)}: {int(n)} samples: too long to diagnose in memory (about "
            f"{need / 2**30:.1f} GiB needed, {free / 2**30:.1f} GiB available); diagnose a part "
            "of it (or use `contactlab analyze`/`track`, which read it in chunks)"
        )


#: arrays of a record's length the reading and the diagnosis hold at once (the channels as
#: read, in SI, and the workflow's own)
_COPIES = 3


def _available_memory() -> int | None:
    """Bytes of memory available to this process (Linux ``MemAvailable``), None if unknown."""
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        return None
    return None


def run(args: argparse.Namespace) -> int:
    import contextlib
    import json

    from .._io_atomic import atomic_path
    from ..commands.common import check_output_targets
    from ..diagnose import diagnose
    from ..errors import ConvergenceError, InputError
    from ..io import read_recording

    if args.structure:
        from .structure import diagnose_structure_cli

        if args.holdout is None:
            args.holdout = HOLDOUT_DEFAULT
        return diagnose_structure_cli(args)
    for dest, flag in _STRUCTURE_ONLY:
        if getattr(args, dest, None) is not None:
            raise InputError(f"{flag} is for a structure: give it with --structure MODEL.json")
    check_output_targets(json_out=args.json, report=args.report, inputs=[args.file])
    from ..commands.common import frame_option, output_filter_taps, parse_columns

    frame = frame_option(args)
    if args.model is None and frame is not None:
        args.model = "tangential"
    columns = parse_columns(args.columns)
    if args.model is None:
        from ..commands.common import infer_model, wrapped

        try:
            args.model, note = infer_model(args.file, None, columns, args.fs)
        except InputError as exc:
            raise InputError(f"{exc} (or --structure MODEL.json: a structure's input and "
                             "response record)") from None  # fmt: skip
        print(wrapped(f"{args.file}: {note}"))
    taps = output_filter_taps(args.output_filter)
    if args.model == "normal" and (taps is not None or args.output_noise is not None):
        raise InputError("--output-filter/--output-noise are for the tangential model (a force "
                         "channel's smoothing)")  # fmt: skip
    rebuilt = None
    if frame is not None:
        from ..tangential import read_frame

        rebuilt = read_frame(args.file, frame["M"], frame["C"], frame["K"], x=frame["x"],
                             y=frame["y"])  # fmt: skip
        rec = rebuilt.recording(args.file)
        print(f"{args.file}: friction frame: {rebuilt.describe()}")
        if taps is not None or args.output_noise is not None:
            print("note: --output-filter/--output-noise replace the reconstruction's own")
    else:
        _check_long(args.file, columns, args.model, args.fs)
        rec = read_recording(args.file, kind=args.model, columns=columns, fs=args.fs,
                             resample=args.resample)  # fmt: skip
        if rec.meta.get("resampled"):
            from ..io.recording import describe_resampling

            print(f"{args.file}: {describe_resampling(rec.meta['resampled'])}")
    delay = getattr(args, "delay", None)
    if delay is not None and args.model != "tangential":
        raise InputError("--delay is for tangential recordings (force against displacement)")
    sign = getattr(args, "force_sign", None)
    if sign is not None and args.model != "tangential":
        raise InputError("--force-sign is for tangential recordings (the force's sign)")
    if args.model == "normal":
        from ..commands.common import with_static_pressure

        rec = with_static_pressure(rec, args.file, getattr(args, "p0", None),
                                   getattr(args, "pa", None))  # fmt: skip
    try:
        opts = _options(args.model, taps, args.output_noise, delay, sign)
        report = diagnose(rec, model=args.model, max_effects=args.max_effects, options=opts)
    except (InputError, ConvergenceError) as exc:  # name the file: the workflow sees arrays
        kind = ConvergenceError if isinstance(exc, ConvergenceError) else InputError
        raise kind(f"{args.file}: {exc}") from exc
    if delay is not None:
        dropped = rec.t.size - report.location["samples"]["recording"]
        print(f"{args.file}: force read {1e3 * delay:.4g} ms later (--delay); {dropped} "
              "samples left without force data dropped")  # fmt: skip
    # every output rendered in memory before any is written (a report that cannot be
    # drawn, or Ctrl-C, leaves the previous outputs as they were)
    text = None
    if args.json:
        doc = report.to_dict()
        meta = rec.meta if isinstance(rec.meta, dict) else {}
        used = taps if taps is not None else meta.get("output_filter")
        noise = args.output_noise if args.output_noise is not None else meta.get("output_noise")
        if used is not None or noise is not None:
            doc["declared_output"] = {
                "filter": args.output_filter or ("frame reconstruction" if rebuilt else None),
                "filter_taps": None if used is None else len(used),
                "noise": None if noise is None else float(noise),
            }
        if rebuilt is not None:
            doc["frame_reconstruction"] = rebuilt.to_dict()
        try:
            text = json.dumps(doc, indent=2, allow_nan=False) + "\n"
        except ValueError as exc:  # a NaN or infinity left in the result
            raise InputError(f"{args.file}: the result cannot be written as JSON ({exc})") from None
    files = None
    if args.report:
        import matplotlib

        matplotlib.use("Agg")
        from ..commands.common import made_by
        from ..report.diagnosis import report_files

        files = report_files(report, intro=f"Made by: {made_by(args, 'diagnose', args.file)}")
    print(report.summary())
    # the JSON is staged beside its target and renamed into place only once the report is
    # committed: a report that cannot be written leaves the JSON as it was
    with contextlib.ExitStack() as stack:
        if text is not None:
            tmp = stack.enter_context(atomic_path(args.json))
            tmp.write_text(text, encoding="utf-8")
        if files is not None:
            from ..report import commit_outputs

            paths = commit_outputs(args.report, files)
            print(f"report: {paths[0]}")
    return 0


def _options(model: str | None, taps: Any, noise: float | None, delay: Any, sign: Any) -> Any:
    """The parsed flags as the diagnosis's typed options (issue 32)."""
    if model == "normal":
        return {"output_filter": taps, "output_noise": noise}
    from ..tangential.options import Options

    return Options(delay=delay, force_sign=sign, output_filter=taps, output_noise=noise)
