"""Package structure: a cheap, lazy ``import contactlab`` (issue 13)."""

from __future__ import annotations

import importlib
import re
import subprocess
import sys
from pathlib import Path

import pytest

import contactlab


def _modules_after(code: str) -> set[str]:
    out = subprocess.run(
        [sys.executable, "-c", f"{code}\nimport sys\nprint('\\n'.join(sys.modules))"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    return set(out.split())


def test_import_contactlab_loads_neither_scipy_nor_the_diagnosis():
    loaded = _modules_after("import contactlab")
    heavy = {"scipy", "scipy.optimize", "matplotlib", "numpy", "contactlab.diagnose"}
    assert not heavy & loaded, sorted(heavy & loaded)
    assert "contactlab.errors" in loaded


def test_masing_alone_does_not_pull_in_the_fitting_stack():
    loaded = _modules_after("import contactlab\ncontactlab.Masing(h0=1.0, ac=1.0)")
    assert "contactlab.masing" in loaded
    assert not {"scipy.optimize", "contactlab.diagnose", "contactlab.fitting"} & loaded


def test_every_public_name_resolves_to_its_home_module():
    for name in contactlab.__all__:
        value = getattr(contactlab, name)
        home = contactlab._LAZY.get(name)
        if home is not None:
            module = importlib.import_module(f"contactlab.{home}")
            assert value is getattr(module, name), name
    assert set(dir(contactlab)) >= set(contactlab.__all__)
    assert callable(contactlab.diagnose)
    assert contactlab.diagnose.diagnose.__module__ == "contactlab.diagnose.workflow"


def test_unknown_attribute_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no_such_name"):
        contactlab.no_such_name  # noqa: B018


def test_version_has_one_home_matching_pyproject():
    from contactlab._version import __version__

    pyproject = Path(__file__).resolve().parents[2] / "pyproject.toml"
    version = re.search(r'^version = "([^"]+)"', pyproject.read_text(), re.MULTILINE)
    assert version is not None
    assert contactlab.__version__ == __version__ == version.group(1)


def test_data_generator_command_still_runs_from_the_data_package():
    done = subprocess.run(
        [sys.executable, "-m", "contactlab.data.generate", "--help"],
        check=True,
        capture_output=True,
        text=True,
    )
    assert "usage: python -m contactlab.data.generate" in done.stdout
    assert "--no-normal" in done.stdout
    from contactlab.data import generate
    from contactlab.synthetic import bundled

    assert generate.generate is bundled.generate


def test_importing_the_data_package_loads_no_model():
    loaded = _modules_after("import contactlab.data")
    assert not {"contactlab.masing", "contactlab.normal", "contactlab.io", "numpy"} & loaded
