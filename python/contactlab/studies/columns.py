"""The columns of the study tables as reports and notebooks show them (display units, errors).

Kept apart from :mod:`contactlab.report.study_report` so that :class:`StudyResult` can show
itself in a notebook without importing the report builder (which imports the study module).
"""

from __future__ import annotations

from .._html import Column
from .cycles import CYCLE_UNITS  # noqa: F401  (defined with the cycles; kept importable here)

TANGENTIAL_COLUMNS = [
    Column("file"),
    Column("material"),
    Column("normal_load", "W", "N"),
    Column("amplitude", "A", "µm", 1e6),
    Column("h0", "h0", "N", stderr="h0_stderr"),
    Column("ac", "ac", "1/mm", 1e-3, stderr="ac_stderr"),
    Column("h0_ac", "h0·ac", "N/µm", 1e-6, stderr="h0_ac_stderr"),
    Column("energy_per_cycle", "E", "µJ", 1e6, stderr="energy_per_cycle_stderr"),
    Column(
        "energy_per_cycle_numeric", "E numeric", "µJ", 1e6, stderr="energy_per_cycle_numeric_stderr"
    ),
    Column("equivalent_damping", "c_e·ω", "N/µm", 1e-6, stderr="equivalent_damping_stderr"),
    Column("k_local0", "k_l(0)", "N/µm", 1e-6, stderr="k_local0_stderr"),
    Column("k_global", "k_g(A)", "N/µm", 1e-6, stderr="k_global_stderr"),
    Column("true_h0", "h0 true", "N"),
    Column("true_ac", "ac true", "1/mm", 1e-3),
    Column("identifiable", "h0, ac separable"),
]
NORMAL_COLUMNS = [
    Column("file"),
    Column("material"),
    Column("p0", "p0", "MPa", 1e-6),
    Column("pa", "pa", "MPa", 1e-6),
    Column("E_d", "E_d", "MPa·µm"),
    Column("E_pu", "E_pu", "MPa·µm"),
    Column("E_pd", "E_pd", "MPa·µm"),
    Column("psi", "ψ (eq. 7)"),
    Column("psi_kv", "ψ KV (eq. 3)"),
    Column("k_tan", "k_tan", "MPa/µm", 1e-12),
    Column("k_sec", "k_sec", "MPa/µm", 1e-12),
    Column("delta_min", "δ_min", "µm", 1e6),
    Column("delta_max", "δ_max", "µm", 1e6),
    Column("b1_paper", "b1", "µm⁻¹·MPa⁻²"),
    Column("b2_paper", "b2", "µm⁻¹·MPa⁻¹"),
    Column("b3_paper", "b3", "µm⁻¹"),
    Column("b4_paper", "b4", "MPa/µm"),
]

__all__ = ["NORMAL_COLUMNS", "TANGENTIAL_COLUMNS"]
