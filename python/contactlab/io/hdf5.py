"""HDF5 recordings (h5py, optional extra ``io``).

Each channel is a 1-D dataset anywhere in the file, found by its name (the last path
component) or by its full path; its unit is the dataset attribute ``unit`` or ``units``. The time
is a dataset (``t``, ``time``) or, failing that, a sampling interval ``dt``/``wf_increment`` or a
rate ``fs``/``sampling_rate`` as an attribute of a data dataset or of the file. Only the needed
datasets are read.
"""

from __future__ import annotations

import bisect
import contextlib
import os
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from .._io_atomic import atomic_path
from ..errors import InputError
from .recording import (
    Recording,
    RecordingError,
    check_equal_lengths,
    finish,
    metadata_scalar,
    real_values,
    resolve_columns,
    step_of_rate,
    time_from_interval,
)


def import_h5py() -> Any:
    """The h5py module (an optional dependency; HDF5 and MATLAB v7.3 readers need it)."""
    try:
        import h5py
    except ImportError:  # pragma: no cover - depends on the installation
        raise InputError("reading HDF5 files needs h5py: pip install 'contactlab[io]'") from None
    return h5py


#: libhdf5 (2.0) decodes a global heap collection ("GCOL", the store of variable-length strings
#: and arrays) by walking its objects until the collection's end; a free-space record (index
#: 0) of size 0 does not advance the walk, and the library loops forever (found by fuzzing:
#: fuzz/regressions/read_hdf5). No signal interrupts it, so such a file is refused before
#: h5py opens it.
_GCOL = b"GCOL\x01"
#: More objects than any collection libhdf5 writes can hold (4 KiB collections; larger only
#: to fit one big object): a walk this long is a damaged file, refused without walking on.
_MAX_HEAP_OBJECTS = 1_000_000


def _superblock(mm: Any, size: int) -> tuple[int, int, int] | None:
    """``(size of offsets, size of lengths, base address)`` from the superblock, found at 0,
    512, 1024, ... as libhdf5 looks for it; None when there is none or it is not understood
    (h5py then reports the file as unreadable)."""
    from .sniff import HDF5_SIGNATURE

    at = 0
    while at + 48 <= size:
        if mm[at : at + 8] == HDF5_SIGNATURE:
            version = mm[at + 8]
            if version < 2:
                noff, nlen = mm[at + 13], mm[at + 14]
                base_at = at + (24 if version == 0 else 28)
            else:
                noff, nlen = mm[at + 9], mm[at + 10]
                base_at = at + 12
            if noff not in (2, 4, 8) or nlen not in (2, 4, 8):
                return None  # libhdf5 rejects such a superblock itself
            return noff, nlen, int.from_bytes(mm[base_at : base_at + noff], "little")
        at = 512 if at == 0 else 2 * at
    return None


def _check_global_heaps(mm: Any, size: int, nlen: int, file: str) -> None:
    """Refuse a global heap collection whose object walk (as libhdf5's
    ``H5HG__cache_heap_deserialize`` does it) would never reach the collection's end."""
    hdr = 8 + nlen  # signature, version, 3 reserved bytes, collection size
    objhdr = 8 + nlen  # index u16, reference count u16, 4 reserved bytes, object size
    pos = mm.find(_GCOL)
    while pos != -1:
        if pos + hdr <= size:
            coll = int.from_bytes(mm[pos + 8 : pos + 8 + nlen], "little")
            end = pos + coll
            p = pos + hdr
            # a collection reaching beyond the file is an error libhdf5 reports itself
            steps = 0
            while end <= size and p < end and p + objhdr <= end:
                idx = int.from_bytes(mm[p : p + 2], "little")
                osize = int.from_bytes(mm[p + 8 : p + 8 + nlen], "little")
                need = objhdr + (osize + 7) // 8 * 8 if idx > 0 else osize
                steps += 1
                if need == 0 or steps > _MAX_HEAP_OBJECTS:
                    raise RecordingError(
                        f"damaged HDF5 file: the global heap collection at byte {pos} has "
                        f"{'a free-space record of size 0' if need == 0 else 'too many objects'}"
                        f" at byte {p}; libhdf5 would never finish reading it",
                        file=file,
                    )
                p += need
        pos = mm.find(_GCOL, pos + 1)


