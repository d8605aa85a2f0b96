"""`contactlab study` and `demo` on all cores: recordings analysed and report figures drawn in
worker processes give the serial outputs byte for byte; a real Ctrl-C during the pooled report
exits 130 and writes nothing."""

from __future__ import annotations

import shutil
import signal
import subprocess
import sys
import time
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
from pathlib import Path

import pytest

from contactlab import InputError
from contactlab.cli import main
from contactlab.commands.common import default_workers, resolve_workers
from contactlab.data import data_dir
from contactlab.report.study_report import build_report
from contactlab.studies import run_study


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    d = tmp_path_factory.mktemp("study")
    picks = [
        "tangential/Al-Al_W50N_A10um.csv",
        "tangential/Al-Al_W109N_A10um.csv",
        "normal/C45-C45_p0-0.5MPa_pa-0.4MPa.csv",
        "normal/C45-C45_p0-1MPa_pa-0.4MPa.mat",
    ]
    for p in picks:
        shutil.copy(data_dir() / p, d / p.split("/")[1])
    return d


def _outputs(d):
    # the HTML carries the time it was made; the figures and tables must be identical
    return {
        p.relative_to(d).as_posix(): p.read_bytes()
        for p in sorted(d.rglob("*"))
        if p.is_file() and p.name != "report.html"
    }


def test_study_on_processes_writes_the_serial_report(folder, tmp_path):
    serial, pooled = tmp_path / "serial", tmp_path / "pooled"
    assert main(["study", str(folder), "--report", str(serial), "--no-progress",
                 "--workers", "0"]) == 0  # fmt: skip
    assert main(["study", str(folder), "--report", str(pooled), "--no-progress",
                 "--workers", "2"]) == 0  # fmt: skip
    a, b = _outputs(serial), _outputs(pooled)
    assert sum(k.startswith("figures/") for k in a) >= 4 + 2  # every recording, study plots
    assert a == b
    html_a = (serial / "report.html").read_text().split("generated", 1)[1].split("<", 1)[1]
    html_b = (pooled / "report.html").read_text().split("generated", 1)[1].split("<", 1)[1]
    # the "Made by" lines repeat each run as typed (issue 31), --workers included
    assert "--workers 0" in html_a and "--workers 2" in html_b

    def body(html: str, out: Path) -> str:
        return "\n".join(s for s in html.replace(str(out), "").splitlines() if "Made by" not in s)

    assert body(html_a, serial) == body(html_b, pooled)


def test_build_report_on_pools_equals_serial(folder):
    result = run_study(folder, progress=False)
    want = build_report(result, "t", dpi=30).files()
    with ProcessPoolExecutor(2) as ex:
        got = build_report(result, "t", executor=ex, dpi=30).files()
    with ThreadPoolExecutor(2) as tx:  # drawn in this thread: pyplot is not thread-safe
        got_t = build_report(result, "t", executor=tx, dpi=30, study_plots=False).files()
    assert list(got) == list(want)
    assert all(got[k] == want[k] for k in want if k != "report.html")
    assert len(got_t) == 1 + 4  # the HTML and each recording's figure
    assert all(got_t[k] == want[k] for k in got_t if k != "report.html")


def test_workers_flag():
    assert resolve_workers(0) is None
    assert resolve_workers(3) == 3
    assert resolve_workers(None) == default_workers()
    assert default_workers() is None or 2 <= default_workers() <= 8
    with pytest.raises(InputError, match="--workers must be >= 0"):
        resolve_workers(-1)


