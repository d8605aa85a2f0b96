"""Deprecated: the normal hidden-effect generator moved to
:mod:`contactlab.synthetic.diagnosis_normal` (issue 32); this module forwards to it."""

from __future__ import annotations

from .._moved import forward_all

__getattr__ = forward_all(
    "contactlab.diagnose.generator_normal", "contactlab.synthetic.diagnosis_normal"
)
