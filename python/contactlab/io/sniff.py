"""Tell a file's format from its first bytes, so a file that is not what its extension says
is reported as such instead of failing somewhere deep inside a parser."""

from __future__ import annotations

from pathlib import Path

from .recording import RecordingError

HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
EXTENSIONS = {
    ".csv": "csv",
    ".txt": "csv",
    ".tsv": "csv",
    ".dat": "csv",
    ".tdms": "tdms",
    ".h5": "hdf5",
    ".hdf5": "hdf5",
    ".hdf": "hdf5",
    ".mat": "mat",
    ".npy": "npy",
    ".npz": "npy",
}
NAMES = {
    "csv": "a text (CSV)",
    "tdms": "a TDMS",
    "hdf5": "an HDF5",
    "mat": "a MATLAB .mat",
    "npy": "a NumPy .npy",
    "npz": "a NumPy .npz (zip)",
}


def content_format(path: Path) -> str:
    """``"tdms"``, ``"hdf5"``, ``"mat"`` (v4-v7), ``"mat73"`` (HDF5 based), ``"npy"``,
    ``"npz"`` (a zip archive), ``"csv"`` or ``"binary"`` (unknown binary), from the content
    alone."""
    with open(path, "rb") as fh:
        head = fh.read(1024)
    if head.startswith(b"TDSm"):
        return "tdms"
    if head.startswith(HDF5_SIGNATURE):
        return "hdf5"
    if head.startswith(b"MATLAB 7.3 MAT-file") and head[512:520] == HDF5_SIGNATURE:
        return "mat73"
    if head.startswith(b"MATLAB 5.0 MAT-file"):
        return "mat"
    if head.startswith(b"\x93NUMPY"):
        return "npy"
    if head.startswith((b"PK\x03\x04", b"PK\x05\x06")):
        return "npz"
    if b"\x00" in head:
        return "binary"
    try:
        head.decode("utf-8")
    except UnicodeDecodeError as exc:
        # A cut multi-byte character at the end of the block is fine.
        if exc.start < len(head) - 4:
            try:
                head.decode("latin-1")
            except UnicodeDecodeError:  # pragma: no cover - latin-1 decodes any byte
                return "binary"
    return "csv"


def _is_mat4(path: Path) -> bool:
    """MATLAB v4 files have no text header; ask scipy whether it can list the variables."""
    import scipy.io

    with open(path, "rb") as fh:
        if 0 not in fh.read(4):
            # scipy would take it for a v5 file (its compiled parser, not safe on arbitrary
            # bytes; a real v5 file starts with its text header and never gets here)
            return False
    try:
        return bool(scipy.io.whosmat(path))
    except Exception:  # any parse failure means: not a v4 file
        return False


def format_of(path: Path, fmt: str | None = None) -> str:
    """The format to read ``path`` with: from its extension (or ``fmt``), verified by content."""
    if not path.exists():
        raise RecordingError("no such file", file=str(path))
    if path.is_dir():
        raise RecordingError("is a directory, not a recording file", file=str(path))
    if fmt == "npz":
        fmt = "npy"  # one reader for both
    if fmt is None:
        fmt = EXTENSIONS.get(path.suffix.lower())
        if fmt is None:
            raise RecordingError(
                f"unknown extension {path.suffix!r}; supported: {sorted(EXTENSIONS)}",
                file=str(path),
            )
    content = content_format(path)
    if fmt == "mat" and content == "binary" and _is_mat4(path):
        return fmt
    ok = {
        "csv": ("csv",),
        "tdms": ("tdms",),
        "hdf5": ("hdf5", "mat73"),
        "mat": ("mat", "mat73"),
        "npy": ("npz", "npy") if path.suffix.lower() == ".npz" else ("npy",),
    }[fmt]
    if content not in ok:
        found = {"mat73": "a MATLAB v7.3 (HDF5)", "binary": "an unknown binary"}.get(
            content, NAMES.get(content, content)
        )
        raise RecordingError(
            f"the extension says {NAMES[fmt]} file but the content is {found} file",
            file=str(path),
        )
    return fmt
