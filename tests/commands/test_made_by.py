"""Issue 31: every report's "Made by" line reproduces the run: run each verb that writes a
report with a non-default flag and check the line holds it (``identify`` dropped ``--fs``; a
structure diagnosis had no line at all)."""

from __future__ import annotations

import html
import re
from pathlib import Path

import numpy as np
import pytest

from contactlab.cli import main
from contactlab.structure import Structure


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("madeby")
    tan = d / "Al-Al_W100N_A20um.csv"
    sim = ["simulate", "tangential", str(tan), "--h0", "40", "--ac", "4e4", "--amplitude",
           "20um", "--cycles", "8", "--fs", "400", "--noise", "0.005", "--seed", "3"]  # fmt: skip
    assert main(sim) == 0
    # a linear oscillator under a multisine force, no time column (--fs gives the rate)
    rng = np.random.default_rng(3107)
    fs, n = 500.0, 400
    t = np.arange(n) / fs
    u = sum(np.sin(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi)) for f in np.arange(3, 60, 0.5))
    u = 6.0 * u / np.std(u)
    y = Structure(1.0, 2.0, 4e3).simulate(t, force=u, substeps=4).x
    y = y + 0.01 * np.std(y) * rng.standard_normal(n)
    struct = d / "rec.csv"
    struct.write_text("u_force_N,y_disp_mm\n" + "\n".join(
        f"{a:.9g},{1e3 * b:.9g}" for a, b in zip(u, y, strict=True)))  # fmt: skip
    folder = d / "study"
    folder.mkdir()
    (folder / tan.name).write_bytes(tan.read_bytes())
    return {"tan": tan, "struct": struct, "folder": folder, "dir": d}


def _made_by(report: Path) -> str:
    text = html.unescape(report.read_text(encoding="utf-8"))
    m = re.search(r"Made by: (contactlab [^<\n]*)", text)
    assert m, f"no 'Made by' line in {report}"
    return m.group(1)


CASES = {
    # verb: (argv with {tan}, {struct}, {folder}, {model}, {out}; the flag that must appear;
    #        the report's file)
    "analyze": (["analyze", "{tan}", "--force-sign", "+1", "--delay", "0.1ms", "--report",
                 "{out}"], "--delay 0.1ms", "report.html"),
    "track": (["track", "{tan}", "--every", "3", "--threads", "1", "--report", "{out}",
               "--no-progress"], "--threads 1", "report.html"),
    "diagnose": (["diagnose", "{tan}", "--model", "tangential", "--max-effects", "0",
                  "--report", "{out}"], "--max-effects 0", "diagnose.html"),
    "study": (["study", "{folder}", "--title", "Made-by check", "--workers", "0",
               "--no-progress", "--report", "{out}"], "--title 'Made-by check'", "report.html"),
    "identify": (["identify", "{struct}", "--joint", "linear", "--fs", "500Hz", "--substeps",
                  "1", "--json", "{model}", "--report", "{out}"], "--fs 500Hz", "report.html"),
    "diagnose-structure": (["diagnose", "{struct}", "--structure", "{model}", "--fs", "500Hz",
                            "--holdout", "0.3", "--max-effects", "0", "--report", "{out}"],
                           "--holdout 0.3", "diagnose.html"),
    "fit-joint": (["fit-joint", "--law", "jenkins", "--fit", "{tan}", "--max-samples", "600",
                   "--report", "{out}"], "--max-samples 600", "report.html"),
}  # fmt: skip


@pytest.mark.parametrize("verb", list(CASES))
def test_made_by_repeats_the_run(verb, files, tmp_path, capsys):
    argv, flag, name = CASES[verb]
    model = files["dir"] / "model.json"
    if verb == "diagnose-structure" and not model.is_file():
        pytest.skip("needs the identify case's model (run the module whole)")
    out = tmp_path / "rep"
    fill = {"tan": files["tan"], "struct": files["struct"], "folder": files["folder"],
            "model": model, "out": out}  # fmt: skip
    args = [a.format(**fill) for a in argv]
    code = main(args)
    capsys.readouterr()
    assert code == 0, verb
    line = _made_by(out / name)
    assert flag in line, (flag, line)
    # the whole command line as typed: every word of it, in order
    assert line.split()[1] == args[0]
    assert all(w in line for w in args[1:] if " " not in w)
