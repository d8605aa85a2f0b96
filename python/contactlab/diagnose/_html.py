"""Self-contained HTML page of a diagnosis: findings, gap table, figures (embedded PNG) and
the JSON result. Written atomically."""

from __future__ import annotations

import base64
import html
import io
from pathlib import Path
from typing import Any

from .._io_atomic import write_text


def _png(fig: Any) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    return base64.b64encode(buf.getvalue()).decode("ascii")


def render(report: Any) -> str:
    """The HTML text of ``report`` (figures drawn with the Agg backend)."""
    from matplotlib.figure import Figure

    figs = []
    for title, fn in (
        ("Loops before and after", report.plot_overlay),
        ("Held-out residual before and after", report.plot_residual),
        ("Where the residual lives", report.plot_location),
        ("Gap shrink", report.plot_gap),
    ):
        fig = Figure(figsize=(7.0, 4.4), layout="constrained")
        fn(ax=fig.add_subplot())
        figs.append((title, _png(fig)))
    e = html.escape
    rows = "".join(
        f"<tr><td>{e(s.added or 'base model')}</td><td>{s.heldout_rms:.4g}</td>"
        f"<td>{s.heldout_rms / report.noise_rms:.2f}</td><td>{s.heldout_peak:.4g}</td>"
        f"<td>{100 * s.energy_error:.2f} %</td></tr>"
        for s in report.steps
    )
    cand = ""
    for i, s in enumerate(report.steps):
        if not s.candidates:
            continue
        cand += f"<h3>Candidates tried after step {i} ({e(s.added or 'base model')})</h3><table>"
        cand += "<tr><th>candidate</th><th>held-out RMS</th><th>gain / σ²</th><th>t</th>"
        cand += "<th>ΔBIC</th><th>verdict</th></tr>"
        for v in s.candidates:
            cand += (
                f"<tr><td>{e(v.name)}</td><td>{v.heldout_rms:.4g}</td><td>{v.gain:.3g}</td>"
                f"<td>{v.t_stat:.2f}</td><td>{v.delta_bic:+.1f}</td><td>{e(v.reason)}</td></tr>"
            )
        cand += "</table>"
    effects = (
        "".join(
            f"<li><b>{e(x.name)}</b>: "
            + ", ".join(
                f"{e(k)} = {v:.5g} ± {x.stderr.get(k, float('nan')):.2g}"
                for k, v in x.parameters.items()
            )
            + "</li>"
            for x in report.effects
        )
        or "<li>none — no candidate improves the held-out error significantly</li>"
    )
    imgs = "".join(
        f'<figure><img alt="{e(t)}" src="data:image/png;base64,{b}"><figcaption>{e(t)}'
        "</figcaption></figure>"
        for t, b in figs
    )
    where = "".join(f"<li>{e(w)}</li>" for w in report.where)
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>contactlab diagnose</title>
<style>body{{font-family:sans-serif;max-width:60em;margin:2em auto}}
table{{border-collapse:collapse}}td,th{{border:1px solid #bbb;padding:2px 8px}}
img{{max-width:100%}}pre{{background:#f4f4f4;padding:1em;overflow:auto}}</style></head><body>
<h1>Model discrepancy: {e(report.model)} contact</h1>
<h2>Where the base model disagrees</h2><ul>{where}</ul>
<h2>Effects added</h2><ul>{effects}</ul>
<h2>Gap shrink (held-out cycles)</h2>
<table><tr><th>step</th><th>held-out RMS</th><th>/ noise</th><th>peak error</th>
<th>loop-energy error</th></tr>{rows}</table>
<p>Noise RMS estimated from the data: {report.noise_rms:.4g}</p>
{imgs}
{cand}
<h2>Result (JSON)</h2><pre>{e(report.to_json())}</pre>
</body></html>
"""


def write_html(report: Any, directory: str | Path) -> Path:
    """Write ``diagnose.html`` into ``directory`` (created if needed); return its path."""
    path = Path(directory) / "diagnose.html"
    write_text(path, render(report))
    return path
