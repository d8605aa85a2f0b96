"""Replays every input the fuzzers found crashing (fuzz/regressions/<target>/), under the
fuzzing invariants: only ContactLabError subclasses, no numpy warning, no NaN in a
successful result, no file left behind on failure. See fuzz/run.sh.

Each saved input is the smallest one atheris kept for a defect now fixed; the expected
outcome is written beside it in fuzz/regressions/README.md.
"""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

import pytest

FUZZ = Path(__file__).resolve().parents[1] / "fuzz"
CASES = sorted(
    p for p in (FUZZ / "regressions").glob("*/*") if p.is_file() and not p.name.endswith(".md")
)


@pytest.fixture(scope="module", autouse=True)
def _fuzz_on_path():
    sys.path.insert(0, str(FUZZ))
    yield
    sys.path.remove(str(FUZZ))


@pytest.mark.parametrize("case", CASES, ids=[f"{p.parent.name}/{p.name[:10]}" for p in CASES])
def test_saved_crash_input_keeps_the_invariants(case: Path) -> None:
    target = importlib.import_module(case.parent.name)
    target.one_input(case.read_bytes())


def test_every_target_has_a_module() -> None:
    names = {p.parent.name for p in CASES}
    assert names, "no saved fuzz inputs"
    for name in names:
        assert (FUZZ / f"{name}.py").is_file(), name
