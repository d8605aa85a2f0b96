"""Long recordings end to end: throughput and peak memory of chunked reading, per-cycle
energies, ``track``/``analyze --stream`` and whole-file ``analyze``, against the Masing kernel
alone on the same samples in the same run (issue 9).

Writes a tangential HDF5 recording of ``--samples`` samples (default 1e8: x and F as float64
with a sampling interval attribute, 1.6 GB) into a temporary folder, deletes it afterwards,
and runs each stage in a child process so that its peak RSS is its own (``os.wait4``).

Stages (``samples/s`` = recording samples per second of wall time):

- ``masing``: ``MasingOperator.push`` over the same displacement, chunk by chunk — the
  reference every ratio is taken against (measured while writing the file);
- ``read``: :func:`contactlab.io.read_chunks` alone (HDF5 slices, unit conversion, checks);
- ``cycles``: read + the per-cycle kernel (crossings, ∮F dx, amplitude, offset per cycle);
- ``track``: :func:`contactlab.track` with ``every="auto"`` (= ``analyze --stream``): windows
  analysed on one helper thread while reading on (the default), on ``--workers`` threads,
  serially (``threads=0``), and on ``--workers`` processes;
- ``analyze``: ``contactlab analyze`` of the long file as a user runs it (auto-streamed,
  windows on two helper threads), wall and CPU time (M samples per CPU-second) and peak RSS;
- ``whole``: ``contactlab analyze`` of a ``--whole-samples`` file (default 1e7): as a user
  runs it (longer than 2^19 samples: streamed and pooled automatically), with ``--whole`` (read
  into memory: the issue's "before") and with ``--stream``;
- ``study``: ``--study-files`` recordings analysed serially, on a process pool and on a thread
  pool (``run_study(executor=...)``), after a warm-up, in ``--study-repeat`` interleaved
  runs: median speed-up, its range and the ratio of the best times. ``--study-mix K`` makes
  every K-th recording eight times as long (a real study's files differ: the one-at-a-time
  collection used to leave a worker idle behind a long file);

Run: ``nice .venv/bin/python benches/bench_track.py [--samples 1e8] [--workers 2]``
(tens of minutes at 1e8 on 2 cores; ``--samples 2e6`` for a quick look).
``--recording FILE`` analyses a file an earlier run wrote (x, F) instead of writing one (the
kernel reference is then timed on its displacement), ``--repeat N`` runs the analyze stage N
times and prints the medians: e.g. ``--recording t1e8.h5 --skip read,cycles,track,
track-serial,track-threads,whole,study --analyze-threads 2 --repeat 3``. Run it with another
build's interpreter for that build's figures (the stage runs ``sys.executable -m contactlab``).
``benches/compare_track.py`` checks that two builds' windows agree.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

FS, FREQ, AMP, H0, AC = 10_000.0, 10.0, 20e-6, 40.0, 4e4
CHUNK = 1 << 20


def _signal(a: int, b: int) -> np.ndarray:
    t = np.arange(a, b, dtype=np.float64) / FS
    return AMP * np.sin(2 * np.pi * FREQ * t)


def write_file(path: Path, n: int, seed: int = 12) -> dict:
    """x (0.1 % sensor noise), F (Masing of the true x, 1 % noise) in chunks; returns the
    Masing kernel's time on them. (Noise on the true x would be real jitter: the force would
    run minor loops around every jitter, dissipating more than the smooth loop.)"""
    import h5py

    import contactlab

    rng = np.random.default_rng(seed)
    op = contactlab.Masing(h0=H0, ac=AC).operator()
    t_kernel = 0.0
    t0 = time.perf_counter()
    with h5py.File(path, "w") as f:
        dx = f.create_dataset("x", shape=(n,), dtype="f8", chunks=(1 << 16,))
        dF = f.create_dataset("F", shape=(n,), dtype="f8", chunks=(1 << 16,))
        for ds, unit in ((dx, "m"), (dF, "N")):
            ds.attrs["unit"] = unit
            ds.attrs["dt"] = 1.0 / FS
        for a in range(0, n, CHUNK):
            b = min(a + CHUNK, n)
            x = _signal(a, b)
            k0 = time.perf_counter()
            F = op.push(x)
            t_kernel += time.perf_counter() - k0
            dx[a:b] = x + 2e-8 * rng.standard_normal(b - a)
            dF[a:b] = F + 0.4 * rng.standard_normal(b - a)
    return {"write_s": time.perf_counter() - t0, "masing_s": t_kernel, "bytes": path.stat().st_size}


def kernel_on_file(path: Path) -> dict:
    """The Masing kernel's time on the displacement of an existing recording (``--recording``:
    a file written by an earlier run is analysed again, not rewritten), chunk by chunk as
    :func:`write_file` times it; returns its size in samples too."""
    import h5py

    import contactlab

    op = contactlab.Masing(h0=H0, ac=AC).operator()
    t_kernel = 0.0
    with h5py.File(path, "r") as f:
        n = int(f["x"].shape[0])
        for a in range(0, n, CHUNK):
            x = f["x"][a : min(a + CHUNK, n)]
            k0 = time.perf_counter()
            op.push(x)
            t_kernel += time.perf_counter() - k0
    return {"masing_s": t_kernel, "bytes": path.stat().st_size, "n": n}


def stage(name: str, path: str, workers: int) -> dict:
    """Run in the child: one stage on ``path``; returns its wall and CPU time (this process,
    imports included) and a check value."""
    import resource

    import h5py  # noqa: F401  (imported before the clock starts)

    from contactlab.io import read_chunks

    t0 = time.perf_counter()
    out: dict = {}
    if name == "read":
        n = sum(len(c) for c in read_chunks(path, chunk_size=CHUNK))
        out["n"] = n
    elif name == "cycles":
        from contactlab.studies.cycles import CycleState, block_cycles

        s, n_cyc = CycleState(), 0
        for c in read_chunks(path, chunk_size=CHUNK):
            n_cyc += block_cycles(c.t, c["x"], c["F"], c["x"], c.meta["offset"], s).energy.size
        out["cycles"] = n_cyc
    elif name.startswith("track"):
        from concurrent.futures import ProcessPoolExecutor

        import contactlab

        if name == "track-serial":
            r = contactlab.track(path, every="auto", threads=0)
        elif name == "track-threads":
            r = contactlab.track(path, every="auto", threads=workers)
        elif workers > 1:
            import resource

            with ProcessPoolExecutor(workers) as ex:
                r = contactlab.track(path, every="auto", executor=ex)
            # the workers have been waited for: the largest of their peaks
            out["worker_peak_rss_mb"] = (
                resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
            )
        else:
            r = contactlab.track(path, every="auto")
        comb = r.combined()
        out.update(
            windows=len(r.rows),
            cycles=comb.get("n_cycles"),
            h0=comb.get("h0"),
            h0_stderr=comb.get("h0_stderr"),
        )
    else:
        raise SystemExit(f"unknown stage {name}")
    out["wall_s"] = time.perf_counter() - t0
    ru = resource.getrusage(resource.RUSAGE_SELF)
    out["cpu_s"] = ru.ru_utime + ru.ru_stime
    return out


def child(cmd: list[str], env: dict | None = None) -> tuple[float, float, str, float]:
    """Wall time (s), peak RSS (MB) of a child process, its stdout and its CPU time (s)."""
    t0 = time.perf_counter()
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, text=True, env=env)
    assert p.stdout is not None
    text = p.stdout.read()
    _, status, usage = os.wait4(p.pid, 0)
    p.returncode = os.waitstatus_to_exitcode(status)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        raise SystemExit(f"{cmd} failed with {p.returncode}")
    # ru_maxrss of the waited child (KiB on Linux); pool workers are its children, so their
    # peaks are not in it: see the track stage's note
    return wall, usage.ru_maxrss / 1024.0, text, usage.ru_utime + usage.ru_stime


def run_stage(name: str, path: Path, workers: int) -> dict:
    cmd = [
        sys.executable,
        __file__,
        "--stage",
        name,
        "--file",
        str(path),
        "--workers",
        str(workers),
    ]
    wall, rss, text, _cpu = child(cmd)
    d = json.loads(text.strip().splitlines()[-1])
    d.update(proc_wall_s=wall, peak_rss_mb=rss)
    return d


def many_recordings(tmp: Path, n_files: int, workers: int, repeat: int, mix: int = 0) -> dict:
    from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

    from contactlab.io import write_recording
    from contactlab.studies import run_study
    from contactlab.synthetic.tangential import synthetic_recording

    files = []
    for i in range(n_files):
        rec = synthetic_recording(
            h0=H0,
            ac=AC,
            amplitude=AMP,
            n_cycles=40 * (8 if mix and i % mix == 0 else 1),
            fs=2000.0,
            frequency=2.0,
            noise=0.01,
            seed=500 + i,
        )
        p = tmp / f"Al-Al_W50N_A20um_{i:03d}.h5"
        write_recording(p, rec)
        files.append(p)
    # warm-up: the first study in a process pays lazy imports and first-call costs that the
    # pool's forked workers would not (a serial-first timing gave x2.9 on 2 cores)
    a = run_study(files[:2], progress=False, keep_recordings=False)
    serial, pooled, threaded = [], [], []
    with ProcessPoolExecutor(workers) as ex, ThreadPoolExecutor(workers) as tx:
        list(ex.map(abs, range(workers)))  # start the workers before timing
        b = run_study(files[:workers], progress=False, executor=ex)  # and warm them up
        same = True
        for r in range(repeat):  # interleaved, alternating order within a pair
            runs = [("s", None), ("p", ex), ("t", tx)]
            for kind, executor in runs if r % 2 == 0 else runs[::-1]:
                t0 = time.perf_counter()
                res = run_study(files, progress=False, executor=executor, keep_recordings=False)
                dt = time.perf_counter() - t0
                {"s": serial, "p": pooled, "t": threaded}[kind].append(dt)
                if kind == "s":
                    a = res
                else:
                    b = res
                    same = same and a.to_csv("tangential") == b.to_csv("tangential")
    med = statistics.median
    return {
        "files": n_files,
        "mix": mix,
        "repeat": repeat,
        "serial_s": med(serial),
        "pool_s": med(pooled),
        "threads_s": med(threaded),
        "pool_up": sorted(s / p for s, p in zip(serial, pooled, strict=True)),
        "threads_up": sorted(s / p for s, p in zip(serial, threaded, strict=True)),
        "pool_minmin": min(serial) / min(pooled),
        "threads_minmin": min(serial) / min(threaded),
        "identical": same,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--samples", type=float, default=1e8)
    ap.add_argument("--whole-samples", type=float, default=1e7)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--study-files", type=int, default=12)
    ap.add_argument(
        "--study-mix", type=int, default=0, help="every K-th study recording 8x longer (0: none)"
    )
    ap.add_argument(
        "--study-repeat", type=int, default=5, help="interleaved serial/pool pairs of the study"
    )
    ap.add_argument(
        "--skip",
        default="",
        help="comma-separated stages to skip (read, cycles, track, track-threads, "
        "track-serial, analyze, whole, study)",
    )
    ap.add_argument(
        "--analyze-threads",
        default="",
        help="comma-separated CONTACTLAB_ANALYZE_THREADS values to run the analyze stage with "
        "(e.g. 0,1,2: serial, one and two helper threads); default: as a user runs it",
    )
    ap.add_argument(
        "--recording",
        help="analyse this tangential HDF5 recording (written by an earlier run, x and F) "
        "instead of writing one; it is not deleted. --samples is then its length",
    )
    ap.add_argument(
        "--repeat", type=int, default=1, help="runs of the analyze stage (medians printed)"
    )
    ap.add_argument("--stage", help=argparse.SUPPRESS)
    ap.add_argument("--file", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.stage:
        print(json.dumps(stage(args.stage, args.file, args.workers)))
        return
    skip = set(filter(None, args.skip.split(",")))
    n = int(args.samples)
    # the package's modules byte-compiled, as an installation leaves them (pip compiles at
    # install; an editable build under PYTHONDONTWRITEBYTECODE would compile them in every
    # timed run: 0.13 s of a 5 s run)
    import compileall

    import contactlab

    compileall.compile_dir(str(Path(contactlab.__file__).parent), quiet=1)
    tmp = Path(tempfile.mkdtemp(prefix="contactlab-bench-track-"))
    try:
        print(f"cores: {os.cpu_count()}, load average {os.getloadavg()[0]:.1f}")
        if args.recording:
            big = Path(args.recording)
            w = kernel_on_file(big)
            n = w["n"]
            print(f"recording {big}: {n:.3g} samples, {w['bytes'] / 1e9:.2f} GB")
        else:
            big = tmp / "long.h5"
            w = write_file(big, n)
            print(f"wrote {n:.3g} samples, {w['bytes'] / 1e9:.2f} GB in {w['write_s']:.1f} s")
        m_rate = n / w["masing_s"]
        print(
            f"reference  Masing kernel alone (push, chunks of {CHUNK}): "
            f"{m_rate / 1e6:8.1f} M samples/s"
        )
        stages = [
            ("read", 1),
            ("cycles", 1),
            ("track", 1),
            ("track-threads", args.workers),
            ("track-serial", 1),
            ("track", args.workers),
        ]
        for name, wk in stages:
            if name in skip:
                continue
            d = run_stage(name, big, wk)
            rate = n / d["wall_s"]
            label = (
                f"{name} ({wk} proc)"
                if name == "track" and wk > 1
                else f"track ({wk} threads)"
                if name == "track-threads"
                else name
            )
            extra = {
                k: v
                for k, v in d.items()
                if k not in ("wall_s", "proc_wall_s", "peak_rss_mb", "n", "cpu_s")
            }
            print(
                f"{label:<16} {d['wall_s']:8.1f} s {rate / 1e6:8.2f} M samples/s  "
                f"ratio to Masing {rate / m_rate:6.3f}  CPU {d['cpu_s']:7.1f} s  "
                f"peak RSS {d['peak_rss_mb']:6.0f} MB"
                f"{'' if wk == 1 else ' (parent only)'}  {extra}"
            )
        if "analyze" not in skip:
            # the bar: `contactlab analyze` as a user runs it (auto-streamed)
            cmd = [sys.executable, "-m", "contactlab", "analyze", str(big), "--model",
                   "tangential", "--no-progress", "--json", str(tmp / "big.json")]  # fmt: skip
            for threads in args.analyze_threads.split(",") if args.analyze_threads else [""]:
                env = dict(os.environ)
                if threads:
                    env["CONTACTLAB_ANALYZE_THREADS"] = threads
                label = f"analyze (CLI{', threads ' + threads if threads else ''})"
                runs = []
                for _ in range(args.repeat):
                    wall, rss, _, cpu = child(cmd, env)
                    runs.append((wall, cpu, rss))
                    h0 = json.loads((tmp / "big.json").read_text())
                    print(
                        f"{label:<24} {wall:8.1f} s {n / wall / 1e6:8.2f} M samples/s  "
                        f"ratio to Masing {n / wall / m_rate:6.3f}  CPU {cpu:7.1f} s "
                        f"({n / cpu / 1e6:.2f} M samples per CPU-second)  peak RSS {rss:6.0f} MB"
                        f"  h0 = {h0['h0']:.6f} ± {h0['h0_stderr']:.2g} N  "
                        f"load {os.getloadavg()[0]:.1f}"
                    )
                if len(runs) > 1:
                    wall, cpu, rss = (float(np.median(c)) for c in zip(*runs, strict=True))
                    print(
                        f"{label + ' median':<24} {wall:8.1f} s {n / wall / 1e6:8.2f} M samples/s"
                        f"  ratio to Masing {n / wall / m_rate:6.3f}  CPU {cpu:7.1f} s  "
                        f"peak RSS {rss:6.0f} MB (of {len(runs)} runs)"
                    )
        if not args.recording:
            big.unlink()
        if "whole" not in skip:
            nw = int(args.whole_samples)
            wf = tmp / "whole.h5"
            write_file(wf, nw, seed=13)
            for label, extra in (
                ("analyze", []),
                ("analyze --whole", ["--whole"]),
                ("analyze --stream", ["--stream"]),
            ):
                cmd = [
                    sys.executable,
                    "-m",
                    "contactlab",
                    "analyze",
                    str(wf),
                    "--model",
                    "tangential",
                    "--no-progress",
                    "--json",
                    str(tmp / "o.json"),
                    *extra,
                ]
                wall, rss, _, cpu = child(cmd)
                print(
                    f"{label:<22} {nw:.0e} samples: {wall:6.1f} s "
                    f"{nw / wall / 1e6:6.2f} M samples/s, CPU {cpu:5.1f} s "
                    f"({nw / cpu / 1e6:.2f} M/CPU-s), peak RSS {rss:6.0f} MB"
                )
            wf.unlink()
        if "study" not in skip:
            s = many_recordings(
                tmp, args.study_files, args.workers, args.study_repeat, args.study_mix
            )
            med = statistics.median
            for key, label in (("pool", "processes"), ("threads", "threads")):
                ups = s[f"{key}_up"]
                print(
                    f"study of {s['files']} recordings"
                    + (f" (every {s['mix']}th 8x longer)" if s["mix"] else "")
                    + f", {s['repeat']} interleaved pairs: serial "
                    f"{s['serial_s']:.2f} s, {args.workers} {label} {s[f'{key}_s']:.2f} s: "
                    f"x{med(ups):.2f} median (range {ups[0]:.2f}-{ups[-1]:.2f}, min/min "
                    f"x{s[f'{key}_minmin']:.2f}), identical: {s['identical']}"
                )
        print(f"load average at the end {os.getloadavg()[0]:.1f}")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
