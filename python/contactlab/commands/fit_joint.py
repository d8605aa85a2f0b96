"""``contactlab fit-joint --fit FILE [FILE ...] [--predict FILE [FILE ...]] --law NAME[,NAME...]``.

Fits joint laws (contactlab.joints: Jenkins, Iwan, Segalman, Maxwell-slip, Dahl, LuGre,
Bouc-Wen, Masing, a law behind a clearance such as backlash:jenkins) to the force against
displacement of the --fit recordings, all at once with shared parameters, and scores each
law's prediction of the --predict recordings, which it never saw (SNR, NRMSE, RRSE, TRAC,
energy per cycle). Prints the parameters with their standard errors and the score table;
--json writes them (SI, with units), --report an HTML report with the loops and time traces.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from ..errors import InputError
from .common import (
    FORCE_SIGN_CHOICES,
    add_reader_flags,
    check_output_targets,
    describe,
    force_sign,
    json_text,
    made_by,
    parse_columns,
    write_json,
)


def _signed(rec: Any, sign: str, say: Any) -> Any:
    """The record with its force sign as asked: ``auto`` makes the loops' work ∮F dx
    positive (a passive joint dissipates; some instruments record the reaction)."""
    import numpy as np

    from ..joints.records import JointRecord

    if sign == "+1":
        return rec
    flip = sign == "-1"
    if sign == "auto":
        work = float(np.sum(0.5 * (rec.F[1:] + rec.F[:-1]) * np.diff(rec.x)))
        flip = work < 0
        if flip:
            print(
                f"{rec.name}: force sign -1 (the loops' work ∮F dx is negative with the "
                "recorded sign; --force-sign +1 keeps it)",
                file=say,
            )
    if not flip:
        return rec
    return JointRecord(rec.t, rec.x, -rec.F, rec.name, rec.mask)


def _read(
    files: list[str], columns: dict | None, fs: float | None, role: str, resample: bool = False
) -> list[Any]:
    from ..io import read_recording
    from ..joints.records import as_record, npy_single_quantity, read_npy_pair

    out, seen = [], set()
    for f in files:
        p = Path(f)
        if p.is_dir():
            raise InputError(f"--{role} {f}: is a folder, not a recording file")
        if not p.is_file():
            raise InputError(f"--{role} {f}: no such file")
        if columns is None and npy_single_quantity(p):
            # one quantity per file (<stem>_x.npy, <stem>_F.npy): the pair is one recording
            try:
                rec = read_npy_pair(p, fs)
            except InputError as exc:
                raise InputError(f"--{role} {exc}") from None
            if rec.name not in seen:
                seen.add(rec.name)
                out.append(rec)
            continue
        rec = read_recording(p, columns=columns, kind="tangential", fs=fs, resample=resample)
        out.append(as_record(rec, name=p.name))
    return out


def _laws(text: str) -> list[str]:
    from ..joints.laws import LAWS

    names = [w.strip().lower() for w in text.split(",") if w.strip()]
    if not names:
        raise InputError("--law: give at least one law name")
    for n in names:
        for part in n.split(":"):
            if part not in LAWS:
                raise InputError(
                    f"--law {n}: unknown law {part!r}; known: {', '.join(sorted(LAWS))}"
                )
    if len(set(names)) != len(names):
        raise InputError(f"--law {text}: a law is named twice")
    return names


def _param_line(f: Any) -> str:
    parts = []
    for n, p in f.params.items():
        unit = f" {p.unit}" if p.unit else ""
        if not p.vary:
            parts.append(f"{n} = {p.value:.5g}{unit} (fixed)")
        elif p.stderr is None:
            why = p.note or "not identifiable"
            parts.append(f"{n} = {p.value:.5g}{unit} ({why})")
        else:
            parts.append(f"{n} = {p.value:.5g} ± {p.stderr:.2g}{unit}")
    return "; ".join(parts)


def _handler(args: argparse.Namespace) -> int:
    from .. import __version__
    from ..joints.compare import compare
    from ..joints.fit import fit

    columns = parse_columns(args.columns)
    laws = _laws(args.law)
    check_output_targets(
        json_out=args.json, report=args.report, inputs=[*args.fit, *(args.predict or [])]
    )
    if args.elements < 1:
        raise InputError(f"--elements must be >= 1, got {args.elements}")
    if args.max_samples is not None and args.max_samples < 100:
        raise InputError(f"--max-samples must be >= 100, got {args.max_samples}")
    names = [Path(f).resolve() for f in [*args.fit, *(args.predict or [])]]
    if len(set(names)) != len(names):
        raise InputError(
            "a file is given twice (in --fit and --predict, or twice in one): "
            "a held-out score needs a recording the fit did not see"
        )
    train = _read(args.fit, columns, args.fs, "fit", args.resample)
    held = _read(args.predict or [], columns, args.fs, "predict", args.resample)
    say = sys.stderr if args.json == "-" else sys.stdout
    train = [_signed(r, args.force_sign, say) for r in train]
    held = [_signed(r, args.force_sign, say) for r in held]
    fits = []
    for law in laws:
        f = fit(
            train,
            law=law,
            offset=args.offset,
            stiffness=args.stiffness,
            damping=args.damping,
            mass=args.mass,
            asymmetry=args.asymmetry,
            max_samples=args.max_samples,
            n_elements=args.elements,
        )
        fits.append(f)
        state = "converged" if f.success else f"NOT converged ({f.message})"
        print(f"{f.name}: {state} in {f.seconds:.2f} s: {_param_line(f)}", file=say)
        for n in f.result.notes:
            print(f"  note: {n}", file=sys.stderr)
    records = train + held
    table = compare({f.name: f for f in fits}, records)
    roles = {r.name: "fitted" for r in train} | {r.name: "held out" for r in held}
    if held:
        held_table = compare({f.name: f for f in fits}, held)
        for f in fits:
            row = held_table.pooled(f.name)
            if row.get("snr_db") is not None:
                print(
                    f"{f.name}: held out (pooled): SNR {row['snr_db']:.2f} dB, NRMSE "
                    f"{row['nrmse']:.4f}, RRSE {row['rrse']:.4f}, TRAC {row['trac']:.4f}",
                    file=say,
                )
    else:
        held_table = None
    print(table.to_text(), file=say)
    doc = {
        "contactlab_version": __version__,
        "fits": [f.to_dict() for f in fits],
        "scores": table.to_dict(),
        "held_out": held_table.to_dict() if held_table is not None else None,
        "roles": roles,
    }
    text = json_text(doc) if args.json else None
    if args.report:
        import matplotlib

        matplotlib.use("Agg")
        from ..report import commit_outputs
        from ..report.joints_report import build_joint_report

        cmd = made_by(
            args,
            "fit-joint",
            "--law",
            args.law,
            "--fit",
            *args.fit,
            *(["--predict", *args.predict] if args.predict else []),
            "--report",
            args.report,
        )
        rep = build_joint_report(
            fits,
            table,
            records,
            roles,
            f"contactlab fit-joint ({', '.join(laws)})",
            intro=f"Made by: {cmd}",
        )
        files = rep.files()
        files["scores.json"] = json_text(table.to_dict()).encode("utf-8")
        for p in commit_outputs(args.report, files):
            if p.suffix == ".html":
                print(f"wrote {p}", file=say)
    if args.json:
        p = write_json(args.json, text)
        if str(p) != "-":
            print(f"wrote {p}", file=say)
    return 0 if all(f.success for f in fits) else 1


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "fit-joint",
        help="fit joint laws to force-displacement recordings and score held-out ones",
        description=describe(__doc__),
    )
    p.add_argument(
        "--fit",
        nargs="+",
        required=True,
        metavar="FILE",
        help="recordings (x, F; .csv .tdms .h5 .mat .npy) the laws are fitted to, together; "
        "a test stored as <stem>_x.npy and <stem>_F.npy with no time column is one "
        "recording (either file names it; give --fs)",
    )
    p.add_argument(
        "--predict",
        nargs="+",
        metavar="FILE",
        help="held-out recordings each fitted law predicts and is scored on",
    )
    p.add_argument(
        "--law",
        default="lugre",
        help="law(s) to fit, comma-separated: jenkins, iwan, segalman, "
        "maxwell_slip, gms, dahl, lugre, bouc_wen, masing, kelvin_voigt, or "
        "backlash:<law> (default: lugre)",
    )
    p.add_argument("--json", metavar="OUT", help="write results as JSON (SI; '-' = stdout)")
    p.add_argument("--report", metavar="DIR", help="write report.html and figures here")
    add_reader_flags(p, model=False)
    p.add_argument(
        "--force-sign",
        type=force_sign,
        choices=FORCE_SIGN_CHOICES,
        default="auto",
        help="fit F (+1) or -F (-1); auto (default): per recording, the sign that "
        "makes the loops' work ∮F dx positive (a passive joint dissipates)",
    )
    p.add_argument(
        "--offset",
        action="store_true",
        help="fit a constant force in parallel (asymmetric friction, a load-cell zero)",
    )
    p.add_argument("--stiffness", action="store_true", help="fit a parallel linear stiffness")
    p.add_argument("--damping", action="store_true", help="fit a parallel viscous term")
    p.add_argument("--mass", action="store_true", help="fit an inertia term m·ẍ in parallel")
    p.add_argument(
        "--asymmetry",
        action="store_true",
        help="fit a direction-dependent gain a·|F_law| (friction that differs "
        "between the two directions, e.g. a self-energising band brake)",
    )
    p.add_argument(
        "--elements",
        type=int,
        default=4,
        metavar="N",
        help="elements of maxwell_slip / gms (default 4)",
    )
    p.add_argument(
        "--max-samples",
        type=int,
        default=None,
        metavar="N",
        help="drive the laws with about N samples during the fit (every n-th plus "
        "every turning point); scores use every sample",
    )
    p.set_defaults(handler=_handler)
