"""The report of an analysis or a study: summary tables, each recording's loop, fit and
residuals, and the study plots (:mod:`contactlab.studies.plots`).

Tangential sections show the averaged measured loop with the fitted Masing loop and the
residuals (via :func:`contactlab.tangential.plot_loop` / ``plot_residuals``) and the lmfit-style
fit report; normal sections show the measured loop p(δ) with the fitted loading, unloading and
centre polynomials of Konowalski's eq. 1.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from .._html import Column, Report
from ..studies.columns import NORMAL_COLUMNS, TANGENTIAL_COLUMNS
from ..studies.study import RecordingResult, StudyResult
from .study_plots import display_unit, normal_study_figures, tangential_study_figures, trends


def _present(columns: Sequence[Column], rows: Sequence[dict]) -> list[Column]:
    return [c for c in columns if any(c.key in r for r in rows)]


def _label(r: RecordingResult) -> str:
    t = r.entry.tags
    parts = [r.entry.name]
    if "material" in t:
        parts.append(str(t["material"]))
    if "normal_load" in t:
        parts.append(f"W = {t['normal_load']:.4g} N")
    if "amplitude_nominal" in t:
        parts.append(f"A = {t['amplitude_nominal'] * 1e6:.4g} µm")
    if "p0" in t:
        parts.append(f"p0 = {t['p0'] * 1e-6:.4g} MPa")
    if "pa" in t:
        parts.append(f"pa = {t['pa'] * 1e-6:.4g} MPa")
    return ", ".join(parts)


def _tangential_detail(rep: Report, r: RecordingResult, dpi: int) -> None:
    import matplotlib.pyplot as plt

    from .tangential import plot_loop, plot_residuals

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(9.0, 3.4), constrained_layout=True)
    plot_loop(r.analysis, ax=a1)
    plot_residuals(r.analysis, ax=a2)
    fig.suptitle(_label(r), fontsize=9)
    rep.figure(fig, f"loop-{r.entry.path.stem}", f"{_label(r)}: loop with fit, residuals", dpi=dpi)
    for w in getattr(r.analysis, "warnings", None) or []:
        rep.text(w, note=True)
    if hasattr(r.analysis, "report"):
        rep.preformatted(r.analysis.report())


def poly_eval(coeffs: Sequence[float], x: np.ndarray) -> np.ndarray:
    """Evaluate a polynomial with ascending coefficients."""
    return np.polynomial.polynomial.polyval(x, np.asarray(coeffs, dtype=float))


def plot_normal_loop(r: RecordingResult, ax: Any = None) -> Any:
    """Measured p(δ) of a normal recording, its averaged cycle and the fitted eq.-1
    polynomials (loading, centre, unloading), in the paper's units (MPa, µm)."""
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(5.0, 3.6), constrained_layout=True)
    rec, row, res = r.recording, r.row, r.analysis
    p0 = float(row.get("p0", 0.0) or 0.0)
    shift = float(row.get("delta_offset", 0.0) or 0.0)
    if rec is not None:  # None: a study run with keep_recordings=False holds no samples
        p = np.asarray(rec["p"], dtype=float)
        d = np.asarray(rec["delta"], dtype=float)
        ax.plot((d - shift) * 1e6, (p - p0) * 1e-6, color="0.75", lw=0.5, label="recorded")
    if res is not None and hasattr(res, "cycle_delta"):
        ax.plot(
            np.asarray(res.cycle_delta) * 1e6,
            np.asarray(res.cycle_p) * 1e-6,
            ".",
            color="0.2",
            ms=2,
            label="averaged cycle",
        )
    lo, hi = row.get("delta_min"), row.get("delta_max")
    if isinstance(lo, float) and isinstance(hi, float) and math.isfinite(lo + hi):
        dm = np.linspace(lo, hi, 200)  # SI: the polynomials take δ in m and give p in Pa
        for name, style in (("poly_load", "C3-"), ("poly_centre", "k--"), ("poly_unload", "C0-")):
            coeffs = [row.get(f"{name}_{i}") for i in range(5)]
            if all(isinstance(c, float) for c in coeffs):
                ax.plot(
                    dm * 1e6,
                    poly_eval(coeffs, dm) * 1e-6,
                    style,
                    lw=1.2,
                    label=name.replace("poly_", ""),
                )
    ax.set_xlabel("normal contact displacement δ [µm]")
    ax.set_ylabel("dynamic pressure p − p0 [MPa]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    return ax


def _normal_detail(rep: Report, r: RecordingResult, dpi: int) -> None:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5.2, 3.6), constrained_layout=True)
    plot_normal_loop(r, ax=ax)
    ax.set_title(_label(r), fontsize=8)
    rep.figure(
        fig, f"loop-{r.entry.path.stem}", f"{_label(r)}: loop and eq.-1 polynomials", dpi=dpi
    )


_TRENDS_CAPTION = (
    "Trends: a series (one amplitude, or one load) counts as rising or falling only when every "
    "step does; others are not counted"
)


def _provenance(rep: Report, result: StudyResult) -> None:
    rows = [r.row for r in result.results if r.ok]
    if not rows:
        return
    rep.section("Data read")
    cols = [
        Column("file"),
        Column("kind"),
        Column("format"),
        Column("n_samples", "samples"),
        Column("fs", "fs", "Hz"),
        Column("units_assumed_si", "columns without units (SI assumed)"),
    ]
    rep.table(rows, cols)
    assumed = [r["file"] for r in rows if r.get("units_assumed_si")]
    if assumed:
        rep.text(
            f"{len(assumed)} file(s) have columns without units, read as SI: " + ", ".join(assumed),
            note=True,
        )


