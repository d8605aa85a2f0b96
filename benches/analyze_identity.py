"""``contactlab analyze FILE --json -`` of every bundled record and of two synthetic HDF5
recordings (``bench_track.write_file``: 3e5 samples seed 9, 4e6 samples seed 5, the second
analysed in streamed windows), as md5 digests: the byte-for-byte check of issue 33 ("results
unchanged") for a change to the analysis chain.

Run: ``nice .venv/bin/python benches/analyze_identity.py OUT.json`` on the tree before and
after (the tree before: ``PYTHONPATH=<a copy of its python/ folder, built>``), then
``benches/analyze_identity.py --compare A.json B.json``. Each command line runs
with a timeout (killed with its session when it overruns).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benches"))

TIMEOUT = 300.0


def _run(path: Path) -> str:
    exe = Path(sys.executable).with_name("contactlab")
    # run in the file's folder on its bare name: the JSON names its source, and a path with
    # a random temporary folder in it would differ from run to run
    with subprocess.Popen(
        [str(exe), "analyze", path.name, "--json", "-"],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
        cwd=path.parent,
    ) as p:
        try:
            out, _ = p.communicate(timeout=TIMEOUT)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.communicate(timeout=10)
            return f"timeout after {TIMEOUT:.0f} s"
    if p.returncode != 0:
        return f"exit {p.returncode}"
    return hashlib.md5(out).hexdigest()


def digests(bundled: bool = True) -> dict[str, str]:
    import bench_track

    data = ROOT / "python" / "contactlab" / "data"
    files = sorted(
        p
        for sub in ("tangential", "normal")
        for p in (data / sub).iterdir()
        if p.suffix in (".csv", ".h5", ".mat", ".tdms")
    )
    out = {str(p.relative_to(data)): _run(p) for p in files} if bundled else {}
    with tempfile.TemporaryDirectory(prefix="contactlab-identity-") as d:
        for n, seed in ((300_000, 9), (4_000_000, 5)):
            p = Path(d) / f"synthetic_{n}_{seed}.h5"
            bench_track.write_file(p, n, seed=seed)
            out[p.name] = _run(p)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", type=Path)
    ap.add_argument("--compare", nargs=2, type=Path)
    ap.add_argument("--synthetic-only", action="store_true", help="leave out the bundled data")
    args = ap.parse_args()
    if args.compare:
        a, b = (json.loads(p.read_text()) for p in args.compare)
        diff = sorted(k for k in a.keys() | b.keys() if a.get(k) != b.get(k))
        print(f"{len(a)} / {len(b)} files, {len(diff)} differ")
        for k in diff:
            print(f"  {k}: {a.get(k)} != {b.get(k)}")
        sys.exit(1 if diff else 0)
    d = digests(bundled=not args.synthetic_only)
    text = json.dumps(d, indent=1, sort_keys=True)
    if args.out:
        args.out.write_text(text + "\n")
    print(text)


if __name__ == "__main__":
    main()
