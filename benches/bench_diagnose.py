"""``contactlab diagnose`` on a long tangential recording, end to end (issue 9: ≤ 3 s for
1e6 samples): wall time, CPU time and peak RSS of the CLI, against references measured in
the same run so that the figures can be read under load.

Writes tangential recordings of ``--samples`` samples (default 1e6) into a temporary folder
(HDF5, x and F as float64, or CSV with ``--format csv``), runs ``contactlab diagnose FILE
--model tangential --json OUT`` on each in a child process (``os.wait4``: its own wall, user +
system CPU and peak RSS) and prints the effects named.

Recordings (10 kHz, excitation 10 Hz in three amplitude blocks, x noise 0.2 % of its RMS,
F noise 1 % of its RMS, h0 = 40 N, ac = 1e5 1/m):

- ``clean``: the Masing force only (the diagnosis should name nothing);
- ``offset``: plus a force-sensor bias of 1 N (``force_offset``);
- ``damping``: plus a viscous force ``c ẋ`` of 2 % of the force RMS (``viscous_damping``).

References, same run, same machine load:

- ``masing``: ``Masing(h0, ac).force`` over the same 1e6 displacements (best of 5);
- ``startup``: ``contactlab --help`` in a child (interpreter start and CLI import);
- ``import``: CPU time of a child importing numpy, scipy.optimize and h5py (the floor of
  any run of the CLI on an HDF5 file).

``--threads-ab`` also runs each recording with ``CONTACTLAB_DIAGNOSE_THREADS=1`` and ``=2``
(threads for the candidate fits; the default is one per idle core) to show what threads
give; the load average is printed because on a shared machine the wall time is mostly a
matter of it.

Run: ``nice .venv/bin/python benches/bench_diagnose.py [--samples 1e6] [--repeat 3]
[--format h5|csv] [--threads-ab] [--profile]``. ``--profile`` runs cProfile on the CLI path
of the first recording and prints the functions with the largest cumulative and own time.
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

import numpy as np

FS, FREQ, H0, AC = 10_000.0, 10.0, 40.0, 1e5
AMPS = (0.8 / AC, 2.0 / AC, 5.0 / AC)


def displacement(n: int) -> np.ndarray:
    """Sine at FREQ in three amplitude blocks (each a third of the record), smooth joins."""
    t = np.arange(n) / FS
    env = np.interp(t, np.linspace(0.0, t[-1], 4), [AMPS[0], AMPS[1], AMPS[2], AMPS[2]])
    return env * np.sin(2 * np.pi * FREQ * t)


def recording(kind: str, n: int, seed: int) -> dict[str, np.ndarray]:
    import contactlab

    rng = np.random.default_rng(seed)
    x = displacement(n)
    F = contactlab.Masing(H0, AC).force(x)
    if kind == "offset":
        F = F + 1.0
    elif kind == "damping":
        xd = np.gradient(x, 1.0 / FS)
        F = F + 0.02 * np.sqrt(np.mean(F * F)) / np.sqrt(np.mean(xd * xd)) * xd
    elif kind != "clean":
        raise SystemExit(f"unknown recording {kind}")
    rms = lambda a: float(np.sqrt(np.mean(a * a)))  # noqa: E731
    xm = x + 0.002 * rms(x) * rng.standard_normal(n)
    Fm = F + 0.01 * rms(F) * rng.standard_normal(n)
    return {"t": np.arange(n) / FS, "x": xm, "F": Fm}


def write(path: Path, rec: dict[str, np.ndarray]) -> None:
    from contactlab.io import Recording, write_recording

    write_recording(
        path, Recording(t=rec["t"], data={"x": rec["x"], "F": rec["F"]}, units={"x": "m", "F": "N"})
    )


def masing_reference(n: int) -> float:
    """Best of 5 of the Masing kernel over the recording's displacement (s)."""
    import contactlab

    x = displacement(n)
    m = contactlab.Masing(H0, AC)
    best = np.inf
    for _ in range(5):
        t0 = time.perf_counter()
        m.force(x)
        best = min(best, time.perf_counter() - t0)
    return best


def run_cli(args: list[str], env: dict[str, str] | None = None, python: bool = False) -> dict:
    """The CLI (or, with ``python``, the interpreter) with ``args`` in a child process."""
    exe = sys.executable if python else str(Path(sys.executable).with_name("contactlab"))
    cmd = [exe, *args]
    with tempfile.TemporaryFile() as errf:
        t0 = time.perf_counter()
        p = subprocess.Popen(
            cmd, stdout=subprocess.PIPE, stderr=errf, env={**os.environ, **(env or {})}
        )
        assert p.stdout is not None
        out = p.stdout.read()
        _, status, usage = os.wait4(p.pid, 0)
        wall = time.perf_counter() - t0
        errf.seek(0)
        err = errf.read()
    p.returncode = os.waitstatus_to_exitcode(status)
    if p.returncode != 0:
        raise SystemExit(f"{cmd} failed with {p.returncode}:\n{err.decode()}")
    return {
        "wall_s": wall,
        "cpu_s": usage.ru_utime + usage.ru_stime,
        "peak_rss_mb": usage.ru_maxrss / 1024.0,
        "stdout": out.decode(),
    }


