"""The :class:`Recording` container, its error type and the checks every reader shares.

A recording holds SI data only: readers convert on the way in (see
:mod:`contactlab.io.units`), so the analysis code never sees µm or MPa. Canonical channel
names: tangential ``x`` (m) and ``F`` (N); normal ``p`` (Pa) and ``delta`` (m); time ``t``
(s).
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InputError
from .units import SI_UNITS, UnknownUnitError, split_name, to_si

#: canonical channel -> physical dimension (``y``: a frame's base displacement)
DIMENSIONS = {
    "t": "time",
    "x": "length",
    "F": "force",
    "p": "pressure",
    "delta": "length",
    "y": "length",
    "N": "force",
}
#: the channels each kind of recording needs
KIND_CHANNELS = {"tangential": ("x", "F"), "normal": ("p", "delta")}
#: channels read along when a column is named like one (never needed): a tangential test's
#: normal force ``N`` (a tribometer's ``Normal [uN]``), kept so that μ = F/N can be given
OPTIONAL_CHANNELS = {"tangential": ("N",)}
#: a base-excited friction frame's displacements (top plate ``x``, base ``y``): read only
#: when asked for (``kind="frame"``), never guessed, so not one of :data:`KIND_CHANNELS`
FRAME_CHANNELS = ("x", "y")
#: words that name a frame's top plate / base displacement column, after ``x`` / ``y``
FRAME_WORDS = {"x": ("x", "top", "plate", "mass"), "y": ("y", "base", "ground", "shaker")}
#: names recognised (case-insensitive, unit stripped) for each canonical channel, best first
ALIASES: dict[str, tuple[str, ...]] = {
    "t": ("t", "time", "zeit", "timestamp", "time_s", "times"),
    "x": (
        "x",
        "disp",
        "displacement",
        "u",
        "x_t",
        "tangential displacement",
        "s",
        "ux",
        "weg",
        "position",
        "pos",
        "stroke",
        "tangential position",
        "stage position",
    ),
    "F": (
        "f",
        "force",
        "ft",
        "f_t",
        "friction",
        "friction force",
        "h",
        "tangential force",
        "kraft",
        "tangential",
        "shear force",
        "friction (tangential) force",
        "reibkraft",
    ),
    "N": ("normal", "normal force", "normal load", "fn", "f_n", "fz", "normalkraft"),
    "p": ("p", "pressure", "contact pressure", "sigma", "p_n", "druck"),
    "delta": ("delta", "δ", "d", "normal displacement", "disp", "displacement", "dn", "weg"),
}


class RecordingError(InputError):
    """A recording that cannot be read as asked; the message names file, column and row.

    Attributes ``file``, ``column``, ``sample`` (0-based sample index), ``line`` (1-based
    line of a text file) and ``row`` (the line for text formats, the sample index otherwise)
    are set when known. Every format words a sample alike: ``sample 1234`` (binary formats),
    ``sample 1234 (line 1236 of run.csv)`` (text); ``row`` alone (a line not yet counted as a
    sample) is worded ``line 1236``.
    """

    def __init__(
        self,
        message: str,
        *,
        file: str | None = None,
        column: str | None = None,
        row: int | None = None,
        sample: int | None = None,
        line: int | None = None,
    ) -> None:
        self.file = file
        self.column = column
        self.sample = sample
        self.line = line if line is not None else (row if sample is None else None)
        self.row = self.line if self.line is not None else sample
        parts = []
        if file is not None:
            parts.append(str(file))
        if column is not None:
            parts.append(f"column {column!r}")
        if sample is not None:
            of = f" of {os.path.basename(file)}" if file else ""
            parts.append(f"sample {sample}" + ("" if line is None else f" (line {line}{of})"))
        elif self.line is not None:
            parts.append(f"line {self.line}")
        prefix = ", ".join(parts)
        super().__init__(f"{prefix}: {message}" if prefix else message)


class RecordingUnitError(RecordingError, UnknownUnitError):
    """A column's unit is unknown (catchable as either parent)."""


