"""Deprecated: the hidden-effect generator moved to :mod:`contactlab.synthetic.diagnosis` (issue
32); this module forwards to it."""

from __future__ import annotations

from .._moved import forward_all

__getattr__ = forward_all("contactlab.diagnose.generator", "contactlab.synthetic.diagnosis")
