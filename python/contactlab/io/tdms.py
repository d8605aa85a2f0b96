"""NI TDMS recordings (npTDMS, optional extra ``io``).

Channels are found by name in any group. The unit comes from the channel property
``unit_string``; the time from a time channel, else from ``wf_increment`` (and
``wf_start_offset``) of the data channels. The file is opened in streaming mode, so only the
needed channels are read from disk.
"""

from __future__ import annotations

import logging
import os
import struct
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
    time_from_interval,
)


def import_nptdms() -> Any:
    try:
        import nptdms
    except ImportError:  # pragma: no cover - depends on the installation
        raise InputError("reading TDMS files needs npTDMS: pip install 'contactlab[io]'") from None
    return nptdms


class quiet_nptdms:
    """Within it, npTDMS logs nothing to stderr (its warnings about a damaged file are
    collected instead: :attr:`truncated` tells whether it found the last segment short); the
    loggers' filters are restored on exit."""

    def __init__(self) -> None:
        self.messages: list[str] = []
        self._loggers: list[logging.Logger] = []

    def filter(self, record: logging.LogRecord) -> bool:
        self.messages.append(record.getMessage())
        return False

    def __enter__(self) -> quiet_nptdms:
        import_nptdms()
        self._loggers = [logging.getLogger("nptdms")] + [
            lg
            for name, lg in list(logging.root.manager.loggerDict.items())
            if name.startswith("nptdms.") and isinstance(lg, logging.Logger)
        ]
        for lg in self._loggers:
            lg.addFilter(self)
        return self

    def __exit__(self, *exc: Any) -> None:
        for lg in self._loggers:
            lg.removeFilter(self)

    @property
    def truncated(self) -> bool:
        return any("less data than expected" in m for m in self.messages)


#: a TDMS segment's lead-in: tag, table-of-contents mask, version, next-segment offset and
#: raw-data offset (both from the lead-in's end)
_LEAD_IN = 28
_TOC_BIG_ENDIAN = 1 << 6
#: most segments walked looking for damage (a file of many small segments stays fast)
_MAX_SEGMENTS = 100_000


def tdms_damage(path: Path) -> str | None:
    """Where the TDMS file at ``path`` is cut short or damaged, in words (None: its segments'
    lead-ins and metadata are all there). Walks the segments' lead-ins, so a file cut inside
    a lead-in or inside a segment's metadata (npTDMS then reads no channel, or drops the
    segment, with only a log message) is named as such."""
    size = os.path.getsize(path)
    pos, k = 0, 0
    with open(path, "rb") as fh:
        while pos < size and k < _MAX_SEGMENTS:
            k += 1
            fh.seek(pos)
            head = fh.read(_LEAD_IN)
            if len(head) >= 4 and head[:4] not in (b"TDSm", b"TDSh"):
                return f"segment {k} at byte {pos} does not start with a TDMS tag ({head[:4]!r})"
            if len(head) < _LEAD_IN:
                return (
                    f"truncated: the file ends at byte {size}, {size - pos} bytes into the "
                    f"{_LEAD_IN}-byte lead-in of segment {k} (at byte {pos})"
                )
            (toc,) = struct.unpack("<I", head[4:8])
            order = ">" if toc & _TOC_BIG_ENDIAN else "<"
            nxt, raw = struct.unpack(order + "QQ", head[12:28])
            meta_end = pos + _LEAD_IN + raw
            if raw > nxt and nxt != 0xFFFFFFFFFFFFFFFF:
                return (
                    f"segment {k} (at byte {pos}) declares its metadata ({raw} bytes) longer "
                    f"than the segment ({nxt} bytes)"
                )
            if meta_end > size:
                return (
                    f"truncated: the file ends at byte {size}, inside the metadata of segment "
                    f"{k} (bytes {pos + _LEAD_IN} to {meta_end})"
                )
            if nxt == 0xFFFFFFFFFFFFFFFF:  # an unfinished last segment (acquisition stopped)
                return None
            end = pos + _LEAD_IN + nxt
            if end > size:
                return (
                    f"truncated: the file ends at byte {size}, inside the data of segment {k} "
                    f"(bytes {meta_end} to {end})"
                )
            pos = end
    return None


def refuse_unread_tdms(
    path: Path, chans: dict[str, Any], quiet: quiet_nptdms, *, file: str
) -> None:
    """Refuse a file npTDMS read no channel from, or whose last segment's metadata it found
    cut short, naming where the file is truncated or damaged (the columns would be ``[]``)."""
    incomplete = any("metadata is incomplete" in m for m in quiet.messages)
    if chans and not incomplete:
        return
    damage = tdms_damage(path)
    if damage is not None and (not chans or "metadata" in damage or "lead-in" in damage):
        raise RecordingError(f"not a readable TDMS file (damaged: {damage})", file=file)
    if not chans and quiet.truncated:
        raise RecordingError("truncated file? no channel could be read", file=file)


