"""Joint laws of contactlab.joints as joints of a Structure (kind "law")."""

from __future__ import annotations

import numpy as np
import pytest

import contactlab
from contactlab.joints import (
    Backlash,
    Dahl,
    Jenkins,
    KelvinVoigt,
    LuGre,
    MasingLaw,
    MaxwellSlip,
    Parallel,
    Segalman,
    Series,
)
from contactlab.structure import Structure, iwan_uniform
from contactlab.structure.joints import decode_law, encode_law


def quasi_static(amp: float, periods: int = 3, **joint) -> object:
    """A light mass on a stiff overdamped tie to a slowly moving base, the joint to ground."""
    s = Structure(1e-3, 300.0, 1e7)
    kind = joint.pop("kind")
    s.add_joint(kind, 0, **joint)
    t = np.linspace(0.0, periods, 2000 * periods + 1)
    y = amp * np.sin(2 * np.pi * t)
    return s.simulate(t, base=y, base_velocity=amp * 2 * np.pi * np.cos(2 * np.pi * t))


def forced(substeps: int = 1, **joint) -> object:
    s = Structure(0.5, 2.0, 4e3)
    kind = joint.pop("kind")
    s.add_joint(kind, 0, **joint)
    t = np.linspace(0.0, 2.0, 4001)
    f = 3.0 * np.sin(2 * np.pi * 12 * t) + 1.0 * np.sin(2 * np.pi * 31 * t)
    return s.simulate(t, force=f, substeps=substeps)


def test_masing_law_joint_equals_builtin_joint() -> None:
    for run in (forced, lambda **j: quasi_static(2e-4, **j)):
        a = run(kind="masing", h0=1.0, ac=2e4, scale=2.0)
        b = run(kind="law", law=MasingLaw(1.0, 2e4))
        assert a.success and b.success
        np.testing.assert_allclose(b.x, a.x, rtol=0, atol=1e-9 * np.abs(a.x).max())


@pytest.mark.parametrize(
    ("builtin", "law"),
    [
        ({"kind": "jenkins", "k": 2e4, "fs": 1.0}, Jenkins(2e4, 1.0)),
        (
            {"kind": "iwan", **iwan_uniform(2e4, 1.0, 8)},
            MaxwellSlip(*iwan_uniform(2e4, 1.0, 8).values()),
        ),
    ],
    ids=["jenkins", "iwan"],
)
def test_law_joint_converges_with_builtin_joint(builtin: dict, law) -> None:
    """The built-in Jenkins/Iwan joints sub-step at each stick-slip transition, the law joint
    only at reversals: both converge to the same response as the step shrinks, at the same
    rate (measured: relative errors 9e-4 / 6e-5 / 2e-6 of the law joint at 1 / 4 / 16
    sub-steps against 1.4e-3 / 9e-5 / 4e-6 of the built-in, both against 32 sub-steps)."""
    ref = forced(32, **builtin).x
    scale = np.abs(ref).max()
    errs = [np.abs(forced(sub, kind="law", law=law).x - ref).max() / scale for sub in (1, 8)]
    assert errs[0] < 2e-3
    assert errs[1] < errs[0] / 30


def test_segalman_joint_dissipates_the_power_law() -> None:
    law = Segalman(1.0, 2e4, -0.5, 0.2)
    amp = 0.3 * law.phi_max
    r = quasi_static(amp, kind="law", law=law)
    n = 2000
    x = r.x[-n - 1 :]
    A = 0.5 * (x.max() - x.min())
    e = r.joint_energy[-n - 1 :, 0]
    assert e[-1] - e[0] == pytest.approx(float(law.loop_energy(A)), rel=2e-3)


def test_composed_law_joint_runs_and_dissipates() -> None:
    law = Parallel(Backlash(1e-4, Series(KelvinVoigt(5e4), Dahl(2e4, 1.0))), k=500.0)
    r = forced(kind="law", law=law)
    assert r.success
    assert r.joint_energy[-1, 0] > 0


def test_law_joint_needs_a_law() -> None:
    s = Structure(1.0, 0.0, 1e3)
    with pytest.raises(contactlab.InputError, match="law="):
        s.add_joint("law", 0)
    with pytest.raises(contactlab.InputError, match=r"contactlab\.joints law"):
        s.add_joint("law", 0, law="lugre")


# SDOF m ẍ + c ẋ + k x + F_joint = f(t) with a rate-dependent joint, against an independent
# integration of the same ODE with the joint's internal state (scipy's Radau, tight
# tolerances): the law joint sees the end-of-step velocity as its velocity over the step, a
# first-order scheme in the rate terms, so the response converges as the step shrinks.
M, C, K = 0.5, 2.0, 4e3
T_S = np.linspace(0.0, 0.5, 1001)


