"""Deprecated: the loop and residual plots moved to :mod:`contactlab.report.tangential` (issue 32);
this module forwards to it.
"""

from __future__ import annotations

from .._moved import forward_all

__getattr__ = forward_all("contactlab.tangential.plots", "contactlab.report.tangential")
