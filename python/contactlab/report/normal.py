"""Plots of a normal-contact comparison, as Konowalski (2009) Figs. 9-12 show it.

The paper's four views — displacement time run (Fig. 9), velocity time run (Fig. 10), phase
portrait δ' against δ (Fig. 11) and loops p(δ) (Fig. 12) — in µm, µm/s and MPa; each accepts
``ax=`` and returns the figure, and never calls ``show()``. The comparison itself is
:func:`contactlab.normal.compare`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import InputError
from ..normal.compare import Comparison


def _axes(ax: Any) -> tuple[Any, Any]:
    if ax is None:
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6.4, 4.0), constrained_layout=True)
        return fig, ax
    return ax.figure, ax


def _window(c: Comparison, cycles: float) -> np.ndarray:
    t0 = c.info.get("t_start", c.t[0])
    return (c.t >= t0) & (c.t <= t0 + cycles * 2 * np.pi / c.omega)


_STYLE = ["-", "--", "-.", ":"]


def _time_run(c: Comparison, ax: Any, cycles: float, key: str, ylabel: str) -> Any:
    """Measured and modelled time runs of ``key`` (``delta`` or ``velocity``), in µm units."""
    fig, ax = _axes(ax)
    w = _window(c, cycles)
    measured = c.delta if key == "delta" else c.velocity
    ax.plot(c.t[w], measured[w] * 1e6, color="0.3", lw=1.0, label="measurement")
    for i, (name, s) in enumerate(c.models.items()):
        ax.plot(c.t[w], s[key][w] * 1e6, _STYLE[i % 4], lw=1.4, label=name)
    ax.set_xlabel("t [s]")
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def plot_displacement(c: Comparison, ax: Any = None, cycles: float = 2.0) -> Any:
    """Displacement time runs, measured and modelled (Fig. 9)."""
    return _time_run(c, ax, cycles, "delta", "δ [µm]")


def plot_velocity(c: Comparison, ax: Any = None, cycles: float = 2.0) -> Any:
    """Velocity time runs (Fig. 10)."""
    return _time_run(c, ax, cycles, "velocity", "v = dδ/dt [µm/s]")


def plot_phase_portrait(c: Comparison, ax: Any = None, cycles: float = 1.0) -> Any:
    """Phase portrait v against δ (Fig. 11)."""
    fig, ax = _axes(ax)
    w = _window(c, cycles)
    ax.plot(c.delta[w] * 1e6, c.velocity[w] * 1e6, color="0.3", lw=1.0, label="measurement")
    for i, (name, s) in enumerate(c.models.items()):
        ax.plot(s["delta"][w] * 1e6, s["velocity"][w] * 1e6, _STYLE[i % 4], lw=1.4, label=name)
    ax.set_xlabel("δ [µm]")
    ax.set_ylabel("v [µm/s]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def plot_loops(c: Comparison, ax: Any = None, cycles: float = 1.0) -> Any:
    """Hysteresis loops p(δ) (Fig. 12)."""
    fig, ax = _axes(ax)
    w = _window(c, cycles)
    ax.plot(c.delta[w] * 1e6, c.p[w] / 1e6, color="0.3", lw=1.0, label="measurement")
    for i, (name, s) in enumerate(c.models.items()):
        ax.plot(s["delta"][w] * 1e6, c.p[w] / 1e6, _STYLE[i % 4], lw=1.4, label=name)
    ax.set_xlabel("δ [µm]")
    ax.set_ylabel("p [MPa]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def plot_comparison(c: Comparison, ax: Any = None) -> Any:
    """All four views (Figs. 9-12) in a 2×2 grid; ``ax`` may be a 2×2 (or 4-long) axes array."""
    if ax is None:
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(2, 2, figsize=(10, 7.5), constrained_layout=True)
    else:
        axes = np.asarray(ax, dtype=object)
        if axes.size != 4:
            raise InputError("ax must hold four axes")
        fig = axes.flat[0].figure
    flat = np.asarray(axes, dtype=object).reshape(-1)
    plot_displacement(c, flat[0])
    plot_velocity(c, flat[1])
    plot_phase_portrait(c, flat[2])
    plot_loops(c, flat[3])
    return fig
