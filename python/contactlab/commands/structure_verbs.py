"""The work behind ``contactlab identify``: fit, hold-out evaluation, report."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import InputError


def identify_record(
    t: np.ndarray,
    u: np.ndarray,
    y: np.ndarray,
    *,
    joint: str,
    excitation: str,
    mass: float | None,
    holdout: float,
    substeps: int,
    periodic: bool,
    title: str,
    intro: str | None = None,
    progress: Any = None,
    **mdof: Any,
) -> tuple[Any, Any, dict[str, Any]]:
    import matplotlib

    matplotlib.use("Agg")
    from ..report.structure import build_structure_report
    from ..structure.identify import identify

    if not (0.0 <= holdout < 0.9):
        raise InputError(f"--holdout must be in [0, 0.9), got {holdout}")
    n_train = round(t.size * (1.0 - holdout))
    if n_train < 20:
        raise InputError("too few training samples after the hold-out")
    model = identify(
        t[:n_train],
        u[:n_train],
        y[:n_train],
        joint=joint,
        excitation=excitation,
        mass=mass,
        substeps=substeps,
        interpolation="fourier" if periodic and holdout == 0 else "linear",
        periodic=periodic,
        **mdof,
        **({"progress": progress} if progress is not None and not mdof else {}),
    )
    if progress is not None:
        progress("done")  # the simulations are over: a bar closes before the report is drawn
    if periodic:
        model.interpolation = "fourier"
    rep, summary = build_structure_report(
        model, t, u, y, title=title, n_train=n_train, mass=mass, intro=intro
    )
    return model, rep, summary
