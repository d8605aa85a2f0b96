"""The report of ``contactlab fit-joint``: each fitted law's parameters with their errors,
the score table on the fitted and the held-out records, and for every record the measured
and predicted loops overlaid and their time traces."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from .html import Column, Report

#: score columns of the comparison table
_SCORE_COLUMNS = [
    Column("model"),
    Column("record"),
    Column("role"),
    Column("snr_db", "SNR", "dB"),
    Column("nrmse", "NRMSE"),
    Column("rrse", "RRSE"),
    Column("trac", "TRAC"),
    Column("energy_error", "energy/cycle error"),
    Column("n_cycles", "cycles"),
]

_PARAM_COLUMNS = [
    Column("name"),
    Column("value", stderr="stderr"),
    Column("unit"),
    Column("note"),
]


def _loop_figure(rec: Any, predictions: Mapping[str, np.ndarray]) -> Any:
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10.5, 3.8))
    ax1.plot(rec.x * 1e3, rec.F, color="0.2", lw=1.2, label="measured")
    ax2.plot(rec.t, rec.F, color="0.2", lw=1.2, label="measured")
    for name, P in predictions.items():
        ax1.plot(rec.x * 1e3, P, lw=0.9, label=name)
        ax2.plot(rec.t, P, lw=0.9, label=name)
    ax1.set_xlabel("displacement x [mm]")
    ax1.set_ylabel("force F [N]")
    ax1.set_title("loops")
    ax2.set_xlabel("time t [s]")
    ax2.set_ylabel("force F [N]")
    ax2.set_title("time traces")
    if rec.mask is not None:
        # shade the samples not scored
        off = ~rec.mask
        if off.any():
            lo, hi = np.min(rec.F), np.max(rec.F)
            ax2.fill_between(rec.t, lo, hi, where=off, color="0.9", step="mid", label="not scored")
    ax1.legend(fontsize=7, loc="best")
    fig.tight_layout()
    return fig


def build_joint_report(
    fits: Sequence[Any],
    table: Any,
    records: Sequence[Any],
    roles: Mapping[str, str],
    title: str,
    *,
    intro: str | None = None,
    max_points: int = 20000,
) -> Report:
    """Assemble the report (figures rendered now); write it with ``Report.files()``.

    ``fits``: fitted joints (:class:`contactlab.joints.JointFit`); ``table``: their
    :class:`contactlab.joints.Comparison` on ``records``; ``roles``: record name -> "fitted"
    or "held out".
    """
    rep = Report(title, intro)
    rep.section("Scores")
    rows = []
    for r in table.to_dict()["rows"]:
        rows.append(dict(r, role=roles.get(r["record"], "all")))
    rep.table(
        rows,
        _SCORE_COLUMNS,
        "SNR = 10 log10(ΣF²/Σ(F−F̂)²); NRMSE = RMSE/(max F − min F); RRSE = "
        "√(Σ(F−F̂)²/Σ(F−F̄)²); TRAC = (ΣFF̂)²/(ΣF²ΣF̂²); energy/cycle error = "
        "(ΣÊ−ΣE)/ΣE over whole cycles",
    )
    for f in fits:
        rep.section(f"Law {f.name}")
        rep.text(
            f"{f.law!r} fitted to {', '.join(f.records)} ({f.n_samples} samples, "
            f"{f.seconds:.2f} s); {'converged' if f.success else 'NOT converged'}: "
            f"{f.message}"
        )
        prow = []
        for n, p in f.params.items():
            prow.append(
                {
                    "name": n,
                    "value": p.value,
                    "stderr": p.stderr,
                    "unit": p.unit,
                    "note": p.note if p.vary else "fixed",
                }
            )
        rep.table(prow, _PARAM_COLUMNS, "parameters ± standard error")
        notes = list(f.result.notes) + list(f.notes)
        for n in notes:
            rep.text(n, note=True)
    rep.section("Loops and time traces")
    for rec in records:
        preds = {}
        for f in fits:
            try:
                preds[f.name] = f.force(rec.t, rec.x)
            except Exception as exc:
                rep.text(f"{f.name} on {rec.name}: {exc}", note=True)
        step = max(1, rec.n // max_points)
        sub = type(rec)(
            rec.t[::step],
            rec.x[::step],
            rec.F[::step],
            rec.name,
            None if rec.mask is None else rec.mask[::step],
        )
        fig = _loop_figure(sub, {k: v[::step] for k, v in preds.items()})
        rep.figure(fig, f"loop-{rec.name}", f"{rec.name} ({roles.get(rec.name, '')})")
    return rep


__all__ = ["build_joint_report"]
