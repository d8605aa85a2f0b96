"""The analyses use numpy Savitzky-Golay filters (contactlab._filters) and scipy.special's
χ² quantile instead of scipy.signal and scipy.stats, whose import cost 1.2 s of every
analysis: the same numbers to rounding, and the analysis paths import neither."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from contactlab.commands.common import output_filter_taps
from contactlab.data import data_dir
from contactlab.tangential.frame import (
    POLYORDER,
    lepski_square_sums,
    savgol_coefficients,
    savgol_derivative,
)
from contactlab.tangential.regime import break_threshold

signal = pytest.importorskip("scipy.signal")
stats = pytest.importorskip("scipy.stats")


@given(
    half=st.integers(2, 200),
    deriv=st.integers(0, 3),
    dt=st.floats(1e-6, 1e2),
)
@settings(max_examples=60, deadline=None)
def test_savgol_weights_match_scipy(half, deriv, dt):
    w = 2 * half + 1
    want = signal.savgol_coeffs(w, POLYORDER, deriv=deriv, delta=dt, use="dot")
    got = savgol_coefficients(w, deriv, dt)
    scale = np.max(np.abs(want)) or 1.0
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-11 * scale)


@pytest.mark.parametrize("window", [7, 15, 101])
@pytest.mark.parametrize("deriv", [0, 1, 2])
def test_savgol_derivative_matches_scipy(window, deriv):
    x = np.random.default_rng(11).standard_normal(3000).cumsum()
    want = signal.savgol_filter(x, window, POLYORDER, deriv=deriv, delta=1e-3, mode="interp")
    got = savgol_derivative(x, window, deriv, 1e-3)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * np.max(np.abs(want)))


def test_lepski_sums_match_scipy_weights():
    x = np.sin(np.linspace(0, 40, 5000)) + 1e-3 * np.random.default_rng(3).standard_normal(5000)
    cands = [7, 11, 21, 41]

    def scipy_dot(w, deriv, dt):
        return signal.savgol_coeffs(w, POLYORDER, deriv=deriv, delta=dt, use="dot")

    want = lepski_square_sums(x, cands, 1e-3, coefficients=scipy_dot)
    got = lepski_square_sums(x, cands, 1e-3)
    np.testing.assert_allclose(got, want, rtol=1e-9)


@pytest.mark.parametrize("positions", [1, 2, 17, 1000, 10**6])
def test_break_threshold_is_the_chi2_quantile(positions):
    assert break_threshold(positions) == float(stats.chi2.isf(0.01 / positions, 1))


@pytest.mark.parametrize(("window", "order"), [(5, 2), (11, 2), (11, 3), (31, 4)])
def test_output_filter_taps_match_scipy(window, order):
    want = signal.savgol_coeffs(window, order, deriv=0, use="dot")
    got = output_filter_taps(f"savgol:{window}:{order}")
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-13)


def test_analyses_do_not_import_scipy_signal_or_stats():
    code = (
        "import sys\n"
        "from contactlab.studies import run_study\n"
        f"d = {str(data_dir())!r}\n"
        "r = run_study([d + '/tangential/Al-Al_W50N_A10um.csv',\n"
        "               d + '/tangential/PVC-steel_W30N_A20um.tdms',\n"
        "               d + '/normal/C45-C45_p0-1MPa_pa-0.4MPa.mat'], progress=False)\n"
        "assert not r.failures, r.failures\n"
        "print(sorted(m for m in ('scipy.signal', 'scipy.stats') if m in sys.modules))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]", out.stdout + out.stderr
