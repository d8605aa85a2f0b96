"""contactlab.fem without the solver: export contents, units, refusals, CLI, .dat parsing."""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import contactlab.normal as cn
from contactlab import InputError, Masing
from contactlab.cli import main
from contactlab.fem import (
    NotIdentifiableError,
    joint_characteristics,
    render,
    unit_system,
)
from contactlab.fem.ccx import parse_dat
from contactlab.fem.checks import interaction_lines, loop_energy, pinned_spring_beam_frequency
from contactlab.fem.models import Beam, Block, beam_deck, two_block_deck
from contactlab.synthetic.normal import synthetic_recording as normal_recording
from contactlab.synthetic.tangential import synthetic_recording
from contactlab.tangential import analyze_tangential


@pytest.fixture(scope="module")
def tangential() -> dict:
    rec = synthetic_recording(h0=40.0, ac=4e4, amplitude=60e-6, n_cycles=4, fs=500.0,
                              noise=0.01, seed=11)  # fmt: skip
    d = analyze_tangential(rec).to_dict()
    return {**d, "model": "tangential", "file": "Al-Al_W50N_A60um.csv", "normal_load": 50.0}


@pytest.fixture(scope="module")
def tangential_small() -> dict:
    rec = synthetic_recording(h0=40.0, ac=4e4, amplitude=0.2e-6, n_cycles=4, fs=500.0,
                              noise=0.01, seed=12)  # fmt: skip
    with warnings.catch_warnings(record=True) as caught:  # other fit notes may come too
        warnings.simplefilter("always")
        d = analyze_tangential(rec).to_dict()
    assert any("NOT separately identifiable" in str(w.message) for w in caught)
    return {**d, "model": "tangential", "file": "St-St_W50N_A0.2um.csv", "normal_load": 50.0}


@pytest.fixture(scope="module")
def normal() -> dict:
    t, p, delta = normal_recording(p0=0.5e6, pa=0.4e6, omega=1.0, n_cycles=4, seed=13)
    return {**cn.analyze_loop(t, p, delta).to_dict(), "model": "normal", "file": "C45.csv"}


def test_tangential_values_follow_the_fit(tangential: dict) -> None:
    jc = joint_characteristics(tangential, area=5e-3, normal_load=50.0, amplitude=20e-6,
                               frequency=100.0)  # fmt: skip
    h0, ac = tangential["h0"], tangential["ac"]
    assert jc.get("mu").value == pytest.approx(h0 / 50.0)
    assert jc.get("mu").stderr == pytest.approx(tangential["h0_stderr"] / 50.0)
    assert jc.get("stick_slope").value == pytest.approx(tangential["h0_ac"] / 5e-3)
    # elastic slip = μp/λ = 1/ac: independent route through the exported numbers
    mu, lam = jc.get("mu").value, jc.get("stick_slope").value
    assert jc.get("elastic_slip").value == pytest.approx(mu * (50.0 / 5e-3) / lam, rel=1e-2)
    m = Masing(h0, ac)
    assert jc.get("k_global").value == pytest.approx(float(m.virgin(20e-6)) / 20e-6)
    e = 8 * (h0 * (20e-6 - (1 - math.exp(-ac * 20e-6)) / ac) - 20e-6 * float(m.virgin(20e-6)) / 2)
    assert jc.get("c_e").value == pytest.approx(e / (math.pi * 20e-6**2 * 2 * math.pi * 100.0))
    assert 0 < jc.get("k_global").stderr < 0.01 * jc.get("k_global").value


