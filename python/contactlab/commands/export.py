"""``contactlab export RESULT.json --format calculix|abaqus|ansys|csv|json -o FILE``.

Turns what ``contactlab analyze --json`` wrote into joint characteristics for a finite-element
model (:mod:`contactlab.fem`): from a normal analysis a pressure–overclosure table with contact
stiffness and damping per unit area; from a tangential one the friction coefficient and stick
slope, and with --amplitude/--frequency a joint spring and dashpot. Values whose parameters
the fit did not identify are refused (exit code 3, nothing written). --check first runs the
CalculiX checks of contactlab.fem.checks on the values and prints their reports.
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

from ..errors import InputError
from .common import command_line, describe
from .simulate import finite_quantity

#: exit code when a requested value is not identifiable (bad input in general exits 1)
EXIT_NOT_IDENTIFIABLE = 3

_AREA = re.compile(
    r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(m2|m\^2|cm2|cm\^2|mm2|mm\^2)?\s*$"
)
_AREA_F = {None: 1.0, "m2": 1.0, "m^2": 1.0, "cm2": 1e-4, "cm^2": 1e-4, "mm2": 1e-6, "mm^2": 1e-6}


def area(text: str) -> float:
    """argparse ``type=``: an area with an optional unit (``50cm2``, ``5e-3m2``, ``100mm2``)."""
    m = _AREA.match(text)
    if not m:
        raise argparse.ArgumentTypeError(f"{text!r} is not an area (e.g. 50cm2, 5e-3m2, 100mm2)")
    v = float(m.group(1)) * _AREA_F[m.group(2)]
    if not (v > 0 and v < float("inf")):
        raise argparse.ArgumentTypeError(f"{text!r}: must be a finite area > 0")
    return v


def points(text: str) -> int:
    """argparse ``type=``: rows of the pressure–overclosure table, an integer in 3..10000."""
    from ..fem.characteristics import MAX_POINTS, MIN_POINTS

    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r} is not an integer (give {MIN_POINTS}..{MAX_POINTS})"
        ) from None
    if not MIN_POINTS <= n <= MAX_POINTS:
        raise argparse.ArgumentTypeError(f"{text!r}: must be in {MIN_POINTS}..{MAX_POINTS}")
    return n


def _handler(args: argparse.Namespace) -> int:
    from .._io_atomic import write_text
    from ..fem import NotIdentifiableError, joint_characteristics, load_result, unit_system
    from ..fem.writers import render

    units = unit_system(args.units)
    out = Path(args.output)
    if out.is_dir():
        raise InputError(f"-o {args.output}: is a folder; give a file name")
    doc = load_result(args.result, args.recording)
    try:
        jc = joint_characteristics(
            doc,
            where=str(args.result),
            area=args.area,
            normal_load=args.normal_load,
            amplitude=args.amplitude,
            frequency=args.frequency,
            points=args.points,
        )
    except NotIdentifiableError as exc:
        print(f"contactlab export: refused: {exc}; nothing written", file=sys.stderr)
        return EXIT_NOT_IDENTIFIABLE
    cmd = command_line(
        "export", args.result, "--format", args.format, "--units", args.units, "-o", args.output
    )
    try:
        text = render(jc, args.format, units, command=cmd)  # refuses what a format cannot hold
    except NotIdentifiableError as exc:
        print(f"contactlab export: refused: {exc}; nothing written", file=sys.stderr)
        return EXIT_NOT_IDENTIFIABLE
    if args.check:
        _check(doc, jc.kind, args)
    path = write_text(out, text)
    print(f"wrote {path} ({jc.kind} joint, {args.format}, {units.name})")
    for n in jc.notes:
        print(f"  note: {n}", file=sys.stderr)
    return 0


def _check(doc: dict, kind: str, args: argparse.Namespace) -> None:
    """Run the CalculiX checks on what is about to be exported; print their reports."""
    from ..fem.checks import check_dynamics, check_normal, check_tangential

    if kind == "normal":
        print(check_normal(doc, points=args.points).report())
        return
    load = args.normal_load if args.normal_load is not None else doc.get("normal_load")
    area_ = args.area if args.area is not None else doc.get("contact_area", doc.get("area"))
    print(check_tangential(doc, area=area_, normal_load=load).report())
    if args.amplitude is not None and args.frequency is not None:
        print(
            check_dynamics(
                doc,
                area=area_,
                normal_load=load,
                amplitude=args.amplitude,
                frequency=args.frequency,
            ).report()
        )


def add_parser(sub: argparse._SubParsersAction) -> None:
    from ..fem.units import FORMATS, SYSTEMS

    p = sub.add_parser(
        "export",
        help="joint characteristics for FE models (CalculiX/Abaqus/ANSYS/CSV) from analyze --json",
        description=describe(__doc__),
    )
    p.add_argument("result", metavar="RESULT.json", help="what `contactlab analyze --json` wrote")
    p.add_argument("--format", required=True, choices=FORMATS)
    p.add_argument("-o", "--output", required=True, metavar="FILE", help="output file")
    p.add_argument(
        "--units",
        default="SI",
        choices=tuple(SYSTEMS),
        help="unit system of the exported numbers (default SI)",
    )
    p.add_argument("--recording", help="which recording of a multi-recording JSON (index/name)")
    p.add_argument("--area", type=area, help="nominal contact area (tangential; e.g. 50cm2)")
    p.add_argument(
        "--normal-load",
        type=finite_quantity("N", positive=True),
        help="normal load W (tangential; default from the tags, e.g. W50N)",
    )
    p.add_argument(
        "--amplitude",
        type=finite_quantity("m", positive=True),
        help="amplitude of the joint spring/dashpot (tangential; 20um)",
    )
    p.add_argument(
        "--frequency",
        type=finite_quantity("Hz", positive=True),
        help="frequency of the viscous values (normal: default the test's)",
    )
    p.add_argument(
        "--points",
        type=points,
        default=25,
        help="rows of the pressure–overclosure table over the measured range, "
        "3..10000 (default 25; solvers interpolate linearly between rows)",
    )
    p.add_argument(
        "--check",
        action="store_true",
        help="first run the CalculiX checks on these values (needs ccx)",
    )
    p.set_defaults(handler=_handler)
