"""Deprecated: the diagnosis plots moved to :mod:`contactlab.report.diagnosis_plots` (issue 32);
this module forwards to it.
"""

from __future__ import annotations

from .._moved import forward_all

__getattr__ = forward_all("contactlab.diagnose.plots", "contactlab.report.diagnosis_plots")
