"""Study tables (CSV with units, Parquet with units metadata) and the study plots."""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from contactlab.masing import Masing
from contactlab.report.study_plots import (
    display_unit,
    normal_study_figures,
    plot_study,
    tangential_study_figures,
    trends,
)
from contactlab.studies.manifest import StudyEntry
from contactlab.studies.study import RecordingResult, StudyResult, flatten


def _tangential_rows():
    """Rows with exact Masing quantities: h0 grows with load, A in three levels."""
    out = []
    for mat, mu, ac in (("Al/Al", 0.4, 6e4), ("PVC/steel", 0.3, 3e4)):
        for W in (50.0, 100.0, 150.0):
            for A in (10e-6, 20e-6, 40e-6):
                m = Masing(mu * W, ac)
                out.append(
                    {
                        "file": f"{mat}-{W}-{A}.csv",
                        "material": mat,
                        "normal_load": W,
                        "amplitude_nominal": A,
                        "amplitude": A * 1.002,
                        "h0": m.h0,
                        "h0_stderr": 0.01 * m.h0,
                        "energy_per_cycle": float(m.loop_energy(A)),
                        "energy_per_cycle_stderr": 1e-7,
                        "energy_per_cycle_numeric": float(m.loop_energy(A)) * 1.01,
                        "equivalent_damping": float(m.equivalent_damping(A)),
                        "k_local0": float(m.local_stiffness(0.0)),
                        "k_global": float(m.global_stiffness(A)),
                        "identifiable": True,
                    }
                )
    return out


def _result(rows, kind="tangential"):
    units = {"h0": "N", "h0_stderr": "N", "energy_per_cycle": "J", "normal_load": "N"}
    return StudyResult(
        [RecordingResult(StudyEntry(Path(r["file"]), kind, {}), dict(r), dict(units)) for r in rows]
    )


def test_csv_has_units_and_round_trips():
    rows = _tangential_rows()
    rows[0]["h0_stderr"] = float("nan")
    res = _result(rows)
    text = res.to_csv("tangential")
    rd = list(csv.reader(io.StringIO(text)))
    assert "h0 [N]" in rd[0] and "energy_per_cycle [J]" in rd[0] and "material" in rd[0]
    assert len(rd) == 1 + len(rows)
    col = rd[0].index("h0 [N]")
    assert [float(r[col]) for r in rd[1:]] == [r["h0"] for r in rows]  # repr: exact
    assert rd[1][rd[0].index("h0_stderr [N]")] == "nan"
    assert rd[1][rd[0].index("identifiable")] == "True"


def test_parquet_round_trip_with_units():
    pq = pytest.importorskip("pyarrow.parquet")
    rows = _tangential_rows()
    rows[3]["extra_tag"] = "only here"
    res = _result(rows)
    t = pq.read_table(io.BytesIO(res.to_parquet("tangential")))
    assert t.num_rows == len(rows)
    assert json.loads(t.schema.metadata[b"units"])["h0"] == "N"
    assert t.column("h0").to_pylist() == [r["h0"] for r in rows]
    assert t.column("extra_tag").to_pylist()[3] == "only here"
    assert t.column("extra_tag").to_pylist()[0] is None
    assert t.column("identifiable").type == "bool"
    files = res.table_files()
    assert set(files) == {"study_tangential.csv", "study_tangential.parquet"}


def test_notebook_repr():
    res = _result(_tangential_rows()[:2])
    res.results.append(
        RecordingResult(StudyEntry(Path("b.csv"), "tangential", {}), {}, {}, error="b.csv: <x>")
    )
    text = res._repr_html_()
    assert text.count("<tr>") == 3 and "h0 [N]" in text and "b.csv: &lt;x&gt;" in text
    assert repr(res) == "StudyResult(2 tangential, 0 normal, 1 failed)"


def test_failures_are_kept_out_of_the_table():
    rows = _tangential_rows()[:2]
    res = _result(rows)
    res.results.append(
        RecordingResult(StudyEntry(Path("bad.csv"), "tangential", {}), {}, {}, error="bad.csv: x")
    )
    assert len(res.table("tangential")) == 2
    assert [r.error for r in res.failures] == ["bad.csv: x"]
    assert res.table("normal") == []
    assert "study_normal.csv" not in res.table_files()


def test_flatten_vectors_nested_and_numpy():
    row, units = flatten(
        {
            "poly_load": np.array([1.0, 2.0, 3.0]),
            "k": np.float64(2.5),
            "n": np.int64(3),
            "fit": {"chisqr": 1.5, "units": {"chisqr": "N^2"}},
            "units": {"poly_load": ["Pa", "Pa/m", "Pa/m^2"], "k": "N/m"},
            "big": np.zeros(100),
        },
        {"poly_load": ["Pa", "Pa/m", "Pa/m^2"], "k": "N/m"},
    )
    assert row == {"poly_load_0": 1.0, "poly_load_1": 2.0, "poly_load_2": 3.0, "k": 2.5, "n": 3,
                   "fit.chisqr": 1.5}  # fmt: skip
    assert units == {"poly_load_0": "Pa", "poly_load_1": "Pa/m", "poly_load_2": "Pa/m^2",
                     "k": "N/m", "fit.chisqr": "N^2"}  # fmt: skip


