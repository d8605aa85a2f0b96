"""Paired A/B of whole command-line runs (issue 33 item 4: the fixed cost of a run counts
against ``analyze``'s throughput bar): this tree against another tree's package
(``--baseline``: a ``python/`` folder with its built ``_core``, e.g. a ``git archive`` of
main's ``python/`` with this tree's ``_core`` copied in).

Commands, each a new process (``python -m contactlab ...``, the same interpreter for both
trees, ``PYTHONPATH`` naming the tree), stdout and stderr to /dev/null as in a script:

- ``help``: ``contactlab --help``;
- ``first read``: the same run ended (``os._exit``) by an audit hook when the reader opens
  the recording: start-up, imports and the checks before the read, nothing of the analysis
  (as ``bench_startup.py``'s, but the command line's own path: ``main()`` of ``sys.argv``);
- ``csv``: ``contactlab analyze`` of the bundled 4 000-sample recording with ``--json``;
- ``h5 FILE``: ``contactlab analyze FILE --json`` of each ``--h5`` file (e.g.
  ``bench_track.write_file``'s 1e7 and 3e7-sample recordings).

Rounds are interleaved: in each round every command runs once per tree, the tree run first
alternating. CPU time is user + system of the child (``os.wait4``), which a loaded machine
disturbs far less than the wall time. Prints per command the medians (CPU and wall) of both
trees, the median paired CPU difference and in how many rounds this tree used less CPU.
The JSON of the two trees is compared byte for byte in every round (``contactlab_version``
aside: both trees are the same version).

Both trees' modules are compiled first (``bench_analyze.compile_tree``: with
``PYTHONDONTWRITEBYTECODE=1`` an uncompiled tree compiles itself in every run).

Run: ``nice .venv/bin/python benches/bench_startup_paired.py --baseline DIR [--h5 F ...]
[--rounds 9] [--pin]``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CSV = ROOT / "python" / "contactlab" / "data" / "tangential" / "Al-Al_W50N_A5um.csv"


#: ``python -c _PROBE FILE OUT``: ``contactlab analyze FILE --json OUT`` ended when the reader
#: opens FILE
_PROBE = r"""
import os, sys
target = os.path.abspath(sys.argv[1])
def _hook(event, args):
    if event == "open" and args and isinstance(args[0], (str, bytes, os.PathLike)):
        try:
            p = os.path.abspath(os.fsdecode(args[0]))
        except (TypeError, ValueError):
            return
        if p == target:
            os._exit(0)
sys.addaudithook(_hook)
sys.argv = ["contactlab", "analyze", target, "--json", sys.argv[2]]
from contactlab.cli import main
main()
os._exit(3)  # the recording was never opened
"""


def run(argv: list[str], env: dict[str, str], pin: int | None) -> tuple[float, float]:
    """Wall and CPU seconds of one ``python -m contactlab argv`` (which must succeed);
    ``argv`` starting with ``-c``: ``python -c ...`` instead."""
    t0 = time.perf_counter()
    p = subprocess.Popen(
        [sys.executable, *(argv if argv[0] == "-c" else ["-m", "contactlab", *argv])],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        env=env,
        preexec_fn=None if pin is None else (lambda: os.sched_setaffinity(0, {pin})),
    )
    _, status, ru = os.wait4(p.pid, 0)
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"contactlab {' '.join(argv)} failed with status {status}")
    return time.perf_counter() - t0, ru.ru_utime + ru.ru_stime


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", type=Path, required=True, help="the other tree's python/")
    ap.add_argument(
        "--tree",
        type=Path,
        default=ROOT / "python",
        help="the tree measured against the baseline (default: this one; a copy beside the "
        "baseline, on the same file system, keeps the comparison even)",
    )
    ap.add_argument("--h5", type=Path, nargs="*", default=[], help="HDF5 recordings")
    ap.add_argument("--rounds", type=int, default=9)
    ap.add_argument("--pin", action="store_true", help="run every child on one CPU")
    ap.add_argument("--skip", nargs="*", default=[], help="leave out: help, first, csv")
    args = ap.parse_args()
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from bench_analyze import compile_tree

    here = args.tree.resolve()
    for tree in (args.baseline, here):
        if compile_tree(tree):
            raise SystemExit(f"{tree}: a module does not compile")
    envs = {
        "before": {**os.environ, "PYTHONPATH": str(args.baseline.resolve())},
        "after": {**os.environ, "PYTHONPATH": str(here)},
    }
    pin = min(os.sched_getaffinity(0)) if args.pin else None
    with tempfile.TemporaryDirectory(prefix="contactlab-startup-") as d:
        cmds: dict[str, list[str]] = {}
        if "help" not in args.skip:
            cmds["contactlab --help"] = ["--help"]
        if "first" not in args.skip:
            cmds["analyze bundled CSV, to the first sample read"] = [
                "-c",
                _PROBE,
                str(CSV),
                str(Path(d) / "probe.json"),
            ]
        if "csv" not in args.skip:
            cmds["analyze bundled CSV --json"] = ["analyze", str(CSV), "--json", "{out}"]
        for f in args.h5:
            cmds[f"analyze {f.name} --json"] = ["analyze", str(f), "--json", "{out}"]
        rows: dict[str, dict[str, list[tuple[float, float]]]] = {
            c: {"before": [], "after": []} for c in cmds
        }
        mismatches: dict[str, int] = dict.fromkeys(cmds, 0)
        for r in range(args.rounds):
            order = ["before", "after"] if r % 2 else ["after", "before"]
            for name, argv in cmds.items():
                texts = {}
                for tree in order:
                    out = str(Path(d) / f"{tree}.json")
                    rows[name][tree].append(
                        run([a.replace("{out}", out) for a in argv], envs[tree], pin)
                    )
                    if "{out}" in argv:
                        texts[tree] = Path(out).read_bytes()
                if texts and texts["before"] != texts["after"]:
                    mismatches[name] += 1
            print(f"round {r + 1}/{args.rounds} done, load {os.getloadavg()[0]:.1f}", flush=True)
    print(
        f"\n{args.rounds} interleaved paired rounds, {'one CPU' if pin is not None else 'all CPUs'}"
        f", load at the end {os.getloadavg()[0]:.1f}\n"
    )
    print(
        "| command | CPU before | CPU after | paired CPU difference (median) | after lower "
        "| wall before | wall after | JSON identical |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for name, v in rows.items():
        cb = statistics.median(c for _, c in v["before"])
        ca = statistics.median(c for _, c in v["after"])
        wb = statistics.median(w for w, _ in v["before"])
        wa = statistics.median(w for w, _ in v["after"])
        diff = [a[1] - b[1] for a, b in zip(v["after"], v["before"], strict=True)]
        same = f"{args.rounds - mismatches[name]}/{args.rounds}"
        if "{out}" not in cmds[name]:
            same = "-"
        print(
            f"| `{name}` | {cb * 1e3:.0f} ms | {ca * 1e3:.0f} ms | "
            f"{statistics.median(diff) * 1e3:+.1f} ms ({statistics.median(diff) / cb:+.0%}) | "
            f"{sum(x < 0 for x in diff)}/{args.rounds} | {wb * 1e3:.0f} ms | {wa * 1e3:.0f} ms "
            f"| {same} |"
        )


if __name__ == "__main__":
    main()
