"""A self-contained HTML report: headings, text, tables and figures embedded as base64 PNG.

The report is one file that opens anywhere (no external CSS, scripts or images), so it can be
mailed or archived beside the raw data. Every figure is also kept as a PNG of its own, and
:meth:`Report.write` writes the HTML and the PNGs all or nothing (see ``_outputs``).
"""

from __future__ import annotations

import base64
import html
import io
import math
import os
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

from ._outputs import commit_outputs
from ._version import __version__
from .errors import InputError

#: The stylesheet of every HTML report (tables, figures, warnings).
CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;margin:2em auto;
max-width:1100px;padding:0 1em;color:#222;line-height:1.45}
h1{border-bottom:2px solid #345;padding-bottom:.2em}h2{border-bottom:1px solid #bbb;margin-top:2em}
table{border-collapse:collapse;font-size:.8em;margin:.6em 0 1.2em;max-width:100%}
th,td{border:1px solid #ccc;padding:.2em .4em;text-align:right;white-space:normal}
th{background:#eef1f5;vertical-align:bottom;overflow-wrap:break-word}
td.s{text-align:left;overflow-wrap:anywhere}caption{caption-side:top;text-align:left;
font-style:italic;padding:.2em 0}figure{margin:1em 0}figure img{max-width:100%;
border:1px solid #ddd}figcaption{font-size:.9em;color:#444}pre{background:#f6f8fa;padding:.6em;
overflow-x:auto;font-size:.8em}.note{color:#7a4b00;background:#fff6e0;padding:.4em .6em;
border-left:3px solid #e0a000}nav ul{columns:2}.tablewrap{overflow-x:auto}
"""

#: the no-break space that holds "± error" together in a table cell
NBSP = "\u00a0"

_SLUG = re.compile(r"[^a-z0-9]+")


def slugify(text: str) -> str:
    """File- and anchor-safe lower-case name: ``"Al/Al, W = 50 N"`` → ``"al-al-w-50-n"``."""
    s = _SLUG.sub("-", text.lower()).strip("-")
    return s or "item"


def figure_png(fig: Any, dpi: int = 100) -> bytes:
    """Render a matplotlib figure to PNG bytes (the figure is left open)."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return buf.getvalue()


def format_value(value: Any, digits: int = 4) -> str:
    """Table cell text: numbers to ``digits`` significant digits, NaN/None as an em dash."""
    if value is None:
        return "—"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "—"
        return f"{value:.{digits}g}"
    return str(value)


def format_measurement(value: float, stderr: float, digits: int = 2) -> str:
    """``value ± stderr`` with the uncertainty to ``digits`` significant digits and the value
    rounded to the same decimal place, as measurements are written.

    Printing the value to a fixed number of significant digits instead gives cells such as
    ``5.764e-14 ± 0.00068``, which claims 14 decimals for a value known to 4, or
    ``2.669 ± 0.00084``, which hides the digits the fit did determine.

    Examples
    --------
    >>> format_measurement(5.764e-14, 0.00068)
    '0.00000 ± 0.00068'
    >>> format_measurement(2.66912, 0.00084)
    '2.66912 ± 0.00084'
    >>> format_measurement(75.512, 0.38)
    '75.51 ± 0.38'
    >>> format_measurement(1588123.0, 840.0)
    '(1.58812 ± 0.00084)e+06'
    """
    v, s = float(value), abs(float(stderr))
    if not math.isfinite(v):
        return format_value(v)
    if not math.isfinite(s) or s == 0.0:
        return f"{format_value(v)} ± {format_value(s, digits)}"
    last = math.floor(math.log10(s)) - (digits - 1)  # decimal exponent of the last digit shown
    big = max(abs(v), s)
    if -8 <= last <= 0 and big < 1e6:
        d = -last
        if round(v, d) == 0.0:
            v = 0.0  # no "-0.00000"
        return f"{v:.{d}f} ± {s:.{d}f}"
    # Very large or very small: one common power of ten.
    e = math.floor(math.log10(big))
    d = max(e - last, 0)
    return f"({v / 10.0**e:.{d}f} ± {s / 10.0**e:.{d}f})e{e:+03d}"


@dataclass
class Column:
    """One table column: ``key`` in the rows, header ``label``, display ``scale`` and ``unit``.

    ``stderr`` names the key of the value's standard error, shown as ``value ± stderr``.
    """

    key: str
    label: str | None = None
    unit: str = ""
    scale: float = 1.0
    stderr: str | None = None

    def header(self) -> str:
        label = self.label or self.key
        return f"{label} [{self.unit}]" if self.unit else label

    def cell(self, row: Mapping[str, Any]) -> tuple[str, bool]:
        v = row.get(self.key)
        numeric = isinstance(v, (int, float)) and not isinstance(v, bool)
        if numeric:
            v = float(v) * self.scale if self.scale != 1.0 else v
        text = format_value(v)
        if self.stderr is not None and numeric:
            s = row.get(self.stderr)
            if isinstance(s, (int, float)) and not isinstance(s, bool):
                text = format_measurement(float(v), float(s) * self.scale)
        return text, numeric


def _header_html(text: str) -> str:
    """A column header, escaped, that may wrap at its spaces and after the ``·`` and ``/`` of
    a compound unit (``[µm⁻¹·<wbr>MPa⁻²]``), so that a wide table fits a narrow page."""
    return "".join(html.escape(ch) + ("<wbr>" if ch in "·/" else "") for ch in text)


def table_html(
    rows: Sequence[Mapping[str, Any]], columns: Sequence[Column], caption: str = ""
) -> str:
    """An HTML table of ``rows`` (also what notebooks show for a study result)."""
    esc = html.escape
    out = ['<div class="tablewrap"><table>']
    if caption:
        out.append(f"<caption>{esc(caption)}</caption>")
    out.append("<tr>" + "".join(f"<th>{_header_html(c.header())}</th>" for c in columns) + "</tr>")
    for r in rows:
        cells = []
        for c in columns:
            text, numeric = c.cell(r)
            cls = "" if numeric else ' class="s"'
            # a narrow window wraps "value ± error" before the ± only (no-break space after
            # it), a text cell anywhere (a long file name), a header at its spaces (issue 31:
            # the demo's summary scrolled sideways at 1400 px)
            cells.append(f"<td{cls}>{esc(text.replace(' ± ', ' ±' + NBSP))}</td>")
        out.append("<tr>" + "".join(cells) + "</tr>")
    out.append("</table></div>")
    return "".join(out)


@dataclass
class _Figure:
    name: str
    png: bytes
    caption: str


@dataclass
class _Section:
    title: str
    anchor: str
    blocks: list[tuple[str, Any]] = field(default_factory=list)


class Report:
    """Builder of a self-contained HTML report.

    Parameters
    ----------
    title : str
        Page title and top heading.
    intro : str, optional
        Paragraph below the title.

    Examples
    --------
    >>> r = Report("Demo")
    >>> r.section("Results").text("Two rows.")
    >>> r.table([{"a": 1.0, "b": "x"}, {"a": 2.5, "b": "y"}], [Column("a", unit="N"), "b"])
    >>> "<table>" in r.render_html()
    True
    """

    def __init__(self, title: str, intro: str | None = None) -> None:
        self.title = title
        self.intro = intro
        self._sections: list[_Section] = []
        self._figures: dict[str, _Figure] = {}
        self._preamble: list[tuple[str, Any]] = []

    # -- building ------------------------------------------------------------------------------
    def section(self, title: str) -> Report:
        """Start a new section (a level-2 heading with an entry in the contents)."""
        anchor = slugify(title)
        taken = {s.anchor for s in self._sections}
        base, k = anchor, 2
        while anchor in taken:
            anchor, k = f"{base}-{k}", k + 1
        self._sections.append(_Section(title, anchor))
        return self

    def _blocks(self) -> list[tuple[str, Any]]:
        return self._sections[-1].blocks if self._sections else self._preamble

    def text(self, text: str, *, note: bool = False) -> None:
        """A paragraph of plain text (escaped); ``note=True`` highlights it as a warning."""
        self._blocks().append(("note" if note else "p", text))

    def subheading(self, text: str) -> None:
        self._blocks().append(("h3", text))

    def preformatted(self, text: str) -> None:
        """Monospaced text, e.g. a fit report."""
        self._blocks().append(("pre", text))

    def figure(self, fig: Any, name: str, caption: str = "", *, dpi: int = 100) -> str:
        """Embed a matplotlib figure; it is also written as ``figures/<name>.png``.

        The figure is rendered now and closed. Returns the PNG's file name.
        """
        import matplotlib.pyplot as plt

        try:
            png = figure_png(fig, dpi=dpi)
        finally:
            plt.close(fig)
        return self.png(png, name, caption)

    def png(self, png: bytes, name: str, caption: str = "") -> str:
        """Embed a figure already rendered to PNG bytes (as :meth:`figure` does after
        rendering); returns its file name, ``<name>.png`` or ``<name>-2.png``... when taken."""
        stem = slugify(name)
        fname, k = f"{stem}.png", 2
        while fname in self._figures:
            fname, k = f"{stem}-{k}.png", k + 1
        self._figures[fname] = _Figure(fname, png, caption)
        self._blocks().append(("fig", fname))
        return fname

    def blocks(self) -> list[tuple[str, Any]]:
        """The blocks added so far outside any section, figures with their PNG bytes:
        ``(kind, payload)`` with ``("fig", (png, name, caption))``; :meth:`extend` adds them to
        another report (a part rendered in another process)."""
        out: list[tuple[str, Any]] = []
        for kind, payload in self._preamble:
            if kind == "fig":
                f = self._figures[payload]
                payload = (f.png, f.name.removesuffix(".png"), f.caption)
            out.append((kind, payload))
        return out

    def extend(self, blocks: Iterable[tuple[str, Any]]) -> None:
        """Add blocks from :meth:`blocks` of another report, in order, to the current section."""
        for kind, payload in blocks:
            if kind == "fig":
                self.png(*payload)
            else:
                self._blocks().append((kind, payload))

    def table(
        self,
        rows: Sequence[Mapping[str, Any]],
        columns: Iterable[Column | str] | None = None,
        caption: str = "",
    ) -> None:
        """A table of ``rows`` (mappings); ``columns`` selects and formats the keys."""
        rows = list(rows)
        if columns is None:
            keys: list[str] = []
            for r in rows:
                keys.extend(k for k in r if k not in keys)
            columns = keys
        cols = [c if isinstance(c, Column) else Column(str(c)) for c in columns]
        self._blocks().append(("table", (rows, cols, caption)))

    # -- output ----------------------------------------------------------------------------------
    @property
    def figures(self) -> dict[str, bytes]:
        """PNG bytes of every figure, keyed by file name."""
        return {k: f.png for k, f in self._figures.items()}

    def _render_block(self, kind: str, payload: Any) -> str:
        esc = html.escape
        if kind == "p":
            return f"<p>{esc(payload)}</p>"
        if kind == "note":
            return f'<p class="note">{esc(payload)}</p>'
        if kind == "h3":
            return f"<h3>{esc(payload)}</h3>"
        if kind == "pre":
            return f"<pre>{esc(payload)}</pre>"
        if kind == "fig":
            f = self._figures[payload]
            b64 = base64.b64encode(f.png).decode("ascii")
            cap = f"<figcaption>{esc(f.caption)} ({esc(f.name)})</figcaption>" if f.caption else ""
            alt = esc(f.caption or f.name)
            return f'<figure><img alt="{alt}" src="data:image/png;base64,{b64}">{cap}</figure>'
        if kind == "table":
            rows, cols, caption = payload
            return table_html(rows, cols, caption)
        raise AssertionError(kind)  # pragma: no cover

    def render_html(self) -> str:
        """The whole report as one HTML string."""
        esc = html.escape
        stamp = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
        parts = [
            "<!DOCTYPE html>",
            '<html lang="en"><head><meta charset="utf-8">',
            f"<title>{esc(self.title)}</title><style>{CSS}</style></head><body>",
            f"<h1>{esc(self.title)}</h1>",
            f"<p><small>contactlab {esc(__version__)} · generated {stamp}</small></p>",
        ]
        if self.intro:
            parts.append(f"<p>{esc(self.intro)}</p>")
        parts.extend(self._render_block(k, p) for k, p in self._preamble)
        if self._sections:
            items = "".join(
                f'<li><a href="#{s.anchor}">{esc(s.title)}</a></li>' for s in self._sections
            )
            parts.append(f"<nav><h2>Contents</h2><ul>{items}</ul></nav>")
        for s in self._sections:
            parts.append(f'<h2 id="{s.anchor}">{esc(s.title)}</h2>')
            parts.extend(self._render_block(k, p) for k, p in s.blocks)
        parts.append("</body></html>\n")
        return "\n".join(parts)

    def files(
        self, html_name: str = "report.html", figure_dir: str = "figures"
    ) -> dict[str, bytes]:
        """Every output of the report: the HTML and one PNG per figure."""
        if not html_name.endswith((".html", ".htm")):
            raise InputError(f"report file name {html_name!r} must end in .html")
        out = {html_name: self.render_html().encode("utf-8")}
        for name, png in self.figures.items():
            out[f"{figure_dir}/{name}"] = png
        return out

    def write(
        self,
        directory: str | os.PathLike[str],
        extra: Mapping[str, bytes] | None = None,
        html_name: str = "report.html",
    ) -> list[Path]:
        """Write the report and ``extra`` files (e.g. tables) into ``directory``, all or nothing."""
        files = self.files(html_name)
        if extra:
            files.update(extra)
        return commit_outputs(directory, files)