def _check_btrees(mm: Any, size: int, noff: int, nlen: int, base: int, file: str) -> None:
    """Refuse version-1 B-tree nodes ("TREE") that libhdf5 would follow for ever: a chain of
    right siblings that comes back on itself (iteration loops) or, in a group's tree, a
    child that is not a node one level down (descent recurses until the stack overflows, a
    segmentation fault). Both found by probing the fuzz seeds; valid trees have neither."""
    undef = (1 << (8 * noff)) - 1
    hdr = 8 + 2 * noff  # signature, type, level, entries used, left and right siblings
    nodes: dict[int, tuple[int, int, int, int]] = {}  # at -> (type, level, entries, right)
    pos = mm.find(b"TREE")
    while pos != -1:
        if pos + hdr <= size:
            right = int.from_bytes(mm[pos + 8 + noff : pos + hdr], "little")
            entries = int.from_bytes(mm[pos + 6 : pos + 8], "little")
            nodes[pos] = (mm[pos + 4], mm[pos + 5], entries, right)
        pos = mm.find(b"TREE", pos + 1)

    def refuse(at: int, why: str) -> None:
        raise RecordingError(
            f"damaged HDF5 file: the B-tree node at byte {at} {why}; libhdf5 would never "
            "finish reading it",
            file=file,
        )

    ends: set[int] = set()  # nodes whose right-sibling chain is known to end
    for start in nodes:
        seen: list[int] = []
        at = start
        while at in nodes and at not in ends:
            if at in seen:
                refuse(at, "is its own right sibling through a cycle of siblings")
            seen.append(at)
            right = nodes[at][3]
            at = -1 if right == undef else base + right
        ends.update(seen)
    for at, (kind, level, entries, _right) in nodes.items():
        if kind != 0 or level == 0:
            continue  # chunk trees' keys depend on the dataset's rank: siblings only
        for i in range(min(entries, 1 << 16)):
            c = at + hdr + nlen + i * (nlen + noff)  # keys (heap offsets) and children interleave
            if c + noff > size:
                break
            child = base + int.from_bytes(mm[c : c + noff], "little")
            if child in nodes and nodes[child][1] != level - 1:
                refuse(at, f"(level {level}) has a child of level {nodes[child][1]}")


def _check_local_heaps(mm: Any, size: int, noff: int, nlen: int, base: int, file: str) -> None:
    """Refuse a local heap ("HEAP", the names of a group's links) whose free list comes back
    on itself: libhdf5 follows it for ever (found by probing the fuzz seeds)."""
    free_null = 1  # H5HL_FREE_NULL: the end of the free list
    pos = mm.find(b"HEAP")
    while pos != -1:
        end = pos + 8 + 2 * nlen + noff
        if end <= size and mm[pos + 4] == 0:
            dsize = int.from_bytes(mm[pos + 8 : pos + 8 + nlen], "little")
            off = int.from_bytes(mm[pos + 8 + nlen : pos + 8 + 2 * nlen], "little")
            data = base + int.from_bytes(mm[pos + 8 + 2 * nlen : end], "little")
            seen: set[int] = set()
            # a block beyond the data segment or the file is an error libhdf5 reports
            while off != free_null and off + 2 * nlen <= dsize and data + off + 2 * nlen <= size:
                if off in seen:
                    raise RecordingError(
                        f"damaged HDF5 file: the free list of the local heap at byte {pos} "
                        f"comes back to offset {off}; libhdf5 would never finish reading it",
                        file=file,
                    )
                seen.add(off)
                off = int.from_bytes(mm[data + off : data + off + nlen], "little")
        pos = mm.find(b"HEAP", pos + 1)


