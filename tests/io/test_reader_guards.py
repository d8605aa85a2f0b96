"""Damaged files that used to take the process down: libhdf5 looping for ever, scipy's MAT v5
parser crashing. Each is now a RecordingError before the library touches it; valid files of
every kind MATLAB, scipy and h5py write still pass the checks.

The inputs that hung or crashed are replayed in a child process with a timeout, so a
regression fails this test instead of hanging or killing the test run.
"""

from __future__ import annotations

import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
import scipy.io
from hypothesis import given, settings
from hypothesis import strategies as st

from contactlab.io import Recording, RecordingError, read_recording, write_recording
from contactlab.io.mat5check import check_mat5

REPO = Path(__file__).resolve().parents[2]
FUZZ = REPO / "fuzz" / "regressions"
SCIPY_MATLAB_FILES = Path(scipy.io.__file__).parent / "matlab" / "tests" / "data"


def _rec() -> Recording:
    t = np.arange(64) / 1000.0
    p = 0.5e6 + 0.4e6 * np.sin(2 * np.pi * 10 * t)
    return Recording(t, {"p": p, "delta": p * 1e-11}, {"p": "Pa", "delta": "m"})


def _read_in_child(path: Path, timeout: float = 60.0) -> str:
    """read_recording(path) in a fresh interpreter: 'ok', or the RecordingError's message.
    A hang is a TimeoutExpired and a crash a non-zero exit, both failures here."""
    code = (
        "import sys\n"
        "from contactlab.io import read_recording, RecordingError\n"
        "try:\n"
        "    read_recording(sys.argv[1])\n"
        "    print('ok')\n"
        "except RecordingError as e:\n"
        "    print('RecordingError:', e)\n"
    )
    run = subprocess.run(
        [sys.executable, "-c", code, str(path)],
        capture_output=True,
        text=True,
        timeout=timeout,
        check=False,
    )
    assert run.returncode == 0, f"exit {run.returncode}: {run.stderr[-2000:]}"
    return run.stdout.strip()


@pytest.mark.parametrize(
    ("name", "ext", "what"),
    [
        # global heap: a free-space record of size 0, where libhdf5 looped
        ("read_hdf5/e3ddb332f852", ".h5", "free-space record of size 0"),
        # a data element typed 49: scipy indexed past its type table (segmentation fault)
        ("read_mat/f10095c36289", ".mat", "element type 49"),
    ],
)
def test_inputs_that_hung_or_crashed_are_a_recording_error(name, ext, what, tmp_path):
    folder, prefix = name.split("/")
    (src,) = [p for p in (FUZZ / folder).iterdir() if p.name.startswith(prefix)]
    path = tmp_path / f"damaged{ext}"
    path.write_bytes(src.read_bytes())
    out = _read_in_child(path)
    assert out.startswith("RecordingError:"), out
    assert "damaged" in out and "byte" in out and what in out, out


def _gcol_file(tmp_path: Path) -> tuple[Path, int]:
    """A valid HDF5 recording (variable-length unit strings live in a global heap) and the
    offset of its first global heap collection."""
    path = tmp_path / "run.h5"
    write_recording(path, _rec())
    raw = path.read_bytes()
    return path, raw.index(b"GCOL\x01")


def test_global_heap_walk_that_never_ends_is_refused(tmp_path):
    path, at = _gcol_file(tmp_path)
    assert read_recording(path).t.size == 64  # the valid file reads
    raw = bytearray(path.read_bytes())
    # object 1 (16-byte header at at+16) claims 128 bytes: the walk lands on zeros, a
    # free-space record of size 0, where libhdf5 loops
    raw[at + 16 + 8 : at + 16 + 16] = (128).to_bytes(8, "little")
    path.write_bytes(bytes(raw))
    with pytest.raises(RecordingError, match=r"global heap collection at byte \d+"):
        read_recording(path)
    # the chunked reader (track's streaming path) opens through the same guard
    from contactlab.io.chunked import read_chunks

    with pytest.raises(RecordingError, match="global heap"):
        read_chunks(path, chunk_size=16)


