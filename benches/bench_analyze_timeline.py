"""Where the wall time of a streamed ``contactlab analyze`` goes, phase by phase (issue 33
item 4: the bar is 0.3 of the Masing kernel, ``bench_analyze.py``).

Each round runs ``contactlab analyze FILE --json OUT`` as a new process (as
``bench_analyze.py`` does) under a probe that wraps, after each module is imported (an
import hook: the command imports what it always imports, in its own order), the calls that
mark its phases, and stamps them in seconds from the interpreter's start:

- ``cli imported``: ``contactlab.cli`` loaded (the structure check of a long file starts
  right after, on its own thread: ``prefetch_structure_check``);
- ``scan start`` / ``scan end``: that check's scan of the whole file (the prefetch thread);
- ``main waits for scan``: the time the main thread spent in ``check_structure`` when it
  first opened the file (waiting for the prefetch to end);
- ``track start``: :func:`contactlab.studies.tracking.track` called (modules imported, the
  file opened three times: model, length, chunks);
- ``first window``: the first window handed to a helper thread (or analysed, serially);
- ``read end``: the last chunk read and its cycles found (``_Dispatch.drain`` entered);
- ``track end``: the last window analysed;
- ``json written``: the document written;
- ``exit``: ``atexit`` (before the interpreter's teardown);
- ``process``: the child's wall time as the parent saw it, and its CPU time
  (user + system, ``os.wait4``).

Also: the windows' count and their analysis time summed over threads, and the time the
reader waited for a free window slot (``concurrent.futures.wait``; large: the helper
threads are the bottleneck, the reader idles).

``--threads N`` sets ``CONTACTLAB_ANALYZE_THREADS`` (default: the command's own choice,
which falls back to none when the machine is busy). Medians of ``--rounds`` runs.

Run: ``nice .venv/bin/python benches/bench_analyze_timeline.py [--samples 3e7]
[--recording FILE] [--rounds 5] [--threads 2] [--baseline DIR]`` (``--baseline``: another
tree's ``python/`` folder, built, run in the same interleaved rounds, as in
``bench_analyze.py``).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benches"))

#: run by the child: the probe, then the command line (argv[1:] are its arguments; the
#: stamps go to the file in CONTACTLAB_TIMELINE_OUT as JSON at exit)
_PROBE = r"""
import atexit, importlib.abc, importlib.machinery, json, os, sys, threading, time
T0 = time.perf_counter()
stamps, sums = {}, {"window_s": 0.0, "windows": 0, "slot_wait_s": 0.0}
lock = threading.Lock()

def stamp(name, first=True):
    with lock:
        if not (first and name in stamps):
            stamps[name] = time.perf_counter() - T0

def patch(mod):
    name = mod.__name__
    if name == "contactlab.cli":
        stamp("cli imported")
    elif name == "contactlab.io.hdf5":
        orig = mod.check_structure
        def check_structure(path, *, file):
            main = threading.current_thread() is threading.main_thread()
            t = time.perf_counter()
            if not main:
                stamp("scan start")
            try:
                return orig(path, file=file)
            finally:
                if main:
                    with lock:
                        stamps.setdefault("main waits for scan", time.perf_counter() - t)
                else:
                    stamp("scan end")
        mod.check_structure = check_structure
    elif name == "contactlab.studies.tracking":
        orig_track = mod.track
        def track(*a, **k):
            stamp("track start")
            try:
                return orig_track(*a, **k)
            finally:
                stamp("track end")
        mod.track = track
        for fname in ("_tangential_window", "_normal_window"):
            f = getattr(mod, fname)
            def win(*a, _f=f, **k):
                stamp("first window")
                t = time.perf_counter()
                try:
                    return _f(*a, **k)
                finally:
                    with lock:
                        sums["window_s"] += time.perf_counter() - t
                        sums["windows"] += 1
            setattr(mod, fname, win)
        drain = mod._Dispatch.drain
        def drain_(self):
            stamp("read end")
            return drain(self)
        mod._Dispatch.drain = drain_
    elif name == "concurrent.futures":
        w = mod.wait
        def wait(*a, **k):
            t = time.perf_counter()
            try:
                return w(*a, **k)
            finally:
                with lock:
                    sums["slot_wait_s"] += time.perf_counter() - t
        mod.wait = wait
    elif name == "contactlab.commands.common":
        wj = mod.write_json
        def write_json(*a, **k):
            try:
                return wj(*a, **k)
            finally:
                stamp("json written")
        mod.write_json = write_json

