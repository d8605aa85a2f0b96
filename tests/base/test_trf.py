"""contactlab._trf: SciPy's bounded trust-region reflective solver without importing
scipy.optimize (issue 9: half a second of every fit-using CLI run), the same to the last bit."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.fft import next_fast_len as scipy_next_fast_len
from scipy.optimize import least_squares

from contactlab import _trf
from contactlab._arrays import next_fast_len
from contactlab.errors import InputError


def _problem(seed: int, n: int, m: int) -> tuple:
    """A nonlinear least-squares problem of ``n`` parameters (a sum of decaying exponentials
    and powers of t, noisy), bounds some of which bind at the optimum, and a start."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 1.0, m)
    true = rng.uniform(0.3, 2.0, n)
    lo = np.where(rng.random(n) < 0.5, -np.inf, rng.uniform(-1.0, 0.2, n))
    hi = np.where(rng.random(n) < 0.5, np.inf, rng.uniform(0.6, 1.5, n))
    lo[0] = 0.0  # (at least one finite bound: the bounded variant)

    def model(z: np.ndarray) -> np.ndarray:
        out = z[0] * np.exp(-(1.0 + z[1 % n] ** 2) * t)
        for k in range(2, n):
            out = out + z[k] * t**k
        return out

    y = model(true) + 0.02 * rng.standard_normal(m)
    z0 = np.clip(rng.uniform(0.0, 1.5, n), lo + 1e-3, hi - 1e-3)
    return model, y, z0, lo, hi


@settings(max_examples=30, deadline=None)
@given(
    seed=st.integers(0, 10_000),
    n=st.integers(1, 5),
    m=st.integers(6, 400),
    tol=st.sampled_from([1e-6, 1e-8, 1e-10]),
    max_nfev=st.sampled_from([None, 3, 8, 400]),
)
def test_trf_same_trial_points_and_end_point_as_scipy(seed, n, m, tol, max_nfev):
    """Every residual evaluation at the same point in the same order, the same end point,
    residuals, status and count as scipy.optimize.least_squares (method trf, 2-point)."""
    model, y, z0, lo, hi = _problem(seed, n, m)
    calls: list[np.ndarray] = []

    def fun(z: np.ndarray) -> np.ndarray:
        calls.append(z.copy())
        return model(z) - y

    ref = least_squares(fun, z0, jac="2-point", bounds=(lo, hi), method="trf", x_scale=1.0,
                        ftol=tol, xtol=tol, gtol=tol, max_nfev=max_nfev)  # fmt: skip
    ref_calls = list(calls)
    calls.clear()
    got = _trf.solve(fun, z0, lo, hi, tol, tol, tol, max_nfev)
    assert len(calls) == len(ref_calls)
    for a, b in zip(calls, ref_calls, strict=True):
        assert np.array_equal(a, b)
    assert np.array_equal(got.x, ref.x)
    assert np.array_equal(got.fun, ref.fun)
    assert (got.status, got.nfev, got.njev, got.success) == (
        ref.status, ref.nfev, ref.njev, ref.success
    )  # fmt: skip
    assert got.message == ref.message


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 10_000),
    n=st.integers(1, 5),
    m=st.integers(6, 300),
    tol=st.sampled_from([1e-6, 1e-8, 1e-10]),
    max_nfev=st.sampled_from([None, 3, 8, 400]),
)
def test_trf_with_an_analytic_jacobian_as_scipy(seed, n, m, tol, max_nfev):
    """``jac=callable``: the same residual and Jacobian evaluations at the same points in the
    same order, end point, status and counts as scipy.optimize.least_squares."""
    model, y, z0, lo, hi = _problem(seed, n, m)
    t = np.linspace(0.0, 1.0, m)
    calls: list[tuple[str, np.ndarray]] = []

    def fun(z: np.ndarray) -> np.ndarray:
        calls.append(("f", z.copy()))
        return model(z) - y

    def jac(z: np.ndarray) -> np.ndarray:
        calls.append(("J", z.copy()))
        e = np.exp(-(1.0 + z[1 % n] ** 2) * t)
        cols = [e]
        if n > 1:
            cols.append(z[0] * e * (-2.0 * z[1] * t))
        else:  # d/dz0 of z0 exp(-(1 + z0²) t)
            cols[0] = e + z[0] * e * (-2.0 * z[0] * t)
        cols += [t**k for k in range(2, n)]
        return np.column_stack(cols)

    ref = least_squares(fun, z0, jac=jac, bounds=(lo, hi), method="trf", x_scale=1.0,
                        ftol=tol, xtol=tol, gtol=tol, max_nfev=max_nfev)  # fmt: skip
    ref_calls = list(calls)
    calls.clear()
    got = _trf.solve(fun, z0, lo, hi, tol, tol, tol, max_nfev, jac=jac)
    assert [k for k, _ in calls] == [k for k, _ in ref_calls]
    for (_, a), (_, b) in zip(calls, ref_calls, strict=True):
        assert np.array_equal(a, b)
    assert np.array_equal(got.x, ref.x)
    assert np.array_equal(got.fun, ref.fun)
    assert (got.status, got.nfev, got.njev, got.success) == (
        ref.status, ref.nfev, ref.njev, ref.success
    )  # fmt: skip
    assert got.message == ref.message


