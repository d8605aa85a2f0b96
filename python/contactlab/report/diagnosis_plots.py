"""Figures of a diagnosis: loops before/after, residual before/after, where the residual
lives, and the gap shrink. Each takes ``ax=`` and returns the axes; none calls ``show()``."""

from __future__ import annotations

from typing import Any

import numpy as np


def _axes(ax: Any, ncols: int = 1) -> Any:
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    _, axs = plt.subplots(1, ncols, figsize=(6.4 * ncols, 4.4), constrained_layout=True)
    return axs


def _labels(report: Any) -> tuple[str, str, float, float]:
    if report.model == "tangential":
        return "x [µm]", "F [N]", 1e6, 1.0
    return "δ [µm]", "p [MPa]", 1e6, 1e-6


def plot_overlay(report: Any, step: int | None = None, ax: Any = None) -> Any:
    """Measured loops with the base model and the model after ``step`` (default: final)."""
    ax = _axes(ax)
    d = report.prepared
    trials = report.trials
    fin = trials[-1 if step is None else step]
    xl, yl, sx, sy = _labels(report)
    if report.model == "tangential":
        X, Y0, Y1, Ym = d.u, trials[0].fitted, fin.fitted, d.y
    else:  # loops p(δ): input p on the vertical axis
        X, Y0, Y1, Ym = d.y, None, None, d.u
    if Y0 is not None:
        ax.plot(X * sx, Ym * sy, ".", ms=1.5, color="0.6", label="measured")
        ax.plot(X * sx, Y0 * sy, lw=0.9, color="C3", label="base model")
        name = "final model" if step is None else f"after step {step}"
        ax.plot(X * sx, Y1 * sy, lw=0.9, color="C0", label=name)
    else:
        ax.plot(X * sx, Ym * sy, ".", ms=1.5, color="0.6", label="measured")
        ax.plot(trials[0].fitted * sx, Ym * sy, lw=0.9, color="C3", label="base model")
        ax.plot(fin.fitted * sx, Ym * sy, lw=0.9, color="C0", label="final model")
    ax.set_xlabel(xl)
    ax.set_ylabel(yl)
    ax.legend(loc="best", fontsize="small")
    ax.set_title("loops: measurement, base and final model")
    return ax


def plot_residual(report: Any, ax: Any = None) -> Any:
    """Held-out residual (measured minus model) against time, base and final model."""
    ax = _axes(ax)
    d = report.prepared
    t0, t1 = report.trials[0], report.trials[-1]
    ax.plot(d.t, d.y - t0.prediction, lw=0.6, color="C3", label="base model")
    ax.plot(d.t, d.y - t1.prediction, lw=0.6, color="C0", label="final model")
    for s in (1, -1):
        ax.axhline(s * report.noise_rms, color="k", lw=0.6, ls="--")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("held-out residual [" + ("N" if report.model == "tangential" else "m") + "]")
    ax.legend(loc="best", fontsize="small")
    ax.set_title("residual before / after (dashed: ± noise RMS)")
    return ax


def plot_location(report: Any, ax: Any = None, bins: int = 20) -> Any:
    """Share of the base residual power by position within the branch (0 = at a reversal)."""
    ax = _axes(ax)
    d = report.prepared
    e = d.y - report.trials[0].fitted
    ph = d.cycles.phase_in_branch
    edges = np.linspace(0.0, 1.0, bins + 1)
    idx = np.clip(np.digitize(ph, edges) - 1, 0, bins - 1)
    p = e * e
    share = np.bincount(idx, weights=p, minlength=bins) / max(p.sum(), 1e-300)
    frac = np.bincount(idx, minlength=bins) / ph.size
    centers = 0.5 * (edges[:-1] + edges[1:])
    ax.bar(centers, 100 * share, width=0.9 / bins, color="C3", label="residual power")
    ax.step(centers, 100 * frac, where="mid", color="k", lw=0.8, label="share of samples")
    ax.set_xlabel("position in branch (0: just after a reversal, 1: next reversal)")
    ax.set_ylabel("% of total")
    ax.legend(loc="best", fontsize="small")
    ax.set_title("where the base model's residual lives")
    return ax


def plot_gap(report: Any, ax: Any = None) -> Any:
    """Held-out RMS over the noise level after each step (1 = down to the noise)."""
    ax = _axes(ax)
    names = ["base"] + [s.label for s in report.steps[1:]]
    vals = [s.heldout_rms / report.noise_rms for s in report.steps]
    ax.bar(range(len(vals)), vals, color=["C3"] + ["C0"] * (len(vals) - 1))
    ax.axhline(1.0, color="k", lw=0.8, ls="--")
    ax.set_xticks(range(len(vals)), names, rotation=20, ha="right")
    ax.set_ylabel("held-out RMS / noise RMS")
    ax.set_title("gap shrink")
    return ax
