"""NI TDMS recordings (npTDMS, optional extra ``io``).

Channels are found by name in any group. The unit comes from the channel property
``unit_string``; the time from a time channel, else from ``wf_increment`` (and
``wf_start_offset``) of the data channels. The file is opened in streaming mode, so only the
needed channels are read from disk.
"""

from __future__ import annotations

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


def read_tdms(
    path: str | Path,
    *,
    columns: dict[str, str] | None = None,
    kind: str | None = None,
    fs: float | None = None,
) -> Recording:
    """Read a TDMS recording; see :func:`contactlab.io.read_recording`.

    A channel may be named ``"name"`` or ``"group/name"`` in ``columns``. Rows in errors are
    0-based sample indices.
    """
    nptdms = import_nptdms()
    path = Path(path)
    file = str(path)
    # Our own handle: npTDMS leaks the one it opens when parsing fails (ResourceWarning).
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
        kind, mapping = resolve_columns(list(chans), columns=columns, kind=kind, file=file)
        raw: dict[str, np.ndarray] = {}
        units: dict[str, str | None] = {}
        for canon, name in mapping.items():
            ch = chans[name]
            raw[canon] = real_values(ch[:], file=file, column=name)
            u = ch.properties.get("unit_string")
            units[canon] = str(u) if u not in (None, "") else None
        check_equal_lengths(raw, mapping, file=file)
        t_fallback = None
        if "t" not in raw:
            ref = chans[mapping[next(c for c in mapping if c != "t")]]
            inc = ref.properties.get("wf_increment")
            if inc is not None and fs is None:
                t0 = float(ref.properties.get("wf_start_offset", 0.0) or 0.0)
                n = next(iter(raw.values())).size
                t_fallback = time_from_interval(
                    float(inc), n, file=file, t0=t0, name="wf_increment", column=ref.name
                )
        return finish(
            raw,
            mapping,
            units,
            kind=kind,
            file=file,
            fs=fs,
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
