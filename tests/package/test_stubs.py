"""The hand-written stub `_core.pyi` must describe the compiled module: every public name in
the extension is declared in the stub and vice versa (classes down to their methods), with the
same signatures (``mypy.stubtest``)."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

import contactlab
from contactlab import _core

STUB = Path(contactlab.__file__).with_name("_core.pyi")


def _declared() -> dict[str, set[str] | None]:
    tree = ast.parse(STUB.read_text(encoding="utf-8"))
    out: dict[str, set[str] | None] = {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            out[node.name] = {
                n.name
                for n in node.body
                if isinstance(n, ast.FunctionDef | ast.AsyncFunctionDef)
                and not n.name.startswith("_")
            }
        elif isinstance(node, ast.FunctionDef):
            out[node.name] = None
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            if not node.target.id.startswith("_") or node.target.id == "__version__":
                out[node.target.id] = None
    return out


def test_stub_matches_extension():
    declared = _declared()
    runtime = {n for n in dir(_core) if not n.startswith("_")} | {"__version__"}
    assert set(declared) == runtime
    for name, methods in declared.items():
        if methods is None:
            continue
        cls = getattr(_core, name)
        have = {m for m in dir(cls) if not m.startswith("_")}
        assert methods == have, f"{name}: stub {sorted(methods ^ have)} differ"


def test_stub_signatures_match_extension():
    """Parameter names, defaults and kinds as the extension reports them (PyO3 text signatures)."""
    pytest.importorskip("mypy.stubtest", reason="mypy (the dev extra; `make test` installs it)")
    allowlist = Path(__file__).resolve().parents[1] / "stubtest_allowlist.txt"
    done = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "contactlab._core", "--concise",
         "--ignore-disjoint-bases", "--allowlist", str(allowlist)],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stdout + done.stderr