def profile(path: Path, out: Path) -> None:
    import cProfile
    import pstats

    from contactlab.cli import main

    pr = cProfile.Profile()
    pr.enable()
    try:
        main(["diagnose", str(path), "--model", "tangential", "--json", str(out)])
    finally:
        pr.disable()
    st = pstats.Stats(pr)
    st.sort_stats("cumulative").print_stats(45)
    st.sort_stats("tottime").print_stats(30)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--samples", type=float, default=1e6)
    ap.add_argument("--repeat", type=int, default=3, help="CLI runs per recording (best kept)")
    ap.add_argument("--format", choices=["h5", "csv"], default="h5")
    ap.add_argument("--recordings", default="clean,offset,damping")
    ap.add_argument("--seed", type=int, default=9101)
    ap.add_argument("--profile", action="store_true", help="cProfile the CLI on the first one")
    ap.add_argument("--keep", metavar="DIR", help="also copy the JSON reports into DIR")
    ap.add_argument(
        "--threads-ab",
        action="store_true",
        help="also run each with CONTACTLAB_DIAGNOSE_THREADS=1 and =2",
    )
    args = ap.parse_args()
    n = int(args.samples)
    kinds = [k for k in args.recordings.split(",") if k]
    with tempfile.TemporaryDirectory(prefix="bench_diagnose_") as tmp:
        tmpd = Path(tmp)
        files = {}
        for i, kind in enumerate(kinds):
            files[kind] = tmpd / f"{kind}.{args.format}"
            write(files[kind], recording(kind, n, args.seed + i))
        if args.profile:
            profile(files[kinds[0]], tmpd / "profile.json")
            return
        t_masing = masing_reference(n)
        t_start = min(run_cli(["--help"])["wall_s"] for _ in range(3))
        floor = [run_cli(["-c", "import numpy, scipy.optimize, h5py"], python=True)]
        floor += [run_cli(["-c", "import numpy, scipy.optimize, h5py"], python=True)]
        t_imp = min(r["cpu_s"] for r in floor)
        print(
            f"{n:.3g} samples ({args.format}), load average {os.getloadavg()[0]:.1f} on "
            f"{os.cpu_count()} cores; references: Masing kernel {t_masing * 1e3:.1f} ms "
            f"({n / t_masing / 1e6:.0f} M samples/s), CLI start-up {t_start:.2f} s wall, "
            f"import numpy+scipy.optimize+h5py {t_imp:.2f} s CPU"
        )
        print(
            f"{'recording':<10}{'run':<9}{'wall s':>8}{'CPU s':>8}{'RSS MB':>8}"
            f"{'/ Masing':>10}{'/ start':>9}  effects"
        )
        variants: list[tuple[str, dict[str, str]]] = [("default", {})]
        if args.threads_ab:
            variants.append(("1 thread", {"CONTACTLAB_DIAGNOSE_THREADS": "1"}))
            variants.append(("2 thread", {"CONTACTLAB_DIAGNOSE_THREADS": "2"}))
        rows = []
        for kind in kinds:
            out = tmpd / f"{kind}.json"
            for label, env in variants:
                cmd = ["diagnose", str(files[kind]), "--model", "tangential", "--json", str(out)]
                runs = [run_cli(cmd, env) for _ in range(args.repeat)]
                best = min(runs, key=lambda r: r["wall_s"])
                rep = json.loads(out.read_text())
                if args.keep:
                    Path(args.keep).mkdir(parents=True, exist_ok=True)
                    tag = label.replace(" ", "")
                    (Path(args.keep) / f"{kind}_{tag}.json").write_text(out.read_text())
                names = [e["name"] for e in rep["effects"]] or ["-"]
                row = {k: v for k, v in best.items() if k != "stdout"}
                rows.append({"recording": kind, "run": label, **row})
                print(
                    f"{kind:<10}{label:<9}{best['wall_s']:>8.2f}{best['cpu_s']:>8.2f}"
                    f"{best['peak_rss_mb']:>8.0f}{best['wall_s'] / t_masing:>10.0f}"
                    f"{best['wall_s'] / t_start:>9.1f}  {', '.join(names)}"
                )
        print(f"load average at the end {os.getloadavg()[0]:.1f}")
        summary = {"masing_s": t_masing, "startup_s": t_start, "import_cpu_s": t_imp}
        print(json.dumps({**summary, "runs": rows}))


if __name__ == "__main__":
    main()