def _read_into(fd: int, buf: memoryview, at: int) -> int:
    """Fill ``buf`` from byte ``at`` of ``fd`` (fewer bytes at the end of the file)."""
    if hasattr(os, "preadv"):
        return os.preadv(fd, [buf], at)
    data = os.pread(fd, len(buf), at)  # pragma: no cover - platforms without preadv
    buf[: len(data)] = data
    return len(data)


def _mapped_hits(
    fd: int, at: int, want: int, needles: tuple[bytes, ...], block: int
) -> list[list[int]] | None:
    """Each needle's positions starting in the ``block`` bytes from ``at`` (``want`` bytes
    searched: the block and what a match starting in it may reach), searched in a read-only
    memory map of just those bytes (the file's cached pages, no copy; unmapped before the
    next block, so the scan's resident memory stays one block): a third of the CPU time of
    reading them into a buffer (3e7-sample file, 480 MB: 0.06 against 0.09-0.19 s). None
    where the block cannot be mapped (then it is read)."""
    import mmap

    from .._core import signature_positions

    if at % mmap.ALLOCATIONGRANULARITY:
        return None
    try:
        m = mmap.mmap(fd, want, offset=at, access=mmap.ACCESS_READ)
    except (OSError, ValueError, OverflowError):
        return None
    try:
        view = np.frombuffer(m, dtype=np.uint8)
        hits = signature_positions(view, list(needles), block, at)
        del view  # no export left when the map closes
        return [h.tolist() for h in hits]
    finally:
        m.close()