WATCH = {"contactlab.cli", "contactlab.io.hdf5", "contactlab.studies.tracking",
         "concurrent.futures", "contactlab.commands.common"}

class Finder(importlib.abc.MetaPathFinder):
    def find_spec(self, fullname, path, target=None):
        if fullname not in WATCH:
            return None
        spec = importlib.machinery.PathFinder.find_spec(fullname, path)
        if spec is None or spec.loader is None:
            return spec
        loader = spec.loader
        run = loader.exec_module
        def exec_module(module):
            run(module)
            patch(module)
        loader.exec_module = exec_module
        return spec

sys.meta_path.insert(0, Finder())

@atexit.register
def done():
    stamp("exit")
    with open(os.environ["CONTACTLAB_TIMELINE_OUT"], "w") as fh:
        json.dump({"stamps": stamps, "sums": sums}, fh)

from contactlab.cli import main
sys.argv = ["contactlab", *sys.argv[1:]]
sys.exit(main())
"""

#: the phases, in the order they happen
PHASES = (
    "cli imported",
    "scan start",
    "scan end",
    "main waits for scan",
    "track start",
    "first window",
    "read end",
    "track end",
    "json written",
    "exit",
)


def run_once(path: Path, out: Path, threads: int | None, tree: Path | None = None) -> dict:
    env = dict(os.environ)
    if tree is not None:
        env["PYTHONPATH"] = str(tree)
    stamps_file = out.with_suffix(".timeline.json")
    env["CONTACTLAB_TIMELINE_OUT"] = str(stamps_file)
    if threads is not None:
        env["CONTACTLAB_ANALYZE_THREADS"] = str(threads)
    t0 = time.perf_counter()
    p = subprocess.Popen(
        [sys.executable, "-c", _PROBE, "analyze", str(path), "--json", str(out)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        env=env,
    )
    err = p.stderr.read() if p.stderr is not None else b""
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"analyze failed: {err.decode()[-2000:]}")
    got = json.loads(stamps_file.read_text())
    stamps_file.unlink()
    got["process"] = {"wall": wall, "cpu": usage.ru_utime + usage.ru_stime}
    return got


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=float, default=3e7)
    ap.add_argument("--recording", type=Path, help="an existing HDF5 recording (not written)")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--threads", type=int, help="CONTACTLAB_ANALYZE_THREADS for the command")
    ap.add_argument("--baseline", type=Path, help="another tree's python/ folder, run alike")
    args = ap.parse_args()
    trees: dict[str, Path | None] = {"this tree": None}
    if args.baseline is not None:
        from bench_analyze import compile_tree

        compile_tree(args.baseline)
        trees["BEFORE (--baseline)"] = args.baseline
    with tempfile.TemporaryDirectory(prefix="contactlab-timeline-") as d:
        tmp = Path(d)
        path = args.recording
        if path is None:
            import bench_track

            path = tmp / "t.h5"
            bench_track.write_file(path, int(args.samples))
        runs: dict[str, list[dict]] = {k: [] for k in trees}
        for r in range(args.rounds):  # interleaved, the order alternating
            order = list(trees) if r % 2 == 0 else list(trees)[::-1]
            for k in order:
                runs[k].append(run_once(path, tmp / f"out{r}.json", args.threads, trees[k]))
    load = ", ".join(f"{a:.2f}" for a in os.getloadavg())
    print(
        f"`contactlab analyze {path.name} --json` ({args.samples:.0e} samples), threads "
        f"{'default' if args.threads is None else args.threads}; load {load} after the runs; "
        f"{os.cpu_count()} CPUs; medians of {args.rounds} runs (seconds from the start)"
    )
    print("| phase | " + " | ".join(f"{k}: median (min-max)" for k in trees) + " |")
    print("|---|" + "---|" * len(trees))

    def row(name: str, get: Any) -> None:
        cells = []
        for k in trees:
            v = np.array([x for x in (get(r) for r in runs[k]) if x is not None])
            cells.append(f"{np.median(v):.3f} ({v.min():.3f}-{v.max():.3f})" if v.size else "")
        print(f"| {name} | " + " | ".join(cells) + " |")

    for name in PHASES:
        row(name, lambda r, n=name: r["stamps"].get(n))
    row("process wall", lambda r: r["process"]["wall"])
    row("process CPU (user + system)", lambda r: r["process"]["cpu"])
    row("windows' analysis, summed over threads", lambda r: r["sums"]["window_s"])
    row("reader waiting for a window slot", lambda r: r["sums"]["slot_wait_s"])
    print(f"windows: {runs['this tree'][0]['sums']['windows']}")


if __name__ == "__main__":
    main()
