"""Paired A/B of ``contactlab analyze --json`` on one core: this tree against another tree's
package (``--baseline``: a ``python/`` folder with its built ``_core``, e.g. a ``git archive``
of an older commit's ``python/`` with its ``_core`` copied in), alternating which runs first,
CPU time (user + system, ``os.wait4``) of each run pinned to one CPU (serial windows).

Both trees' modules are compiled first (``bench_analyze.compile_tree``). Prints the
medians, the median paired difference of CPU and in how many rounds this tree
was lower: a difference of a few percent that the medians of separate rounds do not show
on a loaded machine (issue 33 item 4). Writes nothing but a temporary JSON.

Run: ``nice .venv/bin/python benches/bench_analyze_paired.py FILE.h5 --baseline DIR
[--rounds 12]`` (FILE: e.g. ``bench_track.write_file``'s recording).
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


def run(exe: str, path: str, out: str, env: dict[str, str], cpu: int) -> tuple[float, float]:
    """Wall and CPU seconds of one ``analyze`` pinned to ``cpu`` (which must succeed)."""
    t0 = time.perf_counter()
    p = subprocess.Popen(
        [exe, "analyze", path, "--json", out],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        env=env,
        preexec_fn=lambda: os.sched_setaffinity(0, {cpu}),
    )
    _, status, ru = os.wait4(p.pid, 0)
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"analyze {path} failed with status {status}")
    return time.perf_counter() - t0, ru.ru_utime + ru.ru_stime


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("file")
    ap.add_argument("--baseline", type=Path, required=True)
    ap.add_argument("--rounds", type=int, default=12)
    args = ap.parse_args()
    exe = str(Path(sys.executable).with_name("contactlab"))
    cpu = min(os.sched_getaffinity(0))
    # both trees compiled first (``bench_analyze.compile_tree``): with
    # PYTHONDONTWRITEBYTECODE=1 a tree without its __pycache__ (a ``git archive`` copy) or
    # with modules edited since it was compiled compiles them in every run, ~0.07 s of CPU
    # at 1e7 samples that the other tree does not pay
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from bench_analyze import compile_tree

    for tree in (args.baseline, Path(__file__).resolve().parents[1] / "python"):
        if compile_tree(tree):
            raise SystemExit(f"{tree}: a module does not compile")
    base = {**os.environ, "PYTHONPATH": str(args.baseline)}
    new = dict(os.environ)
    rows: dict[str, list[tuple[float, float]]] = {"b": [], "n": []}
    with tempfile.TemporaryDirectory(prefix="contactlab-paired-") as d:
        out = str(Path(d) / "o.json")
        for r in range(args.rounds):
            order = [("b", base), ("n", new)] if r % 2 else [("n", new), ("b", base)]
            for k, env in order:
                rows[k].append(run(exe, args.file, out, env, cpu))
    diff = [n[1] - b[1] for n, b in zip(rows["n"], rows["b"], strict=True)]
    med = {k: (statistics.median(w for w, _ in v), statistics.median(c for _, c in v))
           for k, v in rows.items()}  # fmt: skip
    print(
        f"{args.file}: {args.rounds} paired rounds, one core: CPU before {med['b'][1]:.3f} s, "
        f"after {med['n'][1]:.3f} s, median paired difference "
        f"{statistics.median(diff) * 1e3:+.1f} ms, after lower in "
        f"{sum(x < 0 for x in diff)}/{args.rounds}; wall before {med['b'][0]:.2f} s, after "
        f"{med['n'][0]:.2f} s; load {os.getloadavg()[0]:.1f}"
    )


if __name__ == "__main__":
    main()