def _usable_cpus() -> int:
    """CPUs this process may run on (its affinity mask; the CPU count without one)."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


#: threads of the structure scan of a long file (:meth:`_FileView.index`)
_SCAN_THREADS = 2


class _FileView:
    """What the structure checks use of a memory map (``view[i]``, ``view[a:b]``,
    ``view.find(needle, start)``), read by ``os.pread`` in blocks: the scan of a long file
    holds one block (16 MiB) instead of mapping the whole file, whose pages would count in
    the process' resident memory (a 1.6 GB file peaked at 1.57 GB)."""

    BLOCK = 1 << 24

    def __init__(self, fd: int, size: int) -> None:
        self.fd, self.size = fd, size
        self._at, self._n = -1, 0  # the block read last (find resumes in it), its length
        self._buf = bytearray()  # one buffer for every block: no fresh pages per block
        self._index: dict[bytes, list[int]] = {}  # needle -> every position (see index)

    def __getitem__(self, k: int | slice) -> Any:
        if isinstance(k, slice):
            a = 0 if k.start is None else max(k.start, 0)
            b = self.size if k.stop is None else min(k.stop, self.size)
            return os.pread(self.fd, b - a, a) if b > a else b""
        if not 0 <= k < self.size:
            raise IndexError("file view index out of range")
        return os.pread(self.fd, 1, k)[0]

    def index(self, needles: tuple[bytes, ...]) -> None:
        """Find every occurrence of each of ``needles`` in one pass over the file (each block
        read once, searched for every needle by the Rust core with the GIL released:
        ``memchr``'s memmem, about 10x Python's ``bytes.find``); :meth:`find` then answers
        from the index. A long file is read and searched on two threads (alternate blocks,
        a buffer each: ``preadv`` and the search both release the GIL), which halves the
        scan that precedes every read of a long recording (1.6 GB: 0.7 s on one core)."""
        longest = max(len(nd) for nd in needles)
        starts = list(range(0, self.size, self.BLOCK))
        n_threads = min(_SCAN_THREADS, len(starts), _usable_cpus())
        if n_threads > 1:
            from concurrent.futures import ThreadPoolExecutor

            with ThreadPoolExecutor(n_threads, thread_name_prefix="contactlab-scan") as ex:
                parts = list(
                    ex.map(
                        lambda k: self._scan_blocks(starts[k::n_threads], needles, longest),
                        range(n_threads),
                    )
                )
            per_block: dict[int, list[list[int]]] = {}
            for part in parts:
                per_block.update(part)
        else:
            per_block = self._scan_blocks(starts, needles, longest, self)
        found: dict[bytes, list[int]] = {nd: [] for nd in needles}
        for at in starts:  # in file order: each needle's positions sorted
            for nd, h in zip(needles, per_block[at], strict=True):
                found[nd].extend(h)
        self._at = -1
        self._index = found

    def _scan_blocks(
        self,
        starts: list[int],
        needles: tuple[bytes, ...],
        longest: int,
        owner: _FileView | None = None,
    ) -> dict[int, list[list[int]]]:
        """Each needle's positions starting in the blocks at ``starts``, by block, read into
        a buffer of this call (``owner``'s reused buffer when given: one thread)."""
        from .._core import signature_positions

        buf = owner._buf if owner is not None else bytearray()
        out: dict[int, list[list[int]]] = {}
        for at in starts:
            if _STOP.is_set():  # the process is ending (stop_prefetched_checks)
                raise InputError("the structure check was stopped: the process is ending")
            want = min(self.BLOCK + longest - 1, self.size - at)
            mapped = _mapped_hits(self.fd, at, want, needles, self.BLOCK)
            if mapped is not None:
                out[at] = mapped
                continue
            if len(buf) < want:
                buf = bytearray(want)
                if owner is not None:
                    owner._buf = buf
            n = _read_into(self.fd, memoryview(buf)[:want], at)
            block = np.frombuffer(buf, dtype=np.uint8, count=n)
            # matches starting in this block (one starting beyond it is the next block's)
            hits = signature_positions(block, list(needles), self.BLOCK, at)
            del block  # the buffer may be replaced by a larger one (no export held)
            out[at] = [h.tolist() for h in hits]
        return out

    def find(self, needle: bytes, start: int = 0) -> int:
        hits = self._index.get(needle)
        if hits is not None:
            k = bisect.bisect_left(hits, max(start, 0))
            return hits[k] if k < len(hits) else -1
        pos = max(start, 0)
        while pos < self.size:
            at = pos - pos % self.BLOCK
            want = min(self.BLOCK + len(needle) - 1, self.size - at)
            if at != self._at or self._n < want:
                # a block and the needle's length after it: a match across the edge is found
                if len(self._buf) < want:
                    self._buf = bytearray(want)
                self._n = _read_into(self.fd, memoryview(self._buf)[:want], at)
                self._at = at
            i = self._buf.find(needle, pos - at, self._n)
            if i >= 0:
                return at + i
            pos = at + self.BLOCK
        return -1


#: long files :func:`check_structure` passed in this process: ``(device, inode, size,
#: mtime_ns, ctime_ns)``; files from this size on are remembered
_CHECKED: set[tuple[int, int, int, int, int]] = set()
_CACHE_ABOVE = 64 << 20