def _edit_h5(tmp_path: Path, name: str, edit) -> Path:
    """A valid HDF5 recording with ``edit(raw, offsets)`` applied; offsets of its (single)
    group B-tree node and local heap, both relative to byte 0 (no user block)."""
    path = tmp_path / f"{name}.h5"
    write_recording(path, _rec())
    raw = bytearray(path.read_bytes())
    tree, heap = raw.index(b"TREE"), raw.index(b"HEAP")
    data = int.from_bytes(raw[heap + 24 : heap + 32], "little")  # data segment address
    edit(raw, tree, heap, data)
    path.write_bytes(bytes(raw))
    return path


def _q(v: int) -> bytes:
    return v.to_bytes(8, "little")


def _sibling_self(raw, tree, heap, data):
    raw[tree + 16 : tree + 24] = _q(tree)  # right sibling: the node itself (libhdf5 loops)


def _child_self(raw, tree, heap, data):
    raw[tree + 5] = 1  # level 1 whose first child is the node itself: endless recursion
    raw[tree + 32 : tree + 40] = _q(tree)  # (a segmentation fault in libhdf5)


def _free_list_self(raw, tree, heap, data):
    head = int.from_bytes(raw[heap + 16 : heap + 24], "little")
    raw[data + head : data + head + 8] = _q(head)  # the free block's next: itself (loops)


@pytest.mark.parametrize(
    ("edit", "what"),
    [
        (_sibling_self, "its own right sibling"),
        (_child_self, "has a child of level 1"),
        (_free_list_self, "free list of the local heap"),
    ],
)
def test_hdf5_structures_libhdf5_never_leaves_are_refused(edit, what, tmp_path):
    path = _edit_h5(tmp_path, edit.__name__, edit)
    out = _read_in_child(path)
    assert out.startswith("RecordingError:") and what in out, out


def test_mat73_file_goes_through_the_hdf5_guard(tmp_path):
    import h5py

    path = tmp_path / "run.mat"
    write_recording(path, _rec(), version="7.3")
    with h5py.File(path, "r+") as f:  # a variable-length string: a global heap collection
        f["p"].attrs["note"] = "bench 2"
    assert read_recording(path).t.size == 64
    raw = bytearray(path.read_bytes())
    at = raw.index(b"GCOL\x01")
    raw[at + 24 : at + 32] = (128).to_bytes(8, "little")
    path.write_bytes(bytes(raw))
    with pytest.raises(RecordingError, match="global heap"):
        read_recording(path)


def _scipy_can_load(path: Path) -> bool:
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            scipy.io.loadmat(path)
    except Exception:
        return False
    return True


def test_every_matlab_file_scipy_reads_passes_the_mat5_check():
    """scipy's collection of files written by MATLAB 5 to 7.x on several platforms (both byte
    orders, compressed, structs, cells, objects, sparse, logical, unicode)."""
    files = sorted(SCIPY_MATLAB_FILES.glob("*.mat")) if SCIPY_MATLAB_FILES.is_dir() else []
    v5 = [p for p in files if 0 not in p.read_bytes()[:4]]
    if len(v5) < 20:
        pytest.skip("scipy's test data is not installed")
    checked = 0
    for p in v5:
        if _scipy_can_load(p):
            check_mat5(p, file=str(p))  # raises on a false alarm
            checked += 1
    assert checked >= 60


@pytest.mark.parametrize("compress", [False, True])
def test_files_scipy_writes_pass_the_mat5_check(compress, tmp_path):
    from scipy.sparse import csc_array

    path = tmp_path / "all.mat"
    data = {
        "x": np.linspace(0, 1, 7),
        "z": np.array([1 + 2j, 3 - 1j]),
        "i": np.arange(5, dtype=np.int16),
        "b": np.array([True, False]),
        "e": np.zeros((0, 3)),
        "s": "text ünïcode",
        "c": np.array([np.arange(3.0), "a", np.zeros((2, 2))], dtype=object),
        "st": {"a": 1.0, "b": {"deep": np.ones(4)}, "u": "m"},
        "sp": csc_array(np.eye(4)),
    }
    scipy.io.savemat(path, data, do_compression=compress)
    check_mat5(path, file=str(path))
    assert read_recording(path, columns={"t": "x", "p": "x", "delta": "x"}, kind="normal")


