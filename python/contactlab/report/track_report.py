"""The report of :func:`contactlab.studies.track`: the pooled result, every tracked quantity
against time (or cycle count) with its standard error, the per-cycle energy of the whole
record, and the window table."""

from __future__ import annotations

from typing import Any

from .._html import Column, Report
from ..studies.tracking import CYCLE_UNITS, TrackResult
from .track_plots import LABELS, track_figures

#: display (label, unit, scale) of the tracked quantities' SI units
_DISPLAY = {
    "N": ("N", 1.0),
    "1/m": ("1/mm", 1e-3),
    "N/m": ("N/µm", 1e-6),
    "J": ("µJ", 1e6),
    "m": ("µm", 1e6),
    "J/m^2": ("J/m²", 1.0),
    "Pa/m": ("MPa/µm", 1e-12),
    "Pa": ("MPa", 1e-6),
}


def _columns(result: TrackResult, with_time: bool = True) -> list[Column]:
    cols = []
    if with_time:
        cols += [Column("window"), Column("t_mid", "t", "s"), Column("cycle_end", "cycles")]
    for q in result.quantities:
        unit, scale = _DISPLAY.get(result.units.get(q, ""), (result.units.get(q, ""), 1.0))
        has_err = any(r.get(f"{q}_stderr") is not None for r in result.rows)
        cols.append(
            Column(q, LABELS.get(q, q), unit, scale, stderr=f"{q}_stderr" if has_err else None)
        )
    return cols


def build_track_report(
    result: TrackResult, title: str, *, against: str = "time", intro: str | None = None
) -> Report:
    """Assemble the report (figures rendered now); write it with ``Report.files()``."""
    rep = Report(title, intro)
    n_cyc = int(result.cycles["energy"].size)
    rep.section("Summary")
    rep.text(
        f"{result.source}: {result.kind} recording, {result.meta.get('n_samples')} samples, "
        f"{n_cyc} complete cycles, {len(result.rows)} windows of {result.every} "
        f"(read in chunks of {result.meta.get('chunk_size')} samples)."
    )
    comb = result.combined()
    rep.table(
        [comb],
        _columns(result, with_time=False),
        "all windows pooled (weighted by window size; error widened by the Birge ratio)",
    )
    for msg in result.notes(comb):  # failed windows, the windows' warnings, scatter
        rep.text(msg, note=True)
    rep.section(f"Quantities against {against}")
    for name, fig in track_figures(result, against=against):
        cap = (
            f"{LABELS.get(name, name)} per window, ±1 standard error"
            if name != "cycle_energy"
            else f"loop energy of every cycle [{CYCLE_UNITS[result.kind]['energy']}]"
        )
        rep.figure(fig, name, cap)
    rep.section("Windows")
    rep.table(result.rows, _columns(result), "one row per window (SI values in the CSV/JSON)")
    return rep


def track_files(result: TrackResult, rep: Report) -> dict[str, Any]:
    """Everything the ``--report`` folder receives: HTML, figures, window and cycle tables."""
    files = rep.files()
    files["track_windows.csv"] = result.to_csv().encode("utf-8")
    files["track_cycles.csv"] = result.cycles_csv().encode("utf-8")
    return files


__all__ = ["build_track_report", "track_files"]