def tdms_lengths(
    lengths: dict[str, int], quiet: quiet_nptdms, *, file: str, what: str = "channels"
) -> None:
    """Refuse channels of different lengths, suspecting truncation when npTDMS found the
    last segment short."""
    if len(set(lengths.values())) > 1:
        hint = "truncated file? " if quiet.truncated else ""
        raise RecordingError(f"{hint}{what} differ in length: {lengths}", file=file)


def tdms_time_step(ref: Any, *, file: str) -> tuple[float | None, float]:
    """``(wf_increment, wf_start_offset)`` of channel ``ref``, checked (None: no increment)."""
    props = ref.properties
    inc = props.get("wf_increment")
    if inc is None:
        return None, 0.0
    where = f"of channel {ref.name!r}"
    dt = metadata_scalar(inc, file=file, label=f"property 'wf_increment' {where}", kind="step")
    t0 = props.get("wf_start_offset")
    if t0 is None or (isinstance(t0, str) and t0 == ""):
        return dt, 0.0
    label = f"property 'wf_start_offset' {where}"
    return dt, metadata_scalar(t0, file=file, label=label, kind="offset")


def read_tdms(
    path: str | Path,
    *,
    columns: dict[str, str] | None = None,
    kind: str | None = None,
    fs: float | None = None,
    resample: bool = False,
) -> Recording:
    """Read a TDMS recording; see :func:`contactlab.io.read_recording`.

    A channel may be named ``"name"`` or ``"group/name"`` in ``columns``. Rows in errors are
    0-based sample indices.
    """
    nptdms = import_nptdms()
    path = Path(path)
    file = str(path)
    # Our own handle: npTDMS leaks the one it opens when parsing fails (ResourceWarning).
    with quiet_nptdms() as quiet:
        return _read_tdms(
            nptdms, path, file, quiet, columns=columns, kind=kind, fs=fs, resample=resample
        )


def _read_tdms(
    nptdms: Any,
    path: Path,
    file: str,
    quiet: quiet_nptdms,
    *,
    columns: Any,
    kind: Any,
    fs: Any,
    resample: bool = False,
) -> Recording:
    fh = open(path, "rb")
    try:
        tf = nptdms.TdmsFile.open(fh)
    except Exception as exc:  # npTDMS raises plain ValueError/KeyError on corrupt files
        fh.close()
        raise RecordingError(f"not a readable TDMS file ({exc})", file=file) from None
    with tf, fh:
        chans: dict[str, Any] = {}
        for g in tf.groups():
            for ch in g.channels():
                chans.setdefault(ch.name, ch)
                chans[f"{g.name}/{ch.name}"] = ch
        refuse_unread_tdms(path, chans, quiet, file=file)
        kind, mapping = resolve_columns(list(chans), columns=columns, kind=kind, file=file)
        raw: dict[str, np.ndarray] = {}
        units: dict[str, str | None] = {}
        for canon, name in mapping.items():
            ch = chans[name]
            raw[canon] = real_values(ch[:], file=file, column=name)
            u = ch.properties.get("unit_string")
            units[canon] = str(u) if u not in (None, "") else None
        tdms_lengths({mapping[c]: v.size for c, v in raw.items()}, quiet, file=file)
        check_equal_lengths(raw, mapping, file=file)
        t_fallback = None
        if "t" not in raw and fs is None:
            ref = chans[mapping[next(c for c in mapping if c != "t")]]
            inc, t0 = tdms_time_step(ref, file=file)
            if inc is not None:
                n = next(iter(raw.values())).size
                t_fallback = time_from_interval(
                    inc, n, file=file, t0=t0, name="wf_increment", column=ref.name
                )
        return finish(
            raw,
            mapping,
            units,
            kind=kind,
            file=file,
            fs=fs,
            resample=resample,
            t_fallback=t_fallback,
            meta={"format": "tdms"},
        )


def write_tdms(path: str | Path, rec: Recording, *, group: str = "recording", **_: Any) -> Path:
    """Write ``rec`` as TDMS, one channel per signal with ``unit_string``; a uniformly sampled
    time axis goes into ``wf_increment``/``wf_start_offset``, otherwise a ``t`` channel."""
    nptdms = import_nptdms()
    d = np.diff(rec.t)
    uniform = d.size > 0 and np.allclose(d, d.mean(), rtol=1e-9, atol=0.0)
    objs = [nptdms.GroupObject(group)]
    if not uniform:
        objs.append(nptdms.ChannelObject(group, "t", rec.t, properties={"unit_string": "s"}))
    for k, v in rec.data.items():
        props: dict[str, Any] = {"unit_string": rec.units[k]}
        if uniform:
            props["wf_increment"] = float(d.mean())
            props["wf_start_offset"] = float(rec.t[0])
        objs.append(nptdms.ChannelObject(group, k, v, properties=props))
    with atomic_path(path) as tmp:
        with nptdms.TdmsWriter(tmp) as w:
            w.write_segment(objs)
    return Path(path)