@pytest.mark.parametrize(
    ("offset", "value", "message"),
    [
        (0x84, 0xFFFFFF00, "overruns"),  # the first variable's size beyond the file
        (0x88, 0x31, "array flags"),  # the flags element's type
        (0x98, 0x07, "dimensions"),  # dims typed single
        (0xB0, 0x31, "element type 49"),  # the real part typed 49 (the scipy crash)
        (0xB4, 0x08, "holds 1 values"),  # 64 doubles declared as 8 bytes
        (0x80, 0x02, "top-level element of type 2"),
    ],
)
def test_damaged_mat5_elements_are_named(offset, value, message, tmp_path):
    path = tmp_path / "run.mat"
    write_recording(path, _rec())
    raw = bytearray(path.read_bytes())
    raw[offset : offset + 4] = value.to_bytes(4, "little")
    path.write_bytes(bytes(raw))
    with pytest.raises(RecordingError, match=message):
        read_recording(path)


def test_binary_that_scipy_would_parse_as_v5_is_not_taken_for_v4(tmp_path):
    # no text header, but nonzero first bytes and a version word at 124: scipy would run its
    # compiled v5 parser on it; the format check calls it an unknown binary instead
    raw = bytearray(b"\x01\x02\x03\x04" + bytes(200))
    raw[124:128] = b"\x00\x01IM"
    raw[128:136] = (14).to_bytes(4, "little") + (0x40000000).to_bytes(4, "little")
    path = tmp_path / "odd.mat"
    path.write_bytes(bytes(raw))
    with pytest.raises(RecordingError, match="unknown binary"):
        read_recording(path)


def test_deep_valid_hdf5_trees_pass_the_structure_check(tmp_path):
    """B-trees of level 1 and 2 with sibling chains (a group of 600 links, a dataset of 500
    chunks), variable-length attributes, and the latest file format: all read."""
    import h5py

    from contactlab.io.hdf5 import check_structure

    for libver in ("earliest", "latest"):
        path = tmp_path / f"deep-{libver}.h5"
        with h5py.File(path, "w", libver=libver) as f:
            f.create_dataset("t", data=np.arange(5000) / 1000.0).attrs["unit"] = "s"
            f.create_dataset("x", data=np.sin(np.arange(5000.0)), chunks=(10,))
            f["x"].attrs["unit"] = "um"
            f.create_dataset("F", data=np.cos(np.arange(5000.0))).attrs["unit"] = "N"
            g = f.create_group("many")
            for i in range(600):
                g.create_dataset(f"d{i:04d}", data=np.arange(2.0)).attrs["note"] = f"v{i}"
        raw = path.read_bytes()
        if libver == "earliest":  # the trees this test is about are there
            levels = {raw[p + 5] for p in range(len(raw)) if raw.startswith(b"TREE", p)}
            assert max(levels) >= 1
        check_structure(path, file=str(path))
        assert read_recording(path).t.size == 5000


def test_a_long_checked_file_is_scanned_once_until_it_changes(tmp_path, monkeypatch):
    """``analyze`` opens a long HDF5 file twice; the structure scan (a read of the whole
    file) runs once, and again when the file changes. Small files are always scanned."""
    import h5py

    from contactlab.io import hdf5

    scans = []
    real = hdf5._check_btrees
    monkeypatch.setattr(hdf5, "_check_btrees", lambda *a: scans.append(1) or real(*a))
    monkeypatch.setattr(hdf5, "_CACHE_ABOVE", 1 << 16)
    monkeypatch.setattr(hdf5, "_CHECKED", set())
    path = tmp_path / "long.h5"
    with h5py.File(path, "w") as f:
        f.create_dataset("x", data=np.zeros(20_000))
    hdf5.check_structure(path, file=str(path))
    hdf5.check_structure(path, file=str(path))
    assert len(scans) == 1
    with h5py.File(path, "a") as f:
        f["x"][0] = 1.0
        f.attrs["note"] = "changed"
    hdf5.check_structure(path, file=str(path))
    assert len(scans) == 2
    small = tmp_path / "small.h5"
    with h5py.File(small, "w") as f:
        f.create_dataset("x", data=np.zeros(10))
    for _ in range(2):
        hdf5.check_structure(small, file=str(small))
    assert len(scans) == 4


