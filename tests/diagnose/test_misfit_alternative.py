"""A virgin curve of another shape than the package's exponential one, taken up by a named
series compliance or parallel stiffness or left unnamed (issue 29 item 3):
:func:`contactlab.diagnose.misfit.alternative_virgin` puts a Masing element of another shape
in place of the base and the named shape effects and compares them on held-out cycles."""

from __future__ import annotations

import json

import numpy as np
import pytest

from contactlab.diagnose._family import Prepared
from contactlab.diagnose.candidates_tangential import TangentialFamily
from contactlab.diagnose.misfit import Unexplained, alternative_virgin
from contactlab.diagnose.scaled_masing import memory, scaled_force
from contactlab.diagnose.select import fit

AC = 1.5e5
H0 = 40.0


def _record(
    virgin: str,
    effects: tuple[str, ...],
    seed: int,
    truth: dict | None = None,
    cycles: int = 10,
    noise: float = 0.01,
    ramp: float = 1.5,
):
    """A record (no input noise, ac·A 3, ``noise`` of the range as output noise, ``cycles``
    cycles from a ramp of ``ramp`` cycles) of a Masing element with a tanh, rational or gamma virgin
    curve, or of the family's own model (``virgin="own"``, parameters ``truth``); the family
    fitted with ``effects`` named."""
    spc = 100
    t = np.arange(cycles * spc) / spc
    u = 2e-5 * np.sin(2 * np.pi * t) * np.minimum(t / ramp, 1.0)
    d = Prepared.build(t, u, np.zeros(t.size), errors_in_input=False)
    fam = TangentialFamily()
    fam.prepare(d)
    start = {"h0": H0, "ac": AC}
    if virgin == "tanh":
        y = scaled_force(lambda s: H0 * np.tanh(AC * s), 2.0, memory(u))
    elif virgin == "rational":
        y = scaled_force(lambda s: H0 * AC * s / (1.0 + AC * np.abs(s)), 2.0, memory(u))
    elif virgin == "gamma":
        y = scaled_force(lambda s: H0 * (1.0 - (1.0 + AC * s) * np.exp(-AC * s)), 2.0, memory(u))
    else:
        own = tuple(k for k in effects)
        y = np.asarray(fam.predict({**start, **(truth or {})}, own, d))
        start = {**start, **(truth or {})}
    sigma = noise * float(np.ptp(y))
    y = y + np.random.default_rng(seed).normal(0.0, sigma, y.size)
    d = Prepared.build(t, u, y, errors_in_input=False)
    fam.prepare(d)
    scales = fam.scales(d)
    f = fit(fam, effects, d, np.ones(d.y.size, bool), start, scales)
    return fam, effects, d, dict(f.params), scales, sigma


@pytest.mark.parametrize("seed", [1, 2])
def test_a_tanh_curve_named_series_compliance_is_flagged(seed: int) -> None:
    fam, eff, d, p, scales, sigma = _record("tanh", ("series_compliance",), seed)
    got = alternative_virgin(fam, eff, d, p, scales, sigma)
    assert got is not None and got["alternative"] and got["held_out"], got
    assert got["flagged"] and got["gain"] > 0, got
    assert got["effects"] == ["series_compliance"] and set(got["virgin"]) == {"tanh"}, got


def test_a_rational_curve_left_unnamed_is_flagged() -> None:
    fam, eff, d, p, scales, sigma = _record("rational", (), 1)
    got = alternative_virgin(fam, eff, d, p, scales, sigma)
    assert got is not None and got["flagged"] and got["effects"] == [], got


@pytest.mark.parametrize("seed", [1, 2])
def test_a_genuine_series_compliance_is_not_flagged(seed: int) -> None:
    truth = {"C_s": 1.0 / (H0 * AC)}  # as compliant as the contact's initial slope
    fam, eff, d, p, scales, sigma = _record("own", ("series_compliance",), seed, truth)
    got = alternative_virgin(fam, eff, d, p, scales, sigma)
    assert got is not None and not got["flagged"] and got["gain"] < 0, got


