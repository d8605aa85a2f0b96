"""Start-up of the command line (issue 33 item 4): ``contactlab --help`` and ``analyze`` up to
its first sample read, against a bare ``python -c pass`` in the same run.

Every command runs as a new process, the commands interleaved round by round (order rotating)
and timed by their medians; besides the wall time each child's CPU time (user + system, from
``os.wait4``) is given, which a loaded machine disturbs much less. Commands:

- ``python``: ``python -c pass`` (the interpreter's own start, the floor);
- ``import``: ``python -c 'import contactlab'``;
- ``help``: ``contactlab --help`` (the installed entry point);
- ``first read``: ``contactlab analyze FILE`` of a bundled CSV recording, ended (``os._exit``)
  by an audit hook at the moment the reader opens that file: parsing, imports and the checks
  before the read, nothing of the analysis;
- ``analyze``: the same run to its end (the whole analysis of a 4 000-sample recording).

Bars (issue 33): ``--help`` <= 150 ms, first read <= 250 ms. The modules each command has
imported are counted too, and whether scipy or matplotlib is among them.

Run: ``.venv/bin/python benches/bench_startup.py [--rounds 9]``.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "python" / "contactlab" / "data"
RECORDING = DATA / "tangential" / "Al-Al_W50N_A5um.csv"

#: run by ``python -c``: analyze argv[1] and stop when the reader opens it (argv[2]: "stop")
#: or at the end; prints the count of imported modules and whether scipy/matplotlib loaded
_PROBE = r"""
import os, sys
target = os.path.abspath(sys.argv[1])
stop = sys.argv[2] == "stop"
def _report():
    heavy = sorted(m for m in ("scipy", "matplotlib") if m in sys.modules)
    sys.stderr.write(f"PROBE {len(sys.modules)} {','.join(heavy) or '-'}\n")
def _hook(event, args):
    if event == "open" and args and isinstance(args[0], (str, bytes, os.PathLike)):
        try:
            p = os.path.abspath(os.fsdecode(args[0]))
        except (TypeError, ValueError):
            return
        if p == target:
            _report()
            sys.stderr.flush()
            os._exit(0)
if stop:
    sys.addaudithook(_hook)
from contactlab.cli import main
code = main(["analyze", target])
_report()
sys.exit(code)
"""

_MODULES = "import sys{imp}; sys.stderr.write(f'PROBE {{len(sys.modules)}} -\\n')"


def run(cmd: list[str], env: dict[str, str]) -> tuple[float, float, str]:
    """Wall time, CPU time (s) of a child and its stderr."""
    t0 = time.perf_counter()
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env)
    err = p.stderr.read().decode() if p.stderr is not None else ""
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    if os.waitstatus_to_exitcode(status) not in (0,):
        raise SystemExit(f"{cmd} failed: {err}")
    return wall, usage.ru_utime + usage.ru_stime, err


def commands() -> dict[str, list[str]]:
    py = sys.executable
    exe = str(Path(py).with_name("contactlab"))
    return {
        "python": [py, "-c", "pass"],
        "import": [py, "-c", "import contactlab"],
        "help": [exe, "--help"],
        "first read": [py, "-c", _PROBE, str(RECORDING), "stop"],
        "analyze": [py, "-c", _PROBE, str(RECORDING), "end"],
    }


def measure(rounds: int) -> dict[str, dict[str, float | str]]:
    """Median wall and CPU seconds of each command over interleaved rounds, and what the
    probes say (imported modules, scipy/matplotlib among them)."""
    env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1")
    cmds = commands()
    keys = list(cmds)
    walls: dict[str, list[float]] = {k: [] for k in keys}
    cpus: dict[str, list[float]] = {k: [] for k in keys}
    notes: dict[str, str] = {}
    for k in keys:  # warm-up: the page cache, .pyc files
        notes[k] = run(cmds[k], env)[2]
    for r in range(rounds):
        for k in keys[r % len(keys) :] + keys[: r % len(keys)]:
            w, c, _ = run(cmds[k], env)
            walls[k].append(w)
            cpus[k].append(c)
    out: dict[str, dict[str, float | str]] = {}
    for k in keys:
        probe = [ln for ln in notes[k].splitlines() if ln.startswith("PROBE")]
        out[k] = {
            "wall": float(np.median(walls[k])),
            "cpu": float(np.median(cpus[k])),
            "probe": probe[-1][6:] if probe else "",
        }
    return out


def help_modules() -> str:
    """Modules ``contactlab --help`` leaves imported, and whether scipy/matplotlib are."""
    code = (
        "import sys, io, contextlib\nfrom contactlab.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()), contextlib.suppress(SystemExit):\n"
        "    main(['--help'])\n"
        "heavy = [m for m in ('numpy', 'scipy', 'matplotlib') if m in sys.modules]\n"
        "print(len(sys.modules), ','.join(heavy) or '-')"
    )
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return p.stdout.strip()


BARS = {"help": 0.150, "first read": 0.250}


def table(rounds: int) -> list[tuple[str, str, str, float, str]]:
    """Rows (task, ours, reference, ratio, note) for ``speed_table.py``."""
    m = measure(rounds)
    base = m["python"]
    rows = []
    for k, label in (
        ("import", "`python -c 'import contactlab'`"),
        ("help", "`contactlab --help`"),
        ("first read", "`contactlab analyze` to the first sample read"),
        ("analyze", "`contactlab analyze` of a bundled 4000-sample CSV, whole run"),
    ):
        v = m[k]
        bar = BARS.get(k)
        ref = (
            f"`python -c pass` {base['wall'] * 1e3:.0f} ms wall, {base['cpu'] * 1e3:.0f} ms CPU"
            + (f"; bar {bar * 1e3:.0f} ms" if bar else "")
        )
        ours = (
            f"{v['wall'] * 1e3:.0f} ms wall (+{(v['wall'] - base['wall']) * 1e3:.0f}), "
            f"{v['cpu'] * 1e3:.0f} ms CPU"
        )
        probe = str(v["probe"]).split()
        note = f"{probe[0]} modules, heavy: {probe[1]}" if len(probe) == 2 else ""
        ratio = bar / v["wall"] if bar else v["wall"] / base["wall"]
        what = "of the bar (wall)" if bar else "x bare python (wall)"
        rows.append((label, ours, ref, ratio, f"{what}; {note}"))
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=9)
    args = ap.parse_args()
    print(
        f"load {', '.join(f'{a:.2f}' for a in os.getloadavg())}; {os.cpu_count()} CPUs; "
        f"medians of {args.rounds} interleaved rounds, each command a new process"
    )
    print(f"`contactlab --help` leaves imported: {help_modules()} (modules, heavy ones)")
    print("| command | contactlab | reference | ratio | note |")
    print("|---|---|---|---|---|")
    for task, ours, ref, ratio, note in table(args.rounds):
        print(f"| {task} | {ours} | {ref} | {ratio:.2f} | {note} |")


if __name__ == "__main__":
    main()