def _render_part(job: tuple) -> list[tuple[str, Any]]:
    """One part of a report rendered alone (in this process or a pool's worker): a
    recording's section, or every ``nparts``-th figure of the study plots. Returns the part's
    blocks (:meth:`Report.blocks`, figures as PNG bytes)."""
    import matplotlib

    if job[0] == "detail":
        _, kind, r, dpi = job
        matplotlib.use("Agg")  # a pool's worker draws off screen
        sub = Report("")
        sub.subheading(_label(r))
        (_tangential_detail if kind == "tangential" else _normal_detail)(sub, r, dpi)
        return sub.blocks()
    _, kind, rows, units, part, nparts, dpi = job
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sub = Report("")
    if kind == "tangential":  # only this part's figures are drawn: k, k + n, ...
        figs = tangential_study_figures(rows, units, part=(part, nparts))
        places = range(part, part + nparts * len(figs), nparts)
    else:  # two figures: made whole, each part renders its own
        figs = normal_study_figures(rows, units)
        places = range(len(figs))
    for i, (name, fig, cap) in zip(places, figs, strict=True):
        if i % nparts == part:
            sub.figure(fig, name, cap, dpi=dpi)
            sub.text(str(i))  # its place among all parts' figures
        else:
            plt.close(fig)
    return sub.blocks()


def _process_pool(executor: Any) -> bool:
    """Figures are drawn on ``executor`` only when it is a process pool: pyplot is not
    thread-safe, and drawing holds the GIL, so threads would gain nothing."""
    from concurrent.futures import ProcessPoolExecutor

    return isinstance(executor, ProcessPoolExecutor)


def build_report(
    result: StudyResult,
    title: str = "contactlab report",
    *,
    study_plots: bool = True,
    details: bool = True,
    dpi: int = 90,
    intro: str | None = None,
    progress: bool | None = False,
    executor: Any = None,
) -> Report:
    """Assemble the report of analysed recordings (and the study plots when asked).

    Rendering the figures is the slow part of a large study (0.6 s a recording on one core):
    with a ``concurrent.futures.ProcessPoolExecutor`` as ``executor`` the recordings' sections
    and the study plots are drawn on its workers, in bounded batches
    (:func:`contactlab.studies.ordered_map`); the report is the serial one, figure for figure
    (other executors: drawn here). ``progress`` shows a bar for the recordings' sections
    (``tqdm.auto``; None: only on a terminal).
    """
    from tqdm.auto import tqdm

    from ..studies.executor import n_workers, ordered_map

    pool = executor if _process_pool(executor) else None
    nparts = n_workers(pool) if pool is not None else 1
    rep = Report(title, intro)
    plan: list[tuple[str, Any]] = []  # (kind, rows) in report order
    jobs: list[tuple] = []
    for kind in ("tangential", "normal"):
        rows = result.table(kind)
        if not rows:
            continue
        units = result.units(kind)
        plan.append((kind, rows))
        if study_plots and len(rows) > 1:
            jobs.extend(("study", kind, rows, units, k, nparts, dpi) for k in range(nparts))
        if details:
            for r in result.of_kind(kind):
                if r.ok:
                    if pool is not None and kind == "tangential":  # its figure needs no samples
                        r = dataclasses.replace(r, recording=None)
                    jobs.append(("detail", kind, r, dpi))
    parts = ordered_map(_render_part, jobs, pool)
    try:
        for kind, rows in plan:
            cols = _present(TANGENTIAL_COLUMNS if kind == "tangential" else NORMAL_COLUMNS, rows)
            rep.section(f"{kind.capitalize()} recordings: summary")
            rep.table(
                rows,
                cols,
                caption="Fitted parameters (± 1 standard error); full table "
                f"with every column in SI: study_{kind}.csv / .parquet",
            )
            warned = [r.entry.name for r in result.of_kind(kind) if r.ok and r.row.get("warnings")]
            if warned:
                rep.text(
                    f"{len(warned)} recording(s) with warnings (see their sections below): "
                    + ", ".join(warned),
                    note=True,
                )
            if study_plots and len(rows) > 1:
                figs: list[tuple[int, tuple[str, Any]]] = []
                for _ in range(nparts):
                    blocks = next(parts)
                    for fig, place in zip(blocks[::2], blocks[1::2], strict=True):
                        figs.append((int(place[1]), fig))
                if figs:
                    rep.section(f"{kind.capitalize()} study plots")
                    if kind == "tangential":
                        cols_t = [
                            "material",
                            "quantity",
                            Column("with_load", "against normal load"),
                            Column("with_amplitude", "against amplitude"),
                        ]
                        rep.table(trends(rows), cols_t, caption=_TRENDS_CAPTION)
                    rep.extend(fig for _, fig in sorted(figs, key=lambda f: f[0]))
            if details:
                rep.section(f"{kind.capitalize()} recordings: loops, fits and residuals")
                n = sum(r.ok for r in result.of_kind(kind))
                bar = tqdm(
                    range(n),
                    desc=f"report ({kind})",
                    unit="fig",
                    disable=None if progress is None else not progress,
                )
                for _ in bar:
                    rep.extend(next(parts))
    finally:
        parts.close()  # cancels what is queued (an error, Ctrl-C)
    _provenance(rep, result)
    if result.failures:
        rep.section("Recordings that could not be analysed")
        for r in result.failures:
            rep.text(str(r.error), note=True)
    return rep


__all__ = [
    "NORMAL_COLUMNS",
    "TANGENTIAL_COLUMNS",
    "build_report",
    "display_unit",
    "plot_normal_loop",
    "poly_eval",
]