@dataclass
class Recording:
    """A measured (or simulated) recording in SI units.

    Parameters
    ----------
    t : ndarray
        Time stamps, s, strictly increasing.
    data : dict of str to ndarray
        Channels, SI, each as long as ``t``. Canonical names: ``x``, ``F``, ``p``, ``delta``.
    units : dict of str to str
        SI unit of each channel (``"m"``, ``"N"``, ``"Pa"``, ...).
    source : str
        Where it came from (a path or ``"synthetic"``).
    meta : dict
        Anything else (original units and column names, sampling rate, kind, ...).

    Examples
    --------
    >>> import numpy as np
    >>> rec = Recording(np.arange(3) * 1e-3, {"x": np.zeros(3), "F": np.ones(3)},
    ...                 {"x": "m", "F": "N"})
    >>> rec["F"].tolist(), rec.fs
    ([1.0, 1.0, 1.0], 1000.0)
    """

    t: np.ndarray
    data: dict[str, np.ndarray]
    units: dict[str, str]
    source: str = "<memory>"
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.t = np.ascontiguousarray(self.t, dtype=np.float64)
        if self.t.ndim != 1:
            raise InputError(f"{self.source}: t must be 1-D, got shape {self.t.shape}")
        for k, v in list(self.data.items()):
            a = np.ascontiguousarray(v, dtype=np.float64)
            if a.shape != self.t.shape:
                raise InputError(
                    f"{self.source}: channel {k!r} has {a.size} samples but t has {self.t.size}"
                )
            self.data[k] = a
        missing = [k for k in self.data if k not in self.units]
        if missing:
            raise InputError(f"{self.source}: no unit given for channel(s) {missing}")

    def __getitem__(self, name: str) -> np.ndarray:
        if name == "t":
            return self.t
        try:
            return self.data[name]
        except KeyError:
            raise KeyError(
                f"{self.source} has no channel {name!r}; channels: {sorted(self.data)}"
            ) from None

    def __contains__(self, name: object) -> bool:
        return name == "t" or name in self.data

    def __len__(self) -> int:
        return int(self.t.size)

    @property
    def channels(self) -> list[str]:
        return list(self.data)

    @property
    def fs(self) -> float:
        """Mean sampling rate, Hz."""
        if self.t.size < 2:
            return float("nan")
        return float((self.t.size - 1) / (self.t[-1] - self.t[0]))

    def window(self, t0: float | None = None, t1: float | None = None) -> Recording:
        """The samples with ``t0 <= t < t1`` (either end open when None), as a new recording
        (e.g. to drop a run-in before the loops settle)."""
        a = 0 if t0 is None else int(np.searchsorted(self.t, t0, side="left"))
        b = self.t.size if t1 is None else int(np.searchsorted(self.t, t1, side="left"))
        if b - a < 2:
            raise InputError(
                f"{self.source}: the window [{t0}, {t1}) holds {max(b - a, 0)} samples"
            )
        meta = dict(self.meta, window=(t0, t1))
        data = {k: v[a:b].copy() for k, v in self.data.items()}
        return Recording(self.t[a:b].copy(), data, dict(self.units), self.source, meta)

    @property
    def kind(self) -> str | None:
        """``"tangential"``, ``"normal"`` or None, from the channels present."""
        for kind, chans in KIND_CHANNELS.items():
            if all(c in self.data for c in chans):
                return kind
        return None


def _not_real(unusable: dict[str, str], *wanted: str) -> str:
    """``; 'F' is complex: ...`` for the unusable objects named like one of ``wanted``."""
    low = {w.strip().lower() for w in wanted}
    hits = [
        f"{n!r} is {what}"
        for n, what in unusable.items()
        if n.strip().lower() in low
        or split_name(n)[0].strip().lower() in low
        or n.rsplit("/", 1)[-1].strip().lower() in low
        or n.rsplit(".", 1)[-1].strip().lower() in low  # a MATLAB struct's field
    ]
    return (
        f"; {', '.join(hits[:5])}: a channel must hold real numbers" if hits else ""
    ) + _structs(unusable)


def _structs(unusable: dict[str, str]) -> str:
    """``; 'data' is a MATLAB struct: ...`` (channels inside a struct are not read)."""
    names = [n for n, what in unusable.items() if what == "a MATLAB struct" and n != "units"]
    if not names:
        return ""
    # a struct's vector fields are read (data.x); a struct inside one is not
    how = (
        f"s = {names[0]}; save(file, '-struct', 's')"
        if "." in names[0]
        else f"save(file, '-struct', {names[0]!r})"
    )
    return (
        f"; {', '.join(repr(n) for n in names[:3])} "
        f"{'is a MATLAB struct' if len(names) == 1 else 'are MATLAB structs'}, whose "
        f"fields are not read: save them as variables (in MATLAB: {how})"
    )


