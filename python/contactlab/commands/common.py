"""Helpers shared by the CLI verbs: quantities with units, JSON output, report writing."""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import shlex
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .._io_atomic import write_text
from .._json import jsonable
from .._version import __version__
from ..errors import InputError

# the studies and the report are imported where used: a verb that needs neither (diagnose)
# does not pay for them at start-up
if TYPE_CHECKING:
    from ..studies.study import RecordingResult, StudyResult

_QTY = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([A-Za-zµμ/]*)\s*$")


def describe(doc: str | None) -> str | None:
    """The second paragraph of a module docstring as plain text for ``--help``."""
    if not doc or "\n\n" not in doc:
        return doc
    text = doc.split("\n\n")[1]
    text = re.sub(r":\w+:`~?([^`]+)`", r"\1", text)  # :mod:`x` -> x
    return text.replace("``", "")


def quantity(default_unit: str, *, positive: bool = False):
    """argparse ``type=``: a number with an optional unit (``20um``, ``0.5MPa``) → SI float.

    ``positive=True`` refuses zero and negative values (a sampling rate, a frequency).
    """

    def parse(text: str) -> float:
        from ..studies.manifest import scaled, si_unit, unit_factor

        compatible = {si_unit(default_unit)} if default_unit else {""}
        # a rate in 1/s may be written rad/s, a frequency in Hz as 1/s (not the other way
        # round: 1 Hz is 2π rad/s)
        compatible |= {"1/s": {"rad/s"}, "Hz": {"1/s"}}.get(next(iter(compatible)), set())
        # ArgumentTypeError: argparse shows its message (a ValueError's is replaced).
        m = _QTY.match(text)
        if not m:
            raise argparse.ArgumentTypeError(
                f"{text!r} is not a number with an optional unit (e.g. 20um, 0.5MPa)"
            )
        unit = m.group(2) or default_unit
        if unit.startswith("/"):  # 40/mm means 40 1/mm
            unit = "1" + unit
        try:
            value = scaled(m.group(1), unit_factor(unit, "value"))  # 20um -> 2e-05 exactly
            si = si_unit(unit)
        except InputError as exc:
            raise argparse.ArgumentTypeError(f"{text!r}: {exc}") from None
        if si not in compatible:
            raise argparse.ArgumentTypeError(
                f"{text!r}: {unit} is not a unit of this option (give {default_unit}, or "
                f"a multiple of it)"
            )
        if not math.isfinite(value):  # 1e400 reads as inf; nan is no value
            raise argparse.ArgumentTypeError(f"{text!r}: must be a finite number")
        if positive and not value > 0:
            raise argparse.ArgumentTypeError(f"{text!r}: must be > 0")
        return value

    parse.__name__ = f"quantity in {default_unit or 'SI'}"
    return parse


def parse_columns(text: str | None) -> dict[str, str] | None:
    """``x=disp,F=force`` (or ``;``-separated) → mapping for the readers."""
    if not text:
        return None
    out = {}
    for part in re.split(r"[;,]", text):
        if not part.strip():
            continue
        if "=" not in part:
            raise InputError(f"--columns: {part!r} must look like 'x=disp'")
        k, v = part.split("=", 1)
        out[k.strip()] = v.strip()
    return out


def recording_json(r: RecordingResult) -> dict[str, Any]:
    """One recording's JSON object: the analysis' ``to_dict()`` (SI, with ``units``) + tags."""
    d = dict(r.analysis.to_dict()) if r.analysis is not None else {}
    if r.extra:
        d.update(r.extra)
    d = {"file": str(r.entry.path), "model": r.entry.kind, **r.entry.tags, **d}
    units = dict(d.get("units", {}) or {})
    for k, u in r.units.items():  # tags' and added keys' units (not the flattened vectors)
        if k in d:
            units.setdefault(k, u)
    d["units"] = units
    return jsonable(d)


