"""Displacement noise in an averaged fit (errors in variables).

A bin's mean displacement errs by ``σx / sqrt(count)``, which the model turns into a force
error ``k σx`` (``k`` the branch's local stiffness, ``h0·ac`` next to each turn). With 1 %
noise on x alone (F clean) the analysis used to warn that the residuals were 2.0-3.0× the
cycle-to-cycle noise (it compared them with the force's spread only) and gave h0 errors
1.7-2.2× their scatter over seeds (equal weights where the noise is concentrated at the
turns). Records are small (10 Hz at 1 kHz, 100 cycles) so that the seeds run in seconds.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import contactlab
from contactlab.tangential import analyze_tangential

H0, AC, A = 40.0, 4e4, 20e-6


def _record(seed: int, nx: float, nF: float, c: float = 0.0) -> contactlab.Recording:
    rng = np.random.default_rng(seed)
    t = np.arange(10_000) / 1000.0
    xt = A * np.sin(2 * np.pi * 10.0 * t)
    Ft = contactlab.Masing(H0, AC).force(np.ascontiguousarray(xt))
    Ft = Ft + c * np.gradient(xt, t)  # viscous force c·ẋ: a loop the Masing model misses
    x = xt + rng.normal(0, nx * np.ptp(xt), t.size)
    F = Ft + rng.normal(0, nF * np.ptp(Ft), t.size)
    return contactlab.Recording(t, {"x": x, "F": F}, {"x": "m", "F": "N"}, f"eiv{seed}")


def _misfit_warnings(res) -> list[str]:
    return [w for w in res.warnings if "residuals are" in w]


@pytest.mark.parametrize(("nx", "nF"), [(0.01, 0.0), (0.0, 0.01), (0.01, 0.01)])
def test_no_misfit_warning_from_noise(nx: float, nF: float) -> None:
    # the old comparison warned on every seed with x-only noise (2.0-3.0×)
    for seed in (71, 72, 73):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = analyze_tangential(_record(seed, nx, nF))
        assert not _misfit_warnings(res), (nx, nF, res.warnings)


def test_misfit_warning_still_fires_on_a_real_misfit() -> None:
    # a viscous force of 30 % of the loop's half height at peak velocity: not a Masing loop
    c = 0.3 * 22.0 / (A * 2 * np.pi * 10.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = analyze_tangential(_record(5, 0.01, 0.01, c=c))
    assert _misfit_warnings(res), res.warnings


def test_x_noise_only_errors_match_scatter() -> None:
    # 40 seeds, x noise only: the reported errors of h0, ac, E and A against their scatter
    # over seeds, and the 2σ coverage (the old code's h0 error was 1.7-2.2x its scatter at
    # 2000 cycles; at these 100 cycles it passes: a guard, not the failing case)
    vals: dict[str, list[tuple[float, float]]] = {"h0": [], "ac": [], "E": [], "A": []}
    for seed in range(400, 440):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = analyze_tangential(_record(seed, 0.01, 0.0))
        p = res.fit.params
        vals["h0"].append((p["h0"].value, p["h0"].stderr))
        vals["ac"].append((p["ac"].value, p["ac"].stderr))
        vals["E"].append(res.derived["energy_per_cycle"])
        vals["A"].append((res.amplitude, res.amplitude_stderr))
    truth = {"h0": H0, "ac": AC, "E": contactlab.Masing(H0, AC).loop_energy(A), "A": A}
    for k, pairs in vals.items():
        v = np.array([a for a, _ in pairs])
        e = np.array([b for _, b in pairs])
        ratio = float(np.mean(e) / np.std(v, ddof=1))
        cover = float(np.mean(np.abs(v - truth[k]) < 2 * e))
        assert 0.65 < ratio < 1.45, (k, ratio)
        assert cover >= 0.8, (k, cover)


def test_turn_smoothing_leaves_an_irregular_drive_alone():
    """Turn instants are smoothed over ±4 turns only where the drive turns evenly: a
    multisine's (the measured Bouc-Wen record) amplitude read 29 µm instead of 684 µm when
    every instant was moved onto the local line."""
    from contactlab.tangential.preprocess import SMOOTH_TOLERANCE, smooth_turn_times

    rng = np.random.default_rng(31)
    steady = np.arange(40) * 1.0 + rng.normal(0, 0.004, 40)  # jitter 0.4 % of the period
    out = smooth_turn_times(steady)
    assert np.all(np.abs(out - steady) <= SMOOTH_TOLERANCE)
    assert np.std(np.diff(out)) < 0.5 * np.std(np.diff(steady))  # smoothed
    irregular = np.cumsum(rng.uniform(0.4, 1.6, 40))
    out = smooth_turn_times(irregular)
    moved = out != irregular
    tol = SMOOTH_TOLERANCE * np.median(np.diff(irregular))
    assert np.all(np.abs(out[moved] - irregular[moved]) <= tol)
    assert moved.sum() < 20  # most instants keep their own
    assert np.all(np.diff(out) > 0)
