"""``contactlab diagnose FILE --model tangential|normal [--json OUT] [--report DIR]``, or
``contactlab diagnose FILE --structure MODEL.json [--json OUT]`` for an identified structure.

Reads the recording (any format :func:`contactlab.io.read_recording` knows), runs
:func:`contactlab.diagnose`, prints the findings and the gap-shrink table, and optionally
writes the JSON result and a self-contained HTML report. Outputs are written atomically.
"""

from __future__ import annotations

import argparse
from typing import Any

from .._io_atomic import write_text


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
    p.add_argument(
        "--model",
        choices=["tangential", "normal"],
        help="tangential: x, F (Masing base); normal: p, delta (Kelvin-Voigt base)",
    )
    p.add_argument(
        "--structure",
        metavar="MODEL.json",
        help="diagnose a structure: this identified model (contactlab identify --json) is "
        "the base; FILE is a CSV with the input and response columns",
    )
    p.add_argument("--u", help="with --structure: input column (force, or base displacement)")
    p.add_argument("--y", help="with --structure: response column (displacement of the mass)")
    p.add_argument("--fs", type=float, help="sampling rate when a file has no time column")
    p.add_argument(
        "--holdout",
        type=float,
        default=0.25,
        help="with --structure: fraction of the record (at its end) no fit sees",
    )
    p.add_argument("--json", metavar="OUT", help="write the result as JSON to OUT")
    p.add_argument(
        "--report", metavar="DIR", help="write DIR/diagnose.html (+ figures/, diagnose.json)"
    )
    p.add_argument("--max-effects", type=int, default=3, help="stop after this many additions")
    from ..commands._common import add_frame_flags, add_pressure_flags, positive_number

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
    p.add_argument("--columns", help="column mapping, e.g. 'x=disp,F=force' (default: by name)")
    p.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    from ..diagnose import diagnose
    from ..errors import InputError
    from ..io import read_recording

    if args.structure:
        from .structure import diagnose_structure_cli

        return diagnose_structure_cli(args)
    from ..commands._common import frame_option, output_filter_taps, parse_columns

    frame = frame_option(args)
    if args.model is None and frame is not None:
        args.model = "tangential"
    if args.model is None:
        raise InputError("diagnose needs --model tangential|normal or --structure MODEL.json")
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
        rec = read_recording(args.file, kind=args.model, columns=parse_columns(args.columns),
                             fs=args.fs)  # fmt: skip
    if args.model == "normal":
        from ..commands._common import with_static_pressure

        rec = with_static_pressure(rec, args.file, getattr(args, "p0", None),
                                   getattr(args, "pa", None))  # fmt: skip
    try:
        report = diagnose(rec, model=args.model, max_effects=args.max_effects,
                          output_filter=taps, output_noise=args.output_noise)  # fmt: skip
    except InputError as exc:  # name the file: the workflow only sees arrays
        raise InputError(f"{args.file}: {exc}") from exc
    print(report.summary())
    if args.json:
        import json

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
        write_text(args.json, json.dumps(doc, indent=2, allow_nan=False) + "\n")
    if args.report:
        import matplotlib

        matplotlib.use("Agg")
        path = report.write_html(args.report)
        print(f"report: {path}")
    return 0
