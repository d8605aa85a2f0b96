"""Identification of structures with joints: known parameters recovered from simulated
records with noise on input and output (seeds not used while developing), the Bouc-Wen
benchmark's training record (skipped without ../shared/data), persistence and the CLI."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import contactlab
from contactlab.cli import main
from contactlab.structure import IdentifiedModel, Structure, identify

DATA = Path(__file__).resolve().parents[2].parent / "shared" / "data"


def _record(joint: str, params: dict, seed: int, n: int = 1500, fs: float = 500.0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    u = sum(np.sin(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi)) for f in np.arange(3, 60, 0.5))
    u *= 6.0 / np.std(u)
    s = Structure(1.0, 2.0, 4e3)
    s.add_joint(joint, 0, **params)
    y = s.simulate(t, force=u, substeps=4).x
    um = u + 0.01 * np.std(u) * rng.standard_normal(n)
    ym = y + 0.01 * np.std(y) * rng.standard_normal(n)
    return t, um, ym, y


@pytest.mark.parametrize(
    "joint,params,seed,checks",
    [
        ("jenkins", {"k": 3e3, "fs": 2.0}, 90211,
         {"m": (1.0, 0.01), "k": (4e3, 0.01), "kj": (3e3, 0.03), "fs": (2.0, 0.03)}),
        ("bouc_wen", {"alpha": 3e3, "beta": 1.0, "gamma": 300.0, "delta": -100.0, "nu": 1.0},
         90212, {"m": (1.0, 0.01), "k": (4e3, 0.01), "alpha": (3e3, 0.02),
                 "gamma": (300.0, 0.05), "delta": (-100.0, 0.08)}),
    ],
)  # fmt: skip
def test_identify_recovers_known_parameters_with_noise(joint, params, seed, checks):
    t, u, y, y_true = _record(joint, params, seed)
    m = identify(t, u, y, joint=joint, substeps=2)
    assert m.fit.success
    for name, (value, rel) in checks.items():
        got = m.fit.params[name].value
        assert abs(got - value) <= rel * abs(value), (name, got, value)
        assert m.fit.params[name].stderr is not None
        # honest errors: they allow for the input noise and cover the error
        assert abs(got - value) <= 3 * m.fit.params[name].stderr, (name, m.fit.params[name])
    assert 0.5 < m.noise["input_noise"] / (0.01 * 6.0) < 2.0
    # 1 % output noise: the residual is at the noise level, the clean response is predicted
    assert m.rms < 1.5 * 0.01 * np.std(y_true)
    pred = m.simulate(t, force=u).x
    assert np.sqrt(np.mean((pred - y_true) ** 2)) < 0.02 * np.std(y_true)


def test_identified_model_json_round_trip(tmp_path):
    t, u, y, _ = _record("jenkins", {"k": 3e3, "fs": 2.0}, 90213, n=600)
    m = identify(t, u, y, joint="jenkins", substeps=1, multistart=False)
    m.save(tmp_path / "m.json")
    m2 = IdentifiedModel.load(tmp_path / "m.json")
    np.testing.assert_array_equal(m.simulate(t, force=u).x, m2.simulate(t, force=u).x)
    d = json.loads((tmp_path / "m.json").read_text())
    assert {"joint", "excitation", "structure", "fit", "x0", "v0", "noise"} <= set(d)
    assert m2.noise == m.noise and m.noise["input_noise"] >= 0.0
    with pytest.raises(contactlab.InputError, match="force-excited"):
        m2.simulate(t, base=u)


def test_identify_bad_input():
    t = np.arange(100) / 100.0
    with pytest.raises(contactlab.InputError, match="joint must be"):
        identify(t, t, t, joint="spring")
    with pytest.raises(contactlab.InputError, match="mass"):
        identify(t, t, t, joint="jenkins", excitation="base")
    with pytest.raises(contactlab.InputError, match="differ in length"):
        identify(t, t[:50], t)


def test_boucwen_benchmark_holdout():
    """Trained on period 1 of the benchmark's training record (8192 samples, from rest),
    simulated over periods 1-5: the error on the held-out period 5 must be below 2e-5 m.
    The bound: the record's output noise alone gives ~5.2e-6 m, the true model simulated
    with this integrator 7.3e-6 m; published black-box/grey-box results on the validation
    multisine are 1e-5…5e-5 m, so 2e-5 m is the better half of them while leaving a
    factor ~2 for training on one period only (benches/eval_boucwen.py trains on four)."""
    path = DATA / "boucwen" / "train_multisine.csv"
    if not path.exists():
        pytest.skip("../shared/data absent")
    d = np.loadtxt(path, delimiter=",", comments="#")
    u, y = d[:, 0], d[:, 1]
    n = 8192
    t = np.arange(u.size) / 750.0
    m = identify(t[:n], u[:n], y[:n], joint="bouc_wen", substeps=2, multistart=False,
                 estimate_initial_state=False)  # fmt: skip
    r = m.simulate(t, force=u, interpolation="fourier")
    e = np.sqrt(np.mean((r.x[4 * n :] - y[4 * n :]) ** 2))
    assert e < 2e-5, e


def test_cli_identify_and_simulate(tmp_path):
    t, u, y, _ = _record("jenkins", {"k": 3e3, "fs": 2.0}, 90214, n=500)
    rec = tmp_path / "rec.csv"
    rec.write_text("t_s,u_force_N,y_disp_mm\n" + "\n".join(
        f"{a:.9g},{b:.9g},{1e3 * c:.9g}" for a, b, c in zip(t, u, y, strict=True)))  # fmt: skip
    js, rep = tmp_path / "model.json", tmp_path / "rep"
    argv = ["identify", str(rec), "--joint", "jenkins", "--json", str(js), "--report", str(rep),
            "--substeps", "1", "--holdout", "0.2"]  # fmt: skip
    assert main(argv) == 0
    doc = json.loads(js.read_text())
    assert doc["joint"] == "jenkins" and doc["summary"]["rms_holdout"] > 0
    assert (rep / "report.html").exists() and (rep / "figures" / "joint-loop.png").exists()
    out = tmp_path / "sim.csv"
    assert main(["simulate", "structure", str(out), "--structure", str(js), "--input",
                 str(rec)]) == 0  # fmt: skip
    sim = np.loadtxt(out, delimiter=",", skiprows=1)
    assert sim.shape == (500, 4)
    assert main(["identify", str(tmp_path / "missing.csv")]) == 1
    # a report that cannot be written leaves the previous JSON as it was
    before = js.read_bytes()
    blocker = tmp_path / "blocker"
    blocker.write_text("a file where the report's folder would be")
    argv[argv.index("--report") + 1] = str(blocker / "rep")
    assert main(argv) == 1
    assert js.read_bytes() == before


def test_cli_simulate_that_stops_early_writes_nothing_unless_partial(tmp_path, capsys):
    # negative damping: the response grows until Newton gives up part-way
    s = Structure(1.0, -50.0, 1.0)
    js = tmp_path / "unstable.json"
    s.save(js)
    t = np.arange(2000) * 1e-2
    src = tmp_path / "in.csv"
    src.write_text("t,u\n" + "\n".join(f"{a:.9g},{np.sin(a):.9g}" for a in t))
    out = tmp_path / "sim.csv"
    argv = ["simulate", "structure", str(out), "--structure", str(js), "--input", str(src)]
    assert main(argv) == 1
    said = capsys.readouterr().err
    assert "stopped early" in said and "nothing written" in said
    assert not out.exists()
    assert main([*argv, "--partial"]) == 1
    assert "wrote" in capsys.readouterr().err
    sim = np.loadtxt(out, delimiter=",", skiprows=1, ndmin=2)
    assert 0 < sim.shape[0] < t.size and np.all(np.isfinite(sim))


def _short_frame(seed: int, dt: float, noise: float, n: int = 400):
    """A base-excited frame with a Jenkins joint to the wall on a short record: 400 samples,
    1 mm base motion (three tones near 1, 2.7, 4.3 Hz), noise on both channels."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt
    freqs = np.array([1.0, 2.7, 4.3]) * rng.uniform(0.9, 1.1)
    arg = 2 * np.pi * freqs[None, :] * t[:, None] + rng.uniform(0, 2 * np.pi, 3)
    ub = np.sin(arg) @ (np.array([1.0, 0.3, 0.16]) * 1e-3)
    s = Structure(3.08, 0.67, 1200.0)
    s.add_joint("jenkins", 0, k=6000.0, fs=0.9)
    x = s.simulate(t, base=ub, substeps=4).x
    return (t, ub + noise * np.std(ub) * rng.standard_normal(n),
            x + noise * np.std(x) * rng.standard_normal(n), noise * np.std(x))  # fmt: skip


