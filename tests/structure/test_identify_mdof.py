"""Structures of several DOFs: identification of a chain of masses or of M/C/K masks with a
joint between two DOFs or to the ground (noise on input and output, seeds not used while
developing), persistence, prediction of a new input and the CLI with several y channels."""

from __future__ import annotations

import json

import numpy as np
import pytest

import contactlab
from contactlab.cli import main
from contactlab.structure import IdentifiedModel, Structure, identify

M2 = np.diag([1.0, 0.5])


def _chain(k0: float, k1: float, c0: float, c1: float) -> tuple[np.ndarray, np.ndarray]:
    K = np.array([[k0 + k1, -k1], [-k1, k1]])
    C = np.array([[c0 + c1, -c1], [-c1, c1]])
    return C, K


def _multisine(t: np.ndarray, rng: np.random.Generator, f_hi: float, rms: float) -> np.ndarray:
    u = sum(np.sin(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi)) for f in np.arange(3, f_hi, 0.5))
    return u * rms / np.std(u)


def _noisy(rng: np.random.Generator, u: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, ...]:
    um = u + 0.01 * np.std(u) * rng.standard_normal(u.shape)
    ym = y + 0.01 * np.std(y, axis=0) * rng.standard_normal(y.shape)
    return um, ym


def _force_record(seed: int, n: int = 1500, fs: float = 500.0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    u = _multisine(t, rng, 60.0, 6.0)
    C, K = _chain(4e3, 2e3, 2.0, 1.0)
    s = Structure(M2, C, K)
    s.add_joint("jenkins", 0, 1, k=1.5e3, fs=1.5)
    f = np.zeros((n, 2))
    f[:, 1] = u
    y = s.simulate(t, force=f, substeps=4).x
    return (t, *_noisy(rng, u, y), y, s)


def test_chain_with_joint_between_dofs_recovers_parameters():
    t, u, y, _, truth = _force_record(40417)
    m = identify(t, u, y, joint="jenkins", joint_dofs=(0, 1), input_dof=1, substeps=2)
    assert m.fit.success and m.structure.n == 2
    p = m.fit.params
    truth_values = {"m0": 1.0, "m1": 0.5, "k0": 4e3, "k1": 2e3, "kj": 1.5e3, "fs": 1.5,
                    "c0": 2.0, "c1": 1.0}  # fmt: skip
    for name, value in truth_values.items():
        tol = 0.05 if name[0] == "c" else 0.015
        assert abs(p[name].value - value) <= tol * value, (name, p[name].value, value)
        # the standard errors allow for the input noise (1 %), and cover the error
        assert p[name].stderr is not None and p[name].stderr < tol * value
        assert abs(p[name].value - value) <= 3 * p[name].stderr, (name, p[name])
        assert p[name].identifiable
    assert m.noise is not None and 0.5 < m.noise["input_noise"] / (0.01 * 6.0) < 2.0
    assert {"x0_0", "v0_0", "x0_1", "v0_1"} <= set(p)
    assert len(m.starts) > 1  # multistart
    # a new input (another multisine, other band) is predicted from rest
    rng = np.random.default_rng(40418)
    t2 = np.arange(1200) / 500.0
    u2 = _multisine(t2, rng, 30.0, 4.0)
    f2 = np.zeros((t2.size, 2))
    f2[:, 1] = u2
    ref = truth.simulate(t2, force=f2, substeps=4).x
    pred = m.simulate(t2, force=u2).x
    assert pred.shape == (t2.size, 2)
    err = np.sqrt(np.mean((pred - ref) ** 2, axis=0)) / np.std(ref, axis=0)
    assert np.all(err < 0.02), err


def test_masks_base_excited_joint_to_ground_recovers_parameters(tmp_path):
    rng = np.random.default_rng(40419)
    n = 2000
    t = np.arange(n) / 500.0
    ub = _multisine(t, rng, 40.0, 2e-3)
    K = np.array([[6e3, -2e3], [-2e3, 2.5e3]])
    C = np.array([[3.0, -1.0], [-1.0, 1.5]])
    s = Structure(M2, C, K)
    s.add_joint("masing", 1, None, h0=2.0, ac=1500.0)
    y_true = s.simulate(t, base=ub, substeps=4).x
    u, y = _noisy(rng, ub, y_true)
    m = identify(t, u, y, joint="masing", excitation="base", masks={"K": np.ones((2, 2), bool)},
                 joint_dofs=(1, None), mass=[1.0, 0.5], substeps=2)  # fmt: skip
    p = m.fit.params
    truth = (("K[0,0]", 6e3, 0.01), ("K[0,1]", -2e3, 0.01), ("K[1,1]", 2.5e3, 0.01),
             ("C[0,0]", 3.0, 0.05), ("C[1,1]", 1.5, 0.05), ("h0", 2.0, 0.02),
             ("ac", 1500.0, 0.03))  # fmt: skip
    for name, value, tol in truth:
        assert abs(p[name].value - value) <= tol * abs(value), (name, p[name].value)
        assert p[name].stderr is not None
    assert "M[0,0]" not in p  # the masses were given
    assert m.rms < 1.5 * 0.01 * float(np.std(y_true))
    np.testing.assert_allclose(m.structure.M, M2)
    # masks survive the JSON round trip; the loaded model predicts the same
    m.save(tmp_path / "masks.json")
    m2 = IdentifiedModel.load(tmp_path / "masks.json")
    assert [n for n, _ in m2.pattern.basis["K"]] == ["K[0,0]", "K[0,1]", "K[1,1]"]
    np.testing.assert_array_equal(m2.simulate(t, base=u).x, m.simulate(t, base=u).x)


def test_mdof_json_round_trip_and_bad_input(tmp_path):
    t, u, y, _, _ = _force_record(40420, n=500)
    m = identify(t, u, y, joint="jenkins", joint_dofs=(0, 1), input_dof=1, substeps=1,
                 multistart=False, max_nfev=30)  # fmt: skip
    m.save(tmp_path / "m.json")
    d = json.loads((tmp_path / "m.json").read_text())
    assert d["n_dofs"] == 2 and d["input_dof"] == 1 and d["joint_dofs"] == [0, 1]
    assert d["pattern"]["kind"] == "chain" and len(d["x0"]) == 2
    m2 = IdentifiedModel.load(tmp_path / "m.json")
    np.testing.assert_array_equal(m.simulate(t, force=u).x, m2.simulate(t, force=u).x)
    assert m2.joint_dofs == (0, 1) and m2.x0 == m.x0
    with pytest.raises(contactlab.InputError, match="joint_dofs"):
        identify(t, u, y, joint="jenkins", joint_dofs=(0, 5))
    with pytest.raises(contactlab.InputError, match="different DOFs"):
        identify(t, u, y, joint="jenkins", joint_dofs=(1, 1))
    with pytest.raises(contactlab.InputError, match="input_dof"):
        identify(t, u, y, joint="jenkins", input_dof=2)
    with pytest.raises(contactlab.InputError, match="masses"):
        identify(t, u, y, joint="jenkins", excitation="base")
    with pytest.raises(contactlab.InputError, match="constant"):
        identify(t, u, np.column_stack([y[:, 0], np.full(t.size, 1e-3)]), joint="jenkins")
    with pytest.raises(contactlab.InputError, match="K mask must free every diagonal"):
        identify(t, u, y, joint="jenkins", masks={"K": [[0, 1], [1, 1]]})
    with pytest.raises(contactlab.InputError, match="symmetric"):
        identify(t, u, y, joint="jenkins", masks={"K": [[1, 1], [0, 1]]})
    with pytest.raises(contactlab.InputError, match="several DOFs"):
        identify(t, u, y, joint="normal")
    with pytest.raises(contactlab.InputError, match="differ in length"):
        identify(t, u[:-1], y, joint="jenkins")
    # the structure diagnosis takes one DOF: a sentence, not a wrong answer
    with pytest.raises(contactlab.InputError, match="single-DOF"):
        contactlab.diagnose((t, u, y[:, 1]), base=m)


def test_cli_identify_several_y_channels(tmp_path, capsys):
    t, u, y, _, _ = _force_record(40421, n=700)
    csv = tmp_path / "rec.csv"
    np.savetxt(csv, np.column_stack([t, u, y]), delimiter=",", header="t,u_N,x0_m,x1_m",
               comments="")  # fmt: skip
    out = tmp_path / "model.json"
    rc = main(["identify", str(csv), "--joint", "jenkins", "--y", "x0_m,x1_m", "--joint-dofs",
               "0,1", "--input-dof", "1", "--substeps", "1", "--holdout", "0.2", "--json",
               str(out), "--report", str(tmp_path / "rep")])  # fmt: skip
    assert rc == 0
    d = json.loads(out.read_text())
    assert d["columns"]["y"] == ["x0_m", "x1_m"] and d["n_dofs"] == 2
    assert d["summary"]["rms_holdout"] < 0.05 * float(np.std(y))
    assert (tmp_path / "rep" / "report.html").exists()
    assert "RMS output error" in capsys.readouterr().out
    # the saved model predicts a new input from the command line, one column per DOF
    pred = tmp_path / "pred.csv"
    assert main(["simulate", "structure", str(pred), "--structure", str(out), "--input",
                 str(csv)]) == 0  # fmt: skip
    head = pred.read_text().splitlines()[0]
    assert head.startswith("t [s],u [N],x0 [m],x1 [m]")
    sim = np.loadtxt(pred, delimiter=",", skiprows=1)
    assert sim.shape == (t.size, 5)
    rc = main(["identify", str(csv), "--joint", "jenkins", "--y", "x0_m,x1_m", "--joint-dofs",
               "0,x", "--json", str(tmp_path / "bad.json")])  # fmt: skip
    assert rc != 0 and not (tmp_path / "bad.json").exists()


def test_cli_columns_by_bare_name():
    """``--u u --y x0,x1`` pick the columns ``u [N]``, ``x0 [m]``, ``x1 [m]`` that contactlab's
    own writers (``simulate structure``, ``write_recording``) head them with."""
    from contactlab import InputError
    from contactlab.commands.structure import pick_column

    cols = {"t [s]": np.zeros(2), "u [N]": np.zeros(2), "x0 [m]": np.zeros(2), "x1_m": np.zeros(2)}
    assert pick_column(cols, "u", (), "u", "f.csv") == "u [N]"
    assert pick_column(cols, "x1", (), "y", "f.csv") == "x1_m"
    assert pick_column(cols, "x0 [m]", (), "y", "f.csv") == "x0 [m]"
    with pytest.raises(InputError, match="no column 'x2'"):
        pick_column(cols, "x2", (), "y", "f.csv")
    both = {"u [N]": np.zeros(2), "u_N": np.zeros(2)}  # ambiguous: refused, not guessed
    with pytest.raises(InputError, match="no column 'u'"):
        pick_column(both, "u", (), "u", "f.csv")


def test_cli_identify_masks_inline_and_file(tmp_path, capsys):
    t, u, y, _, _ = _force_record(40431, n=600)
    csv = tmp_path / "rec.csv"
    np.savetxt(csv, np.column_stack([t, u, y]), delimiter=",", header="t,u_N,x0_m,x1_m",
               comments="")  # fmt: skip
    common = ["identify", str(csv), "--joint", "jenkins", "--y", "x0_m,x1_m", "--joint-dofs",
              "0,1", "--input-dof", "1", "--substeps", "1"]  # fmt: skip
    out = tmp_path / "m.json"
    assert main([*common, "--masks", '{"K": [[1, 1], [1, 1]]}', "--json", str(out)]) == 0
    d = json.loads(out.read_text())
    assert d["pattern"]["kind"] == "masks"
    assert d["pattern"]["parameters"]["K"] == ["K[0,0]", "K[0,1]", "K[1,1]"]
    assert d["pattern"]["parameters"]["M"] == ["M[0,0]", "M[1,1]"]  # missing M: the diagonal
    k = d["fit"]["params"]
    assert (
        abs(k["K[0,1]"]["value"] / -2e3 - 1) < 0.03 and abs(k["K[1,1]"]["value"] / 2e3 - 1) < 0.03
    )
    mfile = tmp_path / "masks.json"
    mfile.write_text(json.dumps({"K": [[True, False], [False, True]], "C": [[1, 0], [0, 1]]}))
    out2 = tmp_path / "m2.json"
    assert main([*common, "--masks", str(mfile), "--json", str(out2)]) == 0
    assert json.loads(out2.read_text())["pattern"]["parameters"]["K"] == ["K[0,0]", "K[1,1]"]
    capsys.readouterr()
    for bad, msg in (("{not json", "--masks is not valid JSON"),
                     (str(tmp_path / "absent.json"), "cannot read --masks file"),
                     ("[1, 2]", "cannot read --masks file"),
                     ('{"K": [[1, 0], [1, 1]]}', "K mask must be symmetric"),
                     ('{"X": [[1]]}', "masks are given for M, C and K only")):  # fmt: skip
        bad_out = tmp_path / "bad.json"
        assert main([*common, "--masks", bad, "--json", str(bad_out)]) != 0
        assert msg in capsys.readouterr().err and not bad_out.exists()
    one = ["identify", str(csv), "--joint", "jenkins", "--y", "x0_m", "--masks", "{}"]
    assert main(one) != 0
    assert "--masks needs several response channels" in capsys.readouterr().err


def test_kelvin_voigt_joint_between_dofs_with_masks():
    """A spring-damper joint between two masses that are otherwise only grounded (K and C
    masks on the diagonal): the joint's kj, cj are recovered; where the pattern already
    has the coupling (a chain) the joint is refused as not identifiable."""
    rng = np.random.default_rng(40441)
    n = 800
    t = np.arange(n) / 500.0
    u = _multisine(t, rng, 40.0, 6.0)
    s = Structure(M2, np.diag([2.0, 1.0]), np.diag([4e3, 1e3]))
    s.add_joint("kelvin_voigt", 0, 1, k=2e3, c=1.5)
    f = np.zeros((n, 2))
    f[:, 1] = u
    y = s.simulate(t, force=f, substeps=2).x
    um, ym = _noisy(rng, u, y)
    eye = np.eye(2, dtype=bool)
    m = identify(t, um, ym, joint="kelvin_voigt", joint_dofs=(0, 1), input_dof=1, substeps=2,
                 masks={"K": eye, "C": eye})  # fmt: skip
    p = m.fit.params
    for name, value, tol in (("kj", 2e3, 0.02), ("cj", 1.5, 0.1), ("K[0,0]", 4e3, 0.02),
                             ("K[1,1]", 1e3, 0.05), ("M[1,1]", 0.5, 0.02)):  # fmt: skip
        assert abs(p[name].value - value) <= tol * value, (name, p[name].value)
        assert abs(p[name].value - value) <= 3 * p[name].stderr, (name, p[name])
    pred = m.simulate(t, force=u).x
    assert np.sqrt(np.mean((pred - y) ** 2)) < 0.01 * np.std(y)
    with pytest.raises(contactlab.InputError, match="duplicates the structure's own spring"):
        identify(t, um, ym, joint="kelvin_voigt", joint_dofs=(0, 1), input_dof=1)