def check_structure(path: str | Path, *, file: str) -> None:
    """Refuse the damaged structures on which libhdf5 itself hangs or overflows its stack
    instead of failing (it cannot be interrupted from Python): global heap collections whose
    walk does not advance, version-1 B-trees with sibling cycles or children on the wrong
    level, local heaps whose free list cycles. Cheap: a scan for the structures' signatures,
    read in blocks (bounded memory). Valid files always pass; a file this does not
    understand is left to libhdf5, which reports it. Not checked: the structures libhdf5
    writes only with newer file-format settings (version-2 B-trees, fractal heaps); object
    header continuation loops and the other damage tried by fuzz/read_hdf5.py libhdf5
    reports itself."""
    with open(path, "rb") as fh:
        st = os.fstat(fh.fileno())
        size = st.st_size
        if size < 48:
            return
        # A long file already checked in this process and unchanged since (same inode, size,
        # modification and change times) is not scanned again: `analyze` opens a long file
        # twice (its length, then the chunks), and each scan reads the whole file (1.6 GB at
        # 1e8 samples). Only long files: their scan outlasts the timestamps' resolution, and
        # small files (a fuzzer rewriting one in place) are always scanned.
        key = (st.st_dev, st.st_ino, size, st.st_mtime_ns, st.st_ctime_ns)
        if size >= _CACHE_ABOVE:
            # a check started ahead (prefetch_structure_check) is waited for; had it failed,
            # the key is not in _CHECKED and this call checks again, raising with its `file`
            pending = _PENDING.get(key)
            if pending is not None and pending is not threading.current_thread():
                pending.join()
            if key in _CHECKED:
                return
        mm = _FileView(fh.fileno(), size)
        sb = _superblock(mm, size)
        if sb is None:
            return
        mm.index((_GCOL, b"TREE", b"HEAP"))  # one pass over the file for the three scans
        noff, nlen, base = sb
        _check_global_heaps(mm, size, nlen, file)
        _check_btrees(mm, size, noff, nlen, base, file)
        _check_local_heaps(mm, size, noff, nlen, base, file)
        if size >= _CACHE_ABOVE:
            if len(_CHECKED) >= 256:
                _CHECKED.clear()
            _CHECKED.add(key)


#: structure checks started ahead of the call that opens the file (prefetch_structure_check)
_PENDING: dict[tuple[int, int, int, int, int], threading.Thread] = {}
_PENDING_LOCK = threading.Lock()
#: the HDF5 format signature (at offset 0, or 512, 1024, ... after a user block)
_SIGNATURE = b"\x89HDF\r\n\x1a\n"


#: set when the process ends (:func:`stop_prefetched_checks`): scans stop at their next block
_STOP = threading.Event()


def stop_prefetched_checks() -> None:
    """Stop the scans of checks started ahead that are still running (the command line ends
    before it opened their file: a usage error, an interrupt), so that the process does not
    wait for a scan of a long file at exit; a check stopped so is not recorded as passed."""
    with _PENDING_LOCK:
        running = list(_PENDING.values())
    if running:
        _STOP.set()
        for th in running:
            th.join()


def prefetch_structure_check(path: str | Path) -> bool:
    """Start :func:`check_structure` of a long HDF5 file (from :data:`_CACHE_ABOVE` bytes) on
    a background thread, so that its scan of the whole file (0.35 s at 1.6 GB on two cores)
    runs while the command line imports the analysis; the call that opens the file waits for
    it (and checks again, raising its own error, when it found damage). True when started.
    Only a file whose first bytes are the HDF5 signature (at 0 or 512) is scanned ahead."""
    try:
        st = os.stat(path)
        if st.st_size < _CACHE_ABOVE or not os.path.isfile(path):
            return False
        with open(path, "rb") as fh:
            head = fh.read(520)
    except OSError:
        return False
    if not (head.startswith(_SIGNATURE) or head[512:520] == _SIGNATURE):
        return False
    key = (st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns, st.st_ctime_ns)

    def run() -> None:
        try:
            check_structure(path, file=str(path))
        except Exception:  # the opening call checks again and reports it
            pass
        finally:
            with _PENDING_LOCK:
                _PENDING.pop(key, None)

    with _PENDING_LOCK:
        if key in _PENDING or key in _CHECKED:
            return False
        th = threading.Thread(target=run, name="contactlab-prefetch", daemon=True)
        _PENDING[key] = th
    th.start()
    return True


def open_hdf5(path: str | Path, *, file: str) -> Any:
    """``h5py.File(path, "r")`` for an untrusted file: structures that make libhdf5 hang are
    refused first (:func:`check_structure`), and what libhdf5 cannot open is a
    :class:`RecordingError`."""
    h5py = import_h5py()
    check_structure(path, file=file)
    try:
        return h5py.File(path, "r")
    except OSError as exc:
        raise RecordingError(f"not a readable HDF5 file ({exc})", file=file) from None


