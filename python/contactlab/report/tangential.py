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


def _plateau_levels(a: TangentialAnalysis) -> bool:
    """h0 comes from the plateau (and its levels are known): the loop plot draws them."""
    return (
        a.identifiability.get("h0_source") == "plateau"
        and "h0_plateau" in a.derived
        and "plateau_offset" in a.meta
    )


def _plateau_case(a: TangentialAnalysis) -> bool:
    """h0 comes from the plateau and the exponential fit identifies neither h0 nor ac: the
    plots show the plateau levels, not the fit's curve (whose h0 is another number)."""
    return not a.identifiable and _plateau_levels(a)


def plateau_residual(a: TangentialAnalysis) -> tuple[np.ndarray, np.ndarray]:
    """Force minus the plateau level (offset ± h0) on the averaged loop's sliding bins (beyond
    ``Δx₉₅`` from the turn and within the middle 90 % of the stroke: a stick holds x at the
    turn while F reverses), and the mask of those bins; NaN elsewhere."""
    loop = a.loop
    assert loop is not None
    h0 = a.derived["h0_plateau"][0]
    off = float(a.meta["plateau_offset"])
    dx95 = float(a.meta.get("plateau_dx95", 0.0))
    desc = np.asarray(loop.descending, dtype=bool)
    u = np.where(desc, loop.x.max() - loop.x, loop.x - loop.x.min())
    level = np.where(desc, off - h0, off + h0)
    stroke = float(np.ptp(loop.x))
    on = (u > max(dx95, 0.05 * stroke)) & (u < 0.95 * stroke)
    return np.where(on, loop.F - level, np.nan), on


def plot_loop(analysis: TangentialAnalysis, ax: Any = None, *, show_scatter: bool = True) -> Any:
    """Measured (averaged) loop, ±1σ cycle-to-cycle band, and the fitted Masing loop.

    Where h0 comes from the sliding plateau and the exponential fit identifies neither h0
    nor ac, the plateau levels (offset ± h0) are drawn instead of the fit's curve, so the
    curve and the title give the same h0. Displacement in µm, force in N.
    """
    ax = _axes(ax)
    a = analysis
    um = 1e6
    plateau = _plateau_case(a) and a.on == "averaged" and a.loop is not None
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
        if not plateau:  # the fit's curve, its own h0 named when the plateau's is reported
            label = "Masing fit"
            if _plateau_levels(a):
                label += f" (its h0 = {a.fit.params['h0'].value:.4g} N)"
            ax.plot(a.x[order] * um, a.F_model[order], "-", color="C3", lw=1.5, label=label)
        if _plateau_levels(a):
            h0 = a.derived["h0_plateau"][0]
            off = float(a.meta["plateau_offset"])
            lo, hi = float(loop.x.min()) * um, float(loop.x.max()) * um
            ax.hlines(
                [off + h0, off - h0],
                lo,
                hi,
                colors="C2" if not plateau else "C3",
                linestyles="--",
                lw=1.5,
                label=f"plateau levels offset ± h0 (h0 = {h0:.4g} N)",
            )
    else:
        s = a.meta.get("fit_start", 0)
        ax.plot(a.x * um, a.F, ",", color="C0", alpha=0.5, label="signal")
        ax.plot(a.x[s:] * um, a.F_model[s:], "-", color="C3", lw=1.0, label="Masing fit")
    ax.set_title(loop_title(a), fontsize=9)
    ax.set_xlabel("displacement x (µm)")
    ax.set_ylabel("tangential force F (N)")
    ax.legend(fontsize=8, loc="upper left")
    ax.grid(True, alpha=0.3)
    return ax


