"""Deprecated: the synthetic normal recordings moved to :mod:`contactlab.synthetic.normal` (issue
32); this module forwards to it."""

from __future__ import annotations

from .._moved import forward_all

__getattr__ = forward_all("contactlab.normal.synthetic", "contactlab.synthetic.normal")