def json_document(result: StudyResult) -> dict[str, Any]:
    """A single recording's object at top level; several as ``{"recordings": [...]}``."""
    recs = [recording_json(r) for r in result.results if r.ok]
    if len(recs) == 1 and not result.failures:
        return {**recs[0], "contactlab_version": __version__}
    return {
        "contactlab_version": __version__,
        "recordings": recs,
        "failures": [{"file": str(r.entry.path), "error": r.error} for r in result.failures],
    }


def json_text(doc: Mapping[str, Any]) -> str:
    """The JSON document as text (rendered before anything is written, so that a document that
    cannot be serialised fails the run before the report lands on disk)."""
    return json.dumps(jsonable(doc), indent=2, allow_nan=False) + "\n"


def _first_existing(path: Path) -> Path:
    p = path.absolute()
    while not p.exists() and p != p.parent:
        p = p.parent
    return p


def check_output_targets(
    *, json_out: str | None = None, report: str | None = None, inputs: Sequence[Any] = ()
) -> None:
    """Refuse output paths that cannot be written *before* a long analysis runs.

    ``--report`` must be a folder (or not exist yet) below a folder; ``--json`` must not be a
    folder, nor one of the ``inputs`` (the recording it would replace). Raises
    :class:`~contactlab.InputError` naming the option and the path.
    """
    if report:
        r = Path(report)
        if r.exists() and not r.is_dir():
            raise InputError(f"--report {report}: exists and is not a folder")
        anc = _first_existing(r)
        if not anc.is_dir():
            raise InputError(f"--report {report}: {anc} is a file, not a folder")
    if json_out and json_out != "-":
        j = Path(json_out)
        if j.is_dir():
            raise InputError(f"--json {json_out}: is a folder; give a file name (or '-')")
        anc = _first_existing(j.parent)
        if not anc.is_dir():
            raise InputError(f"--json {json_out}: {anc} is a file, not a folder")
        if j.exists():
            for src in inputs:
                try:
                    same = os.path.samefile(j, src)
                except OSError:  # an input that does not exist: its reader says so
                    same = False
                if same:
                    raise InputError(
                        f"--json {json_out}: is the input {src}; writing the result there "
                        "would replace the recording (give another file name)"
                    )


def refuse_if_none_analysed(n_ok: int, failures: Sequence[Any]) -> None:
    """With ``--keep-going``, outputs are written when some recordings were analysed (the
    failures listed in them); when none was, an error, and the previous outputs stay as they
    were (a report of nothing would replace them)."""
    if n_ok == 0 and failures:
        first = failures[0]
        text = first.get("error") if isinstance(first, Mapping) else first
        raise InputError(
            f"none of the {len(failures)} recordings could be analysed (first: {text}); "
            "nothing written"
        )


def write_json(path: str, doc: Mapping[str, Any] | str) -> Path:
    text = doc if isinstance(doc, str) else json_text(doc)
    if path == "-":
        print(text, end="")
        return Path("-")
    return write_text(path, text)


def write_report(
    directory: str,
    result: StudyResult,
    title: str,
    *,
    study_plots: bool,
    extra: Mapping[str, bytes] | None = None,
    progress: bool | None = None,
    command: str | None = None,
    executor: Any = None,
) -> list[Path]:
    """Render the report and tables in memory, then write them all or nothing.

    ``command`` (the command line that made it) is quoted at the top of the report; a process
    pool as ``executor`` draws the figures on its workers (the same report).
    """
    import matplotlib

    matplotlib.use("Agg")
    from ..report.study_report import build_report

    intro = f"Made by: {command}" if command else None
    rep = build_report(
        result, title, study_plots=study_plots, progress=progress, intro=intro, executor=executor
    )
    files = rep.files()
    tables, skipped = table_files(result)
    files.update(tables)
    for name, why in skipped.items():
        print(f"note: skipped {name}: {why}", file=sys.stderr)
    if extra:
        files.update(extra)
    from ..report import commit_outputs

    return commit_outputs(directory, files)


def parquet_available() -> str | None:
    """None when Parquet can be written, else why not and what to install."""
    try:
        import pyarrow
        import pyarrow.parquet  # noqa: F401
    except ImportError:
        return "writing Parquet needs pyarrow, which is not installed: pip install 'contactlab[io]'"
    return None


