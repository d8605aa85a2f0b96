"""A friction frame from the command line (issue 8): ``analyze``/``diagnose --frame M,C,K``
read the top-plate and base displacements, reconstruct the friction force
(:func:`contactlab.tangential.read_frame`) and analyse / diagnose it, the diagnosis with the
reconstruction's declared smoothing and noise; ``diagnose --output-filter/--output-noise``
declare a known smoothing of a force channel.

On the measured frames of ``../shared/data/friction_frame`` (skipped when absent) and on an
independent Coulomb-frame simulation (tests/frame_sim.py) written as a CSV a user would have.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import contactlab
from contactlab.cli import main
from contactlab.tangential import frame_friction_force, read_frame
from frame_sim import simulate_frame

DATA = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "friction_frame"
FRAME = "3.0799,0.669,1191"  # the data set's README (kg, N s/m, N/m)


def _measured(load: str) -> Path:
    path = DATA / f"frame_disc{load}g.csv"
    if not path.is_file():
        pytest.skip("../shared/data absent: the measured frames are not here")
    return path


@pytest.fixture(scope="module")
def sim_file(tmp_path_factory):
    """A simulated frame (Fk 0.7 N, Fs 0.8 N, 500 Hz) with 0.5 um noise on both channels,
    written in µm under names the reader must find (``x_top [um]``, ``y_base [um]``)."""
    t, x, y, _F = simulate_frame(Fk=0.7, Fs=0.8, fs=500.0, T=6.0)
    rng = np.random.default_rng(8101)
    x = x + rng.normal(0, 5e-7, x.size)
    y = y + rng.normal(0, 5e-7, y.size)
    path = tmp_path_factory.mktemp("frame") / "rig_run3.csv"
    np.savetxt(path, np.c_[t, 1e6 * x, 1e6 * y], delimiter=",", comments="",
               header="time [s],x_top [um],y_base [um]")  # fmt: skip
    return path, t, x, y


@pytest.mark.parametrize("load", ["250", "450"])
def test_analyze_measured_frame_from_the_cli(load, tmp_path, capsys):
    path = _measured(load)
    out = tmp_path / "a.json"
    assert main(["analyze", str(path), "--model", "tangential", "--frame", FRAME,
                 "--json", str(out)]) == 0  # fmt: skip
    said = capsys.readouterr().out
    assert "x = 'x_top_plate_disp_mm' (mm)" in said and "y = 'y_base_disp_mm' (mm)" in said
    d = json.loads(out.read_text())
    rec = d["frame_reconstruction"]
    ref = read_frame(path, 3.0799, 0.669, 1191.0)  # the Python API: the same reconstruction
    assert rec["window"] == ref.window and rec["force_noise"] == pytest.approx(ref.force_noise)
    assert rec["columns"]["x"] == "x_top_plate_disp_mm" and rec["file_units"]["y"] == "mm"
    assert d["force_sign"] == 1  # a passive contact: the sign kept
    # h0 is the plateau: half the difference of the median sliding forces
    v = np.gradient(ref.x, ref.t)
    fast = np.abs(v) > 0.5 * np.max(np.abs(v))
    plateau = 0.5 * (np.median(ref.F[fast & (v > 0)]) - np.median(ref.F[fast & (v < 0)]))
    assert d["h0"] == pytest.approx(plateau, rel=0.1)


def test_friction_rises_with_the_normal_load_from_the_cli(tmp_path):
    h0 = {}
    for load in ("250", "450"):
        out = tmp_path / f"{load}.json"
        assert main(["analyze", str(_measured(load)), "--model", "tangential", "--frame",
                     "M=3.0799,C=0.669,K=1191", "--json", str(out)]) == 0  # fmt: skip
        h0[load] = json.loads(out.read_text())["h0"]
    assert h0["450"] > 1.3 * h0["250"]


def test_diagnose_measured_frame_declares_the_reconstruction(tmp_path):
    path = _measured("250")
    out = tmp_path / "d.json"
    assert main(["diagnose", str(path), "--frame", FRAME, "--max-effects", "1",
                 "--json", str(out)]) == 0  # fmt: skip
    d = json.loads(out.read_text())
    rec = d["frame_reconstruction"]
    assert d["declared_output"]["filter_taps"] == rec["window"]
    assert d["declared_output"]["noise"] == pytest.approx(rec["force_noise"])
    assert d["noise_rms"] == pytest.approx(rec["force_noise"])  # the declared noise is used
    api = contactlab.diagnose(read_frame(path, 3.0799, 0.669, 1191.0).recording(),
                              max_effects=1)  # fmt: skip
    assert [e["name"] for e in d["effects"]] == api.effect_names
    assert not {"channel_delay", "viscous_damping"} & set(api.effect_names)


def test_simulated_frame_columns_units_and_reconstruction(sim_file, tmp_path, capsys):
    path, t, x, y = sim_file
    out = tmp_path / "a.json"
    assert main(["analyze", str(path), "--model", "tangential", "--frame", "3.08,0.669,1191",
                 "--json", str(out)]) == 0  # fmt: skip
    said = capsys.readouterr().out
    assert "x = 'x_top [um]' (um)" in said and "y = 'y_base [um]' (um)" in said
    d = json.loads(out.read_text())
    r = frame_friction_force(t, x, y, 3.08, 0.669, 1191.0)  # the arrays in metres
    rec = d["frame_reconstruction"]
    assert rec["window"] == r.window
    assert rec["noise_x"] == pytest.approx(r.noise_x, rel=1e-6)
    assert rec["force_noise"] == pytest.approx(r.force_noise, rel=1e-6)
    assert rec["noise_x"] == pytest.approx(5e-7, rel=0.25)  # µm read as µm, not m
    assert d["h0"] == pytest.approx(0.7, rel=0.1)  # the kinetic friction of the simulation


def test_frame_without_units_is_metres_and_said(tmp_path, capsys):
    t, x, y, _ = simulate_frame(Fk=0.7, fs=250.0, T=5.0)
    path = tmp_path / "plain.csv"
    np.savetxt(path, np.c_[t, y, x], delimiter=",", comments="", header="t,base,plate")
    out = tmp_path / "a.json"
    assert main(["analyze", str(path), "--model", "tangential", "--frame", "3.08,0.669,1191",
                 "--json", str(out)]) == 0  # fmt: skip
    captured = capsys.readouterr()
    assert "x = 'plate' (no unit: taken as m)" in captured.out
    assert "no unit in the file for plate, base" in captured.err
    d = json.loads(out.read_text())
    assert d["frame_reconstruction"]["columns"] == {"x": "plate", "y": "base", "t": "t"}
    assert d["h0"] == pytest.approx(0.7, rel=0.1)


def test_frame_columns_by_hand(sim_file, tmp_path):
    path = sim_file[0]
    out = tmp_path / "a.json"
    # swapped by hand: the plate read as the base; the reconstruction follows what was asked
    args = ["--frame-x", "x_top", "--frame-y", "y_base [um]", "--json", str(out)]
    assert main(["analyze", str(path), "--model", "tangential", "--frame", "3.08,0.669,1191",
                 *args]) == 0  # fmt: skip
    cols = json.loads(out.read_text())["frame_reconstruction"]["columns"]
    assert cols["x"] == "x_top [um]" and cols["y"] == "y_base [um]"


def test_output_filter_is_declared_to_the_diagnosis(tmp_path):
    """A force channel smoothed by a known Savitzky-Golay filter: ``--output-filter
    savgol:11`` passes every candidate through the same filter (the API's ``output_filter``)."""
    from scipy.signal import savgol_coeffs, savgol_filter

    from contactlab.synthetic.diagnosis import hidden_effect_recording

    rec = hidden_effect_recording([], seed=5)
    F = savgol_filter(rec["F"], 11, 2)
    path = tmp_path / "smoothed.csv"
    np.savetxt(path, np.c_[rec.t, rec["x"], F], delimiter=",", comments="",
               header="t [s],x [m],F [N]")  # fmt: skip
    out = tmp_path / "d.json"
    args = ["--output-noise", "0.01", "--max-effects", "1", "--json", str(out)]
    assert main(["diagnose", str(path), "--model", "tangential", "--output-filter", "savgol:11",
                 *args]) == 0  # fmt: skip
    d = json.loads(out.read_text())
    assert d["declared_output"] == {"filter": "savgol:11", "filter_taps": 11, "noise": 0.01}
    assert d["noise_rms"] == 0.01
    api = contactlab.diagnose((rec.t, rec["x"], F), output_filter=savgol_coeffs(11, 2),
                              output_noise=0.01, max_effects=1)  # fmt: skip
    assert [e["name"] for e in d["effects"]] == api.effect_names
    # the command line's taps (contactlab._filters.savgol_coeffs) differ from scipy's in the
    # last bit (2.8e-17); the fit carries that to 1e-9 of the held-out RMS
    assert d["steps"][0]["heldout_rms"] == pytest.approx(api.steps[0].heldout_rms, rel=1e-7)
    from contactlab.commands.common import output_filter_taps

    same = contactlab.diagnose((rec.t, rec["x"], F), output_filter=output_filter_taps("savgol:11"),
                               output_noise=0.01, max_effects=1)  # fmt: skip
    assert d["steps"][0]["heldout_rms"] == pytest.approx(same.steps[0].heldout_rms, rel=1e-12)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--frame", "-3,0.6,1191"], "M = -3 kg: must be finite and >= 0"),
        (["--frame", "3,0.6"], "give the frame's mass, damping and stiffness"),
        (["--frame", "3,0.6,0"], "K = 0 N/m: must be finite and > 0"),
        (["--frame", "M=3,C=1,Q=2"], "'Q' is not one of M, C, K"),
        (["--frame", "3,nan,1191"], "C = nan N s/m: must be finite"),
        (["--frame", "3,x,1191"], "C = 'x' is not a number"),
        (["--frame", "3,0.6,1191", "--frame-x", "nope"], "column 'nope' (asked for 'x') not found"),
        (["--frame", "3,0.6,1191", "--frame-y", "time"], "'y' is a length"),
        (["--frame-x", "x_top"], "give --frame M,C,K too"),
        (["--frame", "3,0.6,1191", "--output-filter", "savgol:10"], "odd number of samples >= 3"),
        (["--frame", "3,0.6,1191", "--output-filter", "savgol:5:5"], "order must be >= 0"),
        (["--frame", "3,0.6,1191", "--output-filter", "gauss:5"], "give savgol:WINDOW"),
        (["--model", "normal", "--frame", "3,0.6,1191"], "use --model tangential"),
    ],
)  # fmt: skip
def test_bad_frame_options_are_named(sim_file, args, message, capsys):
    assert main(["diagnose", str(sim_file[0]), *args]) == 1
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err


