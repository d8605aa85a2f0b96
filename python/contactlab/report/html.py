"""The generic HTML writer, as the report package sees it: :class:`Report`, :class:`Column`
and the cell formatting live at the base (:mod:`contactlab._html`, issue 32) so that studies
can describe their tables without importing the report; this module re-exports them."""

from __future__ import annotations

from .._html import (
    Column,
    Report,
    figure_png,
    format_measurement,
    format_value,
    slugify,
    table_html,
)
from .._outputs import commit_outputs

__all__ = [
    "Column",
    "Report",
    "commit_outputs",
    "figure_png",
    "format_measurement",
    "format_value",
    "slugify",
    "table_html",
]