def resolve_columns(
    available: list[str],
    *,
    columns: dict[str, str] | None,
    kind: str | None,
    file: str,
    unusable: dict[str, str] | None = None,
) -> tuple[str | None, dict[str, str]]:
    """Map canonical channel names to names in the file.

    Returns ``(kind, {canonical: file_name})``; ``"t"`` is included when a time column exists.
    Explicit ``columns`` entries match the full name or the name without its unit.
    ``unusable`` maps the file's objects that cannot be channels (not real numbers) to what
    they hold (``"complex"``, ``"text"``, ...): a missing channel's message names those that
    would have matched.
    """
    unusable = dict(unusable or {})

    def not_real(*wanted: str) -> str:
        return _not_real(unusable, *wanted)

    if kind not in (None, "tangential", "normal", "frame"):
        raise InputError(f"kind must be 'tangential', 'normal', 'frame' or None, got {kind!r}")
    columns = dict(columns or {})
    bases = {c: split_name(c)[0].strip().lower() for c in available}
    mapping: dict[str, str] = {}

    def find(name: str) -> str | None:
        for c in available:
            if c == name:
                return c
        low = name.strip().lower()
        for c in available:
            if c.strip().lower() == low or bases[c] == low:
                return c
        return None

    for canon, name in columns.items():
        hit = find(name)
        if hit is None:
            raise RecordingError(
                f"column {name!r} (asked for {canon!r}) not found; columns are {available}"
                f"{not_real(name)}",
                file=file,
                column=name,
            )
        mapping[canon] = hit

    def guess(canon: str) -> str | None:
        used = set(mapping.values())
        for alias in ALIASES[canon]:
            for c in available:
                if c not in used and bases[c] == alias:
                    return c
        return None

    if kind == "frame":
        for canon in FRAME_CHANNELS:
            if canon not in mapping:
                mapping[canon] = frame_column(available, canon, mapping, file=file)
        hit = guess("t")
        if "t" not in mapping and hit is not None:
            mapping["t"] = hit
        return kind, mapping
    if kind is None:
        for k, chans in KIND_CHANNELS.items():
            if all(c in mapping for c in chans):
                kind = k
                break
    if kind is None:
        # Guess: the force column decides tangential, a pressure column normal.
        if "F" in mapping or guess("F") is not None:
            kind = "tangential"
        elif "p" in mapping or guess("p") is not None:
            kind = "normal"
    if kind is None:
        raise RecordingError(
            f"cannot tell a tangential (x, F) from a normal (p, delta) recording; columns are "
            f"{available}{not_real(*ALIASES['F'], *ALIASES['p'])}; pass kind= and columns="
            "{'x': ..., 'F': ...} (command line: --model "
            "tangential|normal and --columns 'x=...,F=...')",
            file=file,
        )
    optional = ("t", *OPTIONAL_CHANNELS.get(kind, ()))
    for canon in (*KIND_CHANNELS[kind], *optional):
        if canon in mapping:
            continue
        hit = guess(canon)
        if hit is not None:
            mapping[canon] = hit
        elif canon not in optional:
            raise RecordingError(
                f"no column for {canon!r} ({DIMENSIONS[canon]}) of a {kind} recording; columns "
                f"are {available}{not_real(*ALIASES[canon])}; name it e.g. "
                f"{ALIASES[canon][0]!r} or pass columns="
                f"{{{canon!r}: 'your column'}} (command line: --columns '{canon}=your column')",
                file=file,
                column=canon,
            )
    return kind, mapping