@pytest.mark.parametrize("block", [4, 5, 8, 1 << 24])
def test_file_view_reads_and_finds_as_bytes_do(tmp_path, monkeypatch, block):
    """The structure scan's block reader (bounded memory instead of a memory map): slices,
    single bytes and find, needles straddling the blocks' edges included."""
    from contactlab.io import hdf5

    monkeypatch.setattr(hdf5._FileView, "BLOCK", block)
    data = b"xxTREExHEAPTREEyyGCOL\x01zzTRE" + bytes(range(256)) + b"TREE"
    path = tmp_path / "b.bin"
    path.write_bytes(data)
    with open(path, "rb") as fh:
        v = hdf5._FileView(fh.fileno(), len(data))
        for needle in (b"TREE", b"HEAP", b"GCOL\x01", b"TRE", b"none"):
            pos, ref = v.find(needle), data.find(needle)
            while ref != -1:
                assert pos == ref, needle
                pos, ref = v.find(needle, pos + 1), data.find(needle, ref + 1)
            assert pos == -1
        assert v[3:9] == data[3:9] and v[len(data) - 2 : len(data) + 5] == data[-2:]
        assert v[7] == data[7] and v[5:5] == b""
        with pytest.raises(IndexError):
            v[len(data)]


@pytest.mark.parametrize("threads", [1, 2, 3])
@pytest.mark.parametrize("block", [4, 5, 8, 1 << 24])
def test_file_view_index_answers_as_find_does(tmp_path, monkeypatch, block, threads):
    """The same index from one scanning thread or several (alternate blocks)."""
    from contactlab.io import hdf5

    monkeypatch.setattr(hdf5._FileView, "BLOCK", block)
    monkeypatch.setattr(hdf5, "_SCAN_THREADS", threads)
    data = b"TREExxHEAPTREEyyGCOL\x01zzTRE" + bytes(range(256)) + b"TREEHEAP"
    path = tmp_path / "b.bin"
    path.write_bytes(data)
    with open(path, "rb") as fh:
        v = hdf5._FileView(fh.fileno(), len(data))
        v.index((b"GCOL\x01", b"TREE", b"HEAP"))
        for needle in (b"TREE", b"HEAP", b"GCOL\x01", b"TRE"):
            for start in range(len(data) + 2):
                assert v.find(needle, start) == data.find(needle, start), (needle, start)


@pytest.mark.parametrize("mapped", [True, False])
def test_file_view_index_mapped_blocks_as_read_ones(tmp_path, monkeypatch, mapped):
    """Blocks of a whole page-granule are searched in a memory map (no copy), others read:
    both give every occurrence, those straddling a block's edge included."""
    import mmap

    from contactlab.io import hdf5

    g = mmap.ALLOCATIONGRANULARITY
    monkeypatch.setattr(hdf5._FileView, "BLOCK", g)
    calls = []
    real = hdf5._mapped_hits

    def spy(*a):
        calls.append(a[1])
        return real(*a) if mapped else None

    monkeypatch.setattr(hdf5, "_mapped_hits", spy)
    rng = np.random.default_rng(3)
    data = bytearray(rng.integers(0, 256, 3 * g + 77, dtype=np.uint8).tobytes())
    for at in (0, g - 2, g + 5, 2 * g - 3, 3 * g + 70):  # across the edges too
        data[at : at + 4] = b"TREE"
    data[2 * g - 1 : 2 * g + 3] = b"HEAP"
    data = bytes(data)
    path = tmp_path / "b.bin"
    path.write_bytes(data)
    with open(path, "rb") as fh:
        v = hdf5._FileView(fh.fileno(), len(data))
        v.index((b"TREE", b"HEAP"))
    assert calls  # the mapped path was asked for every block
    for nd in (b"TREE", b"HEAP"):
        ref = [i for i in range(len(data)) if data.startswith(nd, i)]
        assert v._index[nd] == ref, nd