def test_short_base_excited_record_where_the_equation_error_fails():
    """400 samples, 1 mm: the regression's stiffness comes out negative (the mass is held by
    the wall more than by its spring); identify starts from output-error grids instead of
    stopping with "non-positive stiffness"."""
    from contactlab.structure.identify import equation_error

    def fails(s: int) -> bool:
        return equation_error(*_short_frame(s, 1e-3, 0.03)[:3], "base", 3.08)["k"] <= 0

    seed = next(s for s in range(91000, 91100) if fails(s))
    t, u, y, sigma = _short_frame(seed, 1e-3, 0.03)
    m = identify(t, u, y, joint="jenkins", excitation="base", mass=3.08, substeps=2)
    assert m.fit.success
    assert m.rms < 1.3 * sigma
    p = m.fit.params
    for name, value in (("k", 1200.0), ("kj", 6000.0), ("fs", 0.9)):
        assert p[name].value == pytest.approx(value, rel=0.05), name
    assert any("grid_f" in r["start"] for r in m.starts)


def test_linear_grid_start_finds_the_natural_frequency():
    from contactlab.structure.identify import linear_grid_start

    rng = np.random.default_rng(91200)
    t = np.arange(800) / 200.0
    u = sum(np.sin(2 * np.pi * f * t + rng.uniform(0, 6.3)) for f in (1.3, 2.9, 4.1, 7.7))
    s = Structure(2.0, 1.5, 800.0)  # 3.18 Hz
    step = (t.size / 6.0) ** (1 / 23)  # the grid's ratio between frequencies
    for exc, kw, mass in (("force", {"force": u}, None), ("base", {"base": 1e-3 * u}, 2.0)):
        x = s.simulate(t, **kw).x
        uu = kw.get("force", kw.get("base"))
        g = linear_grid_start(t, uu, x, exc, mass)
        assert 1 <= len(g) <= 3 and g[0]["grid_rms"] <= g[-1]["grid_rms"]
        f0 = g[0]["grid_f"]
        assert 3.18 / step <= f0 <= 3.18 * step, (exc, f0)
        assert g[0]["k"] / g[0]["m"] == pytest.approx((2 * np.pi * f0) ** 2)
        if exc == "force":  # the scale: k within the grid's frequency step (squared)
            assert 800 / step**2 <= g[0]["k"] <= 800 * step**2
    assert linear_grid_start(t[:2], u[:2], u[:2], "force", None) == []


