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
    p.add_argument("--fs", type=float, help="with --structure: sampling rate without a t column")
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
    from ..commands._common import add_pressure_flags

    add_pressure_flags(p)
    p.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    from ..diagnose import diagnose
    from ..errors import InputError
    from ..io import read_recording

    if args.structure:
        from .structure import diagnose_structure_cli

        return diagnose_structure_cli(args)
    if args.model is None:
        raise InputError("diagnose needs --model tangential|normal or --structure MODEL.json")
    rec = read_recording(args.file, kind=args.model)
    if args.model == "normal":
        from ..commands._common import with_static_pressure

        rec = with_static_pressure(rec, args.file, getattr(args, "p0", None),
                                   getattr(args, "pa", None))  # fmt: skip
    try:
        report = diagnose(rec, model=args.model, max_effects=args.max_effects)
    except InputError as exc:  # name the file: the workflow only sees arrays
        raise InputError(f"{args.file}: {exc}") from exc
    print(report.summary())
    if args.json:
        write_text(args.json, report.to_json() + "\n")
    if args.report:
        import matplotlib

        matplotlib.use("Agg")
        path = report.write_html(args.report)
        print(f"report: {path}")
    return 0
