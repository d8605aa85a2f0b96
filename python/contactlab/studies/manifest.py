"""Tagging recordings for a study: a small manifest file, or tags read from file names.

A study (issue 4; the paper's load/amplitude series, its Figs. 6-9, 11-14, 16-18, and
Konowalski's series over p0) is a set of recordings, each tagged with what was varied:
material pair, normal load ``W``, nominal amplitude ``A`` (tangential) or static and dynamic
pressure ``p0``, ``pa`` (normal). Tags are stored in SI.

Manifest: a CSV file with a header row, one recording per row, ``#`` comment lines allowed.
Header cells may carry a unit in brackets, like the recordings themselves::

    file,kind,material,normal_load [N],amplitude [um],frequency [Hz]
    tangential/al-al_W050N_A10um.csv,tangential,Al/Al,50,10,1
    normal/steel_p0-0.5MPa_pa-0.4MPa.mat,normal,C45/C45,,,0.159

Recognised columns: ``file`` (required; relative to the manifest), ``kind``
(``tangential``/``normal``), ``material``, ``normal_load``, ``amplitude``, ``frequency``,
``p0``, ``pa``, ``fs`` (sampling rate for files without a time column), ``columns`` (column
mapping for the reader, ``x=disp;F=force``). Any other column is carried into the study table
as a tag (numbers converted to SI when a unit is given).

File names: when a tag is not given, it is looked for in the file name, split at ``_``:
the first token is the material (``-`` standing for ``/``; only when the name carries some
other tag, so ``run3.csv`` names no material), and tokens ``W50N``, ``A10um``,
``f1Hz``, ``p0-0.5MPa``, ``pa-0.4MPa`` (number and unit, both required) give load, amplitude,
frequency, p0 and pa. A file with a
``p0`` tag is a normal-contact recording unless ``kind`` says otherwise.
"""

from __future__ import annotations

import csv
import math
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import InputError
from ..io import units

# Canonical tag → its SI unit (for the study table's units map).
TAG_UNITS: dict[str, str] = {
    "normal_load": "N",
    "amplitude_nominal": "m",
    "frequency": "Hz",
    "p0": "Pa",
    "pa": "Pa",
    "fs": "Hz",
}

_HEADER = re.compile(r"^\s*([^\[\]]*?)\s*(?:\[\s*([^\]]*?)\s*\])?\s*$")
_TOKEN = re.compile(r"^(W|A|f|p0|pa)[-=]?(\d+(?:\.\d+)?)([A-Za-zµμ/]*)$")
_TOKEN_TAG = {
    "W": "normal_load",
    "A": "amplitude_nominal",
    "f": "frequency",
    "p0": "p0",
    "pa": "pa",
}
_KNOWN = {"file", "kind", "material", "columns", *TAG_UNITS}
# dimension(s) a tag's unit must have (contactlab.io.units): 1/s is accepted for a frequency
_TAG_DIMS: dict[str, tuple[str, ...]] = {
    "normal_load": ("force",),
    "amplitude_nominal": ("length",),
    "frequency": ("frequency", "rate"),
    "fs": ("frequency", "rate"),
    "p0": ("pressure",),
    "pa": ("pressure",),
}
_KINDS = ("tangential", "normal")


def _unit(unit: str, where: str) -> tuple[float, str]:
    """``(factor to SI, SI unit)`` from the package's unit table (:mod:`contactlab.io.units`)."""
    hit = units.lookup(unit)
    if hit is None:
        raise InputError(f"{where}: unknown unit {unit!r} (known: {_KNOWN_UNITS})")
    factor, dim = hit
    return factor, units.SI_UNITS[dim]


_KNOWN_UNITS = (
    "s, ms, us, m, mm, um, nm, N, kN, mN, Pa, kPa, MPa, GPa, bar, Hz, kHz, 1/s, rad/s, 1/m, "
    "1/mm, 1/um, J, mJ, uJ, N/m, N/mm, N/um"
)


def scaled(number: str, factor: float) -> float:
    """``float(number) * factor``, exact to the last digit when ``factor`` is a power of ten
    (``"10"`` µm → ``1e-05`` m, not ``9.999999999999999e-06``)."""
    value = float(number)
    if factor > 0 and math.isfinite(value) and "e" not in repr(value):
        exp = round(math.log10(factor))
        if 10.0**exp == factor:
            return float(f"{value!r}e{exp}")
    return value * factor


def unit_factor(unit: str, where: str) -> float:
    """Factor converting a value in ``unit`` to SI; unknown units raise naming ``where``."""
    return _unit(unit, where)[0]


def si_unit(unit: str, where: str = "unit") -> str:
    """The SI unit a value in ``unit`` is converted to (``"um"`` → ``"m"``)."""
    return _unit(unit, where)[1]


