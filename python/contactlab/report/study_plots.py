"""The paper's study plots from a study table (:mod:`contactlab.studies.study`).

Tangential (the Masing paper, Figs. 6-9 aluminium, 11-14 PVC, 16-18 steel): energy per cycle,
equivalent damping c_e·ω, local and global stiffness against normal load and against amplitude,
one figure per material and quantity. Normal (Konowalski 2009): ψ (eqs. 3 and 7), k_tan
(eq. 4), k_sec (eq. 5) and the coefficients b1..b4 of k_s(p) (eq. 16) against p0.

Each function takes the table rows (dicts in SI as :class:`~contactlab.studies.StudyResult`
gives them), plots on ``ax=`` when given and returns the axes / figure; nothing is shown.
Error bars are ± one standard error as reported by the fit.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..studies.normal import B_PAPER_UNITS

# key, label, SI unit; an optional second key drawn beside it (numeric loop area).
TANGENTIAL_QUANTITIES: list[tuple[str, str, str, str | None]] = [
    ("energy_per_cycle", "energy per cycle E", "J", "energy_per_cycle_numeric"),
    ("equivalent_damping", "equivalent damping c_e·ω", "N/m", None),
    ("k_local0", "local stiffness k_l(0) = h0·ac", "N/m", None),
    ("k_global", "global stiffness k_g(A) = f(A)/A", "N/m", None),
]
NORMAL_QUANTITIES: list[tuple[str, str, str]] = [
    ("psi", "ψ = 2E_d/(E_pu+E_pd) (eq. 7)", "1"),
    ("psi_kv", "ψ = E_d/E_pu (eq. 3)", "1"),
    ("k_tan", "tangent stiffness k_tan (eq. 4)", "Pa/m"),
    ("k_sec", "secant stiffness k_sec (eq. 5)", "Pa/m"),
    ("E_d", "energy dissipated per cycle E_d", "J/m^2"),
]

# Preferred display units of SI quantities (the units the papers print).
_DISPLAY = {
    "m": ("µm", 1e6),
    "Pa": ("MPa", 1e-6),
    "Pa/m": ("MPa/µm", 1e-12),
    "J/m^2": ("MPa·µm", 1.0),  # 1 MPa·µm = 1 J/m²
}
_PREFIX = [(1e9, "G"), (1e6, "M"), (1e3, "k"), (1.0, ""), (1e-3, "m"), (1e-6, "µ"), (1e-9, "n")]


def display_unit(unit: str, values: Sequence[float] = ()) -> tuple[str, float]:
    """Display unit and factor (display = SI × factor) for values in SI ``unit``."""
    if unit in _DISPLAY:
        return _DISPLAY[unit]
    if unit in ("", "1", "-"):
        return "", 1.0
    finite = [abs(v) for v in values if v is not None and math.isfinite(v) and v != 0]
    if not finite:
        return unit, 1.0
    top = max(finite)
    for mult, prefix in _PREFIX:
        if top >= mult:
            return prefix + unit, 1.0 / mult
    return "n" + unit, 1e9


def _num(row: Mapping[str, Any], key: str) -> float:
    v = row.get(key)
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        return math.nan
    return float(v)


def _axes(ax: Any) -> Any:
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(5.0, 3.6), constrained_layout=True)
    return ax


def _group_key(row: Mapping[str, Any], key: str) -> float:
    v = _num(row, key)
    if not math.isfinite(v) or v == 0:
        return v
    digits = 2 - math.floor(math.log10(abs(v)))
    return round(v, digits)  # nominal values: merge measured ones that differ by noise


def plot_study(
    rows: Sequence[Mapping[str, Any]],
    quantity: str,
    against: str,
    group_by: str | None,
    *,
    unit: str = "",
    label: str | None = None,
    secondary: str | None = None,
    units: Mapping[str, str] | None = None,
    ax: Any = None,
) -> Any:
    """Plot ``quantity`` against ``against``, one line per value of ``group_by``.

    Parameters
    ----------
    rows : sequence of mapping
        Study table rows (SI). Rows without a finite ``quantity`` or ``against`` are skipped.
    quantity, against, group_by : str
        Table keys. ``quantity + "_stderr"`` gives error bars (± 1 standard error) if present.
    unit : str
        SI unit of ``quantity`` (display units are chosen from it).
    secondary : str, optional
        A second key drawn with open markers in the same colour (e.g. the numerical energy).
    units : mapping, optional
        SI units of ``against`` and ``group_by`` (for labels).
    ax : matplotlib Axes, optional

    Returns
    -------
    matplotlib Axes
    """
    ax = _axes(ax)
    units = dict(units or {})
    pts = [r for r in rows if math.isfinite(_num(r, quantity)) and math.isfinite(_num(r, against))]
    yunit, yf = display_unit(unit, [_num(r, quantity) for r in pts])
    xunit, xf = display_unit(units.get(against, ""), [_num(r, against) for r in pts])
    gunit, gf = (
        display_unit(units.get(group_by or "", ""), [_num(r, group_by) for r in pts])
        if group_by
        else ("", 1.0)
    )
    groups: dict[float, list[Mapping[str, Any]]] = {}
    for r in pts:
        groups.setdefault(_group_key(r, group_by) if group_by else 0.0, []).append(r)
    for i, (g, members) in enumerate(
        sorted(groups.items(), key=lambda kv: (math.isnan(kv[0]), kv[0]))
    ):
        members = sorted(members, key=lambda r: _num(r, against))
        x = np.array([_num(r, against) for r in members]) * xf
        y = np.array([_num(r, quantity) for r in members]) * yf
        s = np.array([abs(_num(r, quantity + "_stderr")) for r in members]) * yf
        color = f"C{i % 10}"
        name = f"{group_by} = {g * gf:.3g} {gunit}".replace("_", " ") if group_by else quantity
        if np.isfinite(s).any():
            ax.errorbar(
                x,
                y,
                yerr=np.where(np.isfinite(s), s, 0.0),
                color=color,
                marker="o",
                ms=4,
                lw=1.2,
                capsize=2,
                label=name,
            )
        else:
            ax.plot(x, y, color=color, marker="o", ms=4, lw=1.2, label=name)
        if secondary:
            y2 = np.array([_num(r, secondary) for r in members]) * yf
            if np.isfinite(y2).any():
                ax.plot(x, y2, color=color, marker="o", mfc="none", ls=":", ms=6, lw=0.8)
    ax.set_xlabel(f"{against.replace('_', ' ')}" + (f" [{xunit}]" if xunit else ""))
    ax.set_ylabel((label or quantity) + (f" [{yunit}]" if yunit else ""))
    ax.grid(alpha=0.3)
    if groups:
        ax.legend(fontsize=7, title=None)
    return ax


def tangential_study_figures(
    rows: Sequence[Mapping[str, Any]],
    units: Mapping[str, str] | None = None,
    *,
    part: tuple[int, int] = (0, 1),
) -> list[tuple[str, Any, str]]:
    """One figure per material and quantity: against load (left) and amplitude (right).

    Materials with fewer than two recordings are left out. Returns ``(name, figure,
    caption)`` triples; the caller owns (and closes) the figures. ``part=(k, n)``: only the
    figures ``k, k + n, k + 2n, ...`` of the whole list, the others not drawn at all (a
    report split over ``n`` processes).
    """
    k_part, n_parts = part
    index = -1
    import matplotlib.pyplot as plt

    units = {"normal_load": "N", "amplitude": "m", "amplitude_nominal": "m", **(units or {})}
    out = []
    materials = sorted({str(r.get("material", "unknown")) for r in rows})
    for mat in materials:
        mrows = [r for r in rows if str(r.get("material", "unknown")) == mat]
        if len(mrows) < 2:
            continue  # one recording is no load/amplitude study
        # The paper plots against the commanded amplitude; the measured one (in the table)
        # is used when no nominal amplitude is tagged.
        nominal = all(math.isfinite(_num(r, "amplitude_nominal")) for r in mrows)
        amp_group = amp_x = "amplitude_nominal" if nominal else "amplitude"
        for key, label, unit, secondary in TANGENTIAL_QUANTITIES:
            if not any(math.isfinite(_num(r, key)) for r in mrows):
                continue
            index += 1
            if index % n_parts != k_part:
                continue
            fig, (a1, a2) = plt.subplots(1, 2, figsize=(9.0, 3.6), constrained_layout=True)
            plot_study(
                mrows,
                key,
                "normal_load",
                amp_group,
                unit=unit,
                label=label,
                secondary=secondary,
                units=units,
                ax=a1,
            )
            plot_study(
                mrows,
                key,
                amp_x,
                "normal_load",
                unit=unit,
                label=label,
                secondary=secondary,
                units=units,
                ax=a2,
            )
            fig.suptitle(f"{mat}: {label}", fontsize=10)
            cap = f"{mat}: {label} against normal load and amplitude (± 1 standard error)"
            if secondary:
                cap += "; open markers: numerical loop area of the averaged measured loop"
            out.append((f"study-{mat}-{key}", fig, cap))
    return out


def _direction(xs: Sequence[float], ys: Sequence[float]) -> int:
    """+1 when y rises strictly with x over every step, -1 when it falls, 0 otherwise."""
    pts = sorted((x, y) for x, y in zip(xs, ys, strict=True) if math.isfinite(x + y))
    if len(pts) < 2:
        return 0
    d = np.diff([y for _, y in pts])
    return 1 if np.all(d > 0) else -1 if np.all(d < 0) else 0


def trends(
    rows: Sequence[Mapping[str, Any]], quantities: Sequence[str] | None = None
) -> list[dict[str, Any]]:
    """How each quantity moves with load (at fixed nominal amplitude) and with amplitude (at
    fixed load), per material — the trends the tangential paper reports (E and c_e·ω grow with
    load; stiffness grows with load and falls with amplitude).

    Returns rows ``{material, quantity, with_load, with_amplitude}`` where each entry reads
    like ``"rises at 3 of 3 amplitudes"``: a series counts as rising (falling) only when every
    step rises (falls); series with fewer than two points are not counted.
    """
    keys = list(quantities or [q for q, *_ in TANGENTIAL_QUANTITIES])
    out = []
    for mat in sorted({str(r.get("material", "unknown")) for r in rows}):
        mrows = [r for r in rows if str(r.get("material", "unknown")) == mat]
        for key in keys:
            if not any(math.isfinite(_num(r, key)) for r in mrows):
                continue
            entry: dict[str, Any] = {"material": mat, "quantity": key}
            nominal = all(math.isfinite(_num(r, "amplitude_nominal")) for r in mrows)
            amp = "amplitude_nominal" if nominal else "amplitude"
            for label, along, fixed, what in (
                ("with_load", "normal_load", amp, "amplitudes"),
                ("with_amplitude", amp, "normal_load", "loads"),
            ):
                groups: dict[float, list[Mapping[str, Any]]] = {}
                for r in mrows:
                    groups.setdefault(_group_key(r, fixed), []).append(r)
                dirs = [
                    _direction([_num(r, along) for r in g], [_num(r, key) for r in g])
                    for g in groups.values()
                    if sum(math.isfinite(_num(r, key)) for r in g) >= 2
                ]
                up, down, n = dirs.count(1), dirs.count(-1), len(dirs)
                if n == 0:
                    entry[label] = "—"
                elif up == down == 0:
                    entry[label] = f"not monotone at any of {n} {what}"
                elif up >= down:
                    entry[label] = f"rises at {up} of {n} {what}"
                else:
                    entry[label] = f"falls at {down} of {n} {what}"
            out.append(entry)
    return out


def normal_study_figures(
    rows: Sequence[Mapping[str, Any]], units: Mapping[str, str] | None = None
) -> list[tuple[str, Any, str]]:
    """ψ, k_tan, k_sec, E_d and b1..b4 against p0 (one line per pa)."""
    import matplotlib.pyplot as plt

    units = {"p0": "Pa", "pa": "Pa", **(units or {})}
    quantities = [
        (k, lab, u)
        for k, lab, u in NORMAL_QUANTITIES
        if any(math.isfinite(_num(r, k)) for r in rows)
    ]
    bs = [
        f"b{i}_paper"
        for i in range(1, 5)
        if any(math.isfinite(_num(r, f"b{i}_paper")) for r in rows)
    ]
    out = []
    if quantities:
        n = len(quantities)
        ncol = min(3, n)
        nrow = math.ceil(n / ncol)
        fig, axs = plt.subplots(
            nrow, ncol, figsize=(4.2 * ncol, 3.3 * nrow), constrained_layout=True, squeeze=False
        )
        for ax, (key, label, unit) in zip(axs.flat, quantities, strict=False):
            plot_study(rows, key, "p0", "pa", unit=unit, label=label, units=units, ax=ax)
        for ax in list(axs.flat)[n:]:
            ax.set_visible(False)
        fig.suptitle("Normal contact against static pressure p0", fontsize=10)
        out.append(
            (
                "study-normal-loop-quantities",
                fig,
                "ψ, stiffness and dissipated energy against p0 (one line per pa)",
            )
        )
    if bs:
        fig, axs = plt.subplots(
            1, len(bs), figsize=(3.4 * len(bs), 3.2), constrained_layout=True, squeeze=False
        )
        for ax, key in zip(axs.flat, bs, strict=False):
            name = key.split("_")[0]
            plot_study(
                rows, key, "p0", "pa", label=f"{name} [{B_PAPER_UNITS[name]}]", units=units, ax=ax
            )
        fig.suptitle(
            "k_s(p) = b1 p³ + b2 p² + b3 p + b4 (eq. 16; k_s in MPa/µm, p in MPa) against p0",
            fontsize=10,
        )
        out.append(("study-normal-b-coefficients", fig, "b1..b4 of eq. 16 against p0"))
    return out


__all__ = [
    "NORMAL_QUANTITIES",
    "TANGENTIAL_QUANTITIES",
    "display_unit",
    "normal_study_figures",
    "plot_study",
    "tangential_study_figures",
    "trends",
]
