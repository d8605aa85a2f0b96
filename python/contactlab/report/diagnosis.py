"""HTML report of a diagnosis, built with :class:`contactlab.report.Report`: findings,
effects with their parameters, the gap-shrink table, before/after figures, the verdict on
every candidate and the JSON result. Written all or nothing (HTML, PNGs and the JSON)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from .._html import Column, Report
from . import diagnosis_plots

FIGURES = (
    ("loops", "Loops: measurement, base model and final model", "plot_overlay"),
    ("residual", "Held-out residual before and after (dashed: ± noise RMS)", "plot_residual"),
    ("location", "Where the base model's residual lives within the branches", "plot_location"),
    ("gap", "Gap shrink: held-out RMS over the noise level after each step", "plot_gap"),
)


def build(report: Any, intro: str | None = None) -> Report:
    """The :class:`~contactlab.report.Report` of ``report`` (figures drawn off-screen);
    ``intro`` (the "Made by" line of a command-line run) heads it."""
    from matplotlib.figure import Figure

    lead = (
        "Where the base model and the measurement disagree, which candidate effects explain "
        "it (chosen by their error on held-out cycles) and how much the gap shrinks."
    )
    r = Report(
        f"Model discrepancy: {report.model} contact", f"{intro}\n\n{lead}" if intro else lead
    )
    r.section("Where the base model disagrees")
    for w in report.where:
        r.text(w, note=w.startswith("after "))
    r.section("Effects added")
    if report.effects:
        rows = [
            {"effect": e.name, "parameter": k, "value": v, "stderr": e.stderr.get(k)}
            for e in report.effects
            for k, v in e.parameters.items()
        ]
        r.table(rows, ["effect", "parameter", Column("value", stderr="stderr")])
        for e in report.effects:  # the physical argument for each (issue 29)
            if getattr(e, "plausibility", ""):
                r.text(f"{e.name}: {e.plausibility}")
    else:
        r.text("None: no candidate improves the held-out error significantly.")
    r.section("Gap shrink (held-out cycles)")
    rows = [
        {
            "step": s.label,
            "heldout_rms": s.heldout_rms,
            "over_noise": s.heldout_rms / report.noise_rms,
            "heldout_peak": s.heldout_peak,
            "energy_error": 100 * s.energy_error,
        }
        for s in report.steps
    ]
    r.table(
        rows,
        [
            "step",
            Column("heldout_rms", "held-out RMS"),
            Column("over_noise", "/ noise RMS"),
            Column("heldout_peak", "peak error"),
            Column("energy_error", "loop-energy error", unit="%"),
        ],
    )
    r.text(report.noise_text()[0].upper() + report.noise_text()[1:])
    for name, caption, method in FIGURES:
        fig = Figure(figsize=(7.0, 4.4), layout="constrained")
        getattr(diagnosis_plots, method)(report, ax=fig.add_subplot())
        r.figure(fig, name, caption, dpi=110)
    r.section("Candidates tried")
    for i, s in enumerate(report.steps):
        if s.candidates:
            r.subheading(f"after step {i} ({s.label})")
            r.table(
                [v.to_dict() for v in s.candidates],
                [
                    "name",
                    Column("heldout_rms", "held-out RMS"),
                    Column("gain_over_noise_var", "gain / σ²"),
                    Column("t_stat", "t"),
                    Column("delta_bic", "ΔBIC"),
                    "reason",
                ],
            )
    r.section("Result (JSON)")
    r.preformatted(report.to_json())
    return r


def report_files(report: Any, intro: str | None = None) -> dict[str, bytes]:
    """Every file of the report, rendered in memory (relative name → content):
    ``diagnose.html`` first, its figures under ``figures/`` and ``diagnose.json``."""
    files = build(report, intro).files("diagnose.html")
    files["diagnose.json"] = (report.to_json() + "\n").encode("utf-8")
    return files


def write_html(report: Any, directory: str | Path) -> Path:
    """Write ``diagnose.html``, its figures and ``diagnose.json`` into ``directory``, all or
    nothing."""
    from .._outputs import commit_outputs

    return commit_outputs(directory, report_files(report))[0]
