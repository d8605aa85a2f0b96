"""``contactlab study MANIFEST|FOLDER --report DIR``: a load/amplitude (or p0) study.

Analyses every recording a manifest lists (or every recording in a folder, tagged by file
name; see :mod:`contactlab.studies.manifest`) and writes one table (``study_tangential.csv`` /
``.parquet``, ``study_normal.*``; SI, uncertainties as ``*_stderr``), the paper's plots
against load and amplitude per material (and against p0), and the HTML report.
"""

from __future__ import annotations

import argparse
import sys

from .common import (
    add_progress_flags,
    add_workers_flag,
    check_output_targets,
    describe,
    json_document,
    json_text,
    made_by,
    process_pool,
    refuse_if_none_analysed,
    resolve_workers,
    write_json,
    write_report,
)


def _handler(args: argparse.Namespace) -> int:
    from ..studies.study import run_study

    check_output_targets(json_out=args.json, report=args.report, inputs=[args.manifest])
    with process_pool(resolve_workers(args.workers), auto=args.workers is None) as ex:
        result = run_study(
            args.manifest,
            progress=args.progress,
            keep_going=args.keep_going,
            executor=ex,
            keep_recordings=True,  # the report draws them
        )
        for r in result.failures:
            print(f"FAILED: {r.error}", file=sys.stderr)
        n_ok = sum(r.ok for r in result.results)
        refuse_if_none_analysed(n_ok, [str(r.error) for r in result.failures])
        print(f"analysed {n_ok} of {len(result.results)} recordings", flush=True)
        warned = [r.entry.name for r in result.results if r.ok and r.row.get("warnings")]
        if warned:
            print(
                f"{len(warned)} with warnings (listed in the report): {', '.join(warned)}",
                file=sys.stderr,
            )
        doc = json_text(json_document(result)) if args.json else None
        cmd = made_by(args, "study", args.manifest, "--report", args.report)
        paths = write_report(
            args.report,
            result,
            args.title,
            study_plots=True,
            progress=args.progress,
            command=cmd,
            executor=ex,
        )
    for p in paths:
        if p.suffix in (".html", ".csv", ".parquet"):
            print(f"wrote {p}")
    if args.json:
        write_json(args.json, doc)
    return 1 if result.failures else 0


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "study",
        help="analyse a set of tagged recordings: table, study plots and report",
        description=describe(__doc__),
    )
    p.add_argument("manifest", metavar="MANIFEST", help="manifest CSV, or a folder of recordings")
    p.add_argument("--report", metavar="DIR", required=True, help="output folder")
    p.add_argument("--json", metavar="OUT", help="also write every result as JSON (SI)")
    p.add_argument("--title", default="contactlab study", help="report title")
    p.add_argument(
        "--keep-going",
        action="store_true",
        help="skip recordings that fail (exit code 1) instead of stopping",
    )
    add_workers_flag(p, "recordings", per_core=True)
    add_progress_flags(p)
    p.set_defaults(handler=_handler)
