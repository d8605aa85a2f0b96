"""The stated bound of ``asymmetric_branches`` (issue 29, item 2): the size at which the loss
asymmetry passes the rules on its own *and* fits better than the stiffening law fitted in
its place, as the diagnosis names it; not the size at which its direction beyond the law
alone (the 4ω kink of ``|δ'|``, a few per cent of it) would pass them, which lay beyond
the parameter's range (no bound) on single-tone chains where a = -0.3 was named."""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.stats import norm

from contactlab.diagnose.power import DRAWS, _rival_wins, _Setting

BENCHES = Path(__file__).resolve().parents[2] / "benches"


def _setting(n: int = 2000) -> _Setting:
    rng = np.random.default_rng(3)
    return _Setting(
        w=np.ones(n), var=1.0, cycle_of=np.arange(n) // 100, fold_of_cycle=np.arange(20) % 2,
        cycle_mse=np.ones(20), sigma=1.0, z=3.0, gain_floor=0.01, y_rms=1.0,
        rng_normals=rng.standard_normal((DRAWS, 20)), fit_rows=np.arange(n),
        rng_fit=rng.standard_normal(DRAWS), rng_rival=rng.standard_normal(DRAWS),
    )  # fmt: skip


@pytest.mark.parametrize("lam", [4.0, 10.8, 30.0])
def test_rival_comparison_is_the_likelihood_ratio_sign(lam: float) -> None:
    """The rival's excess sum of squares is ``a² λ + 2 a Σ jr e`` (σ² units): the candidate
    wins with probability Φ(|a| √λ / 2), λ the noncentrality of its direction beyond the
    rival (10.8 at 95 %)."""
    st = _setting()
    jr = np.zeros(st.w.size)
    jr[::2] = np.sqrt(lam / (st.w.size // 2))
    rows = np.ones(st.w.size, bool)
    a = np.full(DRAWS, 1.0)
    won = float(np.mean(_rival_wins(a, jr, rows, st)))
    want = float(norm.cdf(np.sqrt(lam) / 2.0))
    assert won == pytest.approx(want, abs=3.0 * np.sqrt(want * (1 - want) / DRAWS) + 0.01)
    # only the rows compared count
    none = np.zeros(st.w.size, bool)
    assert not np.any(_rival_wins(a, jr, none, st))


@pytest.mark.parametrize("lam", [10.8, 53.0])
def test_rival_comparison_asks_its_margin(lam: float) -> None:
    """With a margin of ``z`` deviations (the effect's ``rival_z``, normal contact's
    ``SHAPE_Z``) the candidate wins with probability Φ(|a| √λ / 2 - z): at λ = 53 and
    z = 2 in 95 % of draws, at 10.8 (95 % without the margin) in 36 %."""
    st = _setting()
    jr = np.zeros(st.w.size)
    jr[::2] = np.sqrt(lam / (st.w.size // 2))
    rows = np.ones(st.w.size, bool)
    a = np.full(DRAWS, 1.0)
    won = float(np.mean(_rival_wins(a, jr, rows, st, 2.0)))
    want = float(norm.cdf(np.sqrt(lam) / 2.0 - 2.0))
    assert won == pytest.approx(want, abs=3.0 * np.sqrt(want * (1 - want) / DRAWS) + 0.01)


def test_shape_effects_state_their_margin() -> None:
    """Both shape effects carry the naming rule's margin into their stated bound and
    compare on the same samples."""
    from contactlab.diagnose.effects import registry
    from contactlab.diagnose.effects.normal.asymmetric_branches import SHAPE_Z

    reg = registry("normal")
    for name in ("asymmetric_branches", "stiffness_nonlinearity"):
        assert reg[name].rival_z == SHAPE_Z > 0
        assert callable(getattr(reg[name], "rival_rows", None))


def _chain_clean(seed: int):
    sys.path.insert(0, str(BENCHES))
    try:
        from chain_normal import chain_record
    finally:
        sys.path.remove(str(BENCHES))
    # the conditions a loss asymmetry was missed at on the blind generator (stop 48):
    # one tone at 12-35 Hz, 12-35 cycles, from rest through the sensors
    fac = {"fs": 1000.0, "f": 18.228, "cycles": 29, "ratio": 0.489, "noise_p": 0.0171,
           "noise_d": 0.00845, "bits": 16, "psi": 0.163}  # fmt: skip
    t, p, d, _ = chain_record(None, 0.0, fac, seed)
    return {"t": t, "p": p, "delta": d}


def test_asymmetry_bound_on_a_single_tone_chain() -> None:
    """Clean chain (fresh seed 49300001 of ``benches/eval_normal_asym_creep.py``'s recipe):
    the asymmetry must pass the rules on its own direction and fit better than the law by
    SHAPE_Z deviations of the comparison's white-noise scale (as the search's
    ``shape_test`` asks), its noise widened by the residual's correlation. The base and the
    law take 98 % of its direction here; the bound lies near the range's end (0.83 since
    stop 52; until then none within the range, the margin widened by the correlation
    too). It is in the fitted ``a``, relative to the fitted damping: the chain's sensors
    lag like a damping (fitted ψ 0.60 for 0.163), so a true a = 0.83 is fitted as 0.24
    (chain seed 52100301) and was named exactly on 7 of 12 fresh chains (52100300-311;
    stiffness_nonlinearity on 2, neither on 3, flagged): far below the bound, where no
    promise is made (stop 49 without any margin: 0.36-0.91)."""
    import contactlab

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = contactlab.diagnose(_chain_clean(49300001), "normal")
    assert res.effect_names == []
    b = {x.effect: x for x in res.not_detected}["asymmetric_branches"]
    assert b.detectable_above is not None
    assert 0.6 < b.detectable_above < 0.95
    assert "one excitation frequency" in b.note


def test_bound_models_the_large_gain_route() -> None:
    """Rule 2's large-gain route (normal contact: a held-out gain of twice the floor passes
    at t > 2) is in the stated bound for the candidates the search gives it to, not for a
    channel delay or a hysteretic loss (``large_gain_route`` False); with it the bound of a
    direction whose gain is far above the floor is smaller than at t > 3 alone."""
    from contactlab.diagnose.candidates_normal import STRONG_GAIN, NormalFamily
    from contactlab.diagnose.power import _bound, _strong_route

    fam = NormalFamily()
    for name in ("creep_drift", "stiffness_nonlinearity", "asymmetric_branches"):
        assert _strong_route(fam, name, 3.0) == (STRONG_GAIN[0], min(STRONG_GAIN[1], 3.0))
    for name in ("channel_delay", "hysteretic_damping"):
        assert _strong_route(fam, name, 3.0) is None
    st = _setting()
    rng = np.random.default_rng(5)
    jp = rng.standard_normal(st.w.size)
    at_z = _bound(jp, st)
    routed = _bound(jp, st, strong=(2.0, 2.0))
    assert at_z is not None and routed is not None
    assert routed < 0.95 * at_z
    # a floor the gains at the bound do not reach twice: the route changes nothing
    high = _bound(jp, st, strong=(1e6, 2.0))
    assert high == pytest.approx(at_z, rel=1e-9)


@pytest.mark.parametrize("infl", [1.0, 1.7])
def test_rival_margin_is_on_the_searchs_scale(infl: float) -> None:
    """The search's shape test divides the likelihood ratio by its white-noise deviation
    (``shape_test``: ``2 ‖f_s - f_a‖_w / σ``) and asks ``SHAPE_Z`` of it; a residual
    correlated by the smoothed input's noise (``se_inflation`` c) widens the ratio's noise,
    not that margin: the candidate wins with probability Φ((|a| √λ / 2 - z) / c) (until
    stop 52 Φ(|a| √λ / (2c) - z): the shapes' bounds 1.9-2.0 times the ideal size on short
    one-tone records where the law was named at 1x it on 10 of 10)."""
    import dataclasses

    st = dataclasses.replace(_setting(), se_inflation=infl)
    lam = 53.0
    jr = np.zeros(st.w.size)
    jr[::2] = np.sqrt(lam / (st.w.size // 2))
    rows = np.ones(st.w.size, bool)
    a = np.full(DRAWS, 1.0)
    won = float(np.mean(_rival_wins(a, jr, rows, st, 2.0)))
    want = float(norm.cdf((np.sqrt(lam) / 2.0 - 2.0) / infl))
    assert won == pytest.approx(want, abs=3.0 * np.sqrt(want * (1 - want) / DRAWS) + 0.01)