def table_files(
    result: StudyResult, stem: str = "study"
) -> tuple[dict[str, bytes], dict[str, str]]:
    """The study tables as files (``<stem>_<kind>.csv`` always, ``.parquet`` when pyarrow is
    installed) and, for each table left out, why (a bare install has no ``io`` extra)."""
    from ..studies.study import KINDS

    files: dict[str, bytes] = {}
    skipped: dict[str, str] = {}
    why = parquet_available()
    for kind in KINDS:
        if not result.table(kind):
            continue
        files[f"{stem}_{kind}.csv"] = result.to_csv(kind).encode("utf-8")
        if why is None:
            files[f"{stem}_{kind}.parquet"] = result.to_parquet(kind)
        else:
            skipped[f"{stem}_{kind}.parquet"] = why
    return files, skipped


def made_by(args: Any, verb: str = "", *fallback: Any) -> str:
    """The command line that made a report, as typed (``cli.main`` keeps it in
    ``args.argv``): running it again repeats the run, every option included (``--fs``,
    ``--columns``, ``--resample``, ...). Without it (a handler called from Python), the
    line :func:`command_line` makes of ``verb`` and ``fallback``."""
    argv = getattr(args, "argv", None)
    if argv:
        return " ".join(shlex.quote(w) for w in ["contactlab", *map(str, argv)])
    return command_line(verb, *fallback)


def command_line(verb: str, *parts: Any) -> str:
    """A shell-quoted ``contactlab VERB ...`` line for the report's provenance."""
    words = ["contactlab", verb]
    words += [str(p) for p in parts if p is not None and p is not False and p != ""]
    return " ".join(shlex.quote(w) for w in words)


def add_pressure_flags(p: Any) -> None:
    """``--p0`` and ``--pa`` (normal contact): quantities in Pa (``0.5MPa``)."""
    p.add_argument(
        "--p0",
        type=quantity("Pa", positive=True),
        help="normal: static pressure, e.g. 0.5MPa (needed when the pressure channel holds "
        "only the dynamic part; default: the file-name tag p0-..., the manifest, or the "
        "channel's mean)",
    )
    p.add_argument(
        "--pa",
        type=quantity("Pa", positive=True),
        help="normal: nominal dynamic amplitude, e.g. 0.4MPa (checked against the measured "
        "one; default: the file-name tag pa-... or the manifest)",
    )


def with_static_pressure(rec: Any, file: str, p0: float | None, pa: float | None) -> Any:
    """:func:`contactlab.normal.pressure.with_static_pressure` with ``--p0``/``--pa``, else
    the file-name tags ``p0-...``/``pa-...``; its notes go to stderr as warnings."""
    from ..normal.pressure import with_static_pressure as add_static
    from ..studies.manifest import tags_from_filename

    tags = tags_from_filename(file)
    p0 = p0 if p0 is not None else tags.get("p0")
    pa = pa if pa is not None else tags.get("pa")
    rec, notes = add_static(rec, p0, pa, source=file)
    for note in notes:
        print(f"warning: {note}", file=sys.stderr)
    return rec


def add_workers_flag(p: Any, what: str, *, per_core: bool = False) -> None:
    """``--workers N``: processes; by default serial, or (``per_core``) one per core, at most
    8, with ``--workers 0`` for serial (see :func:`resolve_workers`)."""
    if per_core:
        help_ = (
            f"analyse {what} and draw the report's figures in N processes "
            "(default: one per core, at most 8; 0: serially in this process)"
        )
        p.add_argument("--workers", type=int, default=None, metavar="N", help=help_)
        return
    p.add_argument(
        "--workers",
        type=int,
        default=None,
        metavar="N",
        help=f"analyse {what} in N processes (default: serially)",
    )


def default_workers() -> int | None:
    """One process per core this process may use, at most 8; None (serial) on one core."""
    import os

    try:
        n = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # not on Linux
        n = os.cpu_count() or 1
    n = min(n, 8)
    return n if n > 1 else None


