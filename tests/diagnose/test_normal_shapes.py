"""The normal shape effects as docs/effects.md §2 defines them (issue 29 items 4-5).

``stiffness_nonlinearity``: ``p - p0 = k_s(δ) δ + c δ'`` with ``k_s = a1 + a2 δ + a3 δ²`` and
a constant ``c``; ``asymmetric_branches``: ``p - p0 = k δ + c (1 + a sgn δ') δ'``. The two
solvers are checked against an independent adaptive solve of the same equations, and the
diagnosis must tell the two apart on records of the independent rig (a linear ``a2`` term
was named ``asymmetric_branches`` before, whose candidate was that term).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicHermiteSpline

import contactlab
from contactlab.diagnose.candidates_normal import (
    NormalFamily,
    kelvin_voigt_asymmetric,
    nonlinear_viscous,
)
from contactlab.synthetic.rig import rig_recording

K, PSI, F = 1.3e12, 0.0887, 1.0


def _pressure(n=1000, cycles=2.5):
    t = np.linspace(0.0, cycles / F, n)
    ramp = np.clip(t * F, 0.0, 1.0)
    p = 4e5 * ramp * np.sin(2 * np.pi * F * t) + 1e5 * np.sin(2 * np.pi * 1.7 * F * t) * ramp
    return t, p


def _ivp(t, p, rhs):
    sp = CubicHermiteSpline(t, p, np.gradient(p, t, edge_order=2))
    sol = solve_ivp(
        lambda tt, y: [rhs(float(sp(tt)), y[0])], (t[0], t[-1]), [p[0] / K], t_eval=t,
        method="LSODA", rtol=1e-11, atol=1e-18, max_step=float(t[1] - t[0]),
    )  # fmt: skip
    assert sol.success
    return sol.y[0]


@pytest.mark.parametrize("a", [0.8, -0.5])
def test_asymmetric_joint_against_an_adaptive_solve(a):
    t, p = _pressure()
    c = PSI * K / (2 * np.pi * 2 * np.pi * F)
    ref = _ivp(t, p, lambda pp, d: (pp - K * d) / (c * (1 + a * np.sign(pp - K * d))))
    got = kelvin_voigt_asymmetric(t, p, K, PSI, 2 * np.pi * F, a, passes=50, tol=1e-13)
    sym = kelvin_voigt_asymmetric(t, p, K, PSI, 2 * np.pi * F, 0.0)
    span = float(np.ptp(ref))
    assert np.max(np.abs(got - ref)) < 2e-6 * span
    # the loss asymmetry is resolved: it moves δ by far more than the solver's error
    assert np.max(np.abs(got - sym)) > 100 * np.max(np.abs(got - ref))
    # the fits' four passes from the symmetric joint are within 1e-6 of the span too
    fit = kelvin_voigt_asymmetric(t, p, K, PSI, 2 * np.pi * F, a, start=sym)
    assert np.max(np.abs(fit - got)) < 1e-6 * span


def test_stiffness_law_keeps_a_constant_damping():
    t, p = _pressure()
    dr = 4e5 / K
    coeffs = (K, 0.15 * K / dr, 0.5 * K / dr**2)
    c = PSI * K / (2 * np.pi * 2 * np.pi * F)

    def ks(d):
        return coeffs[0] + d * (coeffs[1] + d * coeffs[2])

    ref = _ivp(t, p, lambda pp, d: (pp - ks(d) * d) / c)
    got = nonlinear_viscous(t, p, coeffs, PSI, 2 * np.pi * F)
    # eq. 17's damping follows k_s: a different equation, off by far more
    eq17 = _ivp(t, p, lambda pp, d: (pp - ks(d) * d) / (c * ks(d) / K))
    span = float(np.ptp(ref))
    assert np.max(np.abs(got - ref)) < 1e-5 * span
    assert np.max(np.abs(eq17 - ref)) > 10 * np.max(np.abs(got - ref))


def test_one_shape_account_at_a_time():
    fam = NormalFamily()
    assert fam.check(("stiffness_nonlinearity", "channel_delay", "creep_drift"))
    assert not fam.check(("stiffness_nonlinearity", "asymmetric_branches"))
    assert not fam.check(("hysteretic_damping", "asymmetric_branches"))


def _rig(effect, seed):
    eff = {
        "stiffness_nonlinearity": {"a2": 0.2 * K / (0.4e6 / K)},
        "asymmetric_branches": {"a": 0.8},
    }[effect]
    return rig_recording({effect: eff}, "normal", seed=seed, fs=1000.0, f=4.0, cycles=3,
                         frequencies=(1.0, 1.7, 0.6), x_noise=0.004, F_noise=0.008)  # fmt: skip


@pytest.mark.parametrize("effect", ["stiffness_nonlinearity", "asymmetric_branches"])
def test_rig_shapes_are_named_by_their_own_candidate(tmp_path, effect):
    rec = contactlab.read_recording(str(_rig(effect, 5).to_csv(tmp_path / "r.csv")))
    rep = contactlab.diagnose(rec, model="normal")
    assert rep.effect_names == [effect]
    p = rep.effects[0].parameters
    if effect == "stiffness_nonlinearity":  # the linear term, hardening in compression
        assert p["kappa1"] > 0.05 and abs(p["kappa"]) < 0.5 * p["kappa1"]
    else:
        assert p["a"] == pytest.approx(0.8, abs=0.15)
