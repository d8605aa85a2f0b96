"""Issue 31: the demo report's summary table scrolled sideways at 1400 px, hiding the columns
after "E numeric". A table fits its page when its min-content width (every cell wrapped at
every place the CSS allows) is within the page's content width: the browser's automatic
table layout then shrinks it to the page. The width is measured here with matplotlib's font
metrics (DejaVu Sans, wider than the system fonts the report asks for) on the demo's rows.
"""

from __future__ import annotations

import re
from html.parser import HTMLParser

import pytest
from matplotlib.backends.backend_agg import RendererAgg
from matplotlib.font_manager import FontProperties

from contactlab.report import CSS, NBSP, Report, table_html
from contactlab.studies.columns import NORMAL_COLUMNS, TANGENTIAL_COLUMNS

#: body{max-width:1100px}: the content width of the page at a 1400 px window
PAGE = 1100.0
FONT_PX = 16 * float(re.search(r"table\{[^}]*font-size:([.\d]+)em", CSS).group(1))
#: th,td{padding:V Hem}: twice H, and a 1 px border
PAD_PX = (
    2 * float(re.search(r"th,td\{[^}]*padding:[.\d]+em ([.\d]+)em", CSS).group(1)) * FONT_PX + 1
)

# the demo's rows (contactlab demo --quick; SI as in study_*.csv)
TANGENTIAL = [
    {"file": "Al-Al_W50N_A5um.csv", "material": "Al/Al", "normal_load": 50.0, "true_h0": 21.0,
     "true_ac": 75595.3, "h0": 21.0256, "h0_stderr": 0.0909, "ac": 75519.0, "ac_stderr": 388.6,
     "amplitude": 4.99871e-06, "h0_ac": 1587830.5, "h0_ac_stderr": 1479.05,
     "energy_per_cycle": 8.29694e-06, "energy_per_cycle_stderr": 3.926e-08,
     "equivalent_damping": 105694.3, "equivalent_damping_stderr": 516.0,
     "k_global": 1322534.9, "k_global_stderr": 507.78, "k_local0": 1587830.5,
     "k_local0_stderr": 1479.05, "energy_per_cycle_numeric": 8.29352e-06,
     "energy_per_cycle_numeric_stderr": 3.759e-08, "identifiable": True},
    {"file": "steel-steel_W75N_A0.25um.h5", "material": "steel/steel", "normal_load": 75.0,
     "true_h0": 13.5, "true_ac": 50000.0, "amplitude": 2.49416e-07, "h0_ac": 696683.8,
     "h0_ac_stderr": 8497.9, "energy_per_cycle": 2.13699e-09,
     "energy_per_cycle_stderr": 6.315e-10, "equivalent_damping": 10934.6,
     "equivalent_damping_stderr": 3232.9, "k_global": 670587.3, "k_global_stderr": 3280.6,
     "k_local0": 696683.8, "k_local0_stderr": 8497.9, "energy_per_cycle_numeric": 2.30347e-09,
     "energy_per_cycle_numeric_stderr": 9.689e-10, "identifiable": False},
]  # fmt: skip
NORMAL = [
    {"file": "C45-C45_p0-0.5MPa_pa-0.4MPa.csv", "material": "C45/C45", "p0": 500025.6,
     "pa": 400033.0, "E_d": 0.015069, "E_pu": 0.038624, "E_pd": 0.090991, "psi": 0.23252,
     "psi_kv": 0.39015, "k_tan": 1324257765183.6, "k_sec": 1264011287574.2,
     "delta_max": 2.17126e-07, "delta_min": -4.15832e-07, "b1_paper": -0.536404,
     "b2_paper": 0.521828, "b3_paper": 1.178871, "b4_paper": 1.325818},
]  # fmt: skip

WBR = "\x00"  # a <wbr> in a cell's text: a place to wrap
_RENDERER = RendererAgg(1, 1, 72)  # at 72 dpi a font size in points is one in pixels


def _width(text: str, bold: bool) -> float:
    prop = FontProperties(family="DejaVu Sans", size=FONT_PX, weight="bold" if bold else "normal")
    return _RENDERER.get_text_width_height_descent(text, prop, ismath=False)[0]


def _rule(selector: str) -> str:
    """The declarations of every CSS rule whose selector list names ``selector``."""
    out = []
    for sel, body in re.findall(r"([^{}]+)\{([^}]*)\}", CSS):
        if selector in [s.strip() for s in sel.split(",")]:
            out.append(body)
    return ";".join(out)


def _pieces(text: str, tag: str, cls: str) -> list[str]:
    """What a cell cannot break inside, as its CSS allows (later rules win)."""
    css = _rule(tag) + ";" + (_rule(f"{tag}.{cls}") if cls else "")
    nowrap = re.findall(r"white-space:(\w+)", css)
    wraps = re.findall(r"overflow-wrap:(\w[\w-]*)", css)
    if nowrap and nowrap[-1] == "nowrap":
        return [text.replace(WBR, "")]
    if wraps and wraps[-1] == "anywhere":
        return list(text.replace(WBR, ""))
    return [p for p in re.split(rf"[ \t\n{WBR}]+", text) if p]  # a no-break space holds


class _Table(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.rows: list[list[tuple[str, str, str]]] = []
        self._cell: list | None = None

    def handle_starttag(self, tag, attrs):
        if tag == "tr":
            self.rows.append([])
        elif tag in ("td", "th"):
            self._cell = [tag, dict(attrs).get("class") or "", ""]
        elif tag == "wbr" and self._cell is not None:
            self._cell[2] += WBR

    def handle_startendtag(self, tag, attrs):
        self.handle_starttag(tag, attrs)

    def handle_data(self, data):
        if self._cell is not None:
            self._cell[2] += data

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self._cell is not None:
            self.rows[-1].append(tuple(self._cell))
            self._cell = None


def min_content_width(html: str) -> float:
    """The table's min-content width in px: per column the widest piece no rule lets wrap."""
    p = _Table()
    p.feed(html)
    widths: dict[int, float] = {}
    for row in p.rows:
        for i, (tag, cls, text) in enumerate(row):
            w = max((_width(s, tag == "th") for s in _pieces(text, tag, cls)), default=0.0)
            widths[i] = max(widths.get(i, 0.0), w)
    return sum(w + PAD_PX for w in widths.values()) + 1


@pytest.mark.parametrize("rows,columns", [(TANGENTIAL, TANGENTIAL_COLUMNS),
                                          (NORMAL, NORMAL_COLUMNS)])  # fmt: skip
def test_demo_summary_tables_fit_a_1400px_window(rows, columns):
    html = table_html(rows, [c for c in columns if any(c.key in r for r in rows)])
    assert html.count("<th>") >= 15  # every column kept
    width = min_content_width(html)
    assert width <= PAGE, f"the table needs {width:.0f} px, the page has {PAGE:.0f}"


def test_measurement_wraps_before_the_plus_minus_only():
    html = table_html([{"h0": 21.0256, "h0_stderr": 0.0909}], TANGENTIAL_COLUMNS[4:5])
    assert f"21.026 ±{NBSP}0.091" in html
    cell = re.search(r"<td>([^<]*)</td>", html).group(1)
    assert _pieces(cell, "td", "") == ["21.026", f"±{NBSP}0.091"]


def test_page_css_keeps_a_scroll_fallback():
    # a table that still cannot fit (a hundred columns) scrolls inside its box, not the page
    assert "overflow-x:auto" in _rule(".tablewrap")
    r = Report("t")
    r.table(TANGENTIAL, TANGENTIAL_COLUMNS)
    assert '<div class="tablewrap"><table>' in r.render_html()