def resolve_workers(workers: int | None) -> int | None:
    """``--workers`` of a verb that uses all cores by default: None -> one per core
    (:func:`default_workers`), 0 -> None (serial), N >= 1 -> N; negative is refused."""
    if workers is None:
        return default_workers()
    if workers < 0:
        raise InputError(f"--workers must be >= 0 (0: serially), got {workers}")
    return workers or None


def _ignore_sigint() -> None:
    """Pool workers leave Ctrl-C to the parent, which cancels what is queued and exits 130
    (otherwise every worker prints its own KeyboardInterrupt traceback)."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _runnable_elsewhere() -> float | None:
    """Tasks runnable on the machine right now besides this process (``procs_running`` of
    ``/proc/stat`` less one), or None where the system does not tell."""
    try:
        with open("/proc/stat", "rb") as f:
            for line in f:
                if line.startswith(b"procs_running"):
                    return max(float(line.split()[1]) - 1.0, 0.0)
    except (OSError, ValueError, IndexError):
        return None
    return None


def _busy_cpus() -> float:
    """CPUs other work keeps busy: the smaller of the 1-minute load average and the tasks
    runnable right now (:func:`_runnable_elsewhere`; the average lags, so a run started just
    after other work ended would otherwise see the machine busy for up to a minute)."""
    try:
        busy = os.getloadavg()[0]
    except (AttributeError, OSError):  # no load average on this system
        busy = 0.0
    now = _runnable_elsewhere()
    return busy if now is None else min(busy, now)


def window_threads() -> int:
    """Helper threads of an auto-streamed analysis and of ``track`` (``track(threads=...)``):
    2 where this process may run on two CPUs or more (its affinity mask) and at least one of
    them is free of other work, else none; ``CONTACTLAB_ANALYZE_THREADS`` sets it (0:
    analyse each window before reading on). They analyse windows (the Rust kernels release
    the GIL) while the main thread reads on; at most threads + 2 windows (2^20 samples each)
    are unanalysed at a time, those waiting for a thread without their time axis (peak
    240-241 MB on 1e7 samples, 245-263 MB on 1e8, with 2). The pooled document is the serial
    one.

    Threads must never lose against the serial run (issue 33 item 5):

    - On one CPU (``taskset -c 0``, a one-CPU container) helper threads only take turns with
      the reader: a 3e7-sample ``analyze`` pinned to one CPU took 4.67-4.68 s serially
      against 4.98-5.05 s with one helper thread and 5.42-5.49 s with two (peak 146 against
      172 and 238 MB).
    - With every CPU busy, a second thread gets no CPU the first would not have had, and the
      GIL hand-overs and more windows in flight cost CPU: 3e7 samples in process at a load
      of 7.7 on 2 CPUs, 2.11-2.61 s wall and 0.82-1.06 s CPU with two helper threads against
      2.00-2.07 s and 0.80-0.83 s serially (5 paired rounds, the threads slower in each).
      Busy is counted as :mod:`contactlab.diagnose` counts it for its fits: the smaller of
      the 1-minute load average and the tasks runnable right now (:func:`_busy_cpus`); the
      threads run when ``int(cpus - busy) + 1 >= 2``."""
    env = os.environ.get("CONTACTLAB_ANALYZE_THREADS", "").strip()
    if env:
        try:
            n = int(env)
        except ValueError:
            raise InputError(
                f"CONTACTLAB_ANALYZE_THREADS must be an integer >= 0, got {env!r}"
            ) from None
        if n < 0:
            raise InputError(f"CONTACTLAB_ANALYZE_THREADS must be an integer >= 0, got {env!r}")
        return n
    try:
        cpus = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # no affinity mask on this system
        cpus = os.cpu_count() or 1
    if cpus <= 1:
        return 0
    usable = int(cpus - _busy_cpus()) + 1  # this process's CPU and the free ones
    return 2 if usable >= 2 else 0


def process_pool(workers: int | None, *, auto: bool = False) -> Any:
    """A ``ProcessPoolExecutor`` for ``--workers N`` (a null context for None).

    Where no process pool can be started (no POSIX semaphores, a sandbox): with ``auto`` (the
    count was the default, not asked for) a note and the serial run, else an error that says
    to use ``--workers 0``."""
    import contextlib

    if workers is None:
        return contextlib.nullcontext(None)
    if workers < 1:
        raise InputError(f"--workers must be >= 1, got {workers}")
    from concurrent.futures import ProcessPoolExecutor

    from .. import _interrupt

    try:
        executor = ProcessPoolExecutor(workers, initializer=_ignore_sigint)
        # the workers start now, with Ctrl-C held back: forked at a first submit, a SIGINT
        # landing in the fork's hooks would be printed as "Exception ignored" and lost
        with _interrupt.deferred():
            executor.submit(int)
        return _InterruptiblePool(executor)
    except (OSError, ImportError, NotImplementedError) as exc:
        if not auto:
            raise InputError(
                f"--workers {workers}: cannot start worker processes here ({exc}); "
                "--workers 0 runs in this process"
            ) from None
        print(
            f"note: cannot start worker processes here ({exc}); running in this process",
            file=sys.stderr,
        )
        return contextlib.nullcontext(None)


class _InterruptiblePool:
    """A process pool's context that does not wait for its workers after Ctrl-C.

    On a normal exit the pool shuts down as usual (waiting for its tasks). On an interrupt
    (or any other escaping exception) the queued tasks are cancelled and the worker processes
    are killed at once: waiting for them could block for ever where SIGINT reached only the
    parent (``kill -INT pid``, ``timeout -s INT``), since the workers ignore SIGINT and one may
    be blocked on a queue's lock that the interrupted parent will never release."""

    def __init__(self, executor: Any) -> None:
        self.executor = executor

    def __enter__(self) -> Any:
        return self.executor

    def __exit__(self, exc_type: Any, exc: Any, tb: Any) -> None:
        from .. import _interrupt

        if exc_type is None:
            try:
                _interrupt.check()  # a Ctrl-C swallowed where it landed ends the run here
            except KeyboardInterrupt:
                self._kill()
                raise
            self.executor.shutdown(wait=True)
            return
        self._kill()

    def _kill(self) -> None:
        from ..studies.executor import kill_worker_processes

        kill_worker_processes()
        self.executor.shutdown(wait=False, cancel_futures=True)


