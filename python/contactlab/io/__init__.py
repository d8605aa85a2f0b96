"""Reading and writing recordings: CSV/text, NI TDMS, HDF5, MATLAB .mat and NumPy .npy/.npz,
SI inside.

Typical use (a file with columns ``t [ms], x [um], F [N]``)::

    from contactlab.io import read_recording
    rec = read_recording("run_109N.csv")
    rec["x"], rec.units["x"]            # metres, "m"

The format comes from the extension and is checked against the content. Channel names are
guessed (``x``/``disp``, ``F``/``force``, ``p``/``pressure``, ``delta``, ``t``/``time``) or given
with ``columns={"x": "LVDT 1", "F": "load cell"}``. Units come from the column name
(``x [um]``) or the format's unit metadata (TDMS ``unit_string``, HDF5 ``unit`` attribute);
a channel without a unit is taken as SI and listed in ``meta["units_assumed_si"]``. TDMS, HDF5
and MAT v7.3 need the optional extra ``contactlab[io]`` (npTDMS, h5py).

Long files: :func:`read_chunks` yields the same recording as consecutive chunks of bounded
size, with the same checks and messages (see :mod:`.chunked`).
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..errors import ContactLabError
from .chunked import DEFAULT_CHUNK, ChunkedRecording, read_chunks
from .recording import DIMENSIONS, KIND_CHANNELS, Recording, RecordingError
from .sniff import EXTENSIONS, format_of
from .units import UnknownUnitError, known_units, split_name, to_si

__all__ = [
    "DEFAULT_CHUNK",
    "DIMENSIONS",
    "KIND_CHANNELS",
    "ChunkedRecording",
    "Recording",
    "RecordingError",
    "UnknownUnitError",
    "known_units",
    "read_chunks",
    "read_recording",
    "split_name",
    "supported_extensions",
    "to_si",
    "write_recording",
]


_FORMAT_NAMES = {"tdms": "TDMS", "hdf5": "HDF5", "mat": "MATLAB", "npy": "NumPy"}
_LIBRARY_ERRORS = (
    OSError,
    RuntimeError,
    KeyError,
    IndexError,
    ValueError,
    TypeError,
    ArithmeticError,  # OverflowError, ZeroDivisionError
    NameError,  # scipy.io's UnboundLocalError on a damaged struct
    AttributeError,
    MemoryError,
    EOFError,
    struct.error,
    UnicodeError,
)


def supported_extensions() -> list[str]:
    """File extensions :func:`read_recording` and :func:`write_recording` handle."""
    return sorted(EXTENSIONS)


def _reader(fmt: str) -> Callable[..., Recording]:
    if fmt == "csv":
        from .csv import read_csv

        return read_csv
    if fmt == "tdms":
        from .tdms import read_tdms

        return read_tdms
    if fmt == "hdf5":
        from .hdf5 import read_hdf5

        return read_hdf5
    if fmt == "npy":
        from .npy import read_npy

        return read_npy
    from .mat import read_mat

    return read_mat


def read_recording(
    path: str | Path,
    *,
    columns: dict[str, str] | None = None,
    kind: str | None = None,
    fs: float | None = None,
    format: str | None = None,
    resample: bool = False,
) -> Recording:
    """Read a recording file into a :class:`Recording` in SI units.

    Parameters
    ----------
    path : str or Path
        ``.csv``/``.txt``/``.tsv``/``.dat``, ``.tdms``, ``.h5``/``.hdf5``, ``.mat``,
        ``.npy`` or ``.npz`` (layouts: :mod:`contactlab.io.npy`).
    columns : dict, optional
        Canonical name (``"t"``, ``"x"``, ``"F"``, ``"p"``, ``"delta"``) to the column,
        channel, dataset or variable name in the file (with or without its unit).
        Unmapped channels are guessed by name.
    kind : {"tangential", "normal", None}
        Which channels are needed (``x, F`` or ``p, delta``); None guesses from the names.
    fs : float, optional
        Sampling rate (Hz) when the file has no time column or time increment.
    format : {"csv", "tdms", "hdf5", "mat", "npy", "npz"}, optional
        Override the extension.
    resample : bool
        Interpolate a non-uniformly sampled record onto the uniform grid of its median step
        (steps up to four grid steps are bridged; a longer one is a real gap and still an
        error); ``meta["resampled"]`` tells the largest gap bridged. See
        :func:`contactlab.io.recording.resample_uniform`.

    Returns
    -------
    Recording

    Raises
    ------
    RecordingError
        (an :class:`~contactlab.InputError`) naming file, column and row: missing or
        misnamed column, unknown unit or a unit of the wrong dimension, a non-numeric cell,
        unsorted, duplicated or gapped time stamps, content that does not match the extension.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "run.csv"
    >>> _ = p.write_text("t [ms],x [um],F [N]\\n0,0,0\\n1,2,0.5\\n2,4,0.9\\n")
    >>> rec = read_recording(p)
    >>> rec.t.tolist(), rec["x"].tolist(), rec.units["x"]
    ([0.0, 0.001, 0.002], [0.0, 2e-06, 4e-06], 'm')
    """
    p = Path(path)
    fmt = format_of(p, format)
    if fmt == "csv":
        return _reader(fmt)(p, columns=columns, kind=kind, fs=fs, resample=resample)
    try:
        return _reader(fmt)(p, columns=columns, kind=kind, fs=fs, resample=resample)
    except ContactLabError:
        raise
    except _LIBRARY_ERRORS as exc:
        # h5py, scipy.io and npTDMS raise all of these (and KeyError for a missing object) on
        # damaged files, from deep inside; found by fuzzing (fuzz/read_{hdf5,mat,tdms}.py)
        raise RecordingError(
            f"not a readable {_FORMAT_NAMES[fmt]} file (damaged? {type(exc).__name__}: {exc})",
            file=str(p),
        ) from None


def write_recording(path: str | Path, rec: Recording, **options: Any) -> Path:
    """Write ``rec`` in the format its extension names, atomically (no half-written file).

    SI units are written with the data (CSV header ``x [m]``, TDMS ``unit_string``, HDF5
    ``unit`` attributes, a MAT ``units`` struct). ``options`` go to the format's writer, e.g.
    ``version="7.3"`` for ``.mat``.
    """
    p = Path(path)
    fmt = options.pop("format", None) or EXTENSIONS.get(p.suffix.lower())
    if fmt is None:
        raise RecordingError(
            f"unknown extension {p.suffix!r}; supported: {supported_extensions()}", file=str(p)
        )
    if not isinstance(rec, Recording):
        raise RecordingError(f"expected a Recording, got {type(rec).__name__}", file=str(p))
    if fmt == "csv":
        from .csv import write_csv as writer
    elif fmt == "tdms":
        from .tdms import write_tdms as writer
    elif fmt == "hdf5":
        from .hdf5 import write_hdf5 as writer
    elif fmt == "npy":
        from .npy import write_npy as writer
    else:
        from .mat import write_mat as writer
    return writer(p, rec, **options)
