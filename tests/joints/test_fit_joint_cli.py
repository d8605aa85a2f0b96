"""``contactlab fit-joint``: fit recordings, score held-out ones, JSON and report; bad input
gives one typed line."""

from __future__ import annotations

import json

import numpy as np
import pytest

from contactlab.cli import main
from contactlab.joints import Jenkins


def _write(path, t, x, F):
    with open(path, "w", encoding="utf-8") as fh:
        fh.write("t [s],x [mm],F [N]\n")
        for a, b, c in zip(t, x * 1e3, F, strict=True):
            fh.write(f"{a:.6f},{b:.9f},{c:.9f}\n")


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("fj")
    law = Jenkins(k=5e3, fs=4.0)
    rng = np.random.default_rng(2)
    out = []
    for k, amp in enumerate((1.5e-3, 2.5e-3, 2e-3)):
        t = np.linspace(0.0, 3.0, 601)
        x = amp * np.sin(2 * np.pi * t + 0.3 * k)
        F = law.force(t, x, float(x[0])) + rng.normal(0, 0.02, t.size)
        p = d / f"test{k}.csv"
        _write(p, t, x, F)
        out.append(p)
    return out


def test_fit_and_predict_with_json_and_report(files, tmp_path, capsys):
    out = tmp_path / "res.json"
    rep = tmp_path / "rep"
    code = main(["fit-joint", "--law", "jenkins,dahl", "--fit", str(files[0]), str(files[1]),
                 "--predict", str(files[2]), "--offset", "--asymmetry", "--json", str(out),
                 "--report", str(rep)])  # fmt: skip
    assert code == 0
    text = capsys.readouterr().out
    assert "held out (pooled): SNR" in text
    doc = json.loads(out.read_text())
    assert [f["law"] for f in doc["fits"]] == ["jenkins", "dahl"]
    jk = doc["fits"][0]
    assert jk["params"]["k"]["value"] == pytest.approx(5e3, rel=0.02)
    assert jk["units"]["k"] == "N/m"
    held = {r["model"]: r for r in doc["held_out"]["rows"] if r["record"] == "pooled"}
    assert held["jenkins"]["snr_db"] > 30.0
    assert doc["roles"]["test2.csv"] == "held out"
    html = (rep / "report.html").read_text()
    assert "Loops and time traces" in html and "test2.csv" in html
    assert (rep / "scores.json").is_file()


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["--law", "nope"], "unknown law 'nope'"),
        (["--law", "jenkins,jenkins"], "named twice"),
        (["--law", "jenkins", "--max-samples", "5"], "--max-samples must be >= 100"),
    ],
)
def test_bad_options_one_line(files, capsys, argv, needle):
    code = main(["fit-joint", "--fit", str(files[0]), *argv])
    assert code == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and needle in err[0] and err[0].startswith("contactlab fit-joint: error")


def test_bad_files_one_line(files, tmp_path, capsys):
    assert main(["fit-joint", "--fit", str(tmp_path / "missing.csv")]) == 1
    assert "no such file" in capsys.readouterr().err
    assert main(["fit-joint", "--fit", str(files[0]), "--predict", str(files[0])]) == 1
    assert "given twice" in capsys.readouterr().err
    bad = tmp_path / "bad.csv"
    bad.write_text("t [s],x [mm],F [N]\n0,1,2\n0.1,nan,3\n0.2,1,2\n")
    assert main(["fit-joint", "--fit", str(bad)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "bad.csv" in err[0]


def test_help_lists_the_verb(capsys):
    with pytest.raises(SystemExit):
        main(["fit-joint", "--help"])
    assert "--predict" in capsys.readouterr().out


def _npy_test(folder, stem, law, fs=200.0, n=1200, amp=2e-3, freq=1.0):
    """A test stored as the friction damper's: <stem>_x.npy and <stem>_F.npy, shape (1, N),
    no time column."""
    t = np.arange(n) / fs
    x = amp * np.sin(2 * np.pi * freq * t)
    np.save(folder / f"{stem}_x.npy", x[None, :])
    np.save(folder / f"{stem}_F.npy", law.force(t, x)[None, :])
    return folder / f"{stem}_x.npy", folder / f"{stem}_F.npy"


def test_npy_pairs_without_time_read_with_fs(tmp_path, capsys):
    law = Jenkins(5e3, 4.0)
    a_x, a_F = _npy_test(tmp_path, "test0", law)
    _, b_F = _npy_test(tmp_path, "test1", law, amp=3e-3)
    out = tmp_path / "out.json"
    code = main(["fit-joint", "--law", "jenkins", "--fit", str(a_x), str(a_F), "--predict",
                 str(b_F), "--fs", "200", "--json", str(out)])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    res = json.loads(out.read_text())
    text = json.dumps(res)
    assert "test0" in text and "test1" in text
    fitted = res["fits"][0] if "fits" in res else res
    assert "jenkins" in json.dumps(fitted)


@pytest.mark.parametrize(
    ("setup", "message"),
    [
        ("no_fs", "give the sampling rate with --fs"),
        ("no_partner", "test0_F.npy, is not next to it"),
        ("bad_name", "name the test's files"),
        ("lengths", "has 1200 samples"),
    ],
)
def test_npy_pairs_missing_parts_are_named(tmp_path, capsys, setup, message):
    a_x, a_F = _npy_test(tmp_path, "test0", Jenkins(5e3, 4.0))
    argv = ["fit-joint", "--law", "jenkins", "--fit", str(a_x), "--fs", "200"]
    if setup == "no_fs":
        argv = argv[:-2]
    elif setup == "no_partner":
        a_F.unlink()
    elif setup == "bad_name":
        np.save(tmp_path / "alone.npy", np.zeros((1, 50)))
        argv[argv.index(str(a_x))] = str(tmp_path / "alone.npy")
    elif setup == "lengths":
        np.save(a_F, np.zeros((1, 900)))
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert message in err
    assert "Traceback" not in err