def text_value(v: Any) -> str:
    """An HDF5 attribute or dataset as text: bytes, one-element string arrays, MATLAB chars."""
    if isinstance(v, bytes):
        return v.decode("utf-8", "replace")
    if isinstance(v, np.ndarray):
        if v.dtype.kind in "SO" and v.size == 1:
            return text_value(v.reshape(-1)[0])
        if v.dtype.kind in "ui":  # MATLAB char arrays: uint16 code points
            return "".join(chr(int(c)) for c in v.reshape(-1))
    return str(v)


@contextlib.contextmanager
def h5_guard(file: str) -> Iterator[None]:
    """Turn what h5py raises on a damaged file while visiting or reading it (a bad object
    header, a soft-link loop, a missing object: RuntimeError, OSError, KeyError) into a
    :class:`RecordingError`; found by audit (a byte flipped in an object header)."""
    try:
        yield
    except (RuntimeError, OSError, KeyError) as exc:
        why = exc.args[0] if isinstance(exc, KeyError) and exc.args else exc
        raise RecordingError(f"not a readable HDF5 file (damaged: {why})", file=file) from None


#: what a dataset of each dtype kind holds, for the message of a channel it cannot be
_KIND_WORDS = {
    "c": "complex",
    "S": "text",
    "U": "text",
    "O": "text (or references)",
    "V": "compound (a table, not numbers)",
    "M": "a date",
    "m": "a time delta",
}


def datasets(f: Any, unusable: dict[str, str] | None = None) -> dict[str, Any]:
    """Every numeric dataset: by full path (no leading slash) and by its last name. The
    others go into ``unusable`` (when given): full path to what they hold."""
    h5py = import_h5py()
    out: dict[str, Any] = {}

    def visit(name: str, obj: Any) -> None:
        if isinstance(obj, h5py.Dataset):
            if obj.dtype.kind in "fiub":
                out[name] = obj
            elif unusable is not None:
                k = obj.dtype.kind
                unusable[name] = _KIND_WORDS.get(k, f"of type {obj.dtype}")

    f.visititems(visit)
    short: dict[str, Any] = {}
    for name, obj in out.items():
        short.setdefault(name.rsplit("/", 1)[-1], obj)
    return {**short, **out}


def vector(ds: Any, *, file: str, column: str) -> np.ndarray:
    """A dataset as a 1-D float64 array (MATLAB row/column vectors are flattened)."""
    shape = ds.shape
    if len([s for s in shape if s != 1]) > 1:
        raise RecordingError(
            f"dataset has shape {shape}; a channel must be a vector", file=file, column=column
        )
    _check_stored(ds, file=file, column=column)
    return real_values(ds[()], file=file, column=column).reshape(-1)


def _check_stored(ds: Any, *, file: str, column: str) -> None:
    """Refuse a long dataset that declares more than it stores (found by audit: a 1.9 KB file
    declaring 1e9 samples was read whole, 8 GB a channel of fill values): none of it written,
    or under a sixteenth where nothing is compressed."""
    nominal = int(ds.size) * int(ds.dtype.itemsize)
    if nominal <= _CHECK_STORED_ABOVE:
        return
    try:
        stored = int(ds.id.get_storage_size())
        filtered = bool(ds.compression or ds.shuffle or ds.scaleoffset)
    except (AttributeError, RuntimeError, ValueError, TypeError):
        return
    if stored == 0 or (not filtered and stored * 16 < nominal):
        raise RecordingError(
            f"dataset declares {ds.size} samples ({nominal / 2**20:.0f} MB) but stores "
            f"{stored} bytes: {'none' if stored == 0 else 'most'} of it was "
            f"{'' if stored == 0 else 'never '}written (a recording stopped early?)",
            file=file,
            column=column,
        )


#: datasets above this many bytes are checked for unwritten storage (_check_stored)
_CHECK_STORED_ABOVE = 8 << 20


def unit_attr(ds: Any) -> str | None:
    for key in ("unit", "units", "unit_string", "Unit"):
        if key in ds.attrs:
            u = text_value(ds.attrs[key]).strip()
            return u or None
    return None