def test_study_refuses_negative_workers(folder, tmp_path, capsys):
    code = main(["study", str(folder), "--report", str(tmp_path / "r"), "--workers", "-2"])
    assert code != 0
    err = capsys.readouterr().err
    assert "--workers must be >= 0" in err and "Traceback" not in err
    assert not (tmp_path / "r").exists()


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_study_real_sigint_during_the_pooled_report_exits_130_without_output(folder, tmp_path):
    out = tmp_path / "rep"
    cmd = [sys.executable, "-m", "contactlab", "study", str(folder),
           "--report", str(out), "--workers", "2", "--no-progress"]  # fmt: skip
    proc = subprocess.Popen(
        cmd,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    assert proc.stdout is not None
    line = proc.stdout.readline()  # printed when the analysis is done, before the report
    assert line.startswith("analysed 4 of 4"), line
    time.sleep(0.5)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode in (130, -signal.SIGINT), err
    assert "interrupted" in err and "Traceback" not in err
    assert not out.exists()


def test_analyze_of_several_files_on_processes_equals_serial(folder, tmp_path):
    more = ("PVC-steel_W30N_A10um.tdms", "steel-steel_W75N_A1um.h5")
    files = [
        *sorted(str(p) for p in folder.glob("Al-Al_*")),
        *(str(data_dir() / "tangential" / n) for n in more),
    ]
    assert len(files) >= 4  # the default then is a process per core
    one, two = tmp_path / "serial.json", tmp_path / "pooled.json"
    base = ["analyze", *files, "--model", "tangential", "--no-progress"]
    assert main([*base, "--json", str(one), "--workers", "0"]) == 0
    assert main([*base, "--json", str(two)]) == 0
    assert one.read_bytes() == two.read_bytes()
    assert main([*base, "--json", str(tmp_path / "x.json"), "--workers", "-1"]) != 0


def _dies(entry, **_):
    import os

    os._exit(3)  # a worker killed mid-task (as the kernel's OOM killer would)


def test_a_worker_that_dies_is_an_error_not_a_traceback(folder, tmp_path, monkeypatch, capsys):
    import multiprocessing

    import contactlab.studies.study as study_mod

    if multiprocessing.get_start_method() != "fork":
        pytest.skip("the patched function reaches the workers only when they are forked")
    monkeypatch.setattr(study_mod, "analyze_entry", _dies)
    out = tmp_path / "rep"
    assert main(["study", str(folder), "--report", str(out), "--workers", "2"]) == 1
    err = capsys.readouterr().err
    assert "a worker process ended unexpectedly" in err and "Traceback" not in err
    assert not out.exists()


def test_no_process_pool_here(folder, tmp_path, monkeypatch, capsys):
    import concurrent.futures

    class Refused(ProcessPoolExecutor):
        def __init__(self, *_a, **_k):
            raise OSError(38, "Function not implemented")

    monkeypatch.setattr(concurrent.futures, "ProcessPoolExecutor", Refused)
    # the default: a note, then the serial run
    out = tmp_path / "rep"
    assert main(["study", str(folder), "--report", str(out), "--no-progress"]) == 0
    assert "cannot start worker processes here" in capsys.readouterr().err
    assert (out / "report.html").exists()
    # asked for: an error that names the way out
    assert main(["study", str(folder), "--report", str(tmp_path / "r2"), "--workers", "2"]) == 1
    err = capsys.readouterr().err
    assert "--workers 0 runs in this process" in err and "Traceback" not in err


@pytest.mark.parametrize("n", [2, 3, 5])
def test_study_figure_parts_interleave_to_the_whole(folder, n):
    import matplotlib.pyplot as plt

    from contactlab.report.study_plots import tangential_study_figures

    result = run_study(folder, progress=False)
    rows, units = result.table("tangential"), result.units("tangential")
    whole = tangential_study_figures(rows, units)
    parts = [tangential_study_figures(rows, units, part=(k, n)) for k in range(n)]
    names = [name for name, _, _ in whole]
    merged = [None] * len(names)
    for k, figs in enumerate(parts):
        for j, (name, _, _) in enumerate(figs):
            merged[k + j * n] = name
    assert len(names) >= 3 and merged == names
    for _, fig, _ in whole + [f for p in parts for f in p]:
        plt.close(fig)
