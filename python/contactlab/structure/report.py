"""Deprecated: the structure and structure-diagnosis reports moved to
:mod:`contactlab.report.structure` (issue 32); this module forwards to it.
"""

from __future__ import annotations

from .._moved import forward_all

__getattr__ = forward_all("contactlab.structure.report", "contactlab.report.structure")
