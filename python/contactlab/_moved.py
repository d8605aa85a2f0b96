"""The deprecation path of names that moved to another module (issue 32, the layering).

A plot, a report writer or a data generator that moved to its one home (``contactlab.report``,
``contactlab.synthetic``, ``contactlab.io``) stays reachable under its old name: the old module
gets a module-level ``__getattr__`` (PEP 562) made by :func:`forward`, which warns with a
``DeprecationWarning`` naming the new place and returns the object from there. The new module
is imported by name (:func:`importlib.import_module`) only when an old name is used, so a
lower layer does not import a higher one when it is loaded; these forwards are the only
exceptions to the layer contract and are listed in ``pyproject.toml`` next to it.
"""

from __future__ import annotations

import importlib
import warnings
from collections.abc import Callable, Mapping
from typing import Any


def moved(old: str, name: str, new: str, attr: str | None = None, stacklevel: int = 3) -> Any:
    """Warn that ``old.name`` is deprecated and return ``new.attr`` (``attr`` defaults to
    ``name``); ``stacklevel`` 3 names the caller of the function that calls this one."""
    attr = attr or name
    warnings.warn(
        f"{old}.{name} is deprecated (issue 32); use {new}.{attr}",
        DeprecationWarning,
        stacklevel=stacklevel,
    )
    return getattr(importlib.import_module(new), attr)


def forward(old: str, names: Mapping[str, str]) -> Callable[[str], Any]:
    """A module ``__getattr__`` for module ``old`` forwarding each of ``names`` (name → new
    module) with a ``DeprecationWarning``; any other name raises ``AttributeError``.

    Parameters
    ----------
    old : str
        Dotted name of the module the names left.
    names : mapping of str to str
        Each moved name and the dotted name of the module that holds it now.

    Returns
    -------
    callable
        The ``__getattr__`` to assign in module ``old``.
    """

    def __getattr__(name: str) -> Any:
        new = names.get(name)
        if new is None:
            raise AttributeError(f"module {old!r} has no attribute {name!r}")
        return moved(old, name, new)

    return __getattr__


def forward_all(old: str, new: str) -> Callable[[str], Any]:
    """A module ``__getattr__`` for a module that moved as a whole: every public name of
    ``old`` is looked up in ``new`` (with a ``DeprecationWarning``)."""

    def __getattr__(name: str) -> Any:
        if name.startswith("__"):  # import machinery probing (__path__ …), not a user
            raise AttributeError(name)
        return moved(old, name, new)

    return __getattr__
