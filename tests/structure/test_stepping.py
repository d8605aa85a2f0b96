"""Error-controlled stepping of :meth:`Structure.simulate` (issue 33 item 6): the default run
against tight references (scipy LSODA at rtol 1e-11 on the Bouc-Wen ODE; fixed Newmark 64
steps per sample), SDOF and MDOF, Bouc-Wen, Masing and Jenkins joints; the energy balance
(input work = kinetic + strain + damping + joint work); bad tolerances as typed errors; the
fixed-step option ``substeps=``."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from contactlab import InputError
from contactlab.structure import Structure
from contactlab.structure.model import DEFAULT_TOL

BW = {"alpha": 5e4, "beta": 1e3, "gamma": 0.8, "delta": -1.1}


def _force(n: int, fs: float, seed: int, amp: float = 20.0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    return amp * sum(
        np.sin(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi)) for f in (7, 19, 53, 131)
    )


def _rrms(x: np.ndarray, ref: np.ndarray) -> float:
    return float(np.sqrt(np.mean((x - ref) ** 2) / np.mean(ref**2)))


def _sdof(kind: str, **p: float) -> Structure:
    s = Structure(2.0, 10.0, 5e4)
    s.add_joint(kind, 0, **p)
    return s


def test_default_bouc_wen_sdof_matches_lsoda_to_1e4():
    # the hysteretic benchmark's oscillator at its own sample rate, 750 Hz: one Newmark step
    # per sample is 8 % off; the default reaches the 1e-4 the issue asks
    fs, n = 750.0, 500
    t = np.arange(n) / fs
    u = _force(n, fs, 5)

    def rhs(tt: float, y: np.ndarray) -> list[float]:
        x, v, z = y
        f = np.interp(tt, t, u)
        dz = BW["alpha"] * v - BW["beta"] * (BW["gamma"] * abs(v) * z + BW["delta"] * v * abs(z))
        return [v, (f - 10.0 * v - 5e4 * x - z) / 2.0, dz]

    sol = solve_ivp(rhs, (0, t[-1]), [0, 0, 0], method="LSODA", t_eval=t, rtol=1e-11,
                    atol=1e-15, max_step=1 / fs)  # fmt: skip
    ref = sol.y[0]
    s = _sdof("bouc_wen", **BW)
    new = _rrms(s.simulate(t, force=u).x, ref)
    old = _rrms(s.simulate(t, force=u, substeps=1).x, ref)
    assert new <= 1e-4, new
    assert old > 100 * new, (old, new)


@pytest.mark.parametrize(
    ("kind", "params"),
    [("masing", {"h0": 40.0, "ac": 2e4, "scale": 2.0}), ("jenkins", {"k": 5e4, "fs": 30.0})],
)
def test_default_sdof_matches_fine_fixed_steps(kind, params):
    fs, n = 3000.0, 1500
    t = np.arange(n) / fs
    u = _force(n, fs, 11)
    s = _sdof(kind, **params)
    ref = s.simulate(t, force=u, substeps=64).x  # second order: ~4000x below one step
    tight = s.simulate(t, force=u, tol=DEFAULT_TOL / 100).x
    assert _rrms(tight, ref) <= 2e-5
    assert _rrms(s.simulate(t, force=u).x, ref) <= 1e-4


def test_default_mdof_matches_fine_fixed_steps():
    m = np.diag([2.0, 1.0, 1.5])
    k = 5e4 * np.array([[2, -1, 0], [-1, 2, -1], [0, -1, 1.0]])
    s = Structure(m, 1e-4 * k + 2.0 * m, k)
    s.add_joint("bouc_wen", 0, **BW)
    s.add_joint("masing", 2, 1, h0=40.0, ac=2e4, scale=2.0)
    s.add_joint("jenkins", 1, k=3e4, fs=20.0)
    fs, n = 3000.0, 1200
    t = np.arange(n) / fs
    f = np.stack([_force(n, fs, 3), np.zeros(n), _force(n, fs, 4, 10.0)], axis=1)
    ref = s.simulate(t, force=f, substeps=64).x
    r = s.simulate(t, force=f)
    assert r.success
    assert _rrms(r.x, ref) <= 1e-4
    assert _rrms(s.simulate(t, force=f, substeps=1).x, ref) > 10 * _rrms(r.x, ref)


@pytest.mark.parametrize("seed", [2, 3])
def test_masing_and_jenkins_mdof_within_1e5_of_fine_fixed_steps(seed):
    # Hermite pieces end their Newton solve after one update; where that update moves an end
    # back across a Masing closure (or the start, or a slip point) the joint is tried anew
    # there. Without that the end was carried along the wrong branch's tangent: 3e-5 to 7e-5
    # on these records (seeds 2 to 5), against 2e-6 to 3e-6 with it.
    m = np.diag([2.0, 1.0, 1.5])
    k = 5e4 * np.array([[2, -1, 0], [-1, 2, -1], [0, -1, 1.0]])
    s = Structure(m, 1e-4 * k + 2.0 * m, k)
    s.add_joint("masing", 0, h0=40.0, ac=2e4, scale=2.0)
    s.add_joint("jenkins", 2, 1, k=3e4, fs=20.0)
    fs, n = 3000.0, 3000
    t = np.arange(n) / fs
    f = np.stack([_force(n, fs, seed, 30.0), np.zeros(n), _force(n, fs, seed + 10, 15.0)], 1)
    ref = s.simulate(t, force=f, substeps=64).x  # second order: ~4000x below one step
    r = s.simulate(t, force=f)
    assert r.success
    assert _rrms(r.x, ref) <= 1e-5


@settings(max_examples=12, deadline=None)
@given(
    kind=st.sampled_from(["bouc_wen", "masing", "jenkins", "iwan"]),
    amp=st.floats(1.0, 60.0),
    seed=st.integers(0, 2**16),
    two=st.booleans(),
)
def test_energy_balance_of_the_error_controlled_run(kind, amp, seed, two):
    params = {
        "bouc_wen": BW,
        "masing": {"h0": 40.0, "ac": 2e4},
        "jenkins": {"k": 5e4, "fs": 30.0},
        "iwan": {"k": [2e4, 3e4], "fs": [10.0, 25.0]},
    }[kind]
    fs, n = 3000.0, 600
    t = np.arange(n) / fs
    u = _force(n, fs, seed, amp)
    if two:
        m, k = np.diag([2.0, 1.0]), 5e4 * np.array([[2, -1], [-1, 1.0]])
        s = Structure(m, 1e-4 * k, k)
        s.add_joint(kind, 1, 0, **params)
        f = np.stack([u, np.zeros(n)], axis=1)
    else:
        m, k = np.array([[2.0]]), np.array([[5e4]])
        s = Structure(m, 10.0, k)
        s.add_joint(kind, 0, **params)
        f = u
    r = s.simulate(t, force=f)
    x, v = r.x.reshape(n, -1), r.v.reshape(n, -1)
    ke = 0.5 * np.einsum("ti,ij,tj->t", v, m, v)
    se = 0.5 * np.einsum("ti,ij,tj->t", x, k, x)
    bal = r.input_work - ke - se - r.damping_work - r.joint_work.sum(axis=1)
    # the error-controlled pieces balance to their own accuracy (fixed steps: to rounding);
    # Hermite pieces of Jenkins/Iwan joints up to 1e-5 of the input work (measured over 15
    # seeds x 4 amplitudes x 1/2 DOFs: 6.8e-6 Jenkins, 1.0e-5 Iwan, 1.9e-6 Bouc-Wen; the
    # stick-slip transitions), step doubling (Masing) 1e-6
    assert np.max(np.abs(bal)) <= 3e-5 * np.max(np.abs(r.input_work))
    # dissipation never negative beyond that accuracy
    assert r.joint_energy[-1].min() >= -3e-5 * np.max(np.abs(r.input_work))


@pytest.mark.parametrize("tol", [0.0, -1e-4, float("nan"), float("inf"), "tight"])
def test_a_bad_tolerance_is_an_input_error(tol):
    s = _sdof("jenkins", k=5e4, fs=30.0)
    t = np.arange(10) / 100.0
    with pytest.raises(InputError, match="tol"):
        s.simulate(t, force=np.ones(10), tol=tol)


@pytest.mark.parametrize(
    ("kw", "match"),
    [({"substeps": 0}, "substeps"), ({"substeps": 2.5}, "substeps"),
     ({"substeps": 2, "tol": 1e-4}, "either")],
)  # fmt: skip
def test_bad_stepping_options_are_input_errors(kw, match):
    s = _sdof("jenkins", k=5e4, fs=30.0)
    t = np.arange(10) / 100.0
    with pytest.raises(InputError, match=match):
        s.simulate(t, force=np.ones(10), **kw)


def test_fixed_substeps_still_work_and_converge_at_second_order():
    fs, n = 3000.0, 900
    t = np.arange(n) / fs
    u = _force(n, fs, 7)
    s = _sdof("masing", h0=40.0, ac=2e4, scale=2.0)
    ref = s.simulate(t, force=u, tol=1e-8).x
    e = [_rrms(s.simulate(t, force=u, substeps=k).x, ref) for k in (1, 2, 4)]
    assert 3.0 < e[0] / e[1] < 5.0 and 3.0 < e[1] / e[2] < 5.0, e
    # band-limited inputs between samples (prepared in Python) keep working
    r = s.simulate(t, force=u, substeps=2, interpolation="fourier")
    assert r.success and r.x.shape == (n,)


@pytest.mark.parametrize("kind", ["masing", "bouc_wen"])
def test_rtol_bounds_the_inner_newton_under_error_control(kind):
    # Hermite pieces end their Newton solve after the update once the residual is below
    # min(1e-2, 1e3 sqrt(rtol)) of the forces (the corrections remove what is left); that end
    # must follow rtol where it is tighter than the default, so that a tighter rtol costs
    # iterations and moves the result towards the tightest one (1e-9 and 1e-6 both end at
    # 1e-2: equal counts where no residual is below 1e-6 before an update)
    m = np.diag([2.0, 1.0, 1.5])
    k = 5e4 * np.array([[2, -1, 0], [-1, 2, -1], [0, -1, 1.0]])
    s = Structure(m, 1e-4 * k + 2.0 * m, k)
    if kind == "masing":
        s.add_joint("masing", 0, h0=40.0, ac=2e4, scale=2.0)
    else:
        s.add_joint("bouc_wen", 0, **BW)
    s.add_joint("jenkins", 2, 1, k=3e4, fs=20.0)
    fs, n = 3000.0, 600
    t = np.arange(n) / fs
    f = np.stack([_force(n, fs, 21), np.zeros(n), _force(n, fs, 22, 10.0)], axis=1)
    runs = {rtol: s.simulate(t, force=f, tol=1e-6, rtol=rtol) for rtol in (1e-6, 1e-9, 1e-13)}
    assert runs[1e-13].n_iter > runs[1e-9].n_iter >= runs[1e-6].n_iter
    assert _rrms(runs[1e-9].x, runs[1e-13].x) <= 1e-7
