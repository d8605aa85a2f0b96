"""Deprecated: moved to :mod:`contactlab.studies.study`; this module forwards to it."""

from __future__ import annotations

import importlib
import warnings
from typing import Any

_NEW = "contactlab.studies.study"


def __getattr__(name: str) -> Any:
    if name.startswith("__"):  # import machinery probing (__path__ …), not a user
        raise AttributeError(name)
    warnings.warn(
        f"contactlab.study is deprecated; import {name} from {_NEW}",
        DeprecationWarning,
        stacklevel=2,
    )
    return getattr(importlib.import_module(_NEW), name)