@pytest.mark.parametrize("seed", [1, 2])
def test_a_clean_record_is_not_flagged(seed: int) -> None:
    fam, eff, d, p, scales, sigma = _record("own", (), seed)
    got = alternative_virgin(fam, eff, d, p, scales, sigma)
    assert got is not None and not got["flagged"] and got["gain"] < 0, got


@pytest.mark.parametrize("seed", [1, 2])
def test_a_short_gamma_record_is_flagged_when_every_cycle_gains(seed, monkeypatch) -> None:
    """Fewer complete cycles than ALT_FEW_CYCLES: every held-out cycle gaining flags in place
    of the t (here made unreachable), on a gamma virgin curve (zero initial slope) left
    unnamed; the same rule does not flag the family's own model, nor a record of as many
    cycles as ALT_FEW_CYCLES (there the t alone decides)."""
    import contactlab.diagnose.misfit as mf

    monkeypatch.setattr(mf, "ALT_Z", 1e9)
    fam, eff, d, p, scales, sigma = _record("gamma", (), seed, cycles=5, noise=0.02, ramp=0.25)
    got = alternative_virgin(fam, eff, d, p, scales, sigma)
    assert got is not None and got["cycles"] < mf.ALT_FEW_CYCLES, got
    assert min(got["per_cycle"]) > 0 and got["flagged"], got
    fam, eff, d, p, scales, sigma = _record("own", (), seed, cycles=5, noise=0.02, ramp=0.25)
    got = alternative_virgin(fam, eff, d, p, scales, sigma)
    assert got is not None and not got["flagged"], got
    n = mf.ALT_FEW_CYCLES + 2
    fam, eff, d, p, scales, sigma = _record("gamma", (), seed, cycles=n, noise=0.02, ramp=0.25)
    got = alternative_virgin(fam, eff, d, p, scales, sigma)
    assert got is not None and got["cycles"] >= mf.ALT_FEW_CYCLES, got
    assert min(got["per_cycle"]) > 0 and not got["flagged"], got


def test_the_flag_says_so() -> None:
    entry = {
        "effects": ["series_compliance"], "virgin": ["tanh", "tanh"], "gain": 40.0, "t": 3.1,
        "cycles": 10, "gain_effects": 900.0, "held_out": True, "alternative": True,
        "flagged": True,
    }  # fmt: skip
    u = Unexplained(
        flagged=True, statistic=10.0, threshold=30.0, p_value=0.5, cycles=10, bins_tested=20,
        where=[], rms=0.01, peak=0.02, rms_percent_of_range=0.1, peak_percent_of_range=0.2,
        rms_over_noise=0.5, unit="N", profile={}, patches=[entry],
    )  # fmt: skip
    s = u.sentence()
    assert "systematic misfit that no candidate explains" in s, s
    assert "tanh" in s and "series_compliance" in s, s
    assert json.loads(json.dumps(u.to_dict()))["patches"][0]["alternative"] is True


@pytest.mark.parametrize("case", range(6))
def test_bounded_min_takes_scipys_steps(case):
    """The alternative's curvature refinement (misfit._bounded_min) runs Brent's bounded
    method step for step as SciPy's minimize_scalar(method="bounded") does: the same point
    and value, bit for bit, on smooth, flat-bottomed, kinked and wiggly functions."""
    from scipy.optimize import minimize_scalar

    from contactlab.diagnose.misfit import _bounded_min

    rng = np.random.default_rng(4900 + case)
    c, w = rng.uniform(-1.0, 1.0), rng.uniform(0.5, 20.0)
    funcs = [
        lambda v: (v - c) ** 2,
        lambda v: abs(v - c) + 0.1 * (v - c) ** 2,
        lambda v: np.cos(w * v) + 0.3 * v,
        lambda v: (v - c) ** 4,
        lambda v: np.exp(v) - 2.0 * v,
        lambda v: float(np.round((v - c) ** 2, 3)),
    ]
    f = funcs[case]
    lo, hi = sorted(rng.uniform(-2.0, 2.0, size=2))
    r = minimize_scalar(f, bounds=(lo, hi), method="bounded", options={"xatol": 1e-3})
    x, fx = _bounded_min(f, float(lo), float(hi), 1e-3)
    assert x == float(r.x) and fx == float(r.fun)