def frame_column(available: list[str], canon: str, mapping: dict[str, str], *, file: str) -> str:
    """The column of a frame's ``x`` (top plate) or ``y`` (base) displacement: the one column
    whose name (unit stripped, split into words at ``_``, spaces, ``-`` and ``.``) has the
    word ``x`` / ``y``, else one of :data:`FRAME_WORDS`; a name that fits none or several is
    a :class:`RecordingError` asking for the column."""
    used = set(mapping.values())
    words = {c: re.split(r"[\s_\-.]+", split_name(c)[0].strip().lower()) for c in available}
    for word in FRAME_WORDS[canon]:
        hits = [c for c in available if c not in used and word in words[c]]
        other = "y" if canon == "x" else "x"
        hits = [c for c in hits if other not in words[c] or word == canon]
        if len(hits) == 1:
            return hits[0]
        if len(hits) > 1:
            raise RecordingError(
                f"several columns could be the frame's {canon!r} ({', '.join(hits)}); name it "
                f"with --frame-{canon} (columns={{{canon!r}: ...}})",
                file=file,
                column=canon,
            )
    what = "top-plate" if canon == "x" else "base"
    raise RecordingError(
        f"no column for the frame's {what} displacement {canon!r}; columns are {available}; "
        f"name it with --frame-{canon} (columns={{{canon!r}: ...}})",
        file=file,
        column=canon,
    )


def unit_factor(
    canon: str, column: str, unit: str | None, *, file: str, assumed: list[str]
) -> tuple[float, str]:
    """Factor to SI of a column, checking the unit's dimension against the channel's."""
    dim = DIMENSIONS.get(canon)
    if unit is None or unit == "":
        assumed.append(column)
        return 1.0, SI_UNITS[dim] if dim else ""
    try:
        factor, udim = to_si(unit)
    except UnknownUnitError as exc:
        raise RecordingUnitError(str(exc), file=file, column=column) from None
    if dim is not None and udim != dim:
        raise RecordingError(
            f"unit {unit!r} is a {udim} unit but {canon!r} is a {dim}", file=file, column=column
        )
    return factor, SI_UNITS[udim]


#: a sample's (0-based, whole record) line of a text file; None for binary formats
RowOf = Callable[[int], int]


def at_sample(i: int, row_of: RowOf | None, offset: int = 0) -> dict[str, int | None]:
    """``sample=``/``line=`` of a :class:`RecordingError` for sample ``offset + i``."""
    k = offset + int(i)
    return {"sample": k, "line": None if row_of is None else row_of(k)}