def test_calculix_and_abaqus_text(tangential: dict, normal: dict) -> None:
    jc = joint_characteristics(tangential, area=5e-3, normal_load=50.0, amplitude=20e-6,
                               frequency=100.0)  # fmt: skip
    mm = unit_system("mm-N-s")
    ccx = render(jc, "calculix", mm)
    assert "** source: Al-Al_W50N_A60um.csv" in ccx and "± " in ccx
    lines = ccx.splitlines()
    i = lines.index("*FRICTION")
    mu, lam = (float(v) for v in lines[i + 1].split(","))
    assert lam == pytest.approx(tangential["h0_ac"] / 5e-3 * 1e-9, rel=1e-8)  # N/mm³
    assert mu == pytest.approx(tangential["h0"] / 50.0, rel=1e-8)
    j = lines.index("*SPRING, ELSET=JOINT_SPRING")
    assert lines[j + 1] == "" and float(lines[j + 2]) == pytest.approx(
        jc.get("k_global").value * 1e-3, rel=1e-8
    )
    aba = render(jc, "abaqus", unit_system("SI"))
    assert f"*FRICTION, ELASTIC SLIP={1 / tangential['ac']:.9g}" in aba
    jn = joint_characteristics(normal)
    txt = render(jn, "abaqus", mm)
    assert "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=TABULAR" in txt
    assert "*CONTACT DAMPING, DEFINITION=DAMPING COEFFICIENT" in txt
    rows = interaction_lines(render(jn, "calculix", mm))[1 : 1 + len(jn.table)]
    tab = np.array([[float(v) for v in r.split(",")] for r in rows])
    assert np.allclose(tab, jn.table * [1e-6, 1e3], rtol=1e-8)


def test_ansys_and_neutral_forms(tangential: dict, normal: dict) -> None:
    jc = joint_characteristics(tangential, area=5e-3, normal_load=50.0, amplitude=20e-6,
                               frequency=100.0)  # fmt: skip
    ans = render(jc, "ansys", unit_system("mm-t-s"))
    assert f"MP,MU,1,{tangential['h0'] / 50.0:.9g}" in ans
    assert "ET,2,COMBIN14" in ans and all(ln.startswith(("!", "/", "MP", "R", "ET"))
                                          for ln in ans.splitlines())  # fmt: skip
    doc = json.loads(render(joint_characteristics(normal), "json", unit_system("SI")))
    pu = np.array(doc["pressure_overclosure"])
    assert pu[0].tolist() == [0.0, 0.0] and np.all(np.diff(pu, axis=0) > 0)
    names = {v["quantity"]: v for v in doc["values"]}
    assert names["c_contact"]["unit"] == "Pa·s/m" and names["psi"]["value"] > 0
    assert len(doc["ks_pressure"]) == 25 and "table_pressure" not in names
    csv_text = render(joint_characteristics(normal), "csv", unit_system("mm-N-s"))
    assert "table_pressure,0,0.0,,MPa,zero pressure" in csv_text


def test_normal_table_matches_the_loading_branch(normal: dict) -> None:
    jc = joint_characteristics(normal, points=40)
    p, u = jc.table[:, 0], jc.table[:, 1]
    assert p[0] == 0 and u[0] == 0 and np.all(np.diff(p) > 0) and np.all(np.diff(u) > 0)
    # measured rows lie on p0 + p_load(δ) with δ = u + δ*, δ* fixed by the last row
    d_star = normal["delta_max"] - u[-1]
    fit = normal["p0"] + np.polynomial.polynomial.polyval(u[1:] + d_star, normal["poly_load"])
    assert np.allclose(p[1:], fit, rtol=1e-9)
    assert p[-1] == pytest.approx(normal["p0"] + normal["pa"], rel=0.02)
    # the tangent segment to zero pressure continues the branch's slope at p0 - pa
    slope = np.polynomial.polynomial.polyval(
        u[1] + d_star, np.polynomial.polynomial.polyder(normal["poly_load"])
    )
    assert p[1] / u[1] == pytest.approx(slope, rel=1e-9)
    # k_s(p), eq. 6: at p0 (δ = 0) it is the centre curve's slope k_tan (eq. 4)
    ks = jc.ks_table
    assert np.interp(normal["p0"], ks[:, 0], ks[:, 1]) == pytest.approx(normal["k_tan"], rel=0.02)
    i = len(ks) // 3
    d_i = np.linspace(normal["delta_min"], normal["delta_max"], len(ks))[i]
    assert ks[i, 1] * d_i == pytest.approx(ks[i, 0] - normal["p0"], rel=1e-6)
    c = jc.get("c_contact").value
    assert c == pytest.approx(normal["psi"] * normal["k_tan"] / (2 * math.pi * normal["omega"]))
    c10 = joint_characteristics(normal, frequency=10.0).get("c_contact").value
    assert c10 == pytest.approx(c * normal["omega"] / (2 * math.pi * 10.0))


