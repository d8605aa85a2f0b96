"""Random-but-plausible recordings for the CLI targets (analyze, diagnose, ...), decoded
from fuzz bytes: a Masing loop or a normal-contact loop in units from nN/nm to kN/mm, with
noise, offsets, drift, clipping, a constant or extreme channel now and then, written as a
CSV with units in the header (the readers convert back to SI)."""

from __future__ import annotations

import contextlib
import io
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
from _harness import Bytes, InvariantViolation, check, files_under

_LEN = {"nm": 1e-9, "um": 1e-6, "mm": 1e-3, "m": 1.0}
_FORCE = {"nN": 1e-9, "mN": 1e-3, "N": 1.0, "kN": 1e3}
_PRESS = {"Pa": 1.0, "kPa": 1e3, "MPa": 1e6}


def build(b: Bytes) -> tuple[str, str]:
    """(kind, CSV text)."""
    from contactlab.masing import Masing

    kind = b.choice(("tangential", "normal"))
    fs = b.choice((200.0, 1000.0, 5000.0, _pos(b, 1000.0, 2.0)))
    f = b.choice((1.0, 5.0, _pos(b, 5.0, 1.0)))
    cycles = b.choice((0.5, 2, 4, 6, b.int(1, 10)))
    n = int(min(4000, max(2, cycles * fs / f)))
    t = np.arange(n) / fs
    with np.errstate(all="ignore"):
        if kind == "tangential":
            A = _pos(b, 2e-5, 3.0)
            h0, ac = _pos(b, 40.0, 6.0), _pos(b, 2.0, 1.0) / A
            x = A * np.sin(2 * np.pi * f * t)
            try:
                F = Masing(h0, ac).force(x)
            except Exception:  # parameters the model refuses: a plain tanh loop instead
                F = h0 * np.tanh(x / A)
            a, c = x, F
        else:
            p0, pa = _pos(b, 0.5e6, 3.0), _pos(b, 0.4e6, 3.0)
            k = _pos(b, 1e11, 3.0)
            lag = b.float(0.0, 0.5)
            p = p0 + pa * np.sin(2 * np.pi * f * t)
            d = (p0 + pa * np.sin(2 * np.pi * f * t - lag)) / k
            a, c = d, p
        mode = b.int(0, 15)
        ra, rc = np.ptp(a) if n else 0.0, np.ptp(c) if n else 0.0
        a = a + b.float(0.0, 0.05) * ra * _noise(b, n)
        c = c + b.float(0.0, 0.05) * rc * _noise(b, n)
        if mode == 1:
            c = np.full(n, b.float(-10, 10))  # a constant channel
        elif mode == 2:
            c = c * b.choice((1e300, 1e-300, 1e150, 1e-150))  # the 1e300·sin(ωt)
        elif mode == 3:
            c = c + b.float(-1, 1) * rc * np.linspace(0, 1, n)  # drift
        elif mode == 4:
            c = np.clip(c, np.min(c), np.min(c) + 0.5 * rc)  # clipped sensor
        elif mode == 5 and n:
            c[b.int(0, n - 1)] = b.choice(Bytes.SPECIAL)  # a spike (or a NaN/inf cell)
        elif mode == 6:
            a = a * b.choice((1e300, 1e-300))
        elif mode == 7:
            a = np.round(a / (ra / 8 + 1e-300)) * (ra / 8)  # coarse quantisation
    if kind == "tangential":
        ua, uc = b.choice(list(_LEN)), b.choice(list(_FORCE))
        head = f"t [s],x [{ua}],F [{uc}]"
        with np.errstate(all="ignore"):
            a, c = a / _LEN[ua], c / _FORCE[uc]
    else:
        ua, uc = b.choice(list(_LEN)), b.choice(list(_PRESS))
        head = f"t [s],delta [{ua}],p [{uc}]"
        with np.errstate(all="ignore"):
            a, c = a / _LEN[ua], c / _PRESS[uc]
    buf = io.StringIO()
    buf.write(head + "\n")
    with np.errstate(all="ignore"):
        for row in zip(t, a, c, strict=True):
            buf.write(",".join(repr(float(v)) for v in row) + "\n")
    return kind, buf.getvalue()


def _pos(b: Bytes, typical: float, decades: float) -> float:
    """A positive rate: ``b.positive`` without its special values (those belong to data)."""
    v = b.positive(typical, decades)
    return v if math.isfinite(v) and v > 0 else typical


def _noise(b: Bytes, n: int) -> np.ndarray:
    rng = np.random.default_rng(b.int(0, 2**16))
    return rng.standard_normal(n)


def run_cli(argv: list[str], out_dir: Path, json_path: Path, required: tuple[str, ...]) -> Any:
    """Run ``contactlab`` with ``argv`` under the invariants: exit 0 or 1 (a clear error),
    nothing in ``out_dir`` on failure, and on success a JSON whose ``required`` keys are
    numbers (no NaN reported as success)."""
    from contactlab.cli import main

    before = set(files_under(out_dir))
    sink = io.StringIO()
    with contextlib.redirect_stdout(sink), contextlib.redirect_stderr(sink):
        rc = check(lambda: main(argv))
    if rc is None:
        raise InvariantViolation("a ContactLabError escaped the CLI's handler")
    written = set(files_under(out_dir)) - before
    if rc != 0:
        if rc != 1:
            raise InvariantViolation(f"exit code {rc}")
        if written:
            raise InvariantViolation(f"failed run left files behind: {sorted(written)}")
        return None
    doc = json.loads(json_path.read_text())
    recs = doc.get("recordings", [doc])
    for r in recs:
        for key in required:
            v = r.get(key)
            if not isinstance(v, (int, float)) or not math.isfinite(v):
                raise InvariantViolation(f"success but {key} = {v!r}: {sink.getvalue()[-300:]}")
    return doc
