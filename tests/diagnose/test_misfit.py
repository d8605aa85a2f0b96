"""The test of structure left in a final residual over phase and branch (issue 29 item 3)."""

from __future__ import annotations

import numpy as np
import pytest

import contactlab
from contactlab.diagnose._family import Prepared
from contactlab.diagnose.misfit import BINS, null_quantile, unexplained_structure
from contactlab.diagnose.scaled_masing import memory, scaled_force
from contactlab.synthetic._common import block_excitation


@pytest.fixture(scope="module")
def sine() -> Prepared:
    t = np.arange(6000) / 400.0  # 15 cycles of 400 samples
    return Prepared.build(t, np.sin(2 * np.pi * t), np.zeros(t.size))


def test_null_rate_is_the_stated_one(sine: Prepared) -> None:
    rng = np.random.default_rng(0)
    flags = [
        unexplained_structure(sine, rng.normal(0, 0.01, sine.y.size), 0.01).flagged
        for _ in range(60)
    ]
    # 3 % stated: 1.8 of 60 expected; P(8 or more) < 2e-3
    assert sum(flags) <= 7


def test_null_quantile_against_chi_square_limit() -> None:
    # many cycles: t -> normal, so Σ t² -> χ² with 2·BINS degrees of freedom
    from scipy.stats import chi2

    q = null_quantile(400, 2 * BINS, 0.03)
    assert q == pytest.approx(chi2.ppf(0.97, 2 * BINS), rel=0.03)
    # few cycles: heavier tails than χ²
    assert null_quantile(5, 2 * BINS, 0.03) > 1.5 * q


def test_structure_is_located(sine: Prepared) -> None:
    rng = np.random.default_rng(1)
    ph = sine.cycles.phase_in_branch
    rising = sine.ud > 0
    bump = 0.004 * ((ph > 0.2) & (ph < 0.4) & rising)  # 0.4 σ on a fifth of a branch
    u = unexplained_structure(sine, rng.normal(0, 0.01, sine.y.size) + bump, 0.01, unit="N")
    assert u.flagged
    assert u.where and all(w["branch"] == "rising" for w in u.where)
    assert min(w["phase_from"] for w in u.where) >= 0.1
    assert max(w["phase_to"] for w in u.where) <= 0.5
    assert "systematic misfit that no candidate explains" in u.sentence()
    js = u.to_dict()
    assert js["flagged"] is True and js["unit"] == "N" and js["bins_tested"] == 2 * BINS
    assert 0.0 < js["rms_over_noise"] < 0.4


def test_tolerance_forgives_what_the_input_noise_can_do(sine: Prepared) -> None:
    rng = np.random.default_rng(2)
    ph = sine.cycles.phase_in_branch
    bump = 0.004 * (ph < 0.2)
    e = rng.normal(0, 0.01, sine.y.size) + bump
    assert unexplained_structure(sine, e, 0.01).flagged
    tol = np.full(e.size, 0.006)  # the bump is within it
    assert not unexplained_structure(sine, e, 0.01, tolerance=tol).flagged


def test_tanh_virgin_curve_is_flagged() -> None:
    # Masing rules on a tanh virgin curve: no candidate draws it
    xfun, total, _ = block_excitation(np.array([0.4, 0.7, 1.0]) * 2e-5, np.array([5, 8.5, 3]), 6)
    t = np.arange(round(total * 600)) / 600.0
    x = xfun(t)
    F = scaled_force(lambda s: 50.0 * np.tanh(1e5 * s), 2.0, memory(x))
    rng = np.random.default_rng(3)
    rec = (t, x + rng.normal(0, 2e-8, t.size), F + rng.normal(0, 0.3, t.size))
    # the candidates the issue saw absorb it (series compliance, position friction) offered
    rep = contactlab.diagnose(
        rec, model="tangential", candidates=["series_compliance", "position_friction"]
    )
    assert rep.unexplained is not None and rep.unexplained.flagged, rep.effect_names
    assert any("systematic misfit that no candidate explains" in w for w in rep.where)
    assert rep.to_dict()["unexplained"]["flagged"] is True


@pytest.mark.parametrize("nu", [2, 3, 5, 20, 100])
def test_t_quantile_equals_scipys(nu):
    """The diagnosis imports no SciPy: its own Student-t quantile against scipy.stats."""
    from scipy.stats import t

    from contactlab.diagnose.misfit import t_quantile

    for p in (0.6, 0.975, 0.999, 1 - 0.03 / 80):
        assert t_quantile(p, nu) == pytest.approx(t.ppf(p, nu), rel=1e-10)


def test_few_samples_per_bin_give_a_finite_statistic() -> None:
    """A fast drive (30 samples per period, 7 cycles: one or two samples per phase bin and
    cycle): white noise must read as noise, a bump locked to the phase as structure (stop
    47: bins of one sample per cycle read zero variance and T near 1e31)."""
    t = np.arange(7 * 30) / 30.0
    d = Prepared.build(t, np.sin(2 * np.pi * t), np.zeros(t.size))
    rng = np.random.default_rng(4701)
    stats = []
    for _ in range(20):
        u = unexplained_structure(d, rng.normal(0.0, 0.01, t.size), 0.01)
        assert u is not None and np.isfinite(u.statistic)
        stats.append(u.statistic)
    assert max(stats) < 10 * 2 * BINS
    assert sum(s > 0 for s in stats) >= 15
    bump = 0.06 * np.exp(-(((t % 1.0) - 0.3) ** 2) / 0.005)
    u = unexplained_structure(d, rng.normal(0.0, 0.01, t.size) + bump, 0.01)
    assert u is not None and u.flagged