@settings(max_examples=40, deadline=None)
@given(
    a1=st.floats(2.0, 5.0),
    a=st.lists(st.floats(0.1, 5.0), min_size=3, max_size=3),
    p0=st.floats(0.05e6, 2e6),
    frac=st.floats(0.1, 1.5),
    n=st.integers(3, 60),
)
def test_table_is_monotone_from_zero(
    a1: float, a: list[float], p0: float, frac: float, n: int
) -> None:
    # p_load(δ) with positive coefficients in paper units (MPa, µm) is increasing for δ > 0;
    # a1 ≥ 2 keeps it increasing on [δ_min, δ_max] = [-0.1, 0.3] µm. frac > 1 makes the branch
    # itself reach zero pressure (p0 < pa).
    coeffs = [0.0] + [ai * 1e6 / 1e-6**k for k, ai in enumerate([a1, *a], start=1)]
    d = {
        "model": "normal",
        "p0": p0,
        "pa": frac * p0,
        "delta_min": -0.1e-6,
        "delta_max": 0.3e-6,
        "poly_load": coeffs,
        "poly_centre": coeffs,
        "k_tan": coeffs[1],
        "psi": 0.1,
        "omega": 1.0,
        "E_d": 1e-3,
    }
    jc = joint_characteristics(d, points=n)
    assert jc.table[0].tolist() == [0.0, 0.0]
    assert np.all(np.diff(jc.table, axis=0) > 0)
    si, mm = render(jc, "csv", unit_system("SI")), render(jc, "csv", unit_system("mm-N-s"))
    assert si.count("\n") == mm.count("\n")


def test_refusals(tangential: dict, tangential_small: dict, normal: dict) -> None:
    with pytest.raises(NotIdentifiableError, match="not identifi"):
        joint_characteristics(tangential_small, area=1e-3, normal_load=50.0)
    with pytest.raises(InputError, match="--area"):
        joint_characteristics(tangential, normal_load=50.0)
    with pytest.raises(InputError, match="--normal-load"):
        joint_characteristics({**tangential, "normal_load": None}, area=1e-3)
    with pytest.raises(InputError, match="contact_area = 'big'"):
        joint_characteristics({**tangential, "contact_area": "big"})
    # a manifest column without a unit arrives as text (SI)
    jc = joint_characteristics({**tangential, "contact_area": "0.005"})
    assert jc.get("stick_slope").value == pytest.approx(tangential["h0_ac"] / 0.005)
    with pytest.raises(InputError, match="--frequency"):
        joint_characteristics(tangential, area=1e-3, normal_load=50.0, amplitude=1e-5)
    bent = {**normal, "poly_load": [0.0, 1e12, -5e19]}  # turns over inside the loop
    with pytest.raises(NotIdentifiableError, match="not increasing"):
        joint_characteristics(bent)
    with pytest.raises(NotIdentifiableError, match="E_d"):
        joint_characteristics({**normal, "E_d_stderr": normal["E_d"]})
    with pytest.raises(InputError, match="model"):
        joint_characteristics({"model": "diagnose"})
    with pytest.raises(InputError, match="unit system"):
        unit_system("cgs")


