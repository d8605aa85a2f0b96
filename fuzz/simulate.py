"""Fuzz target: ``contactlab simulate structure OUT --structure MODEL.json --input FILE`` on
random-but-plausible structures (see _structures.py) saved as ``Structure.save`` or as an
identified model, then damaged now and then (a matrix entry zero, negative, NaN or huge, a
joint's parameter missing or of the wrong type, a degree of freedom out of range, bytes that
are not JSON), and on plausible and adversarial inputs (--periodic, --base, no time column).

Invariants (see _harness.py): exit 0 or 1 with one clear line, no file written on failure
(also when the integration stops early: only ``--partial``, which the target never passes,
writes the samples reached), and on success a CSV of finite numbers.
"""

from __future__ import annotations

import json
import shutil
import tempfile
from pathlib import Path

import numpy as np
from _harness import Bytes, InvariantViolation, check, files_under, instrumented, main

with instrumented(("contactlab",)):
    from _structures import JOINTS, excitation, structure

    import contactlab.cli  # noqa: F401

TARGET = "simulate"
_DIR = Path(tempfile.mkdtemp(prefix="contactlab-fuzz-simulate-"))
_ODD = (0.0, -1.0, float("nan"), float("inf"), 1e300, 1e-300, "x", None, [], {"a": 1})


def _damage(b: Bytes, d: dict) -> None:
    """One adversarial edit of a Structure.to_dict() in place."""
    mode = b.int(0, 11)
    if mode == 0:
        d[b.choice(("M", "C", "K"))] = [[b.choice(_ODD)]]
    elif mode == 1 and d["joints"]:
        j = d["joints"][0]
        params = j.get("params", {})
        if params:
            params[b.choice(sorted(params))] = b.choice(_ODD)
    elif mode == 2 and d["joints"]:
        d["joints"][0]["dof"] = b.choice((1, -1, 5, "0", None))
    elif mode == 3 and d["joints"]:
        d["joints"][0]["kind"] = b.choice(("nope", "", 3, "JENKINS"))
    elif mode == 4:
        d.pop(b.choice(("M", "C", "K", "joints")), None)
    elif mode == 5:
        d["M"] = [[1.0, 0.0], [0.0, 1.0]]  # 2 DOF mass with 1 DOF C and K


def one_input(data: bytes) -> None:
    b = Bytes(data)
    joint = b.choice(JOINTS)
    s, _m, k, reach = structure(b, joint)
    base = b.int(0, 3) == 0
    d = s.to_dict()
    if b.int(0, 1):
        _damage(b, d)
    form = b.int(0, 7)
    if form == 0:  # an identified model around the structure
        d = {
            "kind": "contactlab.structure.IdentifiedModel",
            "joint": joint,
            "excitation": "base" if base else "force",
            "structure": d,
            "fit": {"params": {}},
            "x0": b.float(-1, 1) * reach,
            "v0": 0.0,
            "substeps": b.choice((1, 4, 0, -2)),
        }
    model = _DIR / "model.json"
    if form == 1:  # not JSON at all, or cut off
        model.write_bytes(bytes(b.byte() for _ in range(b.int(0, 64))))
    else:
        text = json.dumps(d)
        model.write_text(text[: b.int(0, len(text))] if form == 2 else text)
    n = b.choice((0, 1, 2, 3, 50, b.int(2, 400)))
    fs = b.choice((200.0, 1000.0, 5000.0))
    t = np.arange(n) / fs
    u = excitation(b, t, reach if base else k * reach)
    rows = [f"{ti!r},{ui!r}" for ti, ui in zip(t.tolist(), u.tolist(), strict=True)]
    col = "y_base [m]" if base else "u_force [N]"
    if b.int(0, 7) == 0:
        rows = [r.split(",")[1] for r in rows]
        header, extra = col, ["--fs", str(fs)]
    else:
        header, extra = f"t [s],{col}", []
    src = _DIR / "input.csv"
    src.write_text(header + "\n" + "\n".join(rows) + ("\n" if rows else ""))
    out = _DIR / "out"
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir()
    csv = out / "response.csv"
    argv = ["simulate", "structure", str(csv), "--structure", str(model), "--input", str(src)]
    argv += extra + (["--base"] if base else []) + (["--periodic"] if b.int(0, 5) == 0 else [])
    before = set(files_under(out))
    rc, _said = _run(argv)
    written = set(files_under(out)) - before
    if rc != 0:
        if rc != 1:
            raise InvariantViolation(f"exit code {rc}")
        if written:  # a run that stops early writes nothing unless --partial is given
            raise InvariantViolation(f"failed run left files behind: {sorted(written)}")
        return
    table = np.loadtxt(csv, delimiter=",", skiprows=1, ndmin=2)
    if not np.all(np.isfinite(table)):
        raise InvariantViolation("simulate structure wrote a non-finite value")


def _run(argv: list[str]) -> tuple[int, str]:
    import contextlib
    import io

    from contactlab.cli import main as cli

    sink = io.StringIO()
    with contextlib.redirect_stdout(sink), contextlib.redirect_stderr(sink):
        rc = check(lambda: cli(argv))
    if rc is None:
        raise InvariantViolation("a ContactLabError escaped the CLI's handler")
    return int(rc), sink.getvalue()


if __name__ == "__main__":
    main(one_input)