@settings(max_examples=60, deadline=None)
@given(
    data=st.binary(max_size=120).map(lambda b: bytes(b"TREAHP"[c % 6] for c in b)),
    block=st.integers(1, 40),
)
def test_file_view_index_is_every_occurrence(tmp_path_factory, data, block):
    """The index (the Rust signature search over blocks and their overlaps) holds every
    occurrence bytes.find gives, overlapping ones ("TT" in "TTT") and those across edges."""
    from contactlab.io import hdf5

    path = tmp_path_factory.mktemp("idx") / "b.bin"
    path.write_bytes(data)
    needles = (b"TREE", b"HEAP", b"EE", b"T")
    old, hdf5._FileView.BLOCK = hdf5._FileView.BLOCK, block
    try:
        with open(path, "rb") as fh:
            v = hdf5._FileView(fh.fileno(), len(data))
            v.index(needles)
    finally:
        hdf5._FileView.BLOCK = old
    for nd in needles:
        ref = [i for i in range(len(data)) if data.startswith(nd, i)]
        assert v._index[nd] == ref, nd


def test_structure_check_started_ahead_is_waited_for_and_damage_still_named(tmp_path, monkeypatch):
    """The command line starts the scan of a long HDF5 file before importing the analysis
    (``prefetch_structure_check``); the call that opens the file waits for it instead of
    scanning again, and a damaged file is refused by that call with its own message."""
    from contactlab.cli import prefetch_checks
    from contactlab.io import hdf5

    scans = []
    real = hdf5._check_btrees
    monkeypatch.setattr(hdf5, "_check_btrees", lambda *a: scans.append(1) or real(*a))
    monkeypatch.setattr(hdf5, "_CACHE_ABOVE", 1 << 10)
    monkeypatch.setattr(hdf5, "_CHECKED", set())
    path, _ = _gcol_file(tmp_path)
    prefetch_checks(["analyze", str(path), "--model", "tangential"])
    hdf5.check_structure(path, file=str(path))
    assert read_recording(path).t.size == 64
    assert len(scans) == 1  # the scan started ahead, waited for; not run again
    assert not hdf5._PENDING
    # not an HDF5 file, a verb that reads nothing, a small file: nothing started
    text = tmp_path / "run.csv"
    text.write_text("t,x\n" + "0,1\n" * 400)
    assert not hdf5.prefetch_structure_check(text)
    assert not hdf5.prefetch_structure_check(tmp_path / "absent.h5")
    # damage: the scan ahead fails quietly, the opening call names it
    (tmp_path / "bad").mkdir()
    bad, at = _gcol_file(tmp_path / "bad")
    raw = bytearray(bad.read_bytes())
    raw[at + 16 + 8 : at + 16 + 16] = (128).to_bytes(8, "little")
    bad.write_bytes(bytes(raw))
    assert hdf5.prefetch_structure_check(bad)
    with pytest.raises(RecordingError, match=r"global heap collection at byte \d+"):
        read_recording(bad)
    assert not hdf5._PENDING


def test_a_scan_started_ahead_stops_when_the_command_line_ends(tmp_path, monkeypatch):
    """A usage error or Ctrl-C ends the run before it opens the file: the scan started ahead
    stops at its next block (the exit does not wait for a read of the whole file), and the
    file is not recorded as checked."""
    import threading

    from contactlab.io import hdf5

    monkeypatch.setattr(hdf5, "_CACHE_ABOVE", 1 << 10)
    monkeypatch.setattr(hdf5, "_CHECKED", set())
    monkeypatch.setattr(hdf5, "_STOP", threading.Event())
    monkeypatch.setattr(hdf5._FileView, "BLOCK", 64)  # many blocks: the stop lands in one
    started = threading.Event()
    real = hdf5._FileView._scan_blocks

    def slow(self, *a, **k):
        started.set()
        hdf5._STOP.wait(5)  # the stop arrives while the scan runs
        return real(self, *a, **k)

    monkeypatch.setattr(hdf5._FileView, "_scan_blocks", slow)
    path, _ = _gcol_file(tmp_path)
    assert hdf5.prefetch_structure_check(path)
    assert started.wait(5)
    hdf5.stop_prefetched_checks()
    assert not hdf5._PENDING and not hdf5._CHECKED