def test_cli_end_to_end(tmp_path, capsys) -> None:
    sim, res = tmp_path / "Al-Al_W50N_A60um.csv", tmp_path / "fit.json"
    assert main(["simulate", "tangential", str(sim), "--amplitude", "60um", "--cycles", "4"]) == 0
    assert main(["analyze", str(sim), "--model", "tangential", "--json", str(res)]) == 0
    out = tmp_path / "joint.inp"
    args = ["export", str(res), "--format", "calculix", "-o", str(out), "--area", "50cm2",
            "--units", "mm-N-s", "--amplitude", "20um", "--frequency", "50Hz"]  # fmt: skip
    assert main(args) == 0
    text = out.read_text()
    assert "*FRICTION" in text and "normal load W: 50 N" in text and "0.005 m^2" in text
    capsys.readouterr()
    # no area: a clear error, exit 1, no file
    bad = tmp_path / "bad.inp"
    assert main(["export", str(res), "--format", "csv", "-o", str(bad)]) == 1
    assert "--area" in capsys.readouterr().err and not bad.exists()


def test_cli_refuses_unidentified(tmp_path, capsys) -> None:
    sim, res = tmp_path / "St-St_W50N_A0.2um.csv", tmp_path / "fit.json"
    main(["simulate", "tangential", str(sim), "--amplitude", "0.2um", "--cycles", "4",
          "--seed", "12"])  # fmt: skip
    main(["analyze", str(sim), "--model", "tangential", "--json", str(res)])
    out = tmp_path / "joint.inp"
    out.write_text("previous\n")
    rc = main(["export", str(res), "--format", "abaqus", "-o", str(out), "--area", "1cm2"])
    err = capsys.readouterr().err
    assert rc == 3 and "refused" in err and "friction coefficient needs h0" in err
    assert "separately identifiable" in err and "nothing written" in err
    assert out.read_text() == "previous\n"
    assert list(tmp_path.glob(".*part")) == []


def test_cli_input_errors(tmp_path, capsys) -> None:
    (tmp_path / "x.json").write_text("{not json")
    assert main(["export", str(tmp_path / "x.json"), "--format", "csv", "-o", "o.csv"]) == 1
    assert "not a JSON file" in capsys.readouterr().err
    multi = {"recordings": [{"model": "normal", "file": "a"}, {"model": "normal", "file": "b"}]}
    (tmp_path / "m.json").write_text(json.dumps(multi))
    assert main(["export", str(tmp_path / "m.json"), "--format", "csv", "-o", "o.csv"]) == 1
    assert "--recording" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["export", "r.json", "--format", "csv", "-o", "o.csv", "--area", "0cm2"])


_DAT = """
 displacements (vx,vy,vz) for set NTOP and time  0.5000000E+00

        46  0.000000E+00  0.000000E+00 -2.446428E-04
        47  1.071429E-06  0.000000E+00 -2.446430E-04

 contact stress (slave node,press,tang1,tang2) for all contact elements and time  0.5000000E+00

        28  1.499999E-01  0.000000E+00  0.000000E+00

 stresses (elem, integ.pnt.,sxx,syy,szz,sxy,sxz,syz) for set EB and time  0.1000000E+01

         9   1 -1.0E-02  2.0E-03 -1.500000E-01  0.0E+00  0.0E+00  0.0E+00
         9   2 -1.0E-02  2.0E-03 -1.500000E-01  0.0E+00  0.0E+00  0.0E+00

 total force (fx,fy,fz) for set NB and time  0.1025000E+01

        1.984817E+00 -3.924976E-08 -5.000000E+01

     E I G E N V A L U E   O U T P U T

 MODE NO    EIGENVALUE                       FREQUENCY
                                     REAL PART            IMAGINARY PART
                           (RAD/TIME)      (CYCLES/TIME     (RAD/TIME)

      1   0.1316383E+07   0.1147337E+04   0.1826044E+03   0.0000000E+00
      2   0.2316383E+08   0.4812882E+04   0.7659908E+03   0.0000000E+00
"""


