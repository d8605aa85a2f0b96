"""The runnable examples in the docstrings of contactlab.normal stay correct."""

from __future__ import annotations

import doctest
import importlib

import pytest

MODULES = ["loop", "models", "pressure", "stiffness", "compare"]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    module = importlib.import_module(f"contactlab.normal.{name}")
    failed, attempted = doctest.testmod(module, optionflags=doctest.ELLIPSIS, report=False)
    assert attempted > 0
    assert failed == 0
