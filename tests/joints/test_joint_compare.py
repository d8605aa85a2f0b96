"""Scores of predicted joint forces (contactlab.joints.compare), each on a hand-computable
example."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from contactlab.errors import InputError
from contactlab.joints import compare
from contactlab.joints.compare import (
    cycle_energies,
    energy_per_cycle_error,
    nrmse,
    rrse,
    snr_db,
    trac,
)
from contactlab.joints.records import JointRecord

F4 = [1.0, -1.0, 1.0, -1.0]
P4 = [0.9, -0.9, 0.9, -0.9]


def test_hand_example_square_wave():
    # error 0.1 on every sample: Σe² = 0.04, ΣF² = 4, range 2, mean 0
    assert snr_db(F4, P4) == pytest.approx(20.0, abs=1e-12)
    assert nrmse(F4, P4) == pytest.approx(0.1 / 2.0, abs=1e-15)
    assert rrse(F4, P4) == pytest.approx(0.1, abs=1e-15)
    assert trac(F4, P4) == pytest.approx(1.0, abs=1e-15)  # proportional: TRAC blind to scale


def test_hand_example_offset_and_orthogonal():
    # F = [3, 1], F̂ = [2, 2]: e = [1, -1]; ΣF² = 10, Σe² = 2 -> 10 log10 5
    assert snr_db([3.0, 1.0], [2.0, 2.0]) == pytest.approx(10 * math.log10(5.0))
    # mean 2: Σ(F - mean)² = 2 -> RRSE 1 (no better than the mean, which F̂ is)
    assert rrse([3.0, 1.0], [2.0, 2.0]) == pytest.approx(1.0)
    # NRMSE = 1 / (3 - 1)
    assert nrmse([3.0, 1.0], [2.0, 2.0]) == pytest.approx(0.5)
    # TRAC = (6 + 2)² / (10 · 8) = 0.8
    assert trac([3.0, 1.0], [2.0, 2.0]) == pytest.approx(0.8)
    assert trac([1.0, 0.0], [0.0, 1.0]) == 0.0
    assert snr_db(F4, F4) == math.inf


def test_energy_of_a_rectangle_loop():
    # a triangle wave x (±A) against a Coulomb force ±Fc: 4 Fc A per cycle
    A, Fc, n = 2e-3, 5.0, 400
    ph = np.arange(3 * n + 1) / n
    x = A * (2.0 / np.pi) * np.arcsin(np.sin(2 * np.pi * ph))  # starts at 0 rising
    v = np.gradient(x)
    F = Fc * np.sign(v)
    E = cycle_energies(x, F)
    assert E.size == 2
    # the force switches within the peak samples (sign(0) = 0 there): the trapezoid rule
    # loses Fc·dx at each of the two reversals of a cycle, dx = 4A/n: E = 4 Fc A (1 - 2/n)
    np.testing.assert_allclose(E, 4 * Fc * A * (1 - 2 / n), rtol=1e-12)
    out = energy_per_cycle_error(x, F, 1.25 * F)
    assert out["energy_error"] == pytest.approx(0.25, abs=1e-12)
    assert out["n_cycles"] == 2


def test_energy_of_an_ellipse():
    # F = c ẋ on x = A sin ωt: E = π c ω A² per cycle
    A, c, w = 1e-3, 40.0, 2 * np.pi * 3.0
    t = np.linspace(0, 4 / 3.0, 8001)
    x = A * np.sin(w * t)
    F = c * A * w * np.cos(w * t)
    # trapezoid rule on 2000 steps a cycle: relative error (2π/2000)² / 6 = 1.6e-6
    np.testing.assert_allclose(cycle_energies(x, F), np.pi * c * w * A**2, rtol=2e-6)


def test_compare_table_and_pooled_rows():
    t = np.linspace(0.0, 2.0, 401)
    x = np.sin(2 * np.pi * t)
    F = np.cos(2 * np.pi * t)
    recs = [JointRecord(t, x, F, "a"), JointRecord(t, x, 2 * F, "b")]
    tab = compare({"half": [0.5 * F, F], "exact": {"a": F, "b": 2 * F}}, recs)
    assert tab.models == ["half", "exact"] and tab.records == ["a", "b"]
    # half of each record: SNR 20 log10 2 per record and pooled
    for rec in ("a", "b", "pooled"):
        assert tab.row("half", rec)["snr_db"] == pytest.approx(20 * math.log10(2.0))
    assert tab.row("half", "a")["energy_error"] == pytest.approx(-0.5, abs=1e-9)
    assert tab.pooled("half")["energy_error"] == pytest.approx(-0.5, abs=1e-9)
    assert tab.pooled("exact")["snr_db"] == math.inf
    assert tab.best("snr_db") == "exact"
    assert tab.best("nrmse") == "exact"
    d = tab.to_dict()
    assert d["units"]["snr_db"] == "dB" and len(d["rows"]) == 6
    assert "pooled" in tab.to_text()


def test_pooled_is_the_concatenation():
    rng = np.random.default_rng(4)
    t = np.arange(200) / 100.0
    recs, preds = [], []
    for k in range(3):
        x = np.sin(2 * np.pi * t + k)
        F = rng.normal(size=t.size) * (k + 1)
        recs.append(JointRecord(t, x, F, f"r{k}"))
        preds.append(F + rng.normal(size=t.size) * 0.3)
    tab = compare({"m": preds}, recs)
    allF, allP = np.concatenate([r.F for r in recs]), np.concatenate(preds)
    assert tab.pooled("m")["snr_db"] == pytest.approx(snr_db(allF, allP))
    assert tab.pooled("m")["nrmse"] == pytest.approx(nrmse(allF, allP))


def test_mask_scores_only_the_selected_samples():
    t = np.arange(100) / 100.0
    x = np.sin(2 * np.pi * t)
    F = np.ones(100)
    F[::2] = -1.0
    P = F.copy()
    P[:50] = 0.0  # wrong where not scored
    mask = np.zeros(100, bool)
    mask[50:] = True
    tab = compare({"m": [P]}, [JointRecord(t, x, F, "r", mask)])
    assert tab.pooled("m")["snr_db"] == math.inf
    assert tab.pooled("m")["n"] == 50


def test_model_failure_is_a_row_not_an_exception():
    t = np.arange(10) / 10.0
    rec = JointRecord(t, np.sin(t), np.cos(t), "r")

    class Broken:
        name = "broken"

        def force(self, t, x):
            raise InputError("cannot")

    tab = compare([Broken()], [rec])
    assert tab.row("broken", "r")["error"] == "cannot"
    assert tab.pooled("broken")["snr_db"] is None


def test_bad_input_is_named():
    with pytest.raises(InputError, match="samples"):
        snr_db([1.0, 2.0], [1.0])
    with pytest.raises(InputError, match="constant"):
        nrmse([1.0, 1.0], [1.0, 2.0])
    with pytest.raises(InputError, match="not finite"):
        trac([1.0, np.nan], [1.0, 2.0])
    t = np.arange(5.0)

    class Named:
        name = "same"

        def force(self, t, x):
            return x

    with pytest.raises(InputError, match="two models"):
        compare([Named(), Named()], [(t, t, t)])
    with pytest.raises(InputError, match="no measured force"):
        compare({"m": [np.ones(5)]}, [(t, t)])


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(-1e3, 1e3), min_size=3, max_size=40),
       st.floats(0.1, 10.0))  # fmt: skip
def test_scale_invariance(values, s):
    F = np.array(values)
    if np.ptp(F) < 1e-6:
        return
    P = F[::-1].copy()
    # every score but the energy is invariant to the units of the force
    assert snr_db(s * F, s * P) == pytest.approx(snr_db(F, P), abs=1e-9)
    assert nrmse(s * F, s * P) == pytest.approx(nrmse(F, P), rel=1e-9)
    assert rrse(s * F, s * P) == pytest.approx(rrse(F, P), rel=1e-9)
    assert 0.0 <= trac(F, P) <= 1.0 + 1e-12