def test_parse_dat() -> None:
    dat = parse_dat(_DAT)
    t, u = dat.series("displacements", "NTOP")
    assert t.tolist() == [0.5] and u[0].shape == (2, 4) and u[0][1, 3] == -2.446430e-4
    _, c = dat.series("contact stress")
    assert c[0][0, 1] == pytest.approx(0.15, rel=1e-5)
    t, f = dat.series("total force", "nb")
    assert t[0] == 1.025 and f[0].shape == (1, 3)
    _, s = dat.series("stresses", "EB")  # *EL PRINT
    assert s[0].shape == (2, 8) and s[0][1, 4] == -0.15
    assert dat.eigen.shape == (2, 5) and dat.eigen[1, 3] == pytest.approx(765.9908)


def test_decks_and_closed_forms() -> None:
    deck = two_block_deck(Block(n=3, m=2), ["*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR",
                                            "1000."], mode="normal", pressure=1.0)  # fmt: skip
    assert deck.count("\n") > 100 and "TYPE=NODE TO SURFACE" in deck
    n_nodes = sum(1 for ln in deck.split("*ELEMENT")[0].splitlines()[1:] if ln[0].isdigit())
    assert n_nodes == 2 * 4 * 4 * 3
    with pytest.raises(InputError):
        two_block_deck(Block(), [], mode="shear", pressure=1.0)
    b = Beam(length=1000.0, side=20.0)
    assert "*FREQUENCY" in beam_deck(b, ["*SPRING, ELSET=JOINT_SPRING", "", "1."])
    m = b.mass_per_length
    # limits: a stiff spring gives the pinned–pinned beam, a soft one the rigid rotation
    pp = math.pi**2 / b.length**2 * math.sqrt(b.EI / m) / (2 * math.pi)
    assert pinned_spring_beam_frequency(b, 1e9) == pytest.approx(pp, rel=1e-4)
    k = 1e-4
    rigid = math.sqrt(3 * k / (m * b.length)) / (2 * math.pi)
    assert pinned_spring_beam_frequency(b, k) == pytest.approx(rigid, rel=1e-4)


def test_loop_energy_of_a_bilinear_loop() -> None:
    fs, k, A = 2.0, 10.0, 1.0
    x = np.array([A, A - 2 * fs / k, -A, -A + 2 * fs / k])
    f = np.array([fs, -fs, -fs, fs])
    assert loop_energy(x, f) == pytest.approx(4 * fs * (A - fs / k))


def test_check_without_ccx_names_the_package(tmp_path, capsys, monkeypatch, normal) -> None:
    import contactlab.fem.ccx as ccx

    monkeypatch.setattr(ccx, "find_ccx", lambda: None)
    res = tmp_path / "fit.json"
    res.write_text(json.dumps(normal))
    out = tmp_path / "joint.inp"
    assert main(["export", str(res), "--format", "calculix", "-o", str(out), "--check"]) == 1
    assert "calculix-ccx" in capsys.readouterr().err and not out.exists()


def test_real_macro_slip_frame() -> None:
    """Measured macro-slip loops (friction frame, two normal loads) give μ from the plateau
    but do not resolve pre-sliding: the stick slope is refused with the analysis' reason
    (CalculiX's *FRICTION needs it, so that format is refused; Abaqus/ANSYS/CSV get μ alone).
    Coulomb: μ must not depend on the load."""
    from pathlib import Path

    from contactlab import Recording

    data = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "friction_frame"
    if not data.is_dir():
        pytest.skip("friction_frame data: ../shared/data absent")
    mus = []
    for grams in (250, 450):
        d = np.genfromtxt(data / f"frame_disc{grams}g.csv", delimiter=",", names=True)
        t, x, y = d["t_s"], d["x_top_plate_disp_mm"] * 1e-3, d["y_base_disp_mm"] * 1e-3
        dt = float(t[1] - t[0])
        xd, yd = np.gradient(x, dt), np.gradient(y, dt)
        # the authors' model: F_f = K (y − x) + C (y' − x') − M x''  (README of the data)
        f = 1191.0 * (y - x) + 0.6690 * (yd - xd) - 3.0799 * np.gradient(xd, dt)
        rec = Recording(t, {"x": x, "F": f}, {"x": "m", "F": "N"}, source=f"frame_{grams}g")
        with pytest.warns(Warning):
            res = {**analyze_tangential(rec).to_dict(), "model": "tangential"}
        w = grams * 1e-3 * 9.81
        jc = joint_characteristics(res, area=1e-4, normal_load=w)
        assert jc.get("stick_slope") is None and jc.get("elastic_slip") is None
        assert any("no stick slope: h0·ac is not identified" in n for n in jc.notes)
        mu = jc.get("mu")
        assert mu.stderr < 0.05 * mu.value
        # the plateau lies below the force's 95th percentile (stick-slip peaks, noise)
        assert mu.value * w < float(np.percentile(np.abs(f), 95))
        mus.append(mu.value)
        with pytest.raises(NotIdentifiableError, match="needs a stick slope"):
            render(jc, "calculix", unit_system("SI"))
        aba = render(jc, "abaqus", unit_system("SI")).splitlines()
        assert aba[-2] == "*FRICTION" and float(aba[-1]) == pytest.approx(mu.value)
        assert "RMODIF" not in render(jc, "ansys", unit_system("SI"))
        with pytest.raises(NotIdentifiableError, match="ac is not identified"):
            joint_characteristics(res, area=1e-4, normal_load=w, amplitude=1e-3, frequency=1.0)
    assert mus[0] == pytest.approx(mus[1], rel=0.1)


