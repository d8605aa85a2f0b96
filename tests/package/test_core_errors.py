"""Core failures reach Python as results or typed errors, never as panics (issue 13)."""

from __future__ import annotations

import numpy as np
import pytest

import contactlab
from contactlab import _core
from contactlab.masing import Masing
from contactlab.normal import KelvinVoigt, NonlinearContact


def _sine(per: int, cycles: int = 2, pa: float = 0.4e6) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(cycles * per + 1) * 2 * np.pi / per
    return t, pa * np.sin(t)


@pytest.mark.parametrize("per", [8, 16, 64])
def test_leaving_the_domain_mid_solve_returns_the_partial_solution(per):
    """k_s(δ) = 1e12 + 5e18 δ vanishes at δ = -0.2 µm; with a loose tolerance an accepted step
    lands beyond it. That used to throw the computed samples away as an InputError."""
    a = (1e12, 5e18)
    m = NonlinearContact(k_s_delta=list(a), psi=0.1, omega=1.0)
    t, p = _sine(per)
    res = m.simulate(t, p, rtol=0.1, interp="linear")
    assert not res.success and res.status == -1
    assert "left the model's domain" in res.message and "not positive" in res.message
    assert "k_s(δ) vanishes at δ = -2e-07 m" in res.message  # the model's hint is appended
    assert 1 < res.delta.size < t.size
    assert res.t.size == res.delta.size == res.velocity.size
    np.testing.assert_array_equal(res.t, t[: res.delta.size])
    assert np.all(np.isfinite(res.delta)) and np.all(a[0] + a[1] * res.delta > 0)
    # The samples it returns are those of the same solve, only cut short.
    ok = m.simulate(t[: res.delta.size], p[: res.delta.size], rtol=0.1, interp="linear")
    np.testing.assert_allclose(ok.delta, res.delta, rtol=0, atol=1e-15)


def test_starting_outside_the_domain_is_still_an_input_error():
    m = NonlinearContact(k_s_delta=[1e12, 5e18], psi=0.1, omega=1.0)
    t, p = _sine(16)
    with pytest.raises(contactlab.InputError, match="stiffness is not positive"):
        m.simulate(t, p, delta0=-1e-6)


@pytest.mark.parametrize("pa", [np.nan, np.inf, -np.inf])
def test_kelvin_voigt_steady_state_rejects_a_non_finite_amplitude(pa):
    kv = KelvinVoigt(1e12, 0.1, 1.0)
    with pytest.raises(contactlab.InputError, match="pa"):
        kv.steady_state(np.linspace(0.0, 1.0, 5), pa)
    with pytest.raises(contactlab.InputError, match="pa"):
        kv.analytic(pa)


def _strided(n: int = 12) -> np.ndarray:
    return np.linspace(0.0, 1.0, 2 * n)[::2]


@pytest.mark.parametrize(
    "call",
    [
        lambda x: _core.poly_fit(x, np.ones(x.size), 1),
        lambda x: _core.poly_roots_in(x, -1.0, 1.0),
        lambda x: _core.kv_steady_state(1.0, 0.1, 1.0, 0.4, x),
        lambda x: _core.fold_cycles(x, 0.0, 4.0, 2, 4),
        lambda x: _core.loop_area(x, np.ones(x.size)),
        lambda x: Masing(1.0, 1.0)._core.push(x),
    ],
)
def test_non_contiguous_arrays_at_the_binding_are_input_errors(call):
    x = _strided()
    assert not x.flags.c_contiguous
    with pytest.raises(contactlab.InputError, match="contiguous"):
        call(x)


def test_restoring_a_state_with_an_impossible_count_is_an_input_error():
    op = Masing(1.0, 1.0).operator()
    with pytest.raises(contactlab.InputError, match="sample count"):
        op.state = [0.0, 0.0, 0.0, 1e30]
    op.push(np.array([0.0, 0.1, -0.05]))  # the operator is still usable
    op.state = [0.0, 0.0, 0.0, 2.0**53]
    assert op.state[3] == 2.0**53


def test_polynomial_degree_at_the_integer_limit_is_an_input_error():
    x = np.linspace(0.0, 1.0, 5)
    with pytest.raises(contactlab.InputError, match="degree"):
        _core.poly_fit(x, x, 2**64 - 1)