def loop_title(a: TangentialAnalysis) -> str:
    """The loop plot's title: the h0 (and ac) of the curve drawn, never a ``nan``."""
    p = a.fit.params
    if a.identifiable:
        if a.identifiability.get("h0_source") == "plateau" and "h0_plateau" in a.derived:
            # the fit's curve is drawn: its own h0, and the plateau's beside it
            h0, e = a.derived["h0_plateau"]
            return (
                f"fit h0 = {p['h0'].value:.4g} N, ac = {p['ac'].value:.4g} 1/m; "
                f"plateau h0 = {h0:.4g} ± {e:.2g} N"
            )
        return (
            f"h0 = {p['h0'].value:.4g} ± {_err(p['h0'].stderr)} N, "
            f"ac = {p['ac'].value:.4g} ± {_err(p['ac'].stderr)} 1/m"
        )
    if "h0_ac" in a.derived:
        k, e = a.derived["h0_ac"]
        return f"h0·ac = {k:.4g} ± {_err(e)} N/m (h0, ac not separable)"
    bound = a.derived.get("ac_lower_bound")
    acb = bound[0] if isinstance(bound, tuple) else bound
    tail = f", ac ≥ {acb:.3g} 1/m" if isinstance(acb, float) and np.isfinite(acb) else ""
    if "h0_plateau" in a.derived and _plateau_case(a):
        h0, e = a.derived["h0_plateau"]
        return f"h0 = {h0:.4g} ± {_err(e)} N (plateau, dashed){tail}"
    # no plateau measured: the fit's curve with its h0 named as not identifiable
    return f"Masing fit: h0 = {p['h0'].value:.4g} N, not identifiable{tail}"


def _err(e: float | None) -> str:
    return f"{e:.2g}" if e is not None and np.isfinite(e) else "(no finite error)"


def plot_residuals(analysis: TangentialAnalysis, ax: Any = None) -> Any:
    """Residuals (data − fit) against phase (averaged loop) or time (signal), in N; where
    the loop plot draws the plateau levels instead of the fit, the sliding bins' force minus
    the plateau level. The title gives the RMS of exactly the residuals plotted."""
    ax = _axes(ax)
    a = analysis
    if a.on == "averaged" and a.loop is not None:
        ph = a.loop.phase
        if _plateau_case(a):
            r, on = plateau_residual(a)
            what = "F − plateau (mid 90 % of strokes)"
            shown = r[on]
            ax.plot(ph[on], shown, ".", ms=3, color="C0")
        else:
            what = "F − fit"
            shown = a.residual
            ax.plot(ph, shown, ".", ms=3, color="C0")
        if a.loop.n_cycles > 1:
            sem = a.loop.F_std / np.sqrt(a.loop.n_cycles)
            o = np.argsort(ph)
            ax.fill_between(
                ph[o], -2 * sem[o], 2 * sem[o], color="0.85", label="±2 s.e.m. (scatter)"
            )
            ax.legend(fontsize=8)
        ax.axvline(0.5, color="0.5", lw=0.8, ls=":")
        ax.set_xlabel("phase (0 = peak, 0.5 = valley)")
    else:
        what = "F − fit"
        s = a.meta.get("fit_start", 0)
        r = a.residual
        tt = a.t if a.t is not None else np.arange(r.size)
        shown = r[s:]
        ax.plot(tt[s:], shown, ",", color="C0")
        ax.set_xlabel("time (s)" if a.t is not None else "sample")
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_ylabel("residual (N)")
    ax.set_title(f"{what}: {residual_title(shown)}", fontsize=8)
    ax.grid(True, alpha=0.3)
    return ax


def residual_title(shown: np.ndarray) -> str:
    """The title ``RMS = <value> N, <n> points`` of exactly the residuals ``shown`` (unweighted:
    the fit's reduced χ² of a weighted fit is another number)."""
    r = np.asarray(shown, dtype=float)
    r = r[np.isfinite(r)]
    if r.size == 0:
        return "no residuals to show"
    rms = float(np.sqrt(np.mean(r * r)))
    return f"RMS = {rms:.3g} N, {r.size} points"
