"""Plots of a tangential analysis: the loop with its fit, and the residuals.

Both take ``ax=`` (a new figure is made when None) and return the axes; they never show.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..tangential.result import TangentialAnalysis


def _axes(ax: Any) -> Any:
    if ax is None:
        from matplotlib.figure import Figure

        fig = Figure(figsize=(6.0, 4.5))
        ax = fig.add_subplot()
    return ax


def plot_loop(analysis: TangentialAnalysis, ax: Any = None, *, show_scatter: bool = True) -> Any:
    """Measured (averaged) loop, ±1σ cycle-to-cycle band, and the fitted Masing loop.

    Displacement in µm, force in N.
    """
    ax = _axes(ax)
    a = analysis
    um = 1e6
    if a.on == "averaged" and a.loop is not None:
        loop = a.loop
        order = np.r_[np.arange(loop.x.size), 0]
        if show_scatter and loop.n_cycles > 1:
            ax.vlines(
                loop.x * um,
                loop.F - loop.F_std,
                loop.F + loop.F_std,
                color="0.75",
                lw=1.0,
                label=f"±1σ cycle to cycle ({loop.n_cycles} cycles)",
            )
        ax.plot(loop.x * um, loop.F, ".", ms=3, color="C0", label="averaged loop")
        ax.plot(a.x[order] * um, a.F_model[order], "-", color="C3", lw=1.5, label="Masing fit")
    else:
        s = a.meta.get("fit_start", 0)
        ax.plot(a.x * um, a.F, ",", color="C0", alpha=0.5, label="signal")
        ax.plot(a.x[s:] * um, a.F_model[s:], "-", color="C3", lw=1.0, label="Masing fit")
    p = a.fit.params
    if a.identifiable:
        title = (
            f"h0 = {p['h0'].value:.4g} ± {p['h0'].stderr:.2g} N, "
            f"ac = {p['ac'].value:.4g} ± {p['ac'].stderr:.2g} 1/m"
        )
    elif "h0_ac" in a.derived:
        k, e = a.derived["h0_ac"]
        title = f"h0·ac = {k:.4g} ± {e:.2g} N/m (h0, ac not separable)"
    else:  # gross sliding / stick-slip: h0 from the plateau, ac only bounded below
        h0, e = a.derived.get("h0_plateau", (p["h0"].value, p["h0"].stderr))
        bound = a.derived.get("ac_lower_bound")
        acb = bound[0] if isinstance(bound, tuple) else bound
        tail = f", ac ≥ {acb:.3g} 1/m" if isinstance(acb, float) else ""
        title = f"h0 = {h0:.4g} ± {e:.2g} N (plateau){tail}"
    ax.set_title(title, fontsize=9)
    ax.set_xlabel("displacement x (µm)")
    ax.set_ylabel("tangential force F (N)")
    ax.legend(fontsize=8, loc="upper left")
    ax.grid(True, alpha=0.3)
    return ax


def plot_residuals(analysis: TangentialAnalysis, ax: Any = None) -> Any:
    """Residuals (data − fit) against phase (averaged loop) or time (signal), in N."""
    ax = _axes(ax)
    a = analysis
    r = a.residual
    if a.on == "averaged" and a.loop is not None:
        ph = a.loop.phase
        ax.plot(ph, r, ".", ms=3, color="C0")
        if a.loop.n_cycles > 1:
            sem = a.loop.F_std / np.sqrt(a.loop.n_cycles)
            ax.fill_between(ph, -2 * sem, 2 * sem, color="0.85", label="±2 s.e.m. (scatter)")
            ax.legend(fontsize=8)
        ax.axvline(0.5, color="0.5", lw=0.8, ls=":")
        ax.set_xlabel("phase (0 = peak, 0.5 = valley)")
    else:
        s = a.meta.get("fit_start", 0)
        tt = a.t if a.t is not None else np.arange(r.size)
        ax.plot(tt[s:], r[s:], ",", color="C0")
        ax.set_xlabel("time (s)" if a.t is not None else "sample")
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_ylabel("residual F − fit (N)")
    # redchi is the unweighted residual variance (N²); show its root, in newtons.
    s_res = np.sqrt(a.fit.redchi) if np.isfinite(a.fit.redchi) else np.nan
    ax.set_title(f"residual RMS s = {s_res:.3g} N, {a.fit.ndata} points", fontsize=9)
    ax.grid(True, alpha=0.3)
    return ax
