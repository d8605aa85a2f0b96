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

Recordings of the hidden-effect generator
(:func:`contactlab.synthetic.diagnosis.hidden_effect_recording`,
its default rig, 1000 samples per reference cycle, as many cycles as make ``--samples``):

- ``t:none`` (tangential, no effect), ``t:NAME`` (one effect NAME of the tangential library
  at the generator's default size), ``t:all`` for every one of them;
- ``n:none`` (normal joint, ``--model normal``), ``n:NAME``, ``n:all`` likewise.

``--recordings all`` runs the three above and every generator recording. ``--workdir DIR``
keeps the recordings in DIR (and reuses them when they are there: generating one takes
seconds), ``--keep DIR`` the JSON reports; ``--compare DIR`` compares the reports with those
kept in DIR by an earlier run (another version of the package): the same effects named, and
the largest change of a parameter in units of its standard error.

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
[--format h5|csv] [--recordings all] [--workdir DIR] [--keep DIR] [--compare DIR]
[--baseline DIR] [--threads-ab] [--profile]``. ``--baseline DIR`` runs another version of
the package (its ``contactlab`` folder in DIR) interleaved with this one, as rows ``before``
and ``after``, compares their reports (with ``--keep``) and sums up the times before and
after (ratios per recording, totals, recordings over 3 s). ``--profile`` runs cProfile on
the CLI path of the first recording and prints the functions with the largest cumulative
and own time.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
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


#: samples per reference cycle of the generator recordings; its three blocks run at 1, 1.7
#: and 0.6 times the reference frequency, so a block of c cycles has 1000 c (1 + 1/1.7 +
#: 1/0.6) samples in all
GEN_SAMPLES_PER_CYCLE = 1000
_GEN_BLOCK = 1.0 + 1.0 / 1.7 + 1.0 / 0.6


def generator_kinds(spec: str) -> list[str]:
    """``t:all`` / ``n:all`` expanded to every effect of that library (and ``:none``)."""
    from contactlab.synthetic.diagnosis import TANGENTIAL_EFFECTS
    from contactlab.synthetic.diagnosis_normal import NORMAL_EFFECTS

    lib = {"t": TANGENTIAL_EFFECTS, "n": NORMAL_EFFECTS}[spec[0]]
    return [f"{spec[0]}:none"] + [f"{spec[0]}:{e}" for e in lib]


def write_generated(path: Path, kind: str, n: int, seed: int) -> None:
    """A hidden-effect generator recording (``t:NAME`` / ``n:NAME``) of about ``n`` samples."""
    from contactlab.io import write_recording
    from contactlab.synthetic.diagnosis import hidden_effect_recording

    model = {"t": "tangential", "n": "normal"}[kind[0]]
    effect = kind[2:]
    cycles = max(4, round(n / (GEN_SAMPLES_PER_CYCLE * _GEN_BLOCK)))
    rec = hidden_effect_recording(
        [] if effect == "none" else [effect],
        model=model,
        seed=seed,
        cycles_per_block=cycles,
        samples_per_cycle=GEN_SAMPLES_PER_CYCLE,
    )
    write_recording(path, rec)


def make_recording(path: Path, kind: str, n: int, seed: int) -> None:
    if ":" in kind:
        write_generated(path, kind, n, seed)
    else:
        write(path, recording(kind, n, seed))


def model_of(kind: str) -> str:
    return "normal" if kind.startswith("n:") else "tangential"


def file_tag(kind: str) -> str:
    return kind.replace(":", "_")


def compare(
    kinds: list[str], new: Path, old: Path, old_tag: str = "default", new_tag: str = "default"
) -> None:
    """Effects named and parameter changes (in standard errors) between two kept runs."""
    print(f"{'recording':<28}{'effects (same?)':<40}{'max |Δp|/σ':>12}  parameter")
    for kind in kinds:
        a, b = old / f"{file_tag(kind)}_{old_tag}.json", new / f"{file_tag(kind)}_{new_tag}.json"
        if not (a.exists() and b.exists()):
            print(f"{kind:<28}(no report in both)")
            continue
        ra, rb = json.loads(a.read_text()), json.loads(b.read_text())
        ea = [e["name"] for e in ra["effects"]]
        eb = [e["name"] for e in rb["effects"]]
        worst, which = 0.0, "-"
        for x, y in zip(ra["effects"], rb["effects"], strict=False):
            for k, v in x["parameters"].items():
                se = x["stderr"].get(k)
                w = y["parameters"].get(k)
                if se and w is not None and abs(w - v) / se > worst:
                    worst, which = abs(w - v) / se, f"{x['name']}.{k}"
        names = ",".join(eb) or "-"
        print(f"{kind:<28}{names + ('' if ea == eb else ' (was ' + ','.join(ea) + ')'):<40}"
              f"{worst:>12.2g}  {which}")  # fmt: skip


def summarise(rows: list[dict]) -> None:
    """Before against after (``--baseline``): per recording the ratio of the best wall and
    CPU times, and over all recordings their sums and the median ratio; the recordings over
    3 s of wall before and after."""
    by = {(r["recording"], r["run"]): r for r in rows}
    kinds = list(dict.fromkeys(r["recording"] for r in rows))
    pairs = [(by[k, "before"], by[k, "after"]) for k in kinds if (k, "after") in by]
    if not pairs:
        return
    print(f"{'recording':<28}{'wall before':>12}{'after':>8}{'ratio':>7}"
          f"{'CPU before':>12}{'after':>8}{'ratio':>7}")  # fmt: skip
    for b, a in pairs:
        print(f"{b['recording']:<28}{b['wall_s']:>12.2f}{a['wall_s']:>8.2f}"
              f"{a['wall_s'] / b['wall_s']:>7.2f}{b['cpu_s']:>12.2f}{a['cpu_s']:>8.2f}"
              f"{a['cpu_s'] / b['cpu_s']:>7.2f}")  # fmt: skip
    for what in ("wall_s", "cpu_s"):
        tb = sum(b[what] for b, _ in pairs)
        ta = sum(a[what] for _, a in pairs)
        med = float(np.median([a[what] / b[what] for b, a in pairs]))
        over = [sum(r[what] > 3.0 for r in side) for side in zip(*pairs, strict=True)]
        print(
            f"{what[:-2]}: total {tb:.1f} s before, {ta:.1f} s after ({ta / tb:.2f}x, median "
            f"ratio {med:.2f}); recordings over 3 s: {over[0]} before, {over[1]} after"
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
    """The CLI (or, with ``python``, the interpreter) with ``args`` in a child process.

    Peak RSS is the child's ``ru_maxrss``; Linux carries the high-water mark of the address
    space a child had before ``exec`` into it, which for a ``vfork``ed child is this process's:
    so this process must stay smaller than the runs it measures (the recordings are made in
    a separate process)."""
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


def profile(path: Path, out: Path, model: str = "tangential") -> None:
    import cProfile
    import pstats

    from contactlab.cli import main

    pr = cProfile.Profile()
    pr.enable()
    try:
        main(["diagnose", str(path), "--model", model, "--json", str(out)])
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
    ap.add_argument("--workdir", metavar="DIR", help="keep (and reuse) the recordings in DIR")
    ap.add_argument(
        "--compare",
        metavar="DIR",
        help="compare the reports kept in --keep with those kept in DIR (no runs)",
    )
    ap.add_argument(
        "--baseline",
        metavar="DIR",
        help="also run another version of the package, whose `contactlab` package is in DIR "
        "(e.g. `git archive REV python | tar -x -C /tmp/base`, with the built extension "
        "copied in), interleaved with this one: rows 'before' and 'after', and their reports "
        "compared (with --keep)",
    )
    ap.add_argument(
        "--threads-ab",
        action="store_true",
        help="also run each with CONTACTLAB_DIAGNOSE_THREADS=1 and =2",
    )
    args = ap.parse_args()
    n = int(args.samples)
    kinds = []
    for k in args.recordings.split(","):
        if k == "all":
            kinds += ["clean", "offset", "damping", *generator_kinds("t"), *generator_kinds("n")]
        elif k in ("t:all", "n:all"):
            kinds += generator_kinds(k)
        elif k:
            kinds.append(k)
    with tempfile.TemporaryDirectory(prefix="bench_diagnose_") as tmp:
        tmpd = Path(tmp)
        store = Path(args.workdir) if args.workdir else tmpd
        store.mkdir(parents=True, exist_ok=True)
        # a recording's seed by its place in the full list: the same recording whatever
        # subset is run (and found again in --workdir)
        canon = ["clean", "offset", "damping", *generator_kinds("t"), *generator_kinds("n")]
        seeds = {
            k: args.seed + (canon.index(k) if k in canon else len(canon) + i)
            for i, k in enumerate(kinds)
        }
        files = {k: store / f"{file_tag(k)}_{n}_{seeds[k]}.{args.format}" for k in kinds}
        todo = [(files[k], k, n, seeds[k]) for k in kinds if not files[k].exists()]
        if todo:  # in a child: this process stays small (see run_cli on peak RSS)
            ctx = multiprocessing.get_context("spawn")
            with ProcessPoolExecutor(1, mp_context=ctx) as ex:
                list(ex.map(make_recording, *zip(*todo, strict=True)))
        if args.compare:
            compare(kinds, Path(args.keep or "."), Path(args.compare))
            return
        if args.profile:
            profile(files[kinds[0]], tmpd / "profile.json", model_of(kinds[0]))
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
            f"{'recording':<28}{'run':<9}{'wall s':>8}{'CPU s':>8}{'RSS MB':>8}"
            f"{'/ Masing':>10}{'/ start':>9}  effects"
        )
        variants: list[tuple[str, dict[str, str]]] = [("default", {})]
        if args.baseline:
            base = os.pathsep.join(
                [str(Path(args.baseline).resolve()), os.environ.get("PYTHONPATH", "")]
            )
            variants = [("before", {"PYTHONPATH": base.rstrip(os.pathsep)}), ("after", {})]
        if args.threads_ab:
            variants.append(("1 thread", {"CONTACTLAB_DIAGNOSE_THREADS": "1"}))
            variants.append(("2 thread", {"CONTACTLAB_DIAGNOSE_THREADS": "2"}))
        rows = []
        for kind in kinds:
            # the variants interleaved, so that a change of the machine's load hits them alike
            runs: dict[str, list[dict]] = {label: [] for label, _ in variants}
            outs = {
                label: tmpd / f"{file_tag(kind)}_{label.replace(' ', '')}.json"
                for label, _ in variants
            }
            for _ in range(args.repeat):
                for label, env in variants:
                    cmd = ["diagnose", str(files[kind]), "--model", model_of(kind)]
                    runs[label].append(run_cli([*cmd, "--json", str(outs[label])], env))
            for label, _ in variants:
                out = outs[label]
                best = min(runs[label], key=lambda r: r["wall_s"])
                rep = json.loads(out.read_text())
                if args.keep:
                    Path(args.keep).mkdir(parents=True, exist_ok=True)
                    tag = label.replace(" ", "")
                    (Path(args.keep) / f"{file_tag(kind)}_{tag}.json").write_text(out.read_text())
                names = [e["name"] for e in rep["effects"]] or ["-"]
                row = {k: v for k, v in best.items() if k != "stdout"}
                rows.append({"recording": kind, "run": label, "load": os.getloadavg()[0], **row})
                print(
                    f"{kind:<28}{label:<9}{best['wall_s']:>8.2f}{best['cpu_s']:>8.2f}"
                    f"{best['peak_rss_mb']:>8.0f}{best['wall_s'] / t_masing:>10.0f}"
                    f"{best['wall_s'] / t_start:>9.1f}  {', '.join(names)}  "
                    f"(load {os.getloadavg()[0]:.1f})"
                )
        print(f"load average at the end {os.getloadavg()[0]:.1f}")
        if args.baseline:
            summarise(rows)
        if args.baseline and args.keep:
            compare(kinds, Path(args.keep), Path(args.keep), old_tag="before", new_tag="after")
        summary = {"masing_s": t_masing, "startup_s": t_start, "import_cpu_s": t_imp}
        print(json.dumps({**summary, "runs": rows}))


if __name__ == "__main__":
    main()
