"""Command-line start-up (issue 33): what ``contactlab --help`` and ``analyze`` import before
they have work for it. A behaviour test on ``sys.modules`` in a new process (no timings)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

import contactlab.fem

RECORDING = (
    Path(__file__).resolve().parents[2]
    / "python"
    / "contactlab"
    / "data"
    / "tangential"
    / "Al-Al_W50N_A5um.csv"
)
HEAVY = ("scipy", "matplotlib")


def _modules_after(code: str, *args: str) -> set[str]:
    out = subprocess.run(
        [
            sys.executable,
            "-c",
            f"{code}\nimport sys\nprint('\\n'.join(sys.modules))",
            *args,
        ],
        check=True,
        capture_output=True,
        text=True,
        timeout=300,
    ).stdout
    return set(out.split())


def _heavy(loaded: set[str]) -> list[str]:
    return sorted(m for m in loaded if m.split(".")[0] in HEAVY)


def test_help_imports_neither_numpy_nor_scipy_nor_matplotlib():
    loaded = _modules_after(
        "import contextlib, io\nfrom contactlab.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()), contextlib.suppress(SystemExit):\n"
        "    main(['--help'])"
    )
    assert "contactlab.commands.export" in loaded  # every verb's parser was built
    assert not _heavy(loaded), _heavy(loaded)
    assert "numpy" not in loaded
    assert "contactlab.fem.ccx" not in loaded


def test_every_verbs_parser_imports_no_scipy_or_matplotlib():
    loaded = _modules_after(
        "import contactlab.commands\nfrom contactlab.cli import _VERB_MODULES, build_parser\n"
        "for m in _VERB_MODULES:\n    build_parser(m)"
    )
    assert not _heavy(loaded), _heavy(loaded)


def test_analyze_reads_its_first_sample_before_importing_scipy_or_matplotlib():
    # an audit hook ends the run when the reader opens the recording; what was imported then
    code = (
        "import os, sys\n"
        "target = os.path.abspath(sys.argv[1])\n"
        "def hook(event, args):\n"
        "    path = args[0] if event == 'open' else None\n"
        "    if isinstance(path, str) and os.path.abspath(path) == target:\n"
        "        print('OPENED'); print('\\n'.join(sys.modules)); sys.stdout.flush(); os._exit(0)\n"
        "sys.addaudithook(hook)\n"
        "from contactlab.cli import main\n"
        "main(['analyze', target])\n"
        "print('NOT OPENED')"
    )
    out = subprocess.run(
        [sys.executable, "-c", code, str(RECORDING)], capture_output=True, text=True, check=True
    ).stdout.split()
    assert out[0] == "OPENED", out[:3]
    loaded = set(out[1:])
    assert "contactlab.commands.analyze" in loaded
    assert not _heavy(loaded), _heavy(loaded)
    assert "contactlab.diagnose" not in loaded


def test_fem_package_loads_its_workers_on_first_use():
    loaded = _modules_after("import contactlab.fem\ncontactlab.fem.unit_system('SI')")
    assert "numpy" not in loaded
    assert not {"contactlab.fem.ccx", "contactlab.fem.characteristics"} & loaded
    from contactlab.fem import ccx, characteristics, writers

    assert contactlab.fem.render is writers.render
    assert contactlab.fem.SolverError is ccx.SolverError
    assert contactlab.fem.joint_characteristics is characteristics.joint_characteristics
    assert contactlab.fem.FORMATS is writers.FORMATS
    assert set(dir(contactlab.fem)) >= set(contactlab.fem.__all__)
    with pytest.raises(AttributeError, match="no_such_name"):
        contactlab.fem.no_such_name  # noqa: B018


def test_studies_package_loads_its_workflows_on_first_use():
    loaded = _modules_after("from contactlab.studies import entry_from_file")
    assert "contactlab.studies.manifest" in loaded
    assert not {"contactlab.studies.study", "contactlab.studies.tracking"} & loaded
    assert "concurrent.futures" not in loaded
    import importlib

    import contactlab.studies as studies

    for name, home in studies._LAZY.items():
        module = importlib.import_module(f"contactlab.studies.{home}")
        assert getattr(studies, name) is getattr(module, name), name
    assert set(dir(studies)) >= set(studies.__all__)
    assert set(studies._LAZY) == set(studies.__all__)
    with pytest.raises(AttributeError, match="no_such_name"):
        studies.no_such_name  # noqa: B018


def test_a_streamed_tangential_analyze_imports_no_normal_study_or_html_module(tmp_path):
    # a recording above STREAM_ABOVE samples is analysed in windows (issue 33: the modules a
    # tangential run never uses cost 30-50 ms of its start-up); its whole run, then sys.modules
    import h5py
    import numpy as np

    import contactlab
    from contactlab.studies.pooled import STREAM_ABOVE

    n = STREAM_ABOVE + 60_000
    t = np.arange(n) / 5000.0
    x = 20e-6 * np.sin(2 * np.pi * 25.0 * t)
    rng = np.random.default_rng(1)
    F = contactlab.Masing(h0=40.0, ac=4e4).force(x) + 0.4 * rng.standard_normal(n)
    x = x + 2e-8 * rng.standard_normal(n)  # (the recording of benches/bench_track.py)
    with h5py.File(path := tmp_path / "long.h5", "w") as f:
        for name, v, unit in (("x", x, "m"), ("F", F, "N")):
            f[name] = v
            f[name].attrs["unit"] = unit
            f[name].attrs["dt"] = 1 / 5000.0
    code = (
        "import contextlib, io, sys\nfrom contactlab.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        "    code = main(['analyze', sys.argv[1], '--json', sys.argv[2]])\n"
        "assert code == 0, code"
    )
    out = tmp_path / "out.json"
    loaded = _modules_after(code, str(path), str(out))
    assert "contactlab.studies.tracking" in loaded  # it was streamed
    assert '"n_windows"' in out.read_text()
    lazy = (
        "contactlab.normal",
        "contactlab.studies.study",
        "contactlab._html",
        "contactlab.io.checks",
    )
    assert not [m for m in loaded if m.startswith(lazy)], sorted(
        m for m in loaded if m.startswith(lazy)
    )


def test_analyze_without_a_terminal_imports_no_progress_bar(tmp_path):
    # stderr is a pipe here: tqdm's own rule (disable=None) would show no bar, so the run
    # does not import tqdm (tqdm.auto pulls in asyncio and ssl)
    out = tmp_path / "r.json"
    loaded = _modules_after(
        "import sys\nfrom contactlab.cli import main\n"
        "assert main(['analyze', sys.argv[1], '--json', sys.argv[2]]) == 0",
        str(RECORDING),
        str(out),
    )
    assert "contactlab.studies.study" in loaded and out.is_file()
    assert not {"tqdm", "asyncio", "ssl"} & loaded, sorted({"tqdm", "asyncio", "ssl"} & loaded)
    assert "concurrent.futures" not in loaded
    assert "contactlab.diagnose" not in loaded


def test_study_progress_bar_only_where_tqdm_would_show_one(monkeypatch):
    import io

    from contactlab.studies import study

    items = [1, 2, 3]
    assert study._progress(items, False, "x") is items
    monkeypatch.setattr(sys, "stderr", io.StringIO())  # not a terminal
    assert study._progress(items, None, "x") is items
    bar = study._progress(items, True, "x")
    assert list(bar) == items and bar is not items
    bar.close()

    class Tty(io.StringIO):
        def isatty(self) -> bool:
            return True

    monkeypatch.setattr(sys, "stderr", Tty())
    bar = study._progress(items, None, "x")
    assert bar is not items and not bar.disable and list(bar) == items
    bar.close()
