"""The layering of ARCHITECTURE.md holds (issue 32): ``lint-imports`` keeps every contract of
pyproject.toml — layers top to bottom, independent workflows and contact kinds, no matplotlib
below the report, no private module crossing its package, no import cycle at any depth
(imports inside functions included) — and the names that moved forward with a warning."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def test_the_import_contracts_hold():
    exe = Path(sys.executable).parent / "lint-imports"
    if not exe.exists():
        pytest.skip("import-linter is not installed (pip install import-linter)")
    run = subprocess.run([exe], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stdout + run.stderr


def test_a_moved_name_warns_and_forwards():
    from contactlab._moved import forward

    getattr_ = forward("contactlab.old", {"Report": "contactlab.report"})
    with pytest.warns(DeprecationWarning, match=r"contactlab\.old\.Report is deprecated"):
        value = getattr_("Report")
    from contactlab.report import Report

    assert value is Report
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        getattr_("nothing")
