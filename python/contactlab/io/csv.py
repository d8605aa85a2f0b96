"""CSV / text recordings: one header row with column names (units in brackets), then numbers.

Lines starting with ``#`` before the header are kept as comments in ``meta``. The delimiter
(comma, semicolon, tab or whitespace) is detected from the header, and a decimal comma
(``1,5`` as European locales write it, with ``;`` or tab delimiters) from the first data line.
Only the needed columns are parsed (``numpy.loadtxt`` with ``usecols``); when that fails, the
file is scanned once more to name the first bad cell by line and column.
"""

from __future__ import annotations

import csv as _csv
import re
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from .._io_atomic import atomic_path
from .recording import Recording, RecordingError, finish, resolve_columns
from .units import split_name


def sniff_encoding(path: Path) -> str:
    """``"utf-8-sig"`` when the file's start decodes as UTF-8, else ``"latin-1"``.

    Acquisition software on Windows writes headers and comments such as ``Weg [µm]`` or
    ``# Prüfstand 2`` in a legacy 8-bit code page; read as UTF-8 those files failed with
    'cannot be parsed as numbers'. Latin-1 decodes any byte, and its µ (0xB5) is cp1252's.
    """
    with open(path, "rb") as fh:
        head = fh.read(1 << 20)
    try:
        head.decode("utf-8")
    except UnicodeDecodeError as exc:
        if exc.start < len(head) - 4:  # not merely a character cut at the end of the block
            return "latin-1"
    return "utf-8-sig"


def read_header(path: Path, enc: str = "utf-8-sig") -> tuple[list[str], str | None, int, list[str]]:
    """Column names, delimiter (None = whitespace), 0-based header line, comment lines."""
    comments: list[str] = []
    with open(path, encoding=enc, errors="replace") as fh:
        for lineno, line in enumerate(fh):
            s = line.strip()
            if not s:
                continue
            if s.startswith("#"):
                comments.append(s[1:].strip())
                continue
            delim = next((d for d in ("\t", ";", ",") if d in s), None)
            names = _fields(s, delim)
            if _all_numbers(names, delim):
                # no header row: the first line holds numbers (a header kept as the last
                # comment, as some exporters write it, names the columns; else their position)
                names = _comment_names(comments, delim, len(names))
                return names, delim, lineno - 1, comments
            return names, delim, lineno, comments
    raise RecordingError("no header row (the file is empty)", file=str(path))


def _fields(s: str, delim: str | None) -> list[str]:
    """The cells of a header line (whitespace-delimited: a unit ``x [um]`` rejoined)."""
    if delim is not None:
        return [c.strip().strip('"') for c in next(_csv.reader([s], delimiter=delim))]
    toks: list[str] = []
    for tok in s.split():  # "x [um]" split by whitespace: rejoin the unit
        if toks and tok[:1] in "[(":
            toks[-1] += " " + tok
        else:
            toks.append(tok)
    return toks


def _number(cell: str, delim: str | None) -> bool:
    c = cell.strip()
    if delim in ("\t", ";"):
        c = c.replace(",", ".")  # a decimal comma
    try:
        float(c)
    except ValueError:
        return False
    return bool(c)


def _all_numbers(cells: list[str], delim: str | None) -> bool:
    return bool(cells) and all(_number(c, delim) for c in cells)


#: a remark in parentheses holding a delimiter or "=" (``(fs=750 Hz, 5 periods)``), not a unit
_REMARK = re.compile(r"\([^()]*[,;=\t][^()]*\)")


def _comment_names(comments: list[str], delim: str | None, n: int) -> list[str]:
    """Column names of a file without a header row: the last comment's cells when they are
    ``n`` distinct names (remarks in parentheses dropped), else ``"0"``, ``"1"``, … (the
    columns' positions, which ``columns=`` then maps: ``x=1,F=0``)."""
    if comments:
        cells = [c for c in _fields(_REMARK.sub("", comments[-1]).strip(), delim) if c]
        if len(cells) == n and len(set(cells)) == n and not any(_number(c, delim) for c in cells):
            return cells
    return [str(i) for i in range(n)]


_DECIMAL_COMMA = re.compile(r"^\s*[+-]?\d+,\d*(?:[eE][+-]?\d+)?\s*$")


def decimal_comma(
    path: Path, delim: str | None, first_data_line: int, enc: str = "utf-8-sig"
) -> bool:
    """Whether numbers are written with a decimal comma (``1,5``; European locales), judged
    from the first data line. Only possible when the delimiter is not a comma."""
    if delim == ",":
        return False
    k = -1  # the data row's sample index
    with open(path, encoding=enc, errors="replace") as fh:
        for lineno, line in enumerate(fh):
            if lineno < first_data_line or not line.strip() or line.lstrip().startswith("#"):
                continue
            k += 1
            cells = line.rstrip("\r\n").split(delim) if delim else line.split()
            return any(_DECIMAL_COMMA.match(c) for c in cells)
    return False