def test_display_unit():
    assert display_unit("Pa/m") == ("MPa/µm", 1e-12)
    assert display_unit("J", [3e-3, 1e-4]) == ("mJ", 1e3)
    assert display_unit("N/m", [2.5e6]) == ("MN/m", 1e-6)
    assert display_unit("", [5.0]) == ("", 1.0)
    assert display_unit("J", [float("nan")]) == ("J", 1.0)


def test_plot_study_groups_and_error_bars():
    rows = [r for r in _tangential_rows() if r["material"] == "Al/Al"]
    ax = plot_study(rows, "energy_per_cycle", "normal_load", "amplitude_nominal", unit="J",
                    secondary="energy_per_cycle_numeric", units={"normal_load": "N",
                    "amplitude_nominal": "m"})  # fmt: skip
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels == [f"amplitude nominal = {a} µm" for a in ("10", "20", "40")]
    # the plotted y values are the table's energies in the display unit (mJ), sorted by load
    line = ax.get_lines()[0]
    want = sorted((r["normal_load"], r["energy_per_cycle"]) for r in rows
                  if r["amplitude_nominal"] == 10e-6)  # fmt: skip
    np.testing.assert_allclose(line.get_ydata(), [e * 1e3 for _, e in want])
    assert ax.get_ylabel().endswith("[mJ]")
    plt.close("all")


def test_study_figures_per_material_and_normal():
    rows = _tangential_rows()
    figs = tangential_study_figures(rows, {"h0": "N"})
    names = [n for n, _, _ in figs]
    qs = ("energy_per_cycle", "equivalent_damping", "k_local0", "k_global")
    assert names == [f"study-{m}-{q}" for m in ("Al/Al", "PVC/steel") for q in qs]
    # stiffness falls with amplitude for every load (the paper's trend; here exact Masing)
    fig = figs[3][1]
    for line in fig.axes[1].get_lines():
        y = line.get_ydata()
        if len(y) == 3:
            assert np.all(np.diff(y) < 0)
    nrows = [
        {
            "p0": p0,
            "pa": 4e5,
            "psi": 0.1 + 0.01 * i,
            "k_tan": 1.2e12 + 1e11 * i,
            "b1_paper": 0.1 * i,
        }
        for i, p0 in enumerate((5e5, 1e6, 1.5e6))
    ]
    nf = normal_study_figures(nrows)
    assert [n for n, _, _ in nf] == ["study-normal-loop-quantities", "study-normal-b-coefficients"]
    ax = nf[0][1].axes[0]
    np.testing.assert_allclose(ax.get_lines()[0].get_xdata(), [0.5, 1.0, 1.5])
    plt.close("all")
    assert not math.isnan(rows[0]["h0"])


def test_trends_match_exact_masing():
    """E grows with load and amplitude; k_g grows with load and falls with amplitude; c_e·ω
    rises with A below its peak at ac·A ≈ 2.69 and falls above it."""
    rows = [r for r in _tangential_rows() if r["material"] == "Al/Al"]  # ac·A = 0.6 .. 2.4
    t = {e["quantity"]: e for e in trends(rows)}
    assert t["energy_per_cycle"]["with_load"] == "rises at 3 of 3 amplitudes"
    assert t["energy_per_cycle"]["with_amplitude"] == "rises at 3 of 3 loads"
    assert t["k_global"]["with_load"] == "rises at 3 of 3 amplitudes"
    assert t["k_global"]["with_amplitude"] == "falls at 3 of 3 loads"
    assert t["equivalent_damping"]["with_amplitude"] == "rises at 3 of 3 loads"
    assert t["k_local0"]["with_amplitude"] == "not monotone at any of 3 loads"  # constant
    z = np.linspace(0.05, 10, 4000)
    assert z[np.argmax(Masing(1.0, 1.0).equivalent_damping(z))] == pytest.approx(2.69, abs=0.01)
    across = []
    for W in (50.0, 100.0):
        m = Masing(0.4 * W, 1e5)  # ac·A = 1, 2.69, 7: across the peak of c_e·ω
        for A in (10e-6, 26.9e-6, 70e-6):
            across.append({"material": "x", "normal_load": W, "amplitude_nominal": A,
                           "equivalent_damping": float(m.equivalent_damping(A))})  # fmt: skip
    t = {e["quantity"]: e for e in trends(across, ["equivalent_damping"])}
    assert t["equivalent_damping"]["with_amplitude"] == "not monotone at any of 2 loads"
    assert t["equivalent_damping"]["with_load"] == "rises at 3 of 3 amplitudes"


def test_report_of_a_study_has_plots_trends_and_provenance():
    from contactlab.report.study_report import build_report

    rows = _tangential_rows()
    for r in rows:
        r.update(format="csv", n_samples=1200, fs=200.0, units_assumed_si="")
    rows[0]["units_assumed_si"] = "x"
    rep = build_report(_result(rows), "t", details=False)
    html = rep.render_html()
    assert "against normal load" in html and "rises at 3 of 3 amplitudes" in html
    assert len(rep.figures) == 8  # 2 materials × 4 quantities
    assert "1 file(s) have columns without units, read as SI" in html
    plt.close("all")