def test_frame_columns_that_cannot_be_told_apart(tmp_path, capsys):
    path = tmp_path / "two.csv"
    rows = "".join(f"{i / 250},0,0,0\n" for i in range(50))
    path.write_text("t,x_left_mm,x_right_mm,y_mm\n" + rows)
    assert main(["analyze", str(path), "--model", "tangential", "--frame", FRAME]) == 1
    assert "several columns could be the frame's 'x'" in capsys.readouterr().err
    rows = "".join(f"{i / 250},0,0\n" for i in range(50))
    path.write_text("t,a_mm,b_mm\n" + rows)
    assert main(["analyze", str(path), "--model", "tangential", "--frame", FRAME]) == 1
    assert "no column for the frame's top-plate displacement" in capsys.readouterr().err
    assert main(["analyze", str(path), "--model", "tangential", "--frame", FRAME, "--stream"]) == 1
    assert "drop --stream" in capsys.readouterr().err


def test_frame_report_of_a_sliding_loop(sim_file, tmp_path):
    """``--report`` on a stick-slip frame: the loop plot is titled by the plateau (its h0 and
    ac's lower bound; it raised KeyError 'h0_ac' when h0 and ac were not both identified) and
    the table carries the reconstruction's window and noise."""
    out = tmp_path / "rep"
    assert main(["analyze", str(sim_file[0]), "--model", "tangential", "--frame",
                 "3.08,0.669,1191", "--report", str(out)]) == 0  # fmt: skip
    assert (out / "report.html").is_file()
    import matplotlib

    matplotlib.use("Agg")
    from contactlab.report.tangential import plot_loop
    from contactlab.tangential import analyze_tangential

    rec = read_frame(sim_file[0], 3.08, 0.669, 1191.0).recording()
    title = plot_loop(analyze_tangential(rec, warn=False)).get_title()
    assert "(plateau, dashed)" in title and "ac ≥" in title
    header = (out / "study_tangential.csv").read_text().splitlines()[0]
    assert "frame_window [samples]" in header and "frame_force_noise [N]" in header