def _dt_attr(objs: list[Any], *, file: str) -> float | None:
    for obj in objs:
        where = "" if obj.name in ("/", None) else f" of {obj.name.lstrip('/')!r}"
        for key in ("dt", "wf_increment", "sampling_interval"):
            if key in obj.attrs:
                label = f"attribute {key!r}{where}"
                return metadata_scalar(obj.attrs[key], file=file, label=label, kind="step")
        for key in ("fs", "sampling_rate", "sample_rate"):
            if key in obj.attrs:
                label = f"attribute {key!r}{where}"
                fs = metadata_scalar(obj.attrs[key], file=file, label=label, kind="rate")
                return step_of_rate(fs, file=file, label=label)
    return None


def hdf5_layout(
    f: Any, *, columns: dict[str, str] | None, kind: str | None, file: str
) -> tuple[str | None, dict[str, str], dict[str, Any], dict[str, str | None], float | None]:
    """What a reader needs before touching the data: ``(kind, mapping, datasets, units, dt)``;
    ``dt`` is the sampling interval from the attributes (None when absent or a ``t`` exists)."""
    unusable: dict[str, str] = {}
    with h5_guard(file):
        dsets = datasets(f, unusable)
        names = [n for n in dsets if not n.startswith("#")]
        kind, mapping = resolve_columns(
            names, columns=columns, kind=kind, file=file, unusable=unusable
        )
        units = {c: unit_attr(dsets[n]) for c, n in mapping.items()}
        dt = None
        if "t" not in mapping:
            dt = _dt_attr([dsets[n] for n in mapping.values()] + [f], file=file)
    return kind, mapping, dsets, units, dt


def read_hdf5(
    path: str | Path,
    *,
    columns: dict[str, str] | None = None,
    kind: str | None = None,
    fs: float | None = None,
    resample: bool = False,
) -> Recording:
    """Read an HDF5 recording; see :func:`contactlab.io.read_recording`.

    Rows in errors are 0-based sample indices.
    """
    path = Path(path)
    file = str(path)
    with open_hdf5(path, file=file) as f:
        kind, mapping, dsets, units, dt = hdf5_layout(f, columns=columns, kind=kind, file=file)
        with h5_guard(file):
            raw = {c: vector(dsets[n], file=file, column=n) for c, n in mapping.items()}
        check_equal_lengths(raw, mapping, file=file)
        t_fallback = None
        if "t" not in raw and fs is None and dt is not None:
            n = next(iter(raw.values())).size
            t_fallback = time_from_interval(dt, n, file=file)
        return finish(
            raw,
            mapping,
            units,
            kind=kind,
            file=file,
            fs=fs,
            resample=resample,
            t_fallback=t_fallback,
            meta={"format": "hdf5"},
        )


def write_hdf5(path: str | Path, rec: Recording, **_: Any) -> Path:
    """Write ``rec`` as HDF5: datasets ``t`` and one per channel, each with a ``unit``
    attribute; the recording's ``source`` and ``kind`` as file attributes."""
    h5py = import_h5py()
    with atomic_path(path) as tmp:
        with h5py.File(tmp, "w") as f:
            f.create_dataset("t", data=rec.t).attrs["unit"] = "s"
            for k, v in rec.data.items():
                f.create_dataset(k, data=v).attrs["unit"] = rec.units[k]
            f.attrs["source"] = rec.source
            if rec.kind:
                f.attrs["kind"] = rec.kind
    return Path(path)


#: samples :meth:`DirectRead.read` asks ``preadv`` for at most when it scans what it reads
#: (256 KB: still in the core's cache when scanned; a streamed analysis's chunk of 2 MB a
#: channel, scanned after its read, came from memory again)
SCAN_PIECE = 1 << 15


