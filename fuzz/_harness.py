"""Shared harness of the atheris fuzz targets: the invariants every entry point must keep.

An input is a *crash* (atheris stops and saves it) when the entry point

- raises anything but a :class:`contactlab.ContactLabError` subclass (``KeyboardInterrupt``
  passes through; a Rust panic arrives as ``PanicException``, a ``BaseException``, or as the
  binding's "internal error ... (panic caught)", which counts as a crash too),
- emits a warning other than :class:`contactlab.ContactLabWarning` (numpy's overflow and
  invalid-value warnings included: they are turned into errors here, as pytest does),
- returns a result that reports success but holds a NaN, or
- leaves a file behind in its output folder when it failed.

Each target module defines ``TARGET = name`` and ``one_input(data: bytes) -> None`` that calls
:func:`check`; ``python fuzz/<target>.py [atheris/libFuzzer flags] CORPUS_DIR`` runs it.
"""

from __future__ import annotations

import math
import os
import sys
import warnings
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent


class InvariantViolation(AssertionError):
    """An entry point broke one of the invariants above."""


def check(fn: Callable[[], Any], *, expected: type[BaseException] | None = None) -> Any:
    """Run ``fn`` under the invariants; return its result, or None when it raised the
    expected error (default :class:`contactlab.ContactLabError`). Anything else propagates
    (atheris reports it as a crash)."""
    from contactlab.errors import ContactLabError, ContactLabWarning

    expected = expected or ContactLabError

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warnings.simplefilter("ignore", ContactLabWarning)
        # numpy's defaults warn on overflow, 0/0 and x/0 (underflow is silent): those are
        # defects here, raised at their source
        with np.errstate(over="raise", divide="raise", invalid="raise", under="ignore"):
            try:
                return fn()
            except KeyboardInterrupt:
                raise
            except BaseException as exc:
                if isinstance(exc, expected) and "internal error" not in str(exc):
                    return None
                raise


def no_nan(value: Any, where: str = "result") -> None:
    """Raise :class:`InvariantViolation` when a (nested) result holds a NaN."""
    if value is None or isinstance(value, (str, bytes, bool)):
        return
    if isinstance(value, float):
        if math.isnan(value):
            raise InvariantViolation(f"{where} is NaN in a successful result")
        return
    if isinstance(value, np.ndarray):
        if value.dtype.kind in "fc" and np.isnan(value).any():
            i = int(np.flatnonzero(np.isnan(value.ravel()))[0])
            raise InvariantViolation(f"{where}[{i}] is NaN in a successful result")
        return
    if isinstance(value, dict):
        for k, v in value.items():
            no_nan(v, f"{where}.{k}")
        return
    if isinstance(value, (list, tuple)):
        for i, v in enumerate(value):
            no_nan(v, f"{where}[{i}]")
        return
    if type(value).__module__ == "contactlab._core":
        # a typed result of the binding (frozen #[pyclass]): its public data attributes
        for k in dir(value):
            if not k.startswith("_"):
                v = getattr(value, k)
                if not callable(v):
                    no_nan(v, f"{where}.{k}")


def files_under(folder: Path) -> list[Path]:
    return sorted(p for p in folder.rglob("*") if p.is_file())