@dataclass
class StudyEntry:
    """One recording of a study: where it is, what kind, its tags (SI) and reader options."""

    path: Path
    kind: str
    tags: dict[str, Any] = field(default_factory=dict)
    units: dict[str, str] = field(default_factory=dict)  # SI units of numeric tags
    columns: dict[str, str] | None = None
    fs: float | None = None
    #: interpolate a non-uniform time axis onto a uniform grid (``--resample``)
    resample: bool = False
    source: str = ""  # "manifest.csv row 3" or the file name, for error messages
    #: a friction frame's displacements (``{"M", "C", "K"}`` and optional ``x``, ``y`` column
    #: names): the friction force is reconstructed (:func:`contactlab.tangential.read_frame`)
    frame: dict[str, Any] | None = None

    @property
    def name(self) -> str:
        return self.path.name

    @property
    def material(self) -> str:
        return str(self.tags.get("material", "unknown"))


def tags_from_filename(name: str | os.PathLike[str]) -> dict[str, Any]:
    """Tags encoded in a file name (see the module docstring), in SI.

    Examples
    --------
    >>> tags_from_filename("Al-Al_W50N_A10um.csv")
    {'material': 'Al/Al', 'normal_load': 50.0, 'amplitude_nominal': 1e-05}
    >>> tags_from_filename("C45_p0-0.5MPa_pa-0.4MPa.mat")["p0"]
    500000.0
    >>> tags_from_filename("run3.csv")  # no tags, so no material either
    {}
    """
    stem = Path(name).stem
    tokens = [t for t in stem.split("_") if t]
    tags: dict[str, Any] = {}
    for i, tok in enumerate(tokens):
        m = _TOKEN.match(tok) if i > 0 else None  # the first token is always the material
        if m and m.group(3):  # a tag needs its unit: "A10um", not "A10"
            key, num, unit = m.groups()
            try:
                factor = unit_factor(unit, f"file name {Path(name).name!r}, token {tok!r}")
            except InputError:
                continue  # not a tag after all (e.g. "A4paper"); leave it
            tags[_TOKEN_TAG[key]] = scaled(num, factor)
        elif i == 0:
            tags["material"] = tok.replace("-", "/")
        elif tok.lower() in _KINDS:
            tags["kind"] = tok.lower()
    if set(tags) <= {"material", "kind"}:
        tags.pop("material", None)  # "run3.csv" names no material: nothing else was tagged
    return tags


def _infer_kind(tags: Mapping[str, Any]) -> str:
    kind = tags.get("kind")
    if kind:
        return str(kind)
    return "normal" if "p0" in tags else "tangential"


def _parse_columns(text: str, where: str) -> dict[str, str] | None:
    text = text.strip()
    if not text:
        return None
    out = {}
    for part in text.split(";"):
        if "=" not in part:
            raise InputError(f"{where}: column mapping {part!r} must look like 'x=disp'")
        k, v = part.split("=", 1)
        out[k.strip()] = v.strip()
    return out


def entry_from_file(path: str | os.PathLike[str], **overrides: Any) -> StudyEntry:
    """A study entry for one file, tagged from its name (``overrides`` take precedence)."""
    p = Path(path)
    tags = tags_from_filename(p)
    tags.update({k: v for k, v in overrides.items() if v is not None})
    kind = _infer_kind(tags)
    tags.pop("kind", None)
    if kind not in _KINDS:
        raise InputError(f"{p}: kind {kind!r} must be 'tangential' or 'normal'")
    units = {k: u for k, u in TAG_UNITS.items() if k in tags}
    return StudyEntry(path=p, kind=kind, tags=tags, units=units, source=p.name)