class DirectRead:
    """Where the samples of an uncompressed 1-d little-endian float64 dataset lie in the file,
    read with ``os.preadv`` straight into the caller's array (:func:`direct_read`): the bytes
    libhdf5 would copy through its chunk cache, without the copy (a streamed read of a 1.6 GB
    file: 0.52-0.58 -> 0.29-0.30 CPU-s, and no array allocated per chunk).

    ``pieces``: ``(first sample, samples, byte offset)`` of each stored piece (the one extent
    of a contiguous dataset, or every chunk), in sample order.
    """

    def __init__(self, pieces: list[tuple[int, int, int]]) -> None:
        self.pieces = pieces
        self.starts = [p[0] for p in pieces]

    def read(self, fd: int, a: int, out: np.ndarray, scan: list[Any] | None = None) -> bool:
        """Samples ``a : a + out.size`` into ``out`` (contiguous float64); False when the file
        gave fewer bytes than asked (truncated: the caller lets libhdf5 report it).

        ``scan`` (``[True, inf, -inf]`` given): each piece read is scanned as it arrives
        (``_core.finite_min_max`` of at most :data:`SCAN_PIECE` samples, in the cache the
        read left them in) and ``scan`` becomes ``[all finite, smallest, largest]`` of
        ``out`` (after a piece not finite, only its first entry is meaningful: False)."""
        from .. import _core

        b = a + out.size
        k = bisect.bisect_right(self.starts, a) - 1
        mv = memoryview(out).cast("B")
        at = 0
        while a < b:
            start, count, offset = self.pieces[k]
            m = min(b, start + count) - a
            if scan is not None:
                m = min(m, SCAN_PIECE)
            want = 8 * m
            if os.preadv(fd, [mv[at : at + want]], offset + 8 * (a - start)) != want:
                return False
            if scan is not None and scan[0]:
                i = at // 8
                finite, lo, hi = _core.finite_min_max(out[i : i + m])
                if not finite:
                    scan[0] = False
                else:
                    if lo < scan[1]:
                        scan[1] = lo
                    if hi > scan[2]:
                        scan[2] = hi
            at += want
            a += m
            if a >= start + count:
                k += 1
        return True


def direct_read(ds: Any, file_size: int) -> DirectRead | None:
    """The :class:`DirectRead` of dataset ``ds`` when its stored bytes are its values as this
    machine holds float64 (1-d, ``<f8`` on a little-endian machine, no filter, no external
    storage, every chunk written and whole, each inside the file, a file without user block);
    None otherwise (libhdf5 reads it)."""
    import sys

    h5py = import_h5py()
    try:
        if sys.byteorder != "little" or ds.ndim != 1 or ds.dtype.str != "<f8":
            return None
        if ds.file.userblock_size != 0:
            return None
        dcpl = ds.id.get_create_plist()
        if dcpl.get_nfilters() != 0 or dcpl.get_external_count() != 0:
            return None
        n = int(ds.shape[0])
        layout = dcpl.get_layout()
        pieces: list[tuple[int, int, int]] = []
        if layout == h5py.h5d.CONTIGUOUS:
            off = ds.id.get_offset()
            if off is None:
                return None
            pieces = [(0, n, int(off))]
        elif layout == h5py.h5d.CHUNKED and hasattr(ds.id, "chunk_iter"):
            c = int(ds.chunks[0])
            infos: list[Any] = []
            ds.id.chunk_iter(infos.append)
            for info in infos:
                if info.filter_mask != 0 or info.byte_offset is None or info.size != 8 * c:
                    return None
                start = int(info.chunk_offset[0])
                pieces.append((start, min(c, n - start), int(info.byte_offset)))
            pieces.sort()
            if [p[0] for p in pieces] != list(range(0, n, c)):
                return None  # chunks never written (fill value): libhdf5 knows
        else:
            return None
    except Exception:  # anything unexpected (a damaged index): libhdf5 reads it
        return None
    if any(count <= 0 or off < 0 or off + 8 * count > file_size for _s, count, off in pieces):
        return None
    return DirectRead(pieces)
