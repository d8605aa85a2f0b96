"""All-or-nothing writing of a set of output files (report, tables, figures).

A run first renders every output in memory, then :func:`commit_outputs` writes them as
hidden temporary files beside their targets and, only when all are complete, renames each into
place. An error or Ctrl-C before that last step removes the temporaries, so the output folder is
left exactly as it was; the renames themselves take microseconds.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Mapping
from pathlib import Path, PurePosixPath

from . import _interrupt
from .errors import InputError


def _check_relative(name: str) -> PurePosixPath:
    rel = PurePosixPath(name)
    if rel.is_absolute() or ".." in rel.parts or not rel.parts:
        raise InputError(f"output name {name!r} must be a relative path inside the output folder")
    return rel


def _default_mode() -> int:
    """Permissions a plain ``open(..., "w")`` would give (mkstemp makes files 0600)."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def commit_outputs(directory: str | os.PathLike[str], files: Mapping[str, bytes]) -> list[Path]:
    """Write ``files`` (relative name → content) under ``directory``, all or nothing.

    Parameters
    ----------
    directory : path
        Output folder; created if missing (with parents).
    files : mapping of str to bytes
        Relative POSIX paths (sub-folders allowed) and their full contents.

    Returns
    -------
    list of Path
        The written files, in the order given.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> [p.name for p in commit_outputs(d, {"a.txt": b"1", "sub/b.txt": b"2"})]
    ['a.txt', 'b.txt']
    """
    root = Path(directory)
    targets = [(root / _check_relative(name), data) for name, data in files.items()]
    mode = _default_mode()
    created_dirs: list[Path] = []
    staged: list[tuple[Path, Path]] = []
    try:
        for final, data in targets:
            parent = final.parent
            missing = []
            while not parent.exists():
                missing.append(parent)
                parent = parent.parent
            for d in reversed(missing):
                d.mkdir()
                created_dirs.append(d)
            fd, tmp = tempfile.mkstemp(prefix=f".{final.name}.", suffix=".part", dir=final.parent)
            staged.append((Path(tmp), final))
            with os.fdopen(fd, "wb") as fh:
                fh.write(data)
            os.chmod(staged[-1][0], mode)
        # Every temporary is complete: move them into place (fast, no more I/O of content),
        # unless a Ctrl-C came and was swallowed where it landed (a finaliser, a fork hook)
        _interrupt.check()
        for tmp, final in staged:
            os.replace(tmp, final)
    except BaseException:
        for tmp, _ in staged:
            with contextlib.suppress(FileNotFoundError):
                tmp.unlink()
        for d in reversed(created_dirs):
            with contextlib.suppress(OSError):
                d.rmdir()  # only removed when still empty
        raise
    return [final for final, _ in targets]