def line_of_sample(path: Path, first_data_line: int, index: int, enc: str = "utf-8-sig") -> int:
    """1-based line of the file holding data row ``index`` (blank and ``#`` lines skipped).

    Called only to word an error, so the extra pass over the file costs nothing normally.
    """
    k = -1
    with open(path, encoding=enc, errors="replace") as fh:
        for lineno, line in enumerate(fh):
            if lineno < first_data_line or not line.strip() or line.lstrip().startswith("#"):
                continue
            k += 1
            if k == index:
                return lineno + 1
    return first_data_line + index + 1


def locate_bad_cell(
    path: Path,
    delim: str | None,
    first_data_line: int,
    cols: list[int],
    names: list[str],
    comma: bool = False,
    enc: str = "utf-8-sig",
) -> RecordingError:
    """Scan the file to find the first cell that is not a number."""
    k = -1  # the data row's sample index
    with open(path, encoding=enc, errors="replace") as fh:
        for lineno, line in enumerate(fh):
            if lineno < first_data_line or not line.strip() or line.lstrip().startswith("#"):
                continue
            k += 1
            cells = line.rstrip("\r\n").split(delim) if delim else line.split()
            for c in cols:
                if c >= len(cells):
                    return RecordingError(
                        f"line has {len(cells)} fields, column {names[c]!r} is field {c + 1}",
                        file=str(path),
                        column=names[c],
                        sample=k,
                        line=lineno + 1,
                    )
                cell = cells[c].strip().strip('"')
                try:
                    if comma:
                        cell = cell.replace(",", ".")
                    float(cell)
                except ValueError:
                    return RecordingError(
                        f"cell {cells[c].strip()!r} is not a number",
                        file=str(path),
                        column=names[c],
                        sample=k,
                        line=lineno + 1,
                    )
    return RecordingError("cannot be parsed as numbers", file=str(path))


def read_csv(
    path: str | Path,
    *,
    columns: dict[str, str] | None = None,
    kind: str | None = None,
    fs: float | None = None,
    resample: bool = False,
) -> Recording:
    """Read a CSV/text recording; see :func:`contactlab.io.read_recording`.

    Rows reported in errors are 1-based lines of the file (the header is a line too).
    """
    path = Path(path)
    file = str(path)
    enc = sniff_encoding(path)
    names, delim, header_line, comments = read_header(path, enc)
    if len(set(names)) != len(names):
        dup = next(n for n in names if names.count(n) > 1)
        raise RecordingError("column name appears twice in the header", file=file, column=dup)
    kind, mapping = resolve_columns(names, columns=columns, kind=kind, file=file)
    canon = list(mapping)
    idx = [names.index(mapping[c]) for c in canon]
    first_data = header_line + 1
    comma = decimal_comma(path, delim, first_data, enc)
    try:
        with warnings.catch_warnings():
            # A header without data rows is reported below as an error of its own; numpy's
            # "input contained no data" UserWarning would only add noise before it.
            warnings.filterwarnings("ignore", message="loadtxt: input contained no data")
            block = np.loadtxt(
                path,
                delimiter=delim,
                skiprows=first_data,
                usecols=idx,
                ndmin=2,
                comments="#",
                dtype=np.float64,
                encoding=enc,
                quotechar='"',
                converters=(lambda v: float(v.replace(",", "."))) if comma else None,
            )
    except UnicodeDecodeError as exc:  # a non-UTF-8 byte after the block sniff_encoding looked at
        raise RecordingError(
            f"byte {exc.object[exc.start : exc.start + 1]!r} is not {enc} text; save the file "
            "as UTF-8",
            file=file,
        ) from None
    except ValueError:
        raise locate_bad_cell(path, delim, first_data, idx, names, comma, enc) from None
    if block.shape[0] == 0:
        raise RecordingError("header but no data rows", file=file)
    raw = {c: np.ascontiguousarray(block[:, j]) for j, c in enumerate(canon)}
    units = {c: split_name(mapping[c])[1] for c in canon}
    return finish(
        raw,
        mapping,
        units,
        kind=kind,
        file=file,
        fs=fs,
        resample=resample,
        row_of=lambda i: line_of_sample(path, first_data, i, enc),
        meta={
            "format": "csv",
            "comments": comments,
            "delimiter": delim or "whitespace",
            "decimal": "," if comma else ".",
            "encoding": enc,
        },
    )


def write_csv(path: str | Path, rec: Recording, *, delimiter: str | None = None, **_: Any) -> Path:
    """Write ``rec`` as CSV with SI units in the header (``t [s],x [m],F [N]``), atomically.

    The delimiter is a tab for ``.tsv`` files and a comma otherwise, unless given. Values are
    written with 17 significant digits, so they read back bit for bit.
    """
    if delimiter is None:
        delimiter = "\t" if Path(path).suffix.lower() == ".tsv" else ","
    cols = [("t", "s", rec.t)] + [(k, rec.units[k], v) for k, v in rec.data.items()]
    header = delimiter.join(f"{k} [{u}]" if u else k for k, u, _ in cols)
    block = np.column_stack([v for _, _, v in cols])
    with atomic_path(path) as tmp:
        np.savetxt(tmp, block, delimiter=delimiter, header=header, comments="", fmt="%.17g")
    return Path(path)
