"""Replay saved inputs: ``python fuzz/replay.py TARGET FILE_OR_DIR...``; prints each failure
(with its signature) and a count. Used to check fixes against fuzz/crashes/<target>/."""

from __future__ import annotations

import importlib
import signal
import sys
import traceback
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _harness import _signature


def main(target: str, paths: list[str]) -> int:
    mod = importlib.import_module(target)
    files = []
    for p in map(Path, paths):
        files += sorted(f for f in p.iterdir() if f.is_file()) if p.is_dir() else [p]
    files = [f for f in files if f.suffix not in (".txt", ".md")]
    bad = 0

    def hang(*_):
        raise TimeoutError("no result after 30 s")

    signal.signal(signal.SIGALRM, hang)
    for f in files:
        signal.alarm(30)
        try:
            mod.one_input(f.read_bytes())
        except Exception as exc:
            bad += 1
            print(f"FAIL {f.name}: {_signature(exc)}")
            if "-v" in sys.argv:
                traceback.print_exc()
        finally:
            signal.alarm(0)
    print(f"{target}: {len(files) - bad}/{len(files)} inputs keep the invariants")
    return 1 if bad else 0


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "-v"]
    sys.exit(main(args[0], args[1:]))
