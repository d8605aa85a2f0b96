"""Plots of a :class:`~contactlab.studies.tracking.TrackResult`: every tracked quantity against
time or cycle count with its standard error as error bars, and the per-cycle energies."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np

from ..studies.columns import CYCLE_UNITS
from .study_plots import display_unit

#: axis labels of the tracked quantities
LABELS = {
    "h0": "h0",
    "ac": "ac",
    "h0_ac": "h0·ac",
    "energy_per_cycle": "E per cycle (analytic)",
    "energy_per_cycle_numeric": "E per cycle (loop area)",
    "equivalent_damping": "c_e·ω",
    "k_local0": "k_local(0)",
    "k_global": "k_global(A)",
    "amplitude": "amplitude A",
    "offset": "force offset",
    "E_d": "E_d",
    "psi": "ψ (eq. 7)",
    "psi_kv": "ψ_KV (eq. 3)",
    "k_tan": "k_tan",
    "k_sec": "k_sec",
    "delta_max": "δ_max",
    "delta_min": "δ_min",
    "p0": "p0",
    "pa": "pa",
}


_MARGINS = {"left": 0.16, "right": 0.97, "bottom": 0.17, "top": 0.93}


def _axes(ax: Any) -> Any:
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(6.0, 3.2))
    return ax


def plot_quantity(result: Any, name: str, *, against: str = "time", ax: Any = None) -> Any:
    """``name`` per window with ±1 standard error bars (where known) against the windows' mid
    time or the cycle count at their ends; SI values shown in display units."""
    if against not in ("time", "cycle"):
        from ..errors import InputError

        raise InputError(f"against must be 'time' or 'cycle', got {against!r}")
    ax = _axes(ax)
    unit = result.units.get(name, "")
    raw = result.column(name)
    shown, scale = display_unit(unit, raw.tolist())
    y = raw * scale
    e = result.column(f"{name}_stderr") * scale
    if against == "time":
        xv, xl = result.column("t_mid"), "time [s]"
    else:
        xv = 0.5 * (result.column("cycle_start") + result.column("cycle_end"))
        xl = "cycle"
    has_err = np.isfinite(e).any()
    ax.errorbar(
        xv,
        y,
        yerr=np.where(np.isfinite(e), e, 0.0) if has_err else None,
        fmt="o-",
        ms=3,
        lw=1,
        capsize=2,
    )
    label = LABELS.get(name, name)
    ax.set_ylabel(f"{label} [{shown}]" if shown else label)
    ax.set_xlabel(xl)
    ax.grid(True, alpha=0.3)
    return ax


def plot_cycles(result: Any, name: str = "energy", ax: Any = None) -> Any:
    """A per-cycle quantity against the cycle number (every cycle of the record)."""
    ax = _axes(ax)
    v = result.cycles[name]
    unit = CYCLE_UNITS[result.kind][name]
    shown, scale = display_unit(unit, v[:1000].tolist())
    n = np.arange(1, v.size + 1)
    ax.plot(n, v * scale, ",", rasterized=True) if v.size > 5000 else ax.plot(n, v * scale, ".-")
    ax.set_xlabel("cycle")
    ax.set_ylabel(f"{name} per cycle [{shown}]")
    ax.grid(True, alpha=0.3)
    return ax


def track_figures(result: Any, *, against: str = "time") -> Iterator[tuple[str, Any]]:
    """``(name, figure)`` for every tracked quantity (a polynomial's coefficients share one
    figure, one panel each), then the per-cycle energy: a generator, so that a caller who
    closes each figure holds one at a time."""
    import matplotlib.pyplot as plt

    polys: dict[str, list[str]] = {}
    for q in result.quantities:
        head, _, tail = q.rpartition("_")
        if q.startswith("poly_") and tail.isdigit():
            polys.setdefault(head, []).append(q)
            continue
        fig, ax = plt.subplots(figsize=(6.0, 3.2))
        plot_quantity(result, q, against=against, ax=ax)
        fig.subplots_adjust(**_MARGINS)  # fixed margins: tight_layout costs 0.5 s a figure
        yield q, fig
    for head, names in polys.items():
        fig, axes = plt.subplots(
            len(names), 1, figsize=(6.0, 1.6 * len(names) + 0.6), sharex=True, squeeze=False
        )
        for ax, q in zip(axes[:, 0], names, strict=True):
            plot_quantity(result, q, against=against, ax=ax)
            ax.set_ylabel(f"a{q.rpartition('_')[2]} [{ax.get_ylabel().rpartition('[')[2]}")
            ax.set_xlabel("")
        axes[-1, 0].set_xlabel("time [s]" if against == "time" else "cycle")
        axes[0, 0].set_title(f"{head} coefficients (ascending powers)")
        fig.subplots_adjust(**{**_MARGINS, "bottom": 0.6 / (1.6 * len(names) + 0.6)})
        yield head, fig
    if result.cycles["energy"].size:
        fig, ax = plt.subplots(figsize=(6.0, 3.2))
        plot_cycles(result, "energy", ax=ax)
        fig.subplots_adjust(**_MARGINS)
        yield "cycle_energy", fig


__all__ = ["LABELS", "plot_cycles", "plot_quantity", "track_figures"]
