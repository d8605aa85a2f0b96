"""Reports: one self-contained HTML file with embedded figures, plus the figures as PNG.

``Report`` assembles headings, text, tables and matplotlib figures; ``commit_outputs`` writes a
set of files all or nothing, so a failed or interrupted run leaves the output folder as it was.
"""

from __future__ import annotations

from .._html import (
    CSS,
    NBSP,
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
    "CSS",
    "NBSP",
    "Column",
    "Report",
    "commit_outputs",
    "figure_png",
    "format_measurement",
    "format_value",
    "slugify",
    "table_html",
]