def add_progress_flags(p: Any) -> None:
    g = p.add_mutually_exclusive_group()
    g.add_argument(
        "--progress",
        dest="progress",
        action="store_true",
        default=None,
        help="always show a progress bar (default: only on a terminal)",
    )
    g.add_argument(
        "--no-progress", dest="progress", action="store_false", help="never show a progress bar"
    )


def normal_options(entry: object, nopts: dict) -> dict:
    """The options a study gives a normal recording's analysis: ``p0``, ``pa`` from the
    command line, else from the file-name tags; ω from a ``frequency`` tag
    (:func:`contactlab.studies.normal.analyze_normal_recording`, which each window runs)."""
    import math

    tags = entry.tags  # type: ignore[attr-defined]
    opts = dict(nopts)
    for key in ("p0", "pa"):
        tag = tags.get(key)
        if opts.get(key) is None and isinstance(tag, float) and math.isfinite(tag):
            opts[key] = tag
    freq = tags.get("frequency")
    if isinstance(freq, float) and math.isfinite(freq) and freq > 0:
        opts["omega"] = 2.0 * math.pi * freq
    return opts


def add_frame_flags(p: Any) -> None:
    """``--frame M,C,K`` with ``--frame-x`` / ``--frame-y``: the file holds a base-excited
    friction frame's displacements; the friction force is reconstructed from its equation of
    motion (:func:`contactlab.tangential.read_frame`)."""
    p.add_argument(
        "--frame",
        metavar="M,C,K",
        help="tangential: the file holds a friction frame's top-plate (x) and base (y) "
        "displacements; reconstruct the friction force F = K (y - x) + C (y' - x') - M x'' "
        "with this mass, damping and stiffness (kg, N s/m, N/m), e.g. 3.0799,0.669,1191 or "
        "M=3.0799,C=0.669,K=1191",
    )
    p.add_argument(
        "--frame-x",
        metavar="COLUMN",
        help="with --frame: the top-plate displacement column (default: the column named "
        "with x/top/plate; unit from the name, e.g. _mm or [mm], else m)",
    )
    p.add_argument(
        "--frame-y",
        metavar="COLUMN",
        help="with --frame: the base displacement column (default: the column named with "
        "y/base; unit from the name, else m)",
    )