def read_manifest(path: str | os.PathLike[str]) -> list[StudyEntry]:
    """Parse a manifest CSV (see the module docstring) into study entries.

    Errors name the manifest, its row (1-based, counting the header as row 1) and column.
    Paths are resolved relative to the manifest's folder; missing files are reported here,
    before any analysis starts.
    """
    mpath = Path(path)
    try:
        text = mpath.read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        raise InputError(f"manifest {mpath} does not exist") from None
    except UnicodeDecodeError as exc:
        raise InputError(f"manifest {mpath} is not a UTF-8 text (CSV) file: {exc}") from None
    lines = [(i + 1, ln) for i, ln in enumerate(text.splitlines()) if ln.strip()]
    lines = [(i, ln) for i, ln in lines if not ln.lstrip().startswith("#")]
    if not lines:
        raise InputError(f"manifest {mpath} is empty (a header row with 'file' is needed)")
    # Spreadsheets in many European locales save "CSV" with ';' (and a decimal comma).
    head = lines[0][1]
    delim = ","
    if "," not in head:
        delim = ";" if ";" in head else "\t" if "\t" in head else ","
    # one csv row per line (a quote left open must not swallow the following lines, which
    # misaligned rows and their line numbers: found by fuzzing)
    rows = [next(csv.reader([ln], delimiter=delim), []) for _, ln in lines]
    header_row, header = lines[0][0], rows[0]
    keys: list[str] = []
    factors: list[float | None] = []
    si: dict[str, str] = {}
    for j, cell in enumerate(header):
        m = _HEADER.match(cell)
        name, unit = (m.group(1), m.group(2)) if m else (cell.strip(), None)
        key = name.strip().lower().replace(" ", "_")
        if key == "amplitude":
            key = "amplitude_nominal"  # the measured amplitude comes from the analysis
        where = f"manifest {mpath}, row {header_row}, column {j + 1} ({cell.strip()!r})"
        if key in keys:
            raise InputError(f"{where}: duplicated column {key!r}")
        keys.append(key)
        if unit is not None:
            f, si[key] = _unit(unit, where)
            dims = _TAG_DIMS.get(key)
            dim = units.lookup(unit)[1]  # known: _unit accepted it
            if dims is not None and dim not in dims:
                raise InputError(
                    f"{where}: [{unit}] is a unit of {dim}, but {key} is a "
                    f"{' or '.join(dims)} (give it in {TAG_UNITS[key]} or a multiple of it)"
                )
            factors.append(f)
        else:
            factors.append(None)
    if "file" not in keys:
        raise InputError(f"manifest {mpath}, row {header_row}: no 'file' column in {header}")

    entries: list[StudyEntry] = []
    seen: dict[Path, int] = {}
    for (lineno, _), cells in zip(lines[1:], rows[1:], strict=True):
        if len(cells) > len(keys):
            raise InputError(
                f"manifest {mpath}, row {lineno}: {len(cells)} cells but {len(keys)} columns"
            )
        cells = cells + [""] * (len(keys) - len(cells))
        raw = dict(zip(keys, cells, strict=True))
        where = f"manifest {mpath}, row {lineno}"
        fname = raw["file"].strip()
        if not fname:
            raise InputError(f"{where}, column 'file': empty file name")
        fpath = _recording_path(mpath, fname, where)
        tags = tags_from_filename(fpath)
        columns = None
        for j, (key, factor, cell) in enumerate(zip(keys, factors, cells, strict=True)):
            cell = cell.strip()
            if key == "file" or cell == "":
                continue
            if key == "columns":
                columns = _parse_columns(cell, f"{where}, column 'columns'")
                continue
            if key in TAG_UNITS or factor is not None:
                if delim != ",":
                    cell = cell.replace(",", ".")  # decimal comma
                try:
                    tags[key] = scaled(cell, factor if factor is not None else 1.0)
                except ValueError:
                    raise InputError(f"{where}, column {key!r}: {cell!r} is not a number") from None
                col = f"{where}, column {j + 1} ({header[j].strip()!r})"
                if not math.isfinite(tags[key]):
                    raise InputError(f"{col}: {cell!r} is not a finite number")
                if key in TAG_UNITS and not tags[key] > 0:
                    raise InputError(f"{col}: {cell!r}: {key} must be > 0")
            else:
                tags[key] = cell
        kind = _infer_kind(tags)
        tags.pop("kind", None)
        if kind not in _KINDS:
            raise InputError(f"{where}, column 'kind': {kind!r} must be 'tangential' or 'normal'")
        fs = tags.pop("fs", None)
        first = seen.setdefault(fpath.resolve(), lineno)
        if first != lineno:
            # analysed twice, it would count twice in every trend and overwrite its figure
            raise InputError(f"{where}, column 'file': {fname} is listed already in row {first}")
        entries.append(
            StudyEntry(
                path=fpath,
                kind=kind,
                tags=tags,
                units={k: u for k, u in {**TAG_UNITS, **si}.items() if k in tags and u},
                columns=columns,
                fs=fs,
                source=where,
            )
        )
    if not entries:
        raise InputError(f"manifest {mpath} lists no recordings")
    return entries


def _recording_path(mpath: Path, fname: str, where: str) -> Path:
    """A manifest row's recording file (relative to the manifest's folder), which exists."""
    fpath = Path(fname)
    if not fpath.is_absolute():
        fpath = mpath.parent / fpath
    if not fpath.exists():
        raise InputError(f"{where}, column 'file': {fpath} does not exist")
    if not fpath.is_file():
        raise InputError(f"{where}, column 'file': {fpath} is a folder, not a recording file")
    return fpath


__all__ = [
    "TAG_UNITS",
    "StudyEntry",
    "entry_from_file",
    "read_manifest",
    "si_unit",
    "tags_from_filename",
    "unit_factor",
]