@settings(max_examples=30, deadline=None)
@given(
    h0=st.floats(1.0, 500.0),
    ac=st.floats(1e3, 1e6),
    area=st.floats(1e-6, 1e-1),
    load=st.floats(1.0, 1e4),
    system=st.sampled_from(["mm-N-s", "mm-t-s"]),
)
def test_units_scale_consistently(h0: float, ac: float, area: float, load: float,
                                  system: str) -> None:  # fmt: skip
    d = {"model": "tangential", "h0": h0, "h0_stderr": 0.01 * h0, "ac": ac,
         "ac_stderr": 0.01 * ac, "h0_ac": h0 * ac, "h0_ac_stderr": 0.01 * h0 * ac,
         "identifiable": {"h0": True, "ac": True, "h0_ac": True, "message": "ok"}}  # fmt: skip
    jc = joint_characteristics(d, area=area, normal_load=load, amplitude=2 / ac, frequency=50.0)
    u = unit_system(system)
    exps = {"length": 1, "stiffness_per_area": -3, "stiffness": -1, "damping": -1,
            "force": 0, "1": 0, "energy": 1}  # fmt: skip
    for v in jc.values:
        val = v.converted(u)[0]
        assert val == pytest.approx(v.value * 1e3 ** exps[v.dim], rel=1e-12)
    # the friction card in mm: λ·A_c·(1/ac) = μ·W (slip starts at the elastic slip 1/ac)
    lam = jc.get("stick_slope").converted(u)[0]
    assert lam * area * 1e6 / (ac * 1e-3) == pytest.approx(jc.get("mu").value * load, rel=1e-9)


def test_cli_mu_only(tmp_path, capsys) -> None:
    """Gross sliding: h0 from the plateau, no stick slope. CalculiX is refused (exit 3, no
    file); Abaqus gets μ alone."""
    d = {"model": "tangential", "file": "gs.csv", "regime": "gross sliding", "h0": 20.0,
         "h0_stderr": 0.2, "ac": None, "h0_ac": None, "ac_lower_bound": 5e5, "normal_load": 50.0,
         "identifiable": {"h0": True, "ac": False, "h0_ac": False,
                          "message": "plateau"}}  # fmt: skip
    res = tmp_path / "gs.json"
    res.write_text(json.dumps(d))
    out = tmp_path / "f.inp"
    args = ["export", str(res), "-o", str(out), "--area", "1cm2", "--format"]
    assert main([*args, "calculix"]) == 3 and not out.exists()
    err = capsys.readouterr().err
    assert "needs a stick slope" in err and "elastic slip ≤ 2e-06 m" in err
    assert main([*args, "abaqus"]) == 0
    assert out.read_text().rstrip().endswith("*FRICTION\n0.4")