def frame_option(args: Any) -> dict[str, Any] | None:
    """The parsed ``--frame`` (``{"M", "C", "K", "x", "y"}``), or None; ``--frame-x``/``-y``
    without ``--frame`` and ``--frame`` with a normal model are :class:`InputError`."""
    text = getattr(args, "frame", None)
    fx, fy = getattr(args, "frame_x", None), getattr(args, "frame_y", None)
    if text is None:
        if fx or fy:
            raise InputError("--frame-x/--frame-y name a frame's columns: give --frame M,C,K too")
        return None
    if getattr(args, "model", None) == "normal":
        raise InputError("--frame gives a tangential recording (x, F): use --model tangential")
    if getattr(args, "columns", None):
        raise InputError(
            "--frame reads the displacements: name them with --frame-x/--frame-y, not --columns"
        )
    from ..tangential.frame import parse_frame

    M, C, K = parse_frame(text)
    return {"M": M, "C": C, "K": K, "x": fx, "y": fy}


def output_filter_taps(text: str | None) -> Any:
    """``--output-filter``: ``savgol:WINDOW[:ORDER]`` (a Savitzky-Golay smoothing, quadratic
    by default: the same weights as cubic), ``mean:WINDOW`` (a centred moving average) or
    ``frame:WINDOW`` (the smoothing of :func:`contactlab.tangential.frame_friction_force`
    with that window) → the filter's taps (odd count, zero phase, sum 1), or None."""
    if text is None:
        return None
    import numpy as np

    kind, _, rest = text.strip().partition(":")
    kind = kind.strip().lower()
    fields = [f.strip() for f in rest.split(":")] if rest else []
    usage = (
        "--output-filter: give savgol:WINDOW[:ORDER], mean:WINDOW or frame:WINDOW "
        "(WINDOW an odd number of samples), e.g. savgol:11"
    )
    if kind not in ("savgol", "mean", "frame") or not fields or len(fields) > 2:
        raise InputError(f"{usage}; got {text!r}")
    if len(fields) == 2 and kind != "savgol":
        raise InputError(f"{usage}; only savgol takes an ORDER, got {text!r}")
    try:
        window = int(fields[0])
        order = int(fields[1]) if len(fields) == 2 else 2  # smoothing: 2 and 3 are the same
    except ValueError:
        raise InputError(f"{usage}; got {text!r}") from None
    least = {"savgol": 3, "mean": 1, "frame": 5}[kind]
    if window < least or window % 2 == 0:
        raise InputError(
            f"--output-filter {text!r}: the window must be an odd number of samples >= {least} "
            f"(a zero-phase filter is centred), got {window}"
        )
    if kind == "mean":
        return np.full(window, 1.0 / window)
    if kind == "frame":
        from ..tangential.frame import force_kernel

        return force_kernel(window)
    if not 0 <= order < window:
        raise InputError(
            f"--output-filter {text!r}: the polynomial order must be >= 0 and below the "
            f"window ({window}), got {order}"
        )
    from .._filters import savgol_coeffs

    return savgol_coeffs(window, order, deriv=0)[::-1]  # dot orientation


def positive_number(name: str):
    """argparse ``type=``: a finite number > 0 (an error naming the option otherwise)."""

    def parse(text: str) -> float:
        import math

        try:
            v = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} {text!r}: not a number") from None
        if not (math.isfinite(v) and v > 0):
            raise argparse.ArgumentTypeError(f"{name} {text!r}: must be a finite number > 0")
        return v

    parse.__name__ = "number > 0"
    return parse


