"""Plain JSON values from results (numpy scalars and arrays, paths, NaN) for every writer."""

from __future__ import annotations

import json
import math
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any


def jsonable(value: Any) -> Any:
    """Plain JSON types; NaN/inf become null (JSON has no NaN)."""
    if isinstance(value, Mapping):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    # numpy only if it is loaded: without it there are no numpy values (and the command
    # line's start-up does not pay for importing it)
    np = sys.modules.get("numpy")
    if np is None:
        if isinstance(value, float) and not math.isfinite(value):
            return None
        return str(value) if isinstance(value, Path) else value
    if isinstance(value, np.ndarray):
        if value.ndim and value.dtype.kind in "biuf":
            # numbers: numpy's own list conversion gives plain ints, floats and bools (a
            # recursion a sample took 2.2 s for the 5e5 per-cycle numbers of 1e8 samples)
            if value.dtype.kind == "f":
                bad = ~np.isfinite(value)
                if bad.any():
                    obj = value.astype(object)
                    obj[bad] = None
                    return obj.tolist()
            return value.tolist()
        return jsonable(value.tolist())
    if isinstance(value, (np.floating, np.integer, np.bool_)):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, Path):
        return str(value)
    return value


def _flat(v: list[Any]) -> bool:
    """No list or dict among ``v``'s items (their types at C speed: 1e5 numbers in ms)."""
    return not any(issubclass(t, (list, dict)) for t in set(map(type, v)))


def dumps(doc: Any, indent: int = 1) -> str:
    """``json.dumps(doc, indent=indent, allow_nan=False)`` of plain JSON values
    (:func:`jsonable`'s), except that a list of numbers, strings and nulls is written on one
    line: by json's C encoder, which the indenting encoder never uses (a track's per-cycle
    arrays at 1e8 samples, 5e5 numbers: 2.2 s, and a line each)."""
    out: list[str] = []

    def emit(o: Any, level: int) -> None:
        if isinstance(o, dict) and o:
            pad = "\n" + " " * (indent * (level + 1))
            out.append("{")
            for i, (k, v) in enumerate(o.items()):
                out.append(("," if i else "") + pad + json.dumps(str(k)) + ": ")
                emit(v, level + 1)
            out.append("\n" + " " * (indent * level) + "}")
        elif isinstance(o, list) and o and not _flat(o):
            pad = "\n" + " " * (indent * (level + 1))
            out.append("[")
            for i, v in enumerate(o):
                out.append(("," if i else "") + pad)
                emit(v, level + 1)
            out.append("\n" + " " * (indent * level) + "]")
        else:
            out.append(json.dumps(o, allow_nan=False))

    emit(doc, 0)
    return "".join(out)
