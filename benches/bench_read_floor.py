"""The reading side of a streamed ``analyze`` against the floors the machine sets (issue 33
item 4): how far the HDF5 reader and the structure check are from a bare pass over the same
bytes, in this process (CPU seconds of the calling thread and its helpers:
``time.process_time``; medians of ``--rounds``, the variants interleaved round by round).

Reader (the file's datasets ``x`` and ``F``, read as ``track`` reads them: chunks of
:data:`~contactlab.studies.track_result.TRACK_CHUNK` samples into caller arrays, the time
axis not made):

- ``chunks_into``: :meth:`contactlab.io.ChunkedRecording.chunks_into` (the reader as it runs:
  ``os.preadv`` of each stored piece into the chunk, each piece scanned as it arrives
  (``_core.finite_min_max``, :data:`~contactlab.io.hdf5.SCAN_PIECE` samples), the checks
  and the conversion of :class:`~contactlab.io.chunked._Finisher`);
- ``preadv + scan``: the same ``DirectRead.read`` calls alone (no finisher, no chunk
  objects);
- ``preadv``: the same reads without the scans (the copy from the page cache: the floor of
  any reader that gives the samples in arrays of its own).

Structure check (:func:`contactlab.io.hdf5.check_structure`, one thread):

- ``check_structure``: the whole check (a read-only map of each 16 MiB block and its
  search for the three signatures, ``_core.signature_positions``);
- ``mapped pass``: the same maps with one vectorised pass over each block instead of the
  search (``_core.finite_min_max`` over its bytes): the floor of any scan of every byte.

Run: ``nice .venv/bin/python benches/bench_read_floor.py [--samples 3e7] [--recording FILE]
[--rounds 5]``.
"""

from __future__ import annotations

import argparse
import mmap
import os
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benches"))


def variants(path: Path) -> dict[str, Callable[[], None]]:
    import h5py

    import contactlab.io.hdf5 as h5
    from contactlab import _core
    from contactlab.io import read_chunks
    from contactlab.studies.track_result import TRACK_CHUNK

    file = str(path)
    cr = read_chunks(path, chunk_size=TRACK_CHUNK)
    bufs: dict[tuple[str, int], np.ndarray] = {}

    def alloc(m: int, names: list[str]) -> dict[str, np.ndarray]:
        return {k: bufs.setdefault((k, m), np.empty(m)) for k in names}

    fd = os.open(path, os.O_RDONLY)
    size = os.fstat(fd).st_size
    with h5py.File(path, "r") as f:
        direct = {k: h5.direct_read(f[k], size) for k in ("x", "F")}
        n = int(f["x"].shape[0])
    if any(d is None for d in direct.values()):
        raise SystemExit(f"{file}: x and F must be uncompressed float64 (read directly)")
    out = np.empty(TRACK_CHUNK)

    def reader() -> None:
        for _c in cr.chunks_into(alloc, time_axis=False):
            pass

    def reads(scan: bool) -> None:
        for a in range(0, n, TRACK_CHUNK):
            m = min(TRACK_CHUNK, n - a)
            for d in direct.values():
                assert d is not None
                d.read(fd, a, out[:m], [True, np.inf, -np.inf] if scan else None)

    def check() -> None:
        h5._CHECKED.clear()
        h5.check_structure(path, file=file)

    def mapped_pass() -> None:
        block = h5._FileView.BLOCK
        for at in range(0, size, block):
            m = mmap.mmap(fd, min(block, size - at), offset=at, access=mmap.ACCESS_READ)
            v = np.frombuffer(m, dtype=np.uint8)
            _core.finite_min_max(v[: v.size // 8 * 8].view(np.float64))
            del v
            m.close()

    h5._SCAN_THREADS = 1
    return {
        "chunks_into": reader,
        "preadv + scan": lambda: reads(True),
        "preadv": lambda: reads(False),
        "check_structure": check,
        "mapped pass": mapped_pass,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=float, default=3e7)
    ap.add_argument("--recording", type=Path, help="an existing HDF5 recording (not written)")
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix="contactlab-read-floor-") as d:
        path = args.recording
        if path is None:
            import bench_track

            path = Path(d) / "t.h5"
            bench_track.write_file(path, int(args.samples))
        runs = variants(path)
        times: dict[str, list[float]] = {k: [] for k in runs}
        for f in runs.values():  # warm-up: the file in the page cache, the code loaded
            f()
        for r in range(args.rounds):
            keys = list(runs) if r % 2 == 0 else list(runs)[::-1]
            for k in keys:
                c = time.process_time()
                runs[k]()
                times[k].append(time.process_time() - c)
        size = path.stat().st_size
    load = ", ".join(f"{a:.2f}" for a in os.getloadavg())
    print(
        f"{path.name}: {size / 1e6:.0f} MB; load {load}; {os.cpu_count()} CPUs; CPU seconds, "
        f"medians of {args.rounds} interleaved rounds"
    )
    print("| variant | CPU s | min | GB/s of the file |")
    print("|---|---|---|---|")
    for k, v in times.items():
        med = float(np.median(v))
        print(f"| {k} | {med:.3f} | {min(v):.3f} | {size / med / 1e9:.1f} |")


if __name__ == "__main__":
    main()
