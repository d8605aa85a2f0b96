"""Write outputs so that an interrupted run never leaves a half-written file behind."""

from __future__ import annotations

import contextlib
import os
import stat
from collections.abc import Iterator
from pathlib import Path

from . import _interrupt


def default_mode() -> int:
    """Permissions a plain ``open(..., "w")`` would give: ``0o666`` less the umask.

    ``tempfile.mkstemp`` creates files ``0o600``; renamed into place as they are, every output
    would be unreadable for colleagues and web servers sharing the results folder.
    """
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def _final_mode(final: Path) -> int:
    """Keep the permissions of a file being replaced; a new file gets :func:`default_mode`."""
    try:
        return stat.S_IMODE(final.stat().st_mode)
    except OSError:
        return default_mode()


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; rename it into place only on success.

    The file gets the permissions an ordinary ``open(path, "w")`` would give it (those of the
    file it replaces, or ``0o666`` less the umask), not ``mkstemp``'s ``0o600``.
    """
    final = Path(path)
    final.parent.mkdir(parents=True, exist_ok=True)
    import tempfile  # here: its imports (shutil, random) cost every command's start-up

    fd, tmp = tempfile.mkstemp(prefix=f".{final.name}.", suffix=".part", dir=final.parent)
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        yield tmp_path
        _interrupt.check()  # a Ctrl-C swallowed where it landed (a finaliser, a fork hook)
        os.chmod(tmp_path, _final_mode(final))
        os.replace(tmp_path, final)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            tmp_path.unlink()
        raise


def write_text(path: str | os.PathLike[str], text: str) -> Path:
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return Path(path)
