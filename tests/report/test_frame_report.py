"""Issue 31: the report of a measured friction frame (``analyze --frame ... --report``).

The loop plot's title and the curve it draws give the same h0 (where h0 comes from the plateau
and the exponential fit identifies neither h0 nor ac, the plateau levels are drawn, not the
fit); the residual panel's title states the RMS of exactly the residuals it plots (not √redchi
of a weighted fit); no "nan" and no absurd standard error in the HTML or the console text.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

from contactlab.cli import main
from contactlab.errors import ContactLabWarning
from contactlab.report.tangential import plot_loop, plot_residuals
from contactlab.tangential import analyze_tangential, read_frame

DATA = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "friction_frame"
FRAME = "3.0799,0.669,1191"  # the data set's README (kg, N s/m, N/m)


@pytest.fixture(scope="module")
def frame250() -> Path:
    path = DATA / "frame_disc250g.csv"
    if not path.is_file():
        pytest.skip("../shared/data absent: the measured frames are not here")
    return path


@pytest.fixture(scope="module")
def analysis(frame250):
    rec = read_frame(frame250, 3.0799, 0.669, 1191.0).recording(frame250)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ContactLabWarning)
        return analyze_tangential(rec)


def _numbers(text: str) -> list[float]:
    return [float(v) for v in re.findall(r"[-+]?\d+\.\d+(?:e[-+]?\d+)?", text)]


def test_loop_title_and_curve_agree(analysis):
    a = analysis
    assert a.identifiability["h0_source"] == "plateau" and not a.identifiable
    h0, _ = a.derived["h0_plateau"]
    fit_h0 = a.fit.params["h0"].value
    assert abs(fit_h0 / h0 - 1) > 0.1  # the case of the issue: the fit's h0 is another number
    ax = plot_loop(a)
    title = ax.get_title()
    assert "plateau" in title
    assert _numbers(title)[0] == pytest.approx(h0, rel=1e-3)
    # the curve drawn: the two plateau levels, h0 apart from their mid-point
    drawn = [c for c in ax.collections if "plateau" in str(c.get_label())]
    assert len(drawn) == 1, "the plateau levels are not drawn"
    levels = sorted(float(seg[0][1]) for seg in drawn[0].get_segments())
    assert len(levels) == 2
    assert 0.5 * (levels[1] - levels[0]) == pytest.approx(h0, rel=1e-9)
    # no line draws the fit's curve (its asymptote h0 is not the title's)
    for line in ax.get_lines():
        assert "fit" not in str(line.get_label()).lower()


def _rms_in_title(title: str) -> float:
    m = re.search(r"RMS = ([-+0-9.e]+) N, (\d+) points", title)
    assert m, title
    return float(m.group(1)), int(m.group(2))


def test_residual_title_is_the_rms_plotted(analysis):
    ax = plot_residuals(analysis)
    y = np.asarray(ax.get_lines()[0].get_ydata(), dtype=float)
    rms, n = _rms_in_title(ax.get_title())
    assert n == y.size
    assert rms == pytest.approx(np.sqrt(np.mean(y * y)), rel=2e-3)
    # the figure: √redchi of the weighted fit (0.854 N) is not what is plotted
    assert abs(rms - np.sqrt(analysis.fit.redchi)) > 0.1 * rms


def test_residual_title_of_a_fitted_loop_is_its_rms(analysis):
    # where the fit's curve is drawn, the residuals and their RMS are of that fit
    a = analysis
    a2 = type(a)(**{**a.__dict__, "identifiability": dict(a.identifiability, h0_source="fit")})
    ax = plot_residuals(a2)
    y = np.asarray(ax.get_lines()[0].get_ydata(), dtype=float)
    assert np.allclose(y, a.residual)
    rms, n = _rms_in_title(ax.get_title())
    assert rms == pytest.approx(np.sqrt(np.mean(a.residual**2)), rel=2e-3) and n == y.size


def _visible_text(html: str) -> str:
    html = re.sub(r'src="data:image/png;base64,[^"]*"', "", html)
    return re.sub(r"<[^>]+>", " ", html)


def test_no_nan_or_absurd_error_in_report_and_console(frame250, tmp_path, capsys):
    out = tmp_path / "rep"
    assert main(["analyze", "--frame", FRAME, str(frame250), "--report", str(out), "-v"]) == 0
    said = capsys.readouterr()
    text = said.out + said.err + _visible_text((out / "report.html").read_text())
    assert not re.search(r"\bnan\b", text, re.IGNORECASE), "a nan in the text"
    assert "± —" not in text and "+/- —" not in text
    # the channel delay's error (47 s on a 1 s period) is written as not identifiable
    delay = [ln for ln in text.splitlines() if "channel_delay =" in ln]
    assert delay and all("not identifiable" in ln for ln in delay)
    for m in re.finditer(r"([-+]?\d[\d.e+-]*) \+/- ([\d.e+-]+)", text):
        v, e = float(m.group(1)), float(m.group(2))
        assert e < 1e3 * max(abs(v), 1e-300), m.group(0)


def test_identified_fit_off_the_plateau_draws_both(analysis):
    # an identified exponential fit whose asymptote is off the plateau (the micro-tribometer:
    # fit 2.606 N, plateau 2.32 N): the curve is drawn with its own h0 in the legend, the
    # plateau levels beside it, and the title names both
    a = type(analysis)(**{**analysis.__dict__, "identifiable": True})
    ax = plot_loop(a)
    fit_h0 = a.fit.params["h0"].value
    h0 = a.derived["h0_plateau"][0]
    labels = [str(line.get_label()) for line in ax.get_lines()]
    assert any(lab.startswith("Masing fit (its h0 = ") for lab in labels), labels
    assert f"{fit_h0:.4g}" in ax.get_title() and f"{h0:.4g}" in ax.get_title()
    assert any("plateau" in str(c.get_label()) for c in ax.collections)