class Bytes:
    """Deterministic decoder of a fuzz input into choices, ints and floats (atheris-free, so
    the regression tests replay saved inputs without atheris installed)."""

    #: values the kernels must survive: extremes, denormals, signed zeros, non-finite
    SPECIAL = (
        0.0,
        -0.0,
        1.0,
        -1.0,
        1e-300,
        -1e-300,
        5e-324,
        2.2250738585072014e-308,
        1e300,
        -1e300,
        1.7976931348623157e308,
        math.nan,
        math.inf,
        -math.inf,
        1e-12,
        1e12,
        0.5,
        2.0,
    )

    def __init__(self, data: bytes) -> None:
        self.data = data
        self.pos = 0

    def byte(self) -> int:
        if self.pos >= len(self.data):
            return 0
        b = self.data[self.pos]
        self.pos += 1
        return b

    def int(self, lo: int, hi: int) -> int:
        """An integer in ``[lo, hi]``."""
        span = hi - lo + 1
        v = 0
        for _ in range(max(1, (span.bit_length() + 7) // 8)):
            v = (v << 8) | self.byte()
        return lo + v % span

    def choice(self, options: Any) -> Any:
        options = list(options)
        return options[self.int(0, len(options) - 1)]

    def raw_float(self) -> float:
        chunk = bytes(self.byte() for _ in range(8))
        return float(np.frombuffer(chunk, dtype="<f8")[0])

    def float(self, lo: float = -1.0, hi: float = 1.0) -> float:
        """Mostly a value in ``[lo, hi]``; sometimes special or any double at all."""
        mode = self.int(0, 15)
        if mode == 0:
            return self.choice(self.SPECIAL)
        if mode == 1:
            return self.raw_float()
        u = self.int(0, 65535) / 65535.0
        return lo + (hi - lo) * u

    def positive(self, typical: float, decades: float = 3.0) -> float:
        """Mostly ``typical`` times 10**[-decades, decades]; sometimes special."""
        if self.int(0, 15) == 0:
            return self.choice(self.SPECIAL)
        return typical * 10.0 ** (decades * (self.int(0, 65535) / 32767.5 - 1.0))

    def array(self, max_len: int = 64) -> np.ndarray:
        """A float array: any length up to ``max_len`` (0, 1, 2 often), mixed content, and
        sometimes non-contiguous, big-endian, float32 or int."""
        n = self.choice((0, 1, 2, 3, self.int(0, max_len)))
        kind = self.int(0, 5)
        if kind == 0:
            a = np.array([self.float(-1e3, 1e3) for _ in range(n)])
        elif kind == 1:
            a = np.array([self.raw_float() for _ in range(n)])
        else:
            amp = self.positive(1.0, 300.0)
            a = amp * np.sin(np.linspace(0.0, self.float(0.0, 60.0), n))
            for _ in range(self.int(0, 3)):
                if n:
                    a[self.int(0, n - 1)] = self.choice(self.SPECIAL)
        layout = self.int(0, 7)
        if layout == 1:
            a = np.repeat(a, 2)[::2]  # non-contiguous view
        elif layout == 2:
            a = a.astype(">f8")
        elif layout == 3:
            with np.errstate(all="ignore"):
                a = a.astype(np.float32)
        elif layout == 4:
            a = a[::-1]
        return a


def fuzzing() -> bool:
    """True when run by ``fuzz/run.sh`` (atheris present and asked for)."""
    return bool(os.environ.get("CONTACTLAB_FUZZING"))


def instrumented(include: Iterable[str] = ("contactlab",)) -> Any:
    """Context for a target's imports: atheris coverage instrumentation when fuzzing, nothing
    otherwise (pytest replays saved inputs without atheris)."""
    if not fuzzing():
        import contextlib

        return contextlib.nullcontext()
    import atheris

    return atheris.instrument_imports(include=list(include))


def _signature(exc: BaseException) -> str:
    """Type, message head and innermost contactlab frame: one line per distinct defect."""
    import traceback

    frames = [f for f in traceback.extract_tb(exc.__traceback__) if "contactlab" in f.filename]
    where = f"{Path(frames[-1].filename).name}:{frames[-1].lineno}" if frames else "?"
    import re

    msg = re.sub(r"\d+", "N", " ".join(str(exc).split()))
    msg = msg.split(": ")[0][:100]  # the head names the defect; the tail has data in it
    return f"{type(exc).__name__} at {where}: {msg}"


def main(one_input: Callable[[bytes], None]) -> None:
    """Run atheris on ``one_input`` with the command line's libFuzzer flags and corpus dirs.

    A violation does not stop the run: its input is saved once per distinct signature (type,
    message, innermost contactlab frame) to ``$CONTACTLAB_FUZZ_CRASHES/<sha1>`` with the
    traceback in ``SIGNATURES.txt`` beside it, and fuzzing goes on, so one run reports every
    defect it meets and a total execution count.
    """
    import hashlib
    import traceback

    import atheris

    out = Path(os.environ.get("CONTACTLAB_FUZZ_CRASHES", "crashes"))
    out.mkdir(parents=True, exist_ok=True)
    seen: set[str] = set()
    sig_file = out / "SIGNATURES.txt"
    if sig_file.exists():
        seen |= {
            ln.split(" ", 1)[1] for ln in sig_file.read_text().splitlines() if ln.startswith("## ")
        }

    def guarded(data: bytes) -> None:
        try:
            one_input(data)
        except KeyboardInterrupt:
            raise
        except BaseException as exc:
            sig = _signature(exc)
            if sig in seen:
                return
            seen.add(sig)
            name = hashlib.sha1(data).hexdigest()
            (out / name).write_bytes(data)
            with sig_file.open("a") as fh:
                fh.write(f"## {sig}\n{name}\n{''.join(traceback.format_exception(exc))}\n")
            print(f"NEW DEFECT {sig} -> {out / name}", file=sys.stderr, flush=True)

    # Coverage of the target's own decoding (which branch, which kernel) guides mutation too:
    # the Rust kernels behind the binding are not instrumented (the `core` AFL target is).
    import inspect

    for mod in {sys.modules[one_input.__module__], sys.modules[__name__]}:
        for name, obj in list(vars(mod).items()):
            if inspect.isfunction(obj) and obj.__module__ == mod.__name__ and name != "main":
                setattr(mod, name, atheris.instrument_func(obj))
    for name, obj in list(vars(Bytes).items()):
        if inspect.isfunction(obj):
            setattr(Bytes, name, atheris.instrument_func(obj))
    one_input = getattr(sys.modules[one_input.__module__], one_input.__name__, one_input)
    atheris.Setup(sys.argv, guarded)
    atheris.Fuzz()


def recording_ok(rec: Any, where: str) -> None:
    """What a reader returns: t finite and strictly increasing, channels as long and finite."""
    t = np.asarray(rec.t)
    if t.ndim != 1 or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise InvariantViolation(f"{where}: t is not finite and strictly increasing")
    for k, v in rec.data.items():
        v = np.asarray(v)
        if v.shape != t.shape:
            raise InvariantViolation(f"{where}: channel {k} has shape {v.shape} vs t {t.shape}")
        if not np.all(np.isfinite(v)):
            raise InvariantViolation(f"{where}: channel {k} holds a non-finite value")
        if k not in rec.units:
            raise InvariantViolation(f"{where}: channel {k} has no unit")