F_S = 3.0 * np.sin(2 * np.pi * 12 * T_S) + 1.0 * np.sin(2 * np.pi * 31 * T_S)
H_S = float(T_S[1] - T_S[0])


def _drive(t):
    """The drive as the integrator sees it: linear between the samples ``T_S``."""
    if np.ndim(t):
        return np.interp(t, T_S, F_S)
    i = min(max(int(t / H_S), 0), T_S.size - 2)
    return F_S[i] + (F_S[i + 1] - F_S[i]) * (t - T_S[i]) / H_S


def _lugre_rhs(law):
    def g(v):
        return law.Fc + (law.Fs - law.Fc) * np.exp(-(np.abs(v / law.vs) ** law.delta))

    def rhs(t, y):
        x, v, z = y
        zdot = v - law.sigma0 * abs(v) * z / g(v)
        F = law.sigma0 * z + law.sigma1 * zdot + law.sigma2 * v
        return [v, (_drive(t) - C * v - K * x - F) / M, zdot]

    return rhs, 3


def _dahl_rhs(law):
    def rhs(t, y):
        x, v, F = y
        # dF/dt = σ0 v (1 - F/Fc sgn v)^α (α = 1 here)
        Fdot = law.sigma0 * (v - abs(v) * F / law.Fc)
        return [v, (_drive(t) - C * v - K * x - F) / M, Fdot]

    return rhs, 3


def _ivp(rhs_n, t):
    from scipy.integrate import solve_ivp

    rhs, n = rhs_n
    sol = solve_ivp(rhs, (t[0], t[-1]), np.zeros(n), method="LSODA", t_eval=t, rtol=1e-8,
                    atol=1e-12)  # fmt: skip
    assert sol.success
    return sol.y[0]


@pytest.mark.parametrize(
    ("law", "rhs"),
    [
        (LuGre(sigma0=2e4, sigma1=20.0, sigma2=1.0, Fc=1.0, Fs=1.5, vs=5e-3), _lugre_rhs),
        (Dahl(sigma0=2e4, Fc=1.0, alpha=1.0), _dahl_rhs),
    ],
    ids=["lugre", "dahl"],
)
def test_rate_dependent_law_joint_matches_an_independent_integration(law, rhs) -> None:
    t = T_S
    ref = _ivp(rhs(law), t)
    scale = np.abs(ref).max()
    errs = []
    for sub in (2, 16):
        s = Structure(M, C, K)
        s.add_joint("law", 0, law=law)
        r = s.simulate(t, force=_drive(t), substeps=sub)
        assert r.success
        errs.append(float(np.abs(r.x - ref).max() / scale))
    # measured (LuGre, Dahl): 2 sub-steps 7.3e-5, 2.3e-4; 16 sub-steps 6.4e-6, 3.7e-6
    # (64: 1.8e-6, 2.5e-7): first order in the step for LuGre's rate terms, second for Dahl
    assert errs[1] < 2e-5
    assert errs[1] < errs[0] / 5


def test_rate_dependent_compositions_run_converge_and_dissipate() -> None:
    from contactlab.joints import GeneralizedMaxwellSlip

    laws = [
        Backlash(5e-5, LuGre(2e4, 20.0, 1.0, 1.0, 1.5, 5e-3)),
        GeneralizedMaxwellSlip(np.full(3, 8e3), np.full(3, 1 / 3), 1.0, 1.5, 5e-3, 50.0),
        Parallel(LuGre(2e4, 20.0, 1.0, 1.0, 1.5, 5e-3), k=300.0, c=0.5),
    ]
    t = T_S
    for law in laws:
        xs = []
        for sub in (4, 32):
            s = Structure(M, C, K)
            s.add_joint("law", 0, law=law)
            r = s.simulate(t, force=_drive(t), substeps=sub)
            assert r.success, law
            assert r.joint_energy[-1, 0] > 0, law
            xs.append(r.x)
        assert np.abs(xs[0] - xs[1]).max() < 2e-2 * np.abs(xs[1]).max(), law


def test_law_joint_round_trips_through_dict() -> None:
    law = Parallel(Backlash(1e-4, Segalman(1.0, 2e4, -0.3, 0.1)), k=500.0)
    assert decode_law(encode_law(law)) == law
    s = Structure(0.5, 2.0, 4e3)
    s.add_joint("law", 0, law=law)
    s2 = Structure.from_dict(s.to_dict())
    assert decode_law(s2.joints[0].arrays["spec"]) == law
    assert s2.joints[0].initial_stiffness == 500.0
