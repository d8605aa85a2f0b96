"""CPU of a streamed ``analyze``'s per-window Python stages, and what the window's big passes
cost the Python that follows them (issue 33 item 4: the per-window Python, about 40 % of a
serial track).

- Stages: :func:`contactlab.studies.tracking.track` of a long HDF5 recording
  (``bench_track.write_file``) as ``analyze --json`` runs it, serially, with the Rust
  kernels of ``bench_analyze_parts`` and the window's Python stages (``steps.fit``,
  ``lag.annotate``, ``start_values``, ``drift_covariance``, ``derived_quantities``,
  ``_reversals``, ``smooth_turn_times``, ...) wrapped: each one's CPU seconds on the calling
  thread less those of the wrapped calls inside it, medians over ``--rounds`` tracks.
- Cold caches: ``smooth_turn_times`` (a small Python stage between two window passes) on
  the turn instants the track gave it, timed in the track, on its own in a loop (warm), and
  on its own right after a 24-MB numpy pass (as a window's fold or detrending pass leaves
  the caches): the same call's CPU in the three settings.

Run: ``nice .venv/bin/python benches/bench_analyze_python_stages.py [--samples 3e7]
[--rounds 5] [--recording FILE]``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benches"))

import bench_analyze_parts as parts  # noqa: E402
import bench_track  # noqa: E402


def _track(path: Path) -> None:
    from contactlab.studies import tracking

    tracking.track(path, "auto", kind="tangential", keep_documents=True, threads=0, cycles=False)


def stages(path: Path, rounds: int) -> None:
    from contactlab import _core
    from contactlab.reversals import ReversalDetector
    from contactlab.studies import tracking
    from contactlab.tangential import analysis, lag, preprocess, steps, window

    targets: list[tuple[Any, str]] = [(_core, k) for k in parts.KERNELS if hasattr(_core, k)]
    targets += [
        (ReversalDetector, "push"),
        (tracking, "block_cycles"),
        (os, "preadv"),
        (window, "_analyze"),
        (window, "window_detrended"),
        (window, "_reversals"),
        (preprocess, "smooth_turn_times"),
        (preprocess, "_loop_of_fold"),
        (steps, "fit"),
        (steps, "start_values"),
        (steps, "fit_data"),
        (steps, "drift_covariance"),
        (lag, "annotate"),
        (analysis, "derived_quantities"),
    ]
    stats: dict[str, list[float]] = {}
    saved = [(o, k, getattr(o, k)) for o, k in targets]
    for o, k, f in saved:
        setattr(o, k, parts._wrapped(f, f"{getattr(o, '__name__', o)}.{k}", stats))
    try:
        _track(path)  # warm
        runs = []
        for _ in range(rounds):
            stats.clear()
            c0 = time.process_time()
            _track(path)
            cpu = time.process_time() - c0
            d = {k: v[1] for k, v in stats.items()}
            d["the rest (interpreter)"] = cpu - sum(d.values())
            d["total"] = cpu
            runs.append((d, {k: int(v[0]) for k, v in stats.items()}))
    finally:
        for o, k, f in saved:
            setattr(o, k, f)
    med = {k: statistics.median(r[0].get(k, 0.0) for r in runs) for k in runs[0][0]}
    print(f"\nserial track, medians of {rounds} rounds by CPU, load {os.getloadavg()[0]:.1f}\n")
    print("| part | CPU s | calls | share |\n|---|---|---|---|")
    for k in sorted(med, key=lambda k: (k == "total", -med[k])):
        print(f"| `{k}` | {med[k]:.4f} | {runs[0][1].get(k, '')} | {med[k] / med['total']:.3f} |")


def cold(path: Path) -> None:
    from contactlab.tangential import preprocess

    orig = preprocess.smooth_turn_times
    caps: list[np.ndarray] = []
    took: list[float] = []

    def wrapped(v: Any, *a: Any, **k: Any) -> Any:
        caps.append(np.array(v))
        c0 = time.process_time()
        r = orig(v, *a, **k)
        took.append(time.process_time() - c0)
        return r

    preprocess.smooth_turn_times = wrapped
    try:
        _track(path)
        _track(path)
    finally:
        preprocess.smooth_turn_times = orig
    half = len(took) // 2
    inputs = caps[half:]
    big = np.random.default_rng(0).normal(size=3_000_000)
    out = np.empty_like(big)
    res = {"in the track": statistics.median(took[half:])}
    for label, trash in (("on its own (warm)", False), ("after a 24-MB pass", True)):
        ts = []
        for _ in range(3):
            for v in inputs:
                if trash:
                    np.multiply(big, 1.0001, out=out)
                c0 = time.process_time()
                orig(v)
                ts.append(time.process_time() - c0)
        res[label] = statistics.median(ts)
    print(f"\nsmooth_turn_times, {inputs[0].size} turn instants, median CPU a call:")
    for k, v in res.items():
        print(f"- {k}: {v * 1e6:.0f} us")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=float, default=3e7)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--recording", type=Path)
    args = ap.parse_args()
    from contactlab._malloc import keep_freed_memory

    keep_freed_memory()  # as the command line
    with tempfile.TemporaryDirectory(prefix="contactlab-bench-stages-") as d:
        path = args.recording
        if path is None:
            path = Path(d) / "rec.h5"
            bench_track.write_file(path, int(args.samples))
        stages(path, args.rounds)
        cold(path)


if __name__ == "__main__":
    main()
