"""Dynamic-only pressure channels (piezo sensors, mean zero): p0 and pa from the Python API,
the CLI flags --p0/--pa, the file-name tags and the manifest columns (issue 8 item 4)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from contactlab import ContactLabWarning, InputError
from contactlab.cli import main
from contactlab.commands.common import with_static_pressure
from contactlab.io import read_recording
from contactlab.normal import analyze_loop
from contactlab.synthetic.normal import synthetic_recording


@pytest.fixture(scope="module")
def piezo():
    t, p, d = synthetic_recording(p0=0.5e6, pa=0.4e6, omega=2 * np.pi, n_cycles=5, seed=41)
    return t, p - 0.5e6, d  # the sensor sees only the dynamic pressure


def _csv(path, t, p, d):
    rows = "\n".join(
        f"{a:.6f},{b / 1e6:.8f},{c * 1e6:.6f}" for a, b, c in zip(t, p, d, strict=True)
    )
    path.write_text("t [s],p [MPa],delta [um]\n" + rows + "\n")
    return path


def test_api_p0_and_nominal_pa(piezo):
    t, p, d = piezo
    with pytest.raises(InputError, match="give the static pressure p0"):
        analyze_loop(t, p, d)
    r = analyze_loop(t, p, d, p0=0.5e6, pa=0.4e6)
    assert r.p0 == 0.5e6 and r.pa == pytest.approx(0.4e6, rel=0.02)
    dd = r.to_dict()
    assert dd["p0_source"] == "given" and dd["pa_nominal"] == 0.4e6
    with pytest.warns(ContactLabWarning, match="differs from the nominal"):
        analyze_loop(t, p, d, p0=0.5e6, pa=0.3e6)
    with pytest.raises(InputError, match="pa must be"):
        analyze_loop(t, p, d, p0=0.5e6, pa=-1.0)


def test_cli_flags_tags_and_manifest(piezo, tmp_path, capsys):
    t, p, d = piezo
    bare = _csv(tmp_path / "piezo.csv", t, p, d)
    out = tmp_path / "o.json"
    assert main(["analyze", str(bare), "--model", "normal", "--json", str(out)]) == 1
    assert "--p0 0.5MPa" in capsys.readouterr().err
    assert main(["analyze", str(bare), "--model", "normal", "--p0", "0.5MPa", "--pa", "400kPa",
                 "--json", str(out)]) == 0  # fmt: skip
    doc = json.loads(out.read_text())
    assert doc["p0"] == 0.5e6 and doc["pa_nominal"] == 4e5 and doc["p0_source"] == "given"
    tagged = _csv(tmp_path / "C45-C45_p0-0.5MPa_pa-0.4MPa.csv", t, p, d)
    assert main(["analyze", str(tagged), "--model", "normal", "--json", str(out)]) == 0
    assert json.loads(out.read_text())["p0"] == 0.5e6
    (tmp_path / "manifest.csv").write_text(
        "file,kind,material,p0 [MPa],pa [MPa]\npiezo.csv,normal,C45/C45,0.5,0.4\n"
    )
    rep = tmp_path / "rep"
    assert main(["study", str(tmp_path / "manifest.csv"), "--report", str(rep)]) == 0
    table = (rep / "study_normal.csv").read_text()
    assert "p0_source" in table.splitlines()[0] and ",given," in table
    capsys.readouterr()


def test_diagnose_gets_the_static_pressure(piezo, tmp_path):
    t, p, d = piezo
    f = _csv(tmp_path / "C45_p0-0.5MPa.csv", t, p, d)
    rec = read_recording(f, kind="normal")
    assert np.mean(with_static_pressure(rec, str(f), None, None)["p"]) == pytest.approx(
        0.5e6, rel=0.01
    )
    bare = _csv(tmp_path / "bare.csv", t, p, d)
    with pytest.raises(InputError, match="--p0"):
        with_static_pressure(read_recording(bare, kind="normal"), str(bare), None, None)
    r2 = with_static_pressure(read_recording(bare, kind="normal"), str(bare), 1e6, None)
    assert np.mean(r2["p"]) == pytest.approx(1e6, rel=0.01)