#: ``--model``'s help, the same in every verb that reads a recording
MODEL_HELP = (
    "tangential (x, F: Masing) or normal (p, delta: Konowalski); default: inferred from the "
    "column names (a force column: tangential; a pressure column: normal), and the "
    "inference is printed"
)


def add_reader_flags(p: Any, *, model: bool = True) -> None:
    """The flags every verb that reads a recording shares, worded alike: ``--model``,
    ``--columns``, ``--fs`` and ``--resample``."""
    if model:
        p.add_argument(
            "--model",
            choices=("tangential", "normal"),
            metavar="{tangential,normal}",
            help=MODEL_HELP,
        )
    p.add_argument(
        "--columns",
        metavar="MAP",
        help="which column is which, e.g. 'x=Position,F=Friction' (names with or without "
        "their unit, or positions 0, 1, ... of a header-less file; default: by name)",
    )
    p.add_argument(
        "--fs",
        type=quantity("Hz", positive=True),
        metavar="RATE",
        help="sampling rate when a file has no time column, e.g. 1kHz",
    )
    p.add_argument(
        "--resample",
        action="store_true",
        help="non-uniform time stamps: interpolate onto a uniform grid of the median step "
        "(steps up to 4 grid steps are bridged and the largest is reported; a longer one is "
        "a real gap and still refused)",
    )


def infer_model(
    file: str, model: str | None, columns: dict[str, str] | None, fs: float | None
) -> tuple[str, str | None]:
    """The model of a recording: ``model`` when given, else inferred from its column names
    exactly as the readers infer it (``contactlab.io.read_chunks``, which reads only the
    header). Returns ``(model, sentence)``; the sentence (None when the model was given)
    says what was inferred from which columns, for the console (``model tangential, inferred
    from the columns x='Position [mm]', F='Friction [uN]' (--model sets it)``)."""
    if model is not None:
        return model, None
    from ..io import read_chunks

    cr = read_chunks(file, columns=columns, fs=fs)
    kind = cr.kind
    if kind not in ("tangential", "normal"):
        raise InputError(
            f"{file}: cannot tell a tangential (x, F) from a normal (p, delta) recording: "
            "give --model tangential|normal"
        )
    chans = ("x", "F") if kind == "tangential" else ("p", "delta")
    named = ", ".join(f"{c}={cr.columns[c]!r}" for c in chans if c in cr.columns)
    return kind, f"model {kind}, inferred from the columns {named} (--model sets it)"


def wrapped(text: str, width: int = 100) -> str:
    """``text`` wrapped to ``width`` characters, continuation lines indented."""
    import textwrap

    return textwrap.fill(
        text, width=width, subsequent_indent="   ", break_long_words=False, break_on_hyphens=False
    )


def wrap_warning(text: str, *, prefix: str = "  warning: ", width: int = 100) -> str:
    """A warning wrapped to ``width`` characters, continuation lines indented under it."""
    import textwrap

    return textwrap.fill(
        text,
        width=width,
        initial_indent=prefix,
        subsequent_indent=" " * len(prefix),
        break_long_words=False,
        break_on_hyphens=False,
    )


#: ``--force-sign``'s values as ``--help`` shows them (``1`` is read as ``+1``)
FORCE_SIGN_CHOICES = ("auto", "+1", "-1")


def force_sign(text: str) -> str:
    """argparse ``type=`` of ``--force-sign``: ``1`` and ``+1`` alike (the choices then
    show ``{auto,+1,-1}`` without a duplicate)."""
    t = text.strip()
    return "+1" if t in ("1", "+1") else t


class DefaultsShown(argparse.HelpFormatter):
    """``--help`` that states each option's default (``(default: 500.0)``) unless its help
    already says it or there is none (None, False)."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        text = action.help or ""
        d = action.default
        if (
            "default" in text
            or d is None
            or d is False
            or d is argparse.SUPPRESS
            or not action.option_strings
        ):
            return text
        return f"{text} (default: %(default)s)"