def real_values(values: Any, *, file: str, column: str) -> np.ndarray:
    """A channel's values as float64; complex or non-numeric data is a :class:`RecordingError`
    (numpy would drop an imaginary part with only a ``ComplexWarning``)."""
    a = np.asarray(values)
    if np.iscomplexobj(a):
        raise RecordingError("complex values; a channel must be real", file=file, column=column)
    try:
        # a float128 or huge integer beyond float64 becomes inf (refused with its row by the
        # finiteness check), not a numpy overflow warning
        with np.errstate(over="ignore", invalid="ignore"):
            return np.asarray(a, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise RecordingError(f"values are not numeric ({exc})", file=file, column=column) from None


#: ``resample=True`` bridges a step of up to this many median steps by interpolation (at most
#: three samples missing in a row); a longer step is a real gap and is still refused
RESAMPLE_MAX_GAP = 4.0


def check_time(
    t: np.ndarray,
    *,
    file: str,
    column: str,
    row_of: RowOf | None = None,
    step: float | None = None,
    offset: int = 0,
    max_gap: float = 1.5,
) -> None:
    """Time stamps finite, strictly increasing, without gaps (> ``max_gap`` median steps).

    ``row_of`` gives a sample's line of a text file (None: a binary format), ``offset`` the
    index of ``t[0]`` in the record; ``step`` replaces the median step as the reference (a
    chunk judged by the first one's). ``max_gap`` is 1.5 (a record read as it is) or
    :data:`RESAMPLE_MAX_GAP` (a record to be resampled: longer steps are bridged).
    """
    if t.size < 2:
        raise RecordingError(f"only {t.size} sample(s)", file=file, column=column)
    d = np.diff(t)
    bad = np.flatnonzero(d <= 0)
    if bad.size:
        i = int(bad[0]) + 1
        what = "duplicated" if d[bad[0]] == 0 else "unsorted (goes back in time)"
        raise RecordingError(
            f"time stamp {float(t[i]):.9g} s is {what}; previous is {float(t[i - 1]):.9g} s",
            file=file,
            column=column,
            **at_sample(i, row_of, offset),
        )
    med = float(np.median(d)) if step is None else float(step)
    gaps = np.flatnonzero(d > max_gap * med)
    if gaps.size:
        i = int(gaps[0]) + 1
        if max_gap > 1.5:
            hint = (
                f"; --resample bridges steps up to {max_gap:g} times the step ("
                f"{max_gap * med:.6g} s), a longer one is a real gap: split the recording there"
            )
        else:
            nonuniform = int(np.count_nonzero(d > 1.5 * med))
            real = int(np.count_nonzero(d > RESAMPLE_MAX_GAP * med))
            hint = (
                "; if the sampling is merely non-uniform, --resample (resample=True) "
                "interpolates the record onto a uniform grid"
                if real == 0 and nonuniform
                else ""
            )
        raise RecordingError(
            f"gap in time: {d[gaps[0]]:.6g} s between samples where the step is {med:.6g} s "
            f"({gaps.size} gap(s) in all){hint}",
            file=file,
            column=column,
            **at_sample(i, row_of, offset),
        )


def uniform_grid(t: np.ndarray, step: float, t0: float | None = None) -> np.ndarray:
    """``t0 + step·k`` for every ``k >= 0`` up to ``t[-1]`` (``t0`` defaults to ``t[0]``)."""
    t0 = float(t[0]) if t0 is None else float(t0)
    n = int(np.floor((float(t[-1]) - t0) / step * (1 + 1e-12))) + 1
    return t0 + step * np.arange(max(n, 0), dtype=np.float64)


def resample_uniform(
    t: np.ndarray,
    data: dict[str, np.ndarray],
    *,
    file: str,
    column: str,
    row_of: RowOf | None = None,
) -> tuple[np.ndarray, dict[str, np.ndarray], dict[str, Any]]:
    """A non-uniformly sampled record on the uniform grid of its median step.

    The rule: the step of the grid is the median step of the time stamps; a step of up to
    :data:`RESAMPLE_MAX_GAP` times it is bridged by linear interpolation of every channel; a
    longer one is a real gap and is refused (:class:`RecordingError` naming the sample). Time
    stamps must still be strictly increasing. A record whose steps all lie within 10⁻⁶ of the
    median is returned as it is.

    Returns
    -------
    t, data, info
        The grid, the channels on it, and ``info`` (``step``, ``largest_step``,
        ``steps_bridged``: steps above 1.5 times the grid step, ``n_read``, ``n_samples``,
        ``resampled``: False when the record was uniform already).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.array([0.0, 0.005, 0.010, 0.020, 0.025])
    >>> tt, d, info = resample_uniform(t, {"x": 2 * t}, file="f", column="t")
    >>> np.round(tt, 9).tolist(), round(info["largest_step"], 3), info["steps_bridged"]
    ([0.0, 0.005, 0.01, 0.015, 0.02, 0.025], 0.01, 1)
    """
    check_time(t, file=file, column=column, row_of=row_of, max_gap=RESAMPLE_MAX_GAP)
    d = np.diff(t)
    med = float(np.median(d))
    info: dict[str, Any] = {
        "step": med,
        "largest_step": float(d.max()),
        "steps_bridged": int(np.count_nonzero(d > 1.5 * med)),
        "n_read": int(t.size),
    }
    if np.all(np.abs(d - med) <= 1e-6 * med):
        info.update(n_samples=int(t.size), resampled=False)
        return t, data, info
    grid = uniform_grid(t, med)
    out = {k: np.interp(grid, t, v) for k, v in data.items()}
    info.update(n_samples=int(grid.size), resampled=True)
    return grid, out, info


def describe_resampling(info: dict[str, Any]) -> str:
    """One sentence on what :func:`resample_uniform` did (for the console and the report)."""
    if not info.get("resampled"):
        return f"--resample: the time stamps are uniform already (step {info['step']:.6g} s)"
    return (
        f"resampled onto a uniform {info['step']:.6g} s grid by linear interpolation "
        f"({info['n_read']} -> {info['n_samples']} samples); largest gap bridged "
        f"{info['largest_step']:.6g} s ({info['steps_bridged']} step(s) over 1.5x the grid step)"
    )


#: what :func:`metadata_scalar` asks of each kind of value, and how its message says it
_SCALAR_KINDS = {
    "rate": "a sampling rate must be a positive number",
    "step": "a time step must be a positive number",
    "offset": "a start time must be a finite number",
}


def _shown(v: Any) -> str:
    """A metadata value as an error message shows it (short)."""
    if isinstance(v, (bytes, np.bytes_)):
        v = bytes(v).decode("utf-8", "replace")
    if isinstance(v, (str, np.str_)):
        text = repr(str(v))
    elif isinstance(v, (float, np.floating)):
        text = f"{float(v):g}"
    else:
        text = str(v)
    return text if len(text) <= 60 else text[:57] + "..."


def metadata_scalar(value: Any, *, file: str, label: str, kind: str) -> float:
    """A sampling rate (``kind="rate"``), time step (``"step"``) or start time (``"offset"``)
    read from a file's metadata (``label`` names it, e.g. ``"attribute 'fs'"``), as a float:
    one finite real number (the first of an array), rate and step > 0. Anything else (empty,
    text, complex, a group, 0, NaN, ...) is a :class:`RecordingError` naming file and label.
    Shared by every reader, whole-file and chunked."""

    def refuse(why: str) -> RecordingError:
        return RecordingError(f"{label} {why}: {_SCALAR_KINDS[kind]}", file=file)

    if hasattr(value, "keys") and not isinstance(value, np.ndarray):  # an HDF5 group
        raise refuse("is a group, not a number")
    if isinstance(value, (str, bytes, np.str_, np.bytes_)):
        a = np.asarray([value], dtype=object)
    else:
        try:
            a = np.asarray(value)
        except Exception:  # an object numpy cannot hold
            raise refuse(f"is a {type(value).__name__}, not a number") from None
    if a.size == 0:
        raise refuse("is empty")
    v = a.reshape(-1)[0]
    if isinstance(v, (bytes, np.bytes_, str, np.str_)):
        try:
            x = float(bytes(v).decode("utf-8") if isinstance(v, (bytes, np.bytes_)) else v)
        except (ValueError, UnicodeDecodeError):
            raise refuse(f"is {_shown(v)}, not a number") from None
    elif np.iscomplexobj(a) or isinstance(v, complex):
        raise refuse(f"is complex ({_shown(v)})")
    elif a.dtype.kind == "b" or isinstance(v, bool):
        raise refuse(f"is a boolean ({v})")
    else:
        try:
            with np.errstate(over="ignore", invalid="ignore"):
                x = float(v)
        except (TypeError, ValueError):
            raise refuse(f"is {_shown(v)}, not a number") from None
    if not math.isfinite(x) or (kind != "offset" and x <= 0):
        raise refuse(f"is {_shown(x)}")
    # found by audit: fs = 1e200 Hz passed, and the analysis divided by its squared steps
    step = x if kind == "step" else 1.0 / x if kind == "rate" else None
    if step is not None and not (STEP_RANGE[0] <= step <= STEP_RANGE[1]):
        raise RecordingError(
            f"{label} is {_shown(x)}: a sampling interval of {step:.3g} s is beyond any data "
            f"acquisition ({STEP_RANGE[0]:g} to {STEP_RANGE[1]:g} s); check its unit",
            file=file,
        )
    return x


#: sampling intervals a recording may have, s (1 THz to one every 30 years)
STEP_RANGE = (1e-12, 1e9)


def step_of_rate(fs: float, *, file: str, label: str) -> float:
    """The sampling interval ``1/fs`` of a valid rate; a rate so large that the step underflows
    (0 or subnormal) or so small that it overflows is a :class:`RecordingError`."""
    with np.errstate(over="ignore", divide="ignore"):
        dt = 1.0 / fs
    if not math.isfinite(dt) or dt < np.finfo(np.float64).tiny:
        raise RecordingError(
            f"{label} is {_shown(fs)}: its sampling interval 1/fs = {dt:g} s "
            f"{'underflows' if dt < 1 else 'overflows'} double precision",
            file=file,
        )
    return dt


def user_rate(fs: Any, *, file: str) -> float:
    """The sampling rate given by the caller (``fs=``, ``--fs``), checked like a file's."""
    return metadata_scalar(fs, file=file, label="fs", kind="rate")


def time_from_fs(n: int, fs: float | None, *, file: str, t0: float = 0.0) -> np.ndarray:
    if fs is None:
        raise RecordingError(
            "no time column and no sampling rate: pass fs= (Hz) or columns={'t': ...} (command "
            "line: --fs or --columns 't=...')",
            file=file,
        )
    fs = user_rate(fs, file=file)
    step_of_rate(fs, file=file, label="fs")
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        t = t0 + np.arange(n, dtype=np.float64) / fs
    # found by audit: fs = 1e-308 makes the axis overflow, a huge fs makes its steps vanish
    if not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise RecordingError(
            f"fs is {_shown(fs)}: it gives no increasing, finite time axis for {n} samples",
            file=file,
        )
    return t


def check_finite(
    a: np.ndarray, *, file: str, column: str, row_of: RowOf | None = None, offset: int = 0
) -> None:
    if np.isfinite(a).all():
        return
    i = int(np.argmax(~np.isfinite(a)))
    raise RecordingError(
        f"value {float(a[i])} is not a finite number",
        file=file,
        column=column,
        **at_sample(i, row_of, offset),
    )


def check_equal_lengths(
    raw: dict[str, np.ndarray], names: dict[str, str], *, file: str, what: str = "channels"
) -> None:
    """Raise naming each channel's length unless all channels of ``raw`` have the same."""
    lengths = {names[c]: v.size for c, v in raw.items()}
    if len(set(lengths.values())) > 1:
        raise RecordingError(f"{what} differ in length: {lengths}", file=file)


def time_from_interval(
    dt: float,
    n: int,
    *,
    file: str,
    t0: float = 0.0,
    name: str = "sampling interval",
    column: str | None = None,
) -> np.ndarray:
    """``t0 + dt·[0, n)`` for a file that stores a sampling interval instead of a time column."""
    if not np.isfinite(dt) or dt <= 0:
        raise RecordingError(f"{name} {dt} is not a positive time step", file=file, column=column)
    if not np.isfinite(t0):
        raise RecordingError(f"start time {t0} is not a finite number", file=file, column=column)
    with np.errstate(over="ignore", invalid="ignore"):
        t = t0 + dt * np.arange(n, dtype=np.float64)
    # found by fuzzing: a huge step overflows, a tiny one vanishes against a large start time
    if not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise RecordingError(
            f"{name} {dt} from start time {t0} gives no increasing, finite time axis for "
            f"{n} samples",
            file=file,
            column=column,
        )
    return t


def finish(
    raw: dict[str, np.ndarray],
    names: dict[str, str],
    file_units: dict[str, str | None],
    *,
    kind: str | None,
    file: str,
    fs: float | None,
    row_of: RowOf | None = None,
    t_fallback: np.ndarray | None = None,
    meta: dict[str, Any] | None = None,
    resample: bool = False,
) -> Recording:
    """Convert raw columns to SI, build ``t`` and check everything; shared by all readers.

    ``raw`` maps canonical name to values in file units; ``names`` to the file's names;
    ``row_of`` gives a sample's line of a text file, for the errors (None: a binary format).
    ``resample``: a non-uniform time axis is interpolated onto a uniform grid
    (:func:`resample_uniform`; ``meta["resampled"]`` says what was done).
    """
    assumed: list[str] = []
    data: dict[str, np.ndarray] = {}
    units: dict[str, str] = {}
    t = None
    for canon, values in raw.items():
        col = names[canon]
        check_finite(values, file=file, column=col, row_of=row_of)
        factor, si = unit_factor(canon, col, file_units.get(canon), file=file, assumed=assumed)
        with np.errstate(over="ignore"):
            v = np.ascontiguousarray(values, dtype=np.float64) * factor
        if not np.all(np.isfinite(v)):  # found by fuzzing: 1e306 kN overflows in N
            i = int(np.argmax(~np.isfinite(v)))
            raise RecordingError(
                f"value {float(values[i])} overflows double precision when converted to SI ({si})",
                file=file,
                column=col,
                **at_sample(i, row_of),
            )
        if canon == "t":
            t = v
        else:
            data[canon] = v
            units[canon] = si
    n = next(iter(data.values())).size if data else 0
    if t is None:
        if t_fallback is not None:
            t = t_fallback
        else:
            t = time_from_fs(n, fs, file=file)
        tcol = "t"
    else:
        tcol = names["t"]
    m = dict(meta or {})
    if resample:
        t, data, m["resampled"] = resample_uniform(t, data, file=file, column=tcol, row_of=row_of)
    else:
        check_time(t, file=file, column=tcol, row_of=row_of)
    m.setdefault("kind", kind)
    m["columns"] = dict(names)
    m["file_units"] = dict(file_units)
    if assumed:
        m["units_assumed_si"] = assumed
    return Recording(t=t, data=data, units=units, source=file, meta=m)