def test_noise_model_covariance_matches_monte_carlo_with_input_and_output_noise():
    """A model linear in its parameters and its input (two filters of the input): the
    errors from noise on both channels against the spread over 150 records; the noise
    levels estimated from the residual spectrum against the true ones."""
    from scipy.signal import lfilter

    from contactlab.fitting import least_squares_fit
    from contactlab.structure.fitkit import noise_model_covariance

    rng = np.random.default_rng(31337)
    n = 1024
    tt = np.arange(n) / 500.0
    u0 = sum(np.sin(2 * np.pi * f * tt + rng.uniform(0, 6.3)) for f in np.arange(3, 40, 0.5))
    r = 0.995  # a lightly damped resonance: the input noise rings for ~200 samples

    def g(x):
        return lfilter([1.0], [1.0, -2 * r * np.cos(0.15), r * r], x)

    def g2(x):
        return lfilter([1.0], [1.0, -0.9], x)

    truth = np.array([2.0, 0.5])
    y0 = truth[0] * g(u0) + truth[1] * g2(u0)
    su, sy = 0.02 * np.std(u0), 0.002 * np.std(y0)
    est, err, white, noise = [], [], [], []
    for _ in range(150):
        um = u0 + su * rng.standard_normal(n)
        ym = y0 + sy * rng.standard_normal(n)

        def res(p, uu=um, ym=ym):
            return p["a"] * g(uu) + p["b"] * g2(uu) - ym

        fit = least_squares_fit(res, {"a": 1.0, "b": 1.0})
        v = fit.values
        r0 = res(v)
        out, info = noise_model_covariance(fit, lambda du, v=v, r0=r0, um=um: res(v, um + du)
                                           - r0, um)  # fmt: skip
        est.append([v["a"], v["b"]])
        err.append([out.params["a"].stderr, out.params["b"].stderr])
        white.append([fit.params["a"].stderr, fit.params["b"].stderr])
        noise.append([info["input_noise"], info["output_noise"][0]])
    spread = np.std(est, axis=0)
    rms_err = np.sqrt(np.mean(np.square(err), axis=0))
    np.testing.assert_allclose(rms_err, spread, rtol=0.2)
    assert np.all(np.mean(white, axis=0) < 0.5 * spread)  # the white-noise errors do not
    np.testing.assert_allclose(np.median(noise, axis=0), [su, sy], rtol=0.15)
    cover = np.mean(np.abs(np.array(est) - truth) <= 2 * np.array(err))
    assert 0.88 <= cover <= 0.99


def test_joint_verbs_on_the_benchmark_record_say_what_it_is(tmp_path, capsys):
    """The record names its columns in a comment line (no header row): `analyze` and
    `diagnose` read them by those names; a structure driven by a multisine is no friction
    loop, and `diagnose` says so in a sentence (exit 1, no traceback)."""
    path = DATA / "boucwen" / "train_multisine.csv"
    if not path.exists():
        pytest.skip("../shared/data absent")
    cols = ["--columns", "x=y_displacement_m,F=u_force_N", "--fs", "750"]
    code = main(["diagnose", str(path), "--model", "tangential", *cols])
    err = capsys.readouterr().err
    assert code == 1 and "no friction loop" in err and "Traceback" not in err
    out = tmp_path / "a.json"
    assert main(["analyze", str(path), "--model", "tangential", *cols, "--json", str(out)]) == 0
    d = json.loads(out.read_text())
    assert d["regime"] == "transition"  # not pre-sliding: the model is warned about
    assert any("describe the loop poorly" in w for w in d["warnings"])
    # the cycles' area beyond the rectangle that bounds any friction loop: not one loop
    assert any("do not repeat one loop" in w for w in d["warnings"])
    assert 5e-4 < d["amplitude"] < 1e-3  # the response's half range, read from y_displacement_m
