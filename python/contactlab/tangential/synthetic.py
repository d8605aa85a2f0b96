"""Deprecated: the synthetic tangential recordings moved to :mod:`contactlab.synthetic.tangential`
(issue 32); this module forwards to it."""

from __future__ import annotations

from .._moved import forward_all

__getattr__ = forward_all("contactlab.tangential.synthetic", "contactlab.synthetic.tangential")
