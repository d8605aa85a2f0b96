"""Running CalculiX (``ccx``) and reading its ``.dat`` output into numpy.

:func:`run_ccx` writes a deck into a temporary folder, runs ``ccx -i job`` with a time limit
and returns the parsed ``.dat``; :func:`parse_dat` reads the print blocks (``*NODE PRINT``,
``*EL PRINT``, ``*CONTACT PRINT``: one block per variable, set and time) and the eigenvalue
table of a ``*FREQUENCY`` step.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import ContactLabError, ConvergenceError

#: Debian/Ubuntu package that provides ``ccx``
CCX_PACKAGE = "calculix-ccx"

_HEAD = re.compile(
    r"^\s*(?P<what>[a-z][^()]*?)\s*(?:\((?P<cols>[^)]*)\))?\s*"
    r"(?:for set (?P<set>\S+)|for all contact elements)?\s*and time\s+(?P<time>\S+)\s*$"
)
_EIG = "E I G E N V A L U E   O U T P U T"


class SolverError(ContactLabError):
    """CalculiX is missing, failed, or did not converge (the message quotes its log)."""


@dataclass
class DatBlock:
    """One print block: what (``"displacements"``, ``"contact stress"``, ...), its column
    names as CalculiX prints them, the set (None for contact blocks), the time and the rows.
    """

    what: str
    columns: str
    set: str | None
    time: float
    data: np.ndarray


@dataclass
class DatFile:
    blocks: list[DatBlock] = field(default_factory=list)
    #: rows of the eigenvalue table: mode, eigenvalue, ω (rad/time), f (cycles/time), imag
    eigen: np.ndarray | None = None

    def series(self, what: str, set_: str | None = None) -> tuple[np.ndarray, list[np.ndarray]]:
        """Times and data of every block whose ``what`` starts with ``what`` (and ``set``)."""
        sel = [
            b
            for b in self.blocks
            if b.what.startswith(what) and (set_ is None or (b.set or "").upper() == set_.upper())
        ]
        return np.array([b.time for b in sel]), [b.data for b in sel]


def _floats(line: str) -> list[float] | None:
    parts = line.split()
    try:
        return [float(p) for p in parts]
    except ValueError:
        return None


def parse_dat(text: str) -> DatFile:
    """Parse the text of a CalculiX ``.dat`` file."""
    out = DatFile()
    lines = text.splitlines()
    i = 0
    while i < len(lines):
        line = lines[i]
        if _EIG in line:
            rows: list[list[float]] = []
            i += 1
            while i < len(lines):
                v = _floats(lines[i])
                if v is not None and len(v) == 5:
                    rows.append(v)
                elif rows and (not lines[i].strip() or v is None):
                    break
                i += 1
            out.eigen = np.array(rows)
            continue
        m = _HEAD.match(line)
        if m:
            rows = []
            i += 1
            while i < len(lines) and not lines[i].strip():
                i += 1
            while i < len(lines) and lines[i].strip():
                v = _floats(lines[i])
                if v is None:
                    break
                rows.append(v)
                i += 1
            width = max((len(r) for r in rows), default=0)
            data = np.array([r + [np.nan] * (width - len(r)) for r in rows], float)
            out.blocks.append(
                DatBlock(
                    m.group("what"),
                    m.group("cols") or "",
                    m.group("set"),
                    float(m.group("time")),
                    data,
                )
            )
            continue
        i += 1
    return out


def find_ccx() -> str | None:
    """Path of the ``ccx`` executable (``$CCX`` or on PATH), or None."""
    env = os.environ.get("CCX")
    if env and Path(env).is_file():
        return env
    return shutil.which("ccx")


def ccx_version(exe: str | None = None) -> str:
    exe = exe or find_ccx()
    if exe is None:
        raise SolverError(f"ccx not found: install the {CCX_PACKAGE} package")
    r = subprocess.run([exe, "-v"], capture_output=True, text=True, timeout=30, check=False)
    m = re.search(r"Version\s+(\S+)", r.stdout + r.stderr)
    return m.group(1) if m else (r.stdout + r.stderr).strip()


@dataclass
class CcxRun:
    dat: DatFile
    seconds: float
    log: str


def run_ccx(deck: str, *, timeout: float = 120.0, keep: str | Path | None = None) -> CcxRun:
    """Run CalculiX on ``deck`` (single-threaded) and parse its ``.dat``.

    Raises :class:`SolverError` when ``ccx`` is missing, fails, exceeds ``timeout`` seconds
    or reports an error (the log's ``*ERROR`` lines are quoted). ``keep`` copies the job's
    files to that folder.
    """
    exe = find_ccx()
    if exe is None:
        raise SolverError(f"ccx not found: install the {CCX_PACKAGE} package")
    with tempfile.TemporaryDirectory(prefix="contactlab-ccx-") as tmp:
        Path(tmp, "job.inp").write_text(deck, encoding="utf-8")
        env = dict(
            os.environ, OMP_NUM_THREADS="1", CCX_NPROC_STIFFNESS="1", CCX_NPROC_EQUATION_SOLVER="1"
        )
        t0 = time.perf_counter()
        try:
            r = subprocess.run(
                [exe, "-i", "job"],
                cwd=tmp,
                capture_output=True,
                text=True,
                timeout=timeout,
                env=env,
                check=False,
            )
        except subprocess.TimeoutExpired as exc:
            raise SolverError(f"ccx did not finish within {timeout:g} s") from exc
        seconds = time.perf_counter() - t0
        log = r.stdout + r.stderr
        if keep is not None:
            Path(keep).mkdir(parents=True, exist_ok=True)
            for f in Path(tmp).iterdir():
                if f.suffix in (".inp", ".dat", ".sta", ".cvg"):
                    shutil.copy(f, Path(keep) / f.name)
            Path(keep, "job.log").write_text(log, encoding="utf-8")
        errors = [ln.strip() for ln in log.splitlines() if "*ERROR" in ln]
        if r.returncode != 0 or errors:
            msg = "; ".join(errors[:3]) or log.strip().splitlines()[-1:]
            cls = ConvergenceError if any("diverge" in e for e in errors) else SolverError
            raise cls(f"ccx failed (exit {r.returncode}): {msg}")
        dat = Path(tmp, "job.dat")
        text = dat.read_text(encoding="utf-8", errors="replace") if dat.exists() else ""
    return CcxRun(parse_dat(text), seconds, log)
