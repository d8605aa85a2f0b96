"""Deprecated: the track plots moved to :mod:`contactlab.report.track_plots` (issue 32); this
module forwards to it.
"""

from __future__ import annotations

from .._moved import forward_all

__getattr__ = forward_all("contactlab.studies.track_plots", "contactlab.report.track_plots")
