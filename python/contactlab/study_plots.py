"""Deprecated: moved to :mod:`contactlab.report.study_plots` (issue 32); this module forwards
to it."""

from __future__ import annotations

from ._moved import forward_all

__getattr__ = forward_all("contactlab.study_plots", "contactlab.report.study_plots")