def test_track_frame_windows_agree_with_analyze(sim_file, tmp_path, capsys):
    """``track --frame``: the simulated frame reconstructed once and tracked window by window;
    the windows' pooled h0 agrees with ``analyze --frame`` of the whole record and with the
    simulation's kinetic friction, and the JSON records the reconstruction."""
    path, *_ = sim_file
    a, t = tmp_path / "a.json", tmp_path / "t.json"
    assert main(["analyze", str(path), "--model", "tangential", "--frame", FRAME,
                 "--json", str(a)]) == 0  # fmt: skip
    assert main(["track", str(path), "--frame", FRAME, "--every", "3cycles", "--json", str(t)]) == 0
    said = capsys.readouterr().out
    assert "friction frame: columns x = 'x_top [um]' (um)" in said
    whole, tr = json.loads(a.read_text()), json.loads(t.read_text())
    assert tr["kind"] == "tangential" and len(tr["windows"]) >= 1
    assert tr["meta"]["frame_reconstruction"]["window"] == whole["frame_reconstruction"]["window"]
    h0 = tr["combined"]["h0"]
    assert h0 == pytest.approx(whole["h0"], rel=0.05)
    assert 0.6 < h0 < 0.85  # Fk 0.7 N, Fs 0.8 N


@pytest.mark.parametrize("load", ["250"])
def test_track_measured_frame(load, tmp_path):
    path = _measured(load)
    out = tmp_path / "t.json"
    assert main(["track", str(path), "--frame", FRAME, "--every", "5cycles",
                 "--json", str(out)]) == 0  # fmt: skip
    d = json.loads(out.read_text())
    ref = read_frame(path, 3.0799, 0.669, 1191.0)
    v = np.gradient(ref.x, ref.t)
    fast = np.abs(v) > 0.5 * np.max(np.abs(v))
    plateau = 0.5 * (np.median(ref.F[fast & (v > 0)]) - np.median(ref.F[fast & (v < 0)]))
    for w in d["windows"]:
        assert w["h0"] == pytest.approx(plateau, rel=0.1)


@pytest.mark.parametrize(
    ("extra", "says"),
    [
        (["--frame-x", "x_top"], "give --frame M,C,K too"),
        (["--frame", FRAME, "--columns", "x=x_top,F=y_base"], "not --columns"),
        (["--frame", FRAME, "--model", "normal"], "use --model tangential"),
        (["--frame", FRAME, "--p0", "1MPa"], "normal-contact"),
        (["--frame", "3,0.6"], "M,C,K"),
    ],
)
def test_track_frame_flags_refused(sim_file, tmp_path, capsys, extra, says):
    path, *_ = sim_file
    out = tmp_path / "t.json"
    assert main(["track", str(path), *extra, "--json", str(out)]) != 0
    err = capsys.readouterr().err
    assert says in err and "Traceback" not in err
    assert not out.exists()
