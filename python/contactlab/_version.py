"""The package version, in a module of its own so that reports and the CLI can stamp it without
importing the package root (which would make every submodule depend on everything)."""

from __future__ import annotations

__version__ = "0.1.0"
