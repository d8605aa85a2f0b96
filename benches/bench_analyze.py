"""Streamed ``contactlab analyze`` of a long HDF5 recording against the Masing kernel on the
same samples, in the same run (issue 33 item 4: the bar is 0.3 of the kernel's throughput).

Writes tangential HDF5 recordings of ``--samples`` samples (x and F float64, a sampling
interval attribute: :func:`bench_track.write_file`, a 10 Hz Masing loop at 10 kHz with sensor
noise) into a temporary folder and deletes them afterwards. Per size, interleaved round by
round:

- ``kernel``: ``Masing(h0, ac).force(x, out=buf)`` over the whole displacement in memory
  (this process; the row of ``speed_table.py``);
- ``analyze``: ``contactlab analyze FILE --json OUT`` as a user runs it (a new process:
  start-up, reading, the windows on the default helper threads, pooling, the JSON), wall time
  and CPU time (user + system of the process and its threads, ``os.wait4``);
- ``read``: :func:`contactlab.io.read_chunks` over the file alone (a new process), the floor
  the reading sets;
- ``analyze, one core``: the same command pinned to one CPU (``sched_setaffinity``: the
  reader, the structure scan and the window threads share it), the single-core figure;
  the ``analyze`` row uses every core the machine gives it (default helper threads).

Throughput = samples / median wall time; the ratio analyze / kernel is the figure (the kernel
is single-threaded in both). The note also gives the ratio of samples per CPU-second (the
kernel's thread time against the command's user + system time): on a loaded machine the
wall times of both stretch with the load, the CPU times much less. The JSON of every
analyze round is compared byte for byte with the first (the windows are deterministic).
``--baseline DIR`` also runs another tree's package (``PYTHONPATH=DIR``, e.g. a ``git
archive`` of an older commit's ``python/`` with its built ``_core`` copied in) in the same
interleaved rounds: before/after rows from one run, and whether its JSON is byte for byte
ours. The baseline's modules are compiled first (:func:`compile_tree`): uncompiled, each of
its runs compiled them, 0.13 s of CPU that was counted as its own.

Run: ``nice .venv/bin/python benches/bench_analyze.py [--samples 1e7 3e7] [--rounds 5]
[--baseline DIR]``.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benches"))

import bench_track  # noqa: E402

READ = (
    "import sys\nfrom contactlab.io import read_chunks\n"
    "n = sum(len(c) for c in read_chunks(sys.argv[1], chunk_size=1 << 20))\nprint(n)"
)


def child(
    cmd: list[str], env: dict[str, str] | None = None, cpu: int | None = None
) -> tuple[float, float]:
    """Wall and CPU seconds of a child process (which must succeed); ``cpu``: pinned to it."""

    def pin() -> None:
        if cpu is not None:
            os.sched_setaffinity(0, {cpu})

    t0 = time.perf_counter()
    p = subprocess.Popen(
        cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env, preexec_fn=pin
    )
    err = p.stderr.read() if p.stderr is not None else b""
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"{cmd} failed: {err.decode()[-2000:]}")
    return wall, usage.ru_utime + usage.ru_stime


def _one_cpu() -> int | None:
    """A CPU this process may run on (for the one-core rows), None without affinity."""
    try:
        return min(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return None


def compile_tree(folder: Path) -> int:
    """Compile every module under ``folder`` into its ``__pycache__`` (as ``make develop``
    does for this tree); the number of modules that failed to compile.

    A baseline copied from ``git archive`` has no compiled modules, and with
    ``PYTHONDONTWRITEBYTECODE=1`` in the environment every run of it compiles the package's
    modules anew: 0.13 s of CPU a run that the tree measured against does not pay (1e7
    samples on one core, the same code on both sides: 0.58 against 0.45 s of user time
    before the baseline was compiled, 0.46 against 0.46 after)."""
    import compileall

    bad = 0
    for pkg in sorted(p for p in folder.iterdir() if (p / "__init__.py").is_file()):
        bad += not compileall.compile_dir(str(pkg), quiet=1)
    return bad


def measure(
    path: Path, n: int, rounds: int, tmp: Path, baseline: Path | None = None
) -> dict[str, float]:
    import h5py

    import contactlab

    with h5py.File(path, "r") as f:
        x = f["x"][:]
    m = contactlab.Masing(h0=bench_track.H0, ac=bench_track.AC)
    buf = np.empty_like(x)
    exe = str(Path(sys.executable).with_name("contactlab"))
    cpu = _one_cpu()
    times: dict[str, list[float]] = {"kernel": [], "kernel_cpu": [], "read": []}
    outputs: dict[str, list[bytes]] = {}

    def kernel() -> None:
        t0, c0 = time.perf_counter(), time.thread_time()
        m.force(x, out=buf)
        times["kernel"].append(time.perf_counter() - t0)
        times["kernel_cpu"].append(time.thread_time() - c0)

    def analyze(label: str, env: dict[str, str] | None, pin: int | None) -> None:
        got = outputs.setdefault(label, [])
        out = tmp / f"{label}{len(got)}.json"
        w, c = child([exe, "analyze", str(path), "--json", str(out)], env, pin)
        times.setdefault(label, []).append(w)
        times.setdefault(f"{label}_cpu", []).append(c)
        got.append(out.read_bytes())
        out.unlink()

    def read() -> None:
        times["read"].append(child([sys.executable, "-c", READ, str(path)])[0])

    steps = [
        kernel,
        lambda: analyze("analyze", None, None),
        lambda: analyze("analyze_1", None, cpu),
        read,
    ]
    if baseline is not None:
        compile_tree(baseline)
        env = {**os.environ, "PYTHONPATH": str(baseline)}
        steps += [
            lambda: analyze("before", env, None),
            lambda: analyze("before_1", env, cpu),
        ]
    m.force(x, out=buf)  # warm-up
    k = len(steps)
    for r in range(rounds):
        for f in steps[r % k :] + steps[: r % k]:
            f()
    first = outputs["analyze"][0]
    med = {key: float(np.median(v)) for key, v in times.items()}
    med["same_json"] = float(all(o == first for v in outputs.values() for o in v))
    return med


def rows(
    sizes: list[int], rounds: int, baseline: Path | None = None
) -> list[tuple[str, str, str, float, str]]:
    """Rows (task, ours, reference, ratio, note) for ``speed_table.py``."""
    out = []
    with tempfile.TemporaryDirectory(prefix="contactlab-bench-analyze-") as d:
        tmp = Path(d)
        for n in sizes:
            path = tmp / f"t{n:.0e}.h5"
            bench_track.write_file(path, n)
            r = measure(path, n, rounds, tmp, baseline)
            path.unlink()
            ka, rd = n / r["kernel"] / 1e6, n / r["read"] / 1e6
            kc = n / r["kernel_cpu"] / 1e6
            same = "identical in every round" if r["same_json"] else "DIFFERS between rounds"
            if baseline is not None:
                same += " and builds"
            labels = [("analyze", "all cores"), ("analyze_1", "one core")]
            if baseline is not None:
                labels += [("before", "all cores, BEFORE"), ("before_1", "one core, BEFORE")]
            for key, what in labels:
                an = n / r[key] / 1e6
                cpu = r[f"{key}_cpu"]
                out.append(
                    (
                        f"`contactlab analyze --json`, {n:.0e}-sample HDF5, command line, {what}",
                        f"{r[key]:.2f} s wall ({an:.1f} M samples/s), "
                        f"{cpu:.2f} s CPU ({n / cpu / 1e6:.1f} M/CPU-s)",
                        f"Masing kernel {ka:.0f} M/s, {kc:.0f} M/CPU-s (one thread); "
                        f"read_chunks alone (new process) {r['read']:.2f} s ({rd:.0f} M/s)",
                        an / ka,
                        f"of the kernel (by CPU time: {n / cpu / 1e6 / kc:.2f}); JSON {same}",
                    )
                )
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=float, nargs="+", default=[1e7, 3e7])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--baseline", type=Path, help="another tree's python/ folder, run alike")
    args = ap.parse_args()
    print(
        f"load {', '.join(f'{a:.2f}' for a in os.getloadavg())}; {os.cpu_count()} CPUs; "
        f"medians of {args.rounds} interleaved rounds"
    )
    print("| task | contactlab | reference | ratio | note |")
    print("|---|---|---|---|---|")
    for task, ours, ref, ratio, note in rows(
        [int(s) for s in args.samples], args.rounds, args.baseline
    ):
        print(f"| {task} | {ours} | {ref} | {ratio:.2f} | {note} |")


if __name__ == "__main__":
    main()