def test_trf_with_workers_and_an_active_bound():
    """Jacobian columns through a map-like ``workers`` and an optimum on a bound: as SciPy."""
    t = np.linspace(0.0, 1.0, 200)
    y = 2.0 * np.exp(-3.0 * t) - 0.5
    fun = lambda z: z[0] * np.exp(-z[1] * t) + z[2] - y  # noqa: E731
    lo, hi = np.array([0.0, 0.0, -0.2]), np.array([5.0, 10.0, 1.0])  # the offset binds
    z0 = np.array([1.0, 1.0, 0.0])
    mapped = []

    def workers(f, items):
        items = list(items)
        mapped.append(len(items))
        return [f(i) for i in items]

    ref = least_squares(fun, z0, jac="2-point", bounds=(lo, hi), method="trf", x_scale=1.0,
                        ftol=1e-8, xtol=1e-8, gtol=1e-8, workers=workers)  # fmt: skip
    n_ref = list(mapped)
    mapped.clear()
    got = _trf.solve(fun, z0, lo, hi, 1e-8, 1e-8, 1e-8, None, workers)
    assert mapped == n_ref and len(mapped) > 1
    assert np.array_equal(got.x, ref.x) and got.nfev == ref.nfev
    assert got.x[2] == pytest.approx(-0.2, abs=1e-6)


def test_trf_refuses_what_it_does_not_cover():
    f = lambda z: z - 1.0  # noqa: E731
    with pytest.raises(ValueError, match="bounded"):
        _trf.solve(f, np.zeros(2), np.full(2, -np.inf), np.full(2, np.inf), 1e-8, 1e-8, 1e-8, None)
    with pytest.raises(ValueError, match="outside"):
        _trf.solve(f, np.full(2, 3.0), np.zeros(2), np.ones(2), 1e-8, 1e-8, 1e-8, None)


def test_next_fast_len_is_scipys():
    sizes = [*range(1, 2000), 999_256, 1_000_003, 2**20 + 1, 123_456_789]
    for n in sizes:
        for real in (True, False):
            assert next_fast_len(n, real) == scipy_next_fast_len(n, real), (n, real)
    with pytest.raises(InputError):
        next_fast_len(0)


@pytest.mark.parametrize("model", ["tangential", "normal"])
def test_diagnosis_imports_no_scipy(model):
    """A diagnosis fits with contactlab._trf and numpy's FFT: it imports no part of SciPy
    (scipy.optimize, scipy.fft and what they pull in: half a second of a 1e6-sample run)."""
    code = (
        "import sys\n"
        "import numpy as np\n"
        "import contactlab\n"
        "rng = np.random.default_rng(5)\n"
        "t = np.arange(6000) / 200.0\n"
        + (
            "x = 4e-5 * np.sin(2 * np.pi * t)\n"
            "F = contactlab.Masing(40.0, 1e5).force(x) + 0.2 * rng.normal(size=t.size)\n"
            "contactlab.diagnose((t, x + 1e-8 * rng.normal(size=t.size), F), "
            "model='tangential', max_effects=1)\n"
            if model == "tangential"
            else "p = 5e5 + 2e5 * np.sin(2 * np.pi * t) + 1e3 * rng.normal(size=t.size)\n"
            "d = (p - 5e5) / 1.3e12 + 2e-10 * rng.normal(size=t.size)\n"
            "contactlab.diagnose((t, p, d), model='normal', max_effects=1)\n"
        )
        + "print([m for m in sys.modules if m == 'scipy' or m.startswith('scipy.')])\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip().splitlines()[-1] == "[]"
