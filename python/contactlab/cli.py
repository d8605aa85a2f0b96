"""Command-line interface: ``contactlab <verb> ...``.

Each verb lives in its own module and registers itself through ``add_parser(subparsers)``;
its handler returns an exit code. Errors derived from ``ContactLabError`` print one clear line
and exit non-zero; Ctrl-C exits 130 without leaving partial outputs (writers are atomic).
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import importlib
import re
import sys
from collections.abc import Sequence

from ._malloc import keep_freed_memory
from ._version import __version__
from .errors import ContactLabError

# a command-line run is this process: freed arrays of a few MB stay in it for reuse instead
# of being page-faulted and zeroed by the kernel again (streamed analyses, see _malloc)
keep_freed_memory()

# Modules providing `add_parser(subparsers)`; each sets `handler` via set_defaults.
_VERB_MODULES = [
    "contactlab.commands.analyze",
    "contactlab.commands.study",
    "contactlab.commands.track",
    "contactlab.commands.simulate",
    "contactlab.commands.demo",
    "contactlab.commands.diagnose",
    "contactlab.commands.export",
    "contactlab.commands.structure",
    "contactlab.commands.fit_joint",
]
#: verbs whose module is not ``contactlab.commands.<verb>``
_VERB_ALIASES = {
    "identify": "contactlab.commands.structure",
    "fit-joint": "contactlab.commands.fit_joint",
}


# Temporaries of the atomic writers: ".report.html.k2j4x9.part" beside "report.html".
_TEMP = re.compile(r"(^|[/\\])\.([^/\\]+)\.[A-Za-z0-9_]+\.part$")


def os_error_text(exc: OSError) -> str:
    """``strerror: path``, naming the output the user asked for rather than its temporary."""
    name = exc.filename2 or exc.filename  # os.replace(tmp, final): final is filename2
    if name is None:
        return str(exc)
    name = _TEMP.sub(r"\1\2", str(name))
    return f"{exc.strerror or exc}: {name}"


def _verb_module(argv: Sequence[str]) -> str | None:
    """The module of the verb ``argv`` names (its first word not an option), None when it
    names none of them (``--help``, a misspelt verb: the full parser says what there is)."""
    verb = next((a for a in argv if not a.startswith("-")), None)
    if verb is None:
        return None
    name = _VERB_ALIASES.get(verb, f"contactlab.commands.{verb}")
    return name if name in _VERB_MODULES else None


def build_parser(verb_module: str | None = None) -> argparse.ArgumentParser:
    """The parser of every verb, or of the verb of ``verb_module`` only (the verbs' modules
    import what their options need — a run of one verb need not import the others')."""
    p = argparse.ArgumentParser(
        prog="contactlab",
        description="Hysteresis of contact joints: fit, measure and diagnose contact models.",
    )
    p.add_argument("--version", action="version", version=f"contactlab {__version__}")
    sub = p.add_subparsers(dest="verb", metavar="VERB")
    for name in _VERB_MODULES if verb_module is None else [verb_module]:
        try:
            mod = importlib.import_module(name)
        except ModuleNotFoundError as exc:  # a verb whose optional module is absent
            if exc.name != name:
                raise
            continue
        mod.add_parser(sub)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    if argv is None:  # the process's own command line: it ends when this returns
        from . import _interrupt

        _interrupt.install()
        one_blas_thread(sys.argv[1:])
        try:
            code = _main(sys.argv[1:])
            if code == _INTERRUPTED:
                _exit_interrupted()
            if _interrupt.pending():
                # swallowed where it landed after the last output was committed: the run had
                # done its work and its outputs are whole; say so rather than nothing
                print("contactlab: interrupt arrived after the outputs were complete; "
                      "they are whole", file=sys.stderr)  # fmt: skip
            return code
        except KeyboardInterrupt:  # before the verb's handler started, or after it ended
            print("contactlab: interrupted; no partial outputs written", file=sys.stderr)
            _exit_interrupted()
            raise  # not reached
        except Exception as exc:
            if not (_interrupt.pending() or _by_interrupt(exc)):
                raise
            # a Ctrl-C that Python wrapped in another exception where it landed (a class
            # body's __set_name__ while matplotlib was imported turns it into RuntimeError)
            print("contactlab: interrupted; no partial outputs written", file=sys.stderr)
            _exit_interrupted()
            raise  # not reached
        finally:
            _interrupt.uninstall()
            # a structure scan started ahead for a file the run never opened (a usage error,
            # Ctrl-C) stops at its next block instead of holding the exit for the whole file
            hdf5 = sys.modules.get("contactlab.io.hdf5")
            if hdf5 is not None:
                hdf5.stop_prefetched_checks()
            # Python's collections at shutdown walk every object of every module imported
            # (numpy, h5py, the package): 0.05-0.15 s of a 1e6-sample diagnosis (issue 9)
            # for memory the process is about to give back anyway
            gc.freeze()
    return _main(list(argv))


#: the exit status of an interrupted run (128 + SIGINT), as a shell reports it
_INTERRUPTED = 130


def _by_interrupt(exc: BaseException) -> bool:
    """Whether ``exc`` was caused by a ``KeyboardInterrupt`` (its cause or context chain):
    Python wraps an exception raised in ``__set_name__`` or an import hook in another one."""
    seen: set[int] = set()
    e: BaseException | None = exc
    while e is not None and id(e) not in seen:
        if isinstance(e, KeyboardInterrupt):
            return True
        seen.add(id(e))
        e = e.__cause__ or e.__context__
    return False


def _exit_interrupted() -> None:
    """End an interrupted run now, with status 130: the pools' workers are killed and the
    interpreter's exit handlers are skipped (they join the pools' threads, which can wait for
    ever on a worker blocked where SIGINT reached only the parent). Nothing is lost: outputs
    are written all or nothing, and an interrupted run wrote none."""
    import os

    try:
        from .studies.executor import kill_worker_processes

        kill_worker_processes()
    finally:
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(Exception):
                stream.flush()
        os._exit(_INTERRUPTED)


#: verbs that read recordings named on their command line
_READING_VERBS = {"analyze", "track", "diagnose"}

#: verbs whose least-squares problems are small (a window's or an averaged loop's few hundred
#: bins, a few parameters): they run BLAS on one thread (:func:`one_blas_thread`)
_SMALL_BLAS_VERBS = {"analyze", "track"}

#: the variables OpenBLAS takes its thread count from (the first one set); a user's setting of
#: any of them is kept
_BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS")


def one_blas_thread(argv: Sequence[str]) -> bool:
    """Set ``OPENBLAS_NUM_THREADS=1`` for ``analyze`` and ``track`` before numpy is imported.

    OpenBLAS starts a thread per CPU when numpy is imported, and the new threads spin before
    they sleep: ``import numpy`` took 25 ms more CPU on this project's 2-CPU VM than with one
    thread (20 of 20 paired runs, 128 against 102 ms). A streamed analysis's windows already
    run their least-squares problems on one BLAS thread
    (:func:`contactlab.studies.tracking.track`), so nothing they compute changes, and the
    results of ``analyze``/``track`` no longer depend on the machine's number of CPUs through
    BLAS's splitting of long dot products. Called for the process's own command line only
    (``main()`` without arguments); the verb's worker processes inherit the setting.

    Parameters
    ----------
    argv : sequence of str
        The command line's words after the program name.

    Returns
    -------
    bool
        True when the variable was set; False for another verb, when numpy is already
        imported, or when the user set any of ``OPENBLAS_NUM_THREADS``, ``GOTO_NUM_THREADS``
        or ``OMP_NUM_THREADS`` (kept as they are).
    """
    import os

    verb = next((a for a in argv if not a.startswith("-")), None)
    if verb not in _SMALL_BLAS_VERBS or "numpy" in sys.modules:
        return False
    if any(os.environ.get(v) for v in _BLAS_THREAD_VARIABLES):
        return False
    os.environ["OPENBLAS_NUM_THREADS"] = "1"
    return True


def prefetch_checks(argv: list[str]) -> None:
    """Start the structure check of each long HDF5 file named on the command line of a verb
    that reads recordings (:func:`contactlab.io.hdf5.prefetch_structure_check`: a scan of the
    whole file) before the verb's modules are imported, which then runs alongside."""
    verb = next((a for a in argv if not a.startswith("-")), None)
    if verb not in _READING_VERBS:
        return
    import os

    files = [a for a in argv if not a.startswith("-") and a != verb and os.path.isfile(a)]
    if not files:
        return
    from .io.hdf5 import prefetch_structure_check

    for f in files:
        prefetch_structure_check(f)


#: a Python hint followed by its command-line form: ``pass fs= (Hz) or columns={'t': ...}
#: (command line: --fs or --columns 't=...')`` -> ``give --fs or --columns 't=...'``
_PY_HINT = re.compile(
    r"(?:pass |give )?(?:[a-z_]+=(?:\{[^{}]*\}|[^\s(),;]*)(?: \([^)]*\))?(?:,? (?:and|or) )?)+"
    r" \(command line: ([^)]*)\)"
)
#: a Python spelling in parentheses after the command-line one: ``--frame-x (columns={...})``
_PY_ASIDE = re.compile(r" \((?:columns|resample|kind|fs)=[^)]*\)")
#: keyword arguments named in messages -> their flags
_PY_NAMES = re.compile(r"\b(max_effects|chunk_size|max_window|output_noise|output_filter)\b")


def cli_wording(message: str) -> str:
    """An error message of the library as the command line says it: the hints name flags,
    not keyword arguments (``columns={'x': ...}`` -> ``--columns``, ``max_effects`` ->
    ``--max-effects``).

    Examples
    --------
    >>> cli_wording("no time column: pass fs= (Hz) or columns={'t': ...} (command line: "
    ...             "--fs or --columns 't=...')")
    "no time column: give --fs or --columns 't=...'"
    >>> cli_wording("max_effects must be >= 0, got -1")
    '--max-effects must be >= 0, got -1'
    """
    text = _PY_HINT.sub(lambda m: "give " + m.group(1), message)
    text = _PY_ASIDE.sub("", text)
    return _PY_NAMES.sub(lambda m: "--" + m.group(1).replace("_", "-"), text)


_NEGATIVE = re.compile(r"^-(\d|\.\d)")


def join_negative_values(argv: list[str]) -> list[str]:
    """``--area -50cm2`` as ``--area=-50cm2`` (and ``--frame -3,0.6,1191``, ``--delay -1ms``):
    argparse takes a word starting with ``-`` for an option unless it is a plain number, and
    would say only "expected one argument". A long option followed by a word that starts
    with a minus and a digit gets it as its value (no verb has a positional that could be
    a negative number: positionals are files).

    Examples
    --------
    >>> join_negative_values(["export", "r.json", "--area", "-50cm2", "--check"])
    ['export', 'r.json', '--area=-50cm2', '--check']
    """
    out = list(argv)
    for i in range(len(out) - 2, -1, -1):
        if out[i] == "--":
            break
        if out[i].startswith("--") and "=" not in out[i] and _NEGATIVE.match(out[i + 1]):
            out[i : i + 2] = [f"{out[i]}={out[i + 1]}"]
    return out


def _main(argv: list[str]) -> int:
    given = list(argv)  # as typed, for the reports' "Made by" line
    argv = join_negative_values(argv)
    prefetch_checks(argv)
    parser = build_parser(_verb_module(argv))
    args = parser.parse_args(argv)
    args.argv = given
    if not getattr(args, "handler", None):
        parser.print_help()
        return 2
    try:
        return int(args.handler(args) or 0)
    except ContactLabError as exc:
        if _by_interrupt(exc):
            print(f"contactlab {args.verb}: interrupted; no partial outputs written",
                  file=sys.stderr)  # fmt: skip
            return _INTERRUPTED
        print(f"contactlab {args.verb}: error: {cli_wording(str(exc))}", file=sys.stderr)
        return 1
    except OSError as exc:  # the file system said no (permissions, full disk, a file in the way)
        print(f"contactlab {args.verb}: error: {os_error_text(exc)}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"contactlab {args.verb}: interrupted; no partial outputs written", file=sys.stderr)
        return _INTERRUPTED
    except RuntimeError as exc:  # a worker process was killed (out of memory, a signal)
        futures = sys.modules.get("concurrent.futures")  # imported by whatever started a pool
        if _by_interrupt(exc):
            print(f"contactlab {args.verb}: interrupted; no partial outputs written",
                  file=sys.stderr)  # fmt: skip
            return _INTERRUPTED
        if futures is None or not isinstance(exc, futures.BrokenExecutor):
            raise
        print(
            f"contactlab {args.verb}: error: a worker process ended unexpectedly ({exc}); "
            "it may have run out of memory: try fewer --workers (0: in this process); no "
            "partial outputs written",
            file=sys.stderr,
        )
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
