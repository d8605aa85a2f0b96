"""Replays every input the fuzzers found crashing (fuzz/regressions/<target>/), under the
fuzzing invariants: only ContactLabError subclasses, no numpy warning, no NaN in a
successful result, no file left behind on failure. See fuzz/run.sh.

Each saved input is the smallest one atheris kept for a defect now fixed; the expected
outcome is written beside it in fuzz/regressions/README.md.
"""

from __future__ import annotations

import importlib
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

FUZZ = Path(__file__).resolve().parents[2] / "fuzz"
CASES = sorted(
    p for p in (FUZZ / "regressions").glob("*/*") if p.is_file() and not p.name.endswith(".md")
)


@pytest.fixture(scope="module", autouse=True)
def _fuzz_on_path():
    sys.path.insert(0, str(FUZZ))
    yield
    sys.path.remove(str(FUZZ))


#: inputs that hung libhdf5 or crashed scipy (a segmentation fault) before the readers
#: refused them: replayed in a child process with a timeout, so a regression fails the test
#: instead of hanging the run or killing it
IN_CHILD = {
    "e3ddb332f8521879d250453391ae977340069c6d",  # HDF5 global heap walk that never ends
    "f10095c362899d652997f103d2353561c11bed31",  # MAT v5 element type 49 (scipy segfault)
}


@pytest.mark.parametrize("case", CASES, ids=[f"{p.parent.name}/{p.name[:10]}" for p in CASES])
def test_saved_crash_input_keeps_the_invariants(case: Path) -> None:
    if case.name in IN_CHILD:
        code = (
            "import sys; sys.path.insert(0, sys.argv[1]); import importlib\n"
            "t = importlib.import_module(sys.argv[2])\n"
            "t.one_input(open(sys.argv[3], 'rb').read())\n"
        )
        args = [sys.executable, "-c", code, str(FUZZ), case.parent.name, str(case)]
        run = subprocess.run(args, capture_output=True, text=True, timeout=60, check=False)
        assert run.returncode == 0, f"exit {run.returncode}: {run.stderr[-3000:]}"
        return
    target = importlib.import_module(case.parent.name)
    target.one_input(case.read_bytes())


def test_child_replayed_inputs_are_saved() -> None:
    assert IN_CHILD <= {p.name for p in CASES}


def test_every_target_has_a_module() -> None:
    names = {p.parent.name for p in CASES}
    assert names, "no saved fuzz inputs"
    for name in names:
        assert (FUZZ / f"{name}.py").is_file(), name


# Kernel defects the `kernels` target (and AFL++ on the core) found: finite but extreme inputs
# returned NaN as a success. Each is now a clear InputError (CoreError::OutOfRange) or, for
# loop_area, a correct finite value.


def _input_error(fn):
    from contactlab import InputError

    with pytest.raises(InputError, match=r"out of the double-precision range|must be"):
        fn()


def test_kernel_exponential_with_overflowing_initial_stiffness():
    from contactlab import Masing

    _input_error(lambda: Masing(4e201, 4e204))


def test_kernel_tabulated_push_overflow_is_an_error():
    from contactlab import _core

    core = _core.MasingCore.tabulated(np.array([0.0, 1.0]), np.array([0.0, 1.7e308]), 2.0)
    _input_error(lambda: core.push(np.array([1.0, -0.99])))
    assert core.get_state()[3] == 0  # nothing counted: the state is as before


def test_kernel_loop_area_of_1e274_data_is_finite():
    from contactlab import loop_area

    x = np.array([1e274, -1e274, -1e274, 1e274])
    assert abs(loop_area(x, np.array([1e30, 1e30, -1e30, -1e30]))) == pytest.approx(4e304)


def test_kernel_kelvin_voigt_extremes():
    from contactlab import _core

    _input_error(lambda: _core.kv_analytic(1e31, 1.7976931348623157e308, 1e300, 1e7))
    _input_error(lambda: _core.kv_steady_state(1e31, 500.0, 1000.0, 1e7, np.array([-2e305])))
    # k = pa = 5e-324 with ψ = 178.6: ψ/k = inf against 0.5·pa = 0 gave E_d = NaN as a success
    out = _core.kv_analytic(5e-324, 178.6122250935734, 0.0020975929644084586, 5e-324)
    assert all(np.isfinite(v) for v in out) and out[3] >= 0.0
    # ψ/k underflowing to 0 while E_d = pa² ψ / (2 k (1 + g²)) is ordinary (0.5)
    assert _core.kv_analytic(1e100, 1e-300, 1.0, 1e200)[3] == pytest.approx(0.5, rel=1e-12)


def test_kernel_poly_fit_of_underflowing_abscissae():
    from contactlab import _core

    x = np.array([-9.2718e-199, 5.3096e-199, 0.0])
    _input_error(lambda: _core.poly_fit(x, np.zeros(3), 2, np.ones(3)))


def test_kernel_cycle_energy_overflow_is_an_error():
    from contactlab import _core

    core = _core.MasingCore.exponential(3.19e176, 3.19e179 / 1e60, 840.0)
    x = 2e262 * np.sin(np.linspace(0, 40, 44))
    _input_error(lambda: core.cycles(x))
