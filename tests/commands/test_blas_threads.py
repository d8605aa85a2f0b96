"""``analyze`` and ``track`` run BLAS on one thread unless the user chose (issue 33: OpenBLAS's
threads spin at numpy's import; ``contactlab.cli.one_blas_thread``). Behaviour tests in new
processes (the variable only acts before numpy is imported); no timings."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from contactlab.cli import _BLAS_THREAD_VARIABLES

RECORDING = (
    Path(__file__).resolve().parents[2]
    / "python"
    / "contactlab"
    / "data"
    / "tangential"
    / "Al-Al_W50N_A5um.csv"
)


def _run(code: str, *args: str, **env: str) -> str:
    clean = {k: v for k, v in os.environ.items() if k not in _BLAS_THREAD_VARIABLES}
    return subprocess.run(
        [sys.executable, "-c", code, *args],
        env={**clean, **env},
        check=True,
        capture_output=True,
        text=True,
        timeout=120,
    ).stdout.strip()


CALL = (
    "import os, sys\nfrom contactlab.cli import one_blas_thread\n"
    "{before}"
    "print(one_blas_thread(sys.argv[1:]), os.environ.get('OPENBLAS_NUM_THREADS'))"
)


@pytest.mark.parametrize(
    ("argv", "before", "env", "expected"),
    [
        (["analyze", "f.h5"], "", {}, "True 1"),
        (["--progress", "track", "f.h5"], "", {}, "True 1"),
        (["diagnose", "f.h5"], "", {}, "False None"),  # not a verb of small problems
        (["--help"], "", {}, "False None"),
        (["analyze", "f.h5"], "", {"OMP_NUM_THREADS": "3"}, "False None"),  # the user's
        (["analyze", "f.h5"], "", {"OPENBLAS_NUM_THREADS": "2"}, "False 2"),
        (["analyze", "f.h5"], "import numpy\n", {}, "False None"),  # too late to act
    ],
)
def test_one_blas_thread_only_for_small_problem_verbs_and_never_over_a_users_choice(
    argv, before, env, expected
):
    assert _run(CALL.format(before=before), *argv, **env) == expected


def test_an_analyze_run_computes_on_one_blas_thread_and_its_json_is_unchanged(tmp_path):
    threadpoolctl = pytest.importorskip("threadpoolctl")
    del threadpoolctl
    code = (
        "import json, sys\nfrom contactlab.cli import main\n"
        "sys.argv = ['contactlab', 'analyze', sys.argv[1], '--json', sys.argv[2]]\n"
        "code = main()\n"
        "from threadpoolctl import threadpool_info\n"
        "print(json.dumps([code, [i['num_threads'] for i in threadpool_info()"
        " if i['internal_api'] == 'openblas']]))"
    )
    one, many = tmp_path / "one.json", tmp_path / "many.json"
    code_rc, threads = json.loads(_run(code, str(RECORDING), str(one)).splitlines()[-1])
    assert code_rc == 0
    if not threads:
        pytest.skip("numpy is not linked to OpenBLAS here")
    assert set(threads) == {1}
    # the same run with BLAS on two threads (the user's choice): the same document
    _run(code, str(RECORDING), str(many), OPENBLAS_NUM_THREADS="2")
    assert one.read_bytes() == many.read_bytes()
