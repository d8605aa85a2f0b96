"""``contactlab identify FILE``: identify a structure with a joint from input and response;
``contactlab simulate structure OUT --structure MODEL.json --input FILE``: predict.

The record is a CSV whose first line names the columns (a leading ``#`` is allowed); units
come from the column names (``x_mm``, ``u_force_N``, ``y [um]``) or default to SI.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import InputError
from .common import (
    add_progress_flags,
    check_output_targets,
    describe,
    json_text,
    made_by,
    quantity,
    write_json,
)

if TYPE_CHECKING:
    import numpy as np

_UNIT = re.compile(r"(?:\[([^\]]+)\]|_([A-Za-z]+))\s*$")


def read_table(path: str) -> dict[str, np.ndarray]:
    """Columns of a CSV (header line, optional ``#``), converted to SI from unit suffixes."""
    import numpy as np

    from ..io.csv import read_header, sniff_encoding
    from ..studies.manifest import unit_factor

    p = Path(path)
    # the header as `analyze` finds it: `#` comment lines before it are skipped (they may hold
    # commas), a header written as the last comment (`# t,u,y`) names the columns
    try:
        enc = sniff_encoding(p)
        names, delim, header_line, _comments = read_header(p, enc)
    except OSError as exc:
        raise InputError(f"{path}: cannot read ({exc.strerror})") from None
    if len(names) < 2:
        raise InputError(f"{path}: the header line must name the columns (comma-separated)")
    try:
        with warnings.catch_warnings():
            # numpy warns "input contained no data" for a header alone: refused just below
            warnings.simplefilter("ignore", UserWarning)
            data = np.loadtxt(
                p, delimiter=delim, skiprows=header_line + 1, ndmin=2, comments="#", encoding=enc
            )
    except ValueError as exc:
        raise InputError(f"{path}: not a numeric table: {exc}") from None
    if data.size == 0:
        raise InputError(f"{path}: no data rows after the header line")
    if data.shape[1] != len(names):
        raise InputError(f"{path}: {len(names)} column names but {data.shape[1]} columns")
    out = {}
    for i, name in enumerate(names):
        col = data[:, i]
        bad = ~np.isfinite(col)
        if bad.any():
            raise InputError(f"{path}: column {name!r} row {int(np.argmax(bad)) + 2} not finite")
        m = _UNIT.search(name)
        factor = 1.0
        if m:
            unit = m.group(1) or m.group(2)
            try:
                factor = unit_factor(unit, f"{path}: column {name!r}")
            except InputError:
                factor = 1.0  # a word, not a unit (e.g. "_force")
        out[name] = col * factor
    return out


def pick_column(
    cols: dict[str, np.ndarray], want: str | None, guesses: tuple[str, ...], what: str, path: str
) -> str:
    if want:
        if want in cols:
            return want
        # a bare name picks the column it heads: "u" for "u [N]" or "u_N" (the headers
        # contactlab's own writers give)
        bare = [name for name in cols if _UNIT.sub("", name).strip() == want]
        if len(bare) == 1:
            return bare[0]
        raise InputError(f"{path}: no column {want!r} (columns: {', '.join(cols)})")
    for g in guesses:
        for name in cols:
            low = name.lower()
            if low.startswith(g) and not low.startswith(("t_", "time")) and low != "t":
                return name
    raise InputError(f"{path}: cannot tell which column is {what}; name it with --{what}")


def _time(cols: dict[str, np.ndarray], args: argparse.Namespace, n: int, path: str) -> np.ndarray:
    import numpy as np

    for name in cols:
        if name.lower() in ("t", "time") or name.lower().startswith(("t_", "t [", "time")):
            return cols[name]
    if args.fs:
        return np.arange(n) / args.fs
    raise InputError(f"{path}: no time column (t, t_s, time); give the sampling rate --fs")


def _identify(args: argparse.Namespace) -> int:
    import numpy as np

    from ..report import commit_outputs
    from .structure_verbs import identify_record

    check_output_targets(json_out=args.json, report=args.report, inputs=[args.file])
    cols = read_table(args.file)
    exc = args.excitation
    ucol = pick_column(
        cols,
        args.u,
        ("u", "f", "y_base", "base") if exc == "force" else ("y_base", "base", "y"),
        "u",
        args.file,
    )
    ynames = [c.strip() for c in args.y.split(",")] if args.y and "," in args.y else None
    if ynames:
        # several response channels: one displacement per DOF (a multi-DOF structure)
        ycols = [pick_column(cols, c, (), "y", args.file) for c in ynames]
        if ucol in ycols or len(set(ycols)) < len(ycols):
            raise InputError(f"{args.file}: --y names the input or a column twice")
        y = np.stack([cols[c] for c in ycols], axis=1)
        ycol: str | list[str] = ycols
    else:
        ycol = pick_column(
            cols,
            args.y,
            ("y_disp", "y", "x") if exc == "force" else ("x", "y_disp"),
            "y",
            args.file,
        )
        if ucol == ycol:
            raise InputError(f"{args.file}: input and response are the same column {ucol!r}")
        y = cols[ycol]
    u = cols[ucol]
    t = _time(cols, args, u.size, args.file)
    mass = _masses(args.mass)
    if mass is not None and y.ndim == 1:
        if len(mass) != 1:
            raise InputError("--mass: one mass for a single response channel")
        mass = mass[0]
    mdof: dict[str, object] = {}
    if y.ndim == 2:
        mdof = {"joint_dofs": _joint_dofs(args.joint_dofs), "input_dof": args.input_dof}
        if args.masks is not None:
            mdof["masks"] = _masks(args.masks)
    elif args.masks is not None:
        raise InputError("--masks needs several response channels (--y x0,x1,...)")
    cmd = made_by(
        args,
        "identify",
        args.file,
        "--joint",
        args.joint,
        "--excitation",
        exc,
        *(["--fs", args.fs] if args.fs else []),
    )
    bar = _progress_bar(args.progress) if y.ndim == 1 else None
    try:
        model, rep, summary = identify_record(
            t,
            u,
            y,
            joint=args.joint,
            excitation=exc,
            mass=mass,
            holdout=args.holdout,
            substeps=args.substeps,
            periodic=args.periodic,
            title=f"{Path(args.file).name}: {args.joint} joint",
            intro=f"Made by: {cmd}",
            progress=bar.step if bar is not None else None,
            **mdof,
        )
    finally:
        if bar is not None:
            bar.close()
    doc = model.to_dict()
    doc["summary"] = summary
    doc["columns"] = {"u": ucol, "y": ycol}
    # everything rendered first; the report (all or nothing) before the JSON: a report that
    # cannot be written leaves the previous JSON as it was
    text = json_text(doc) if args.json else None
    files = rep.files() if args.report else None
    if files is not None:
        commit_outputs(args.report, files)
    if text is not None:
        write_json(args.json, text)
    if args.json != "-":
        hold, train = summary.get("rms_holdout"), summary["rms_train"]
        print(
            f"{args.joint}: RMS output error "
            + (f"{train:.4g} m (training)" if train is not None else "n/a (training)")
            + (f", {hold:.4g} m (hold-out)" if hold is not None else "")
            + f"; identified in {model.elapsed:.1f} s"
        )
        print(parameter_lines(model.fit))
    return 0


def parameter_lines(fit: Any) -> str:
    """The fitted parameters, one a line: ``  k = 3012 ± 25 N/m``; a fixed one says so, an
    unidentified one is written ``not identifiable: <why>`` (never ``± nan``)."""
    from ..fitting import UNDETERMINED_REL_STDERR
    from ..report import format_measurement

    lines = ["fitted parameters (± 1 standard error):"]
    width = max((len(n) for n in fit.params), default=0)
    for name, p in fit.params.items():
        unit = f" {p.unit}" if getattr(p, "unit", "") else ""
        head = f"  {name:<{width}} = "
        if not p.vary:
            lines.append(f"{head}{p.value:.6g}{unit} (held fixed)")
        elif p.identifiable is False or p.stderr is None or not math.isfinite(p.stderr):
            why = p.note if p.note else "no finite standard error"
            why = why.removeprefix("not identifiable: ")
            lines.append(f"{head}{p.value:.6g}{unit} (not identifiable: {why})")
        elif p.rel_stderr is not None and not p.rel_stderr < UNDETERMINED_REL_STDERR:
            lines.append(
                f"{head}{p.value:.6g}{unit} (not identifiable: standard error "
                f"{p.stderr:.2g}, over {100 * UNDETERMINED_REL_STDERR:.0f} % of the "
                "value)"
            )
        else:
            lines.append(f"{head}{format_measurement(p.value, p.stderr)}{unit}")
    return "\n".join(lines)


#: seconds before the progress bar shows (a quicker run prints none)
PROGRESS_DELAY = 1.0


class _Bar:
    """A tqdm bar of the simulations an identification runs, on stderr, shown after a
    second (a quick run prints none); its description follows the stage."""

    def __init__(self) -> None:
        from tqdm.auto import tqdm

        self._bar = tqdm(
            desc="identify: starts", unit="sim", file=sys.stderr, delay=PROGRESS_DELAY, leave=False
        )
        self._stage = "starts"

    def step(self, stage: str) -> None:
        if stage == "done":
            self.close()
            return
        if stage != self._stage:
            self._stage = stage
            self._bar.set_description_str(f"identify: {stage}", refresh=False)
        self._bar.update(1)

    def close(self) -> None:
        self._bar.close()


def _progress_bar(progress: bool | None) -> _Bar | None:
    """A bar when ``--progress``, or on a terminal unless ``--no-progress``."""
    if progress or (progress is None and sys.stderr.isatty()):
        return _Bar()
    return None


def _masses(text: str | None) -> list[float] | None:
    import numpy as np

    if text is None:
        return None
    try:
        vals = [float(v) for v in str(text).split(",")]
    except ValueError:
        raise InputError(
            f"--mass must be a number or comma-separated numbers, got {text!r}"
        ) from None
    if not all(np.isfinite(v) and v > 0 for v in vals):
        raise InputError(f"--mass values must be positive and finite, got {text!r}")
    return vals


def _masks(text: str) -> dict[str, object]:
    """``--masks``: inline JSON (starting with ``{``) or a JSON file, ``{"K": [[...]], "C":
    ..., "M": ...}`` (boolean matrices of free entries; checked by ``identify``)."""
    src = "--masks"
    raw = str(text).strip()
    if not raw.startswith("{"):
        src = f"--masks file {raw}"
        try:
            raw = Path(raw).read_text()
        except (OSError, ValueError) as exc:
            raise InputError(f"cannot read {src}: {exc}") from None
    try:
        d = json.loads(raw)
    except ValueError as exc:
        raise InputError(f"{src} is not valid JSON: {exc}") from None
    if not isinstance(d, dict):
        raise InputError(f'{src} must be a JSON object like {{"K": [[true, true], ...]}}')
    return d


def _joint_dofs(text: str) -> tuple[int, int | None]:
    parts = [p.strip().lower() for p in str(text).split(",")]
    try:
        i = int(parts[0])
        j = None if len(parts) < 2 or parts[1] in ("", "ground", "none") else int(parts[1])
    except ValueError:
        raise InputError(f"--joint-dofs must be I,J or I,ground, got {text!r}") from None
    if len(parts) > 2:
        raise InputError(f"--joint-dofs takes two DOFs, got {text!r}")
    return i, j


def simulate_structure(args: argparse.Namespace) -> int:
    """Handler of ``contactlab simulate structure OUT --structure MODEL --input FILE``."""
    import numpy as np

    from .._io_atomic import write_text
    from ..structure import IdentifiedModel, Structure

    if not args.structure or not args.input:
        raise InputError("simulate structure needs --structure MODEL.json and --input FILE")
    doc_path = Path(args.structure)
    try:
        model: IdentifiedModel | None = IdentifiedModel.load(doc_path)
    except InputError:
        if not doc_path.is_file():
            raise  # missing, or a folder: said before the input is read
        model = None  # perhaps a Structure.save file (read below)
    cols = read_table(args.input)
    exc = model.excitation if model else ("base" if args.base else "force")
    ucol = pick_column(
        cols, args.u, ("u", "f") if exc == "force" else ("y_base", "base", "y"), "u", args.input
    )
    u = cols[ucol]
    t = _time(cols, args, u.size, args.input)
    kw = {"force": u} if exc == "force" else {"base": u}
    if model is not None:
        s = model.structure
        r = model.simulate(t, periodic=args.periodic, **kw)
    else:
        s = Structure.load(doc_path)
        r = s.simulate(t, periodic=args.periodic, **kw)
    # the samples reached: a run that stopped early may hold fewer responses than times
    x = np.asarray(r.x).reshape(-1, s.n)
    m = min(x.shape[0], r.t.size, r.joint_force.shape[0])
    header = ["t [s]", f"u [{'N' if exc == 'force' else 'm'}]"]
    header += [f"x{i} [m]" if x.shape[1] > 1 else "x [m]" for i in range(x.shape[1])]
    header += [f"F_joint{j} [N]" for j in range(r.joint_force.shape[1])]
    # the input as run: a periodic run that failed returns its tiled record (fuzz/simulate)
    uu = np.resize(u, r.t.size)
    table = np.column_stack([r.t[:m], uu[:m], x[:m], r.joint_force[:m]])
    lines = [",".join(header)] + [",".join(f"{v:.10g}" for v in row) for row in table]
    if not r.success:
        # no file on failure, unless asked for: the samples reached are useful to find where
        # the integrator gave up, but must not pass for a finished run
        if not getattr(args, "partial", False):
            raise InputError(
                f"simulation stopped early ({r.message}) after {m} of {r.t.size} samples; "
                "nothing written (--partial writes the samples reached)"
            )
        write_text(args.out, "\n".join(lines) + "\n")
        raise InputError(f"simulation stopped early ({r.message}); wrote {m} samples (--partial)")
    path = write_text(args.out, "\n".join(lines) + "\n")
    print(f"wrote {path} ({m} samples)")
    return 0


def diagnose_structure_cli(args: argparse.Namespace) -> int:
    """Handler of ``contactlab diagnose FILE --structure MODEL.json``: the identified model is
    the base; prints the findings, writes ``--json``."""
    from .._io_atomic import write_text
    from ..diagnose.structure import diagnose_structure
    from ..structure import IdentifiedModel

    check_output_targets(json_out=args.json, report=args.report, inputs=[args.file, args.structure])
    model = IdentifiedModel.load(args.structure)
    cols = read_table(args.file)
    exc = model.excitation
    ucol = pick_column(
        cols, args.u, ("u", "f") if exc == "force" else ("y_base", "base", "y"), "u", args.file
    )
    ycol = pick_column(
        cols, args.y, ("y_disp", "y", "x") if exc == "force" else ("x", "y_disp"), "y", args.file
    )
    if ucol == ycol:
        raise InputError(f"{args.file}: input and response are the same column {ucol!r}")
    u, y = cols[ucol], cols[ycol]
    t = _time(cols, args, u.size, args.file)
    try:
        rep = diagnose_structure(
            (t, u, y), model, holdout=args.holdout, max_effects=args.max_effects
        )
    except InputError as exc_:
        raise InputError(f"{args.file}: {exc_}") from exc_
    print(rep.summary())
    text = None
    if args.json:  # rendered first; written after the report (all or nothing)
        doc = rep.to_dict()
        doc["columns"] = {"u": ucol, "y": ycol}
        text = json.dumps(doc, indent=2, allow_nan=False) + "\n"
    if args.report:
        import matplotlib

        matplotlib.use("Agg")
        from ..report.structure import write_diagnosis_html

        cmd = made_by(
            args, "diagnose", args.file, "--structure", args.structure, "--report", args.report
        )
        print(f"report: {write_diagnosis_html(rep, args.report, intro=f'Made by: {cmd}')}")
    if text is not None:
        write_text(args.json, text)
    return 0


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "identify",
        help="identify a structure with a joint (M, C, K and joint parameters) from a record",
        description=describe(__doc__),
    )
    p.add_argument("file", metavar="FILE", help="CSV record (input and response columns)")
    p.add_argument(
        "--joint",
        default="bouc_wen",
        choices=("masing", "jenkins", "iwan", "bouc_wen", "kelvin_voigt", "normal", "linear"),
    )
    p.add_argument("--excitation", default="force", choices=("force", "base"))
    p.add_argument("--u", metavar="COLUMN", help="input column (force, or base displacement)")
    p.add_argument(
        "--y",
        metavar="COLUMN",
        help="response column (displacement of the mass); several "
        "comma-separated columns (one per DOF, in DOF order) identify a chain of "
        "masses",
    )
    p.add_argument(
        "--fs",
        type=quantity("Hz", positive=True),
        metavar="RATE",
        help="sampling rate when there is no time column, e.g. 1kHz",
    )
    p.add_argument(
        "--mass",
        help="known mass (kg), held fixed; needed for base; one per DOF "
        "(comma-separated) with several --y channels",
    )
    p.add_argument(
        "--joint-dofs",
        default="0,ground",
        help="several DOFs: the DOFs the joint joins, I,J or I,ground (default 0,ground)",
    )
    p.add_argument(
        "--input-dof",
        type=int,
        default=None,
        help="several DOFs, force excitation: the DOF the input force acts on (default the last)",
    )
    p.add_argument(
        "--masks",
        default=None,
        help="several DOFs: free entries of M, C, K instead of a chain, as inline "
        "JSON or a JSON file, e.g. '{\"K\": [[1, 1], [1, 1]]}' (missing M: the "
        "diagonal; missing C: as K)",
    )
    p.add_argument(
        "--holdout",
        type=float,
        default=0.0,
        help="fraction of the record (at its end) kept out of the fit and "
        "reported as hold-out error",
    )
    p.add_argument("--substeps", type=int, default=4, help="integration steps per sample")
    p.add_argument(
        "--periodic",
        action="store_true",
        help="the record holds whole periods of a periodic input (band-limited "
        "interpolation between samples)",
    )
    p.add_argument(
        "--json", metavar="OUT", help="write the model (and summary) as JSON ('-': stdout)"
    )
    p.add_argument("--report", metavar="DIR", help="write report.html and figures/ here")
    add_progress_flags(p)
    p.set_defaults(handler=_identify)
