"""One Simulator protocol for every model with ``simulate(t, input, ...)`` (issue 32)."""

from __future__ import annotations

import numpy as np
import pytest

from contactlab import InputError
from contactlab.diagnose import ExtendedModel
from contactlab.normal import KelvinVoigt, NonlinearContact
from contactlab.simulation import Simulator, simulate
from contactlab.structure import IdentifiedModel, Structure


@pytest.mark.parametrize(
    "cls", [ExtendedModel, KelvinVoigt, NonlinearContact, Structure, IdentifiedModel]
)
def test_every_simulating_model_is_a_simulator(cls):
    assert issubclass(cls, Simulator)


def test_the_front_calls_the_models_own_simulate():
    t = np.linspace(0.0, 2 * np.pi, 400)
    p = 0.4e6 * np.sin(t)
    kv = KelvinVoigt(k=1.3e12, psi=0.2, omega=1.0)
    a = simulate(kv, t, p)
    b = kv.simulate(t, p)
    np.testing.assert_array_equal(a.delta, b.delta)
    s = Structure(M=[[1.0]], C=[[0.5]], K=[[100.0]])
    f = np.sin(3.0 * t)
    np.testing.assert_array_equal(simulate(s, t, force=f).x, s.simulate(t, force=f).x)


def test_a_non_model_is_refused_with_a_typed_error():
    assert not isinstance(object(), Simulator)
    with pytest.raises(InputError, match="float is not a simulator"):
        simulate(1.0, [0.0, 1.0], [0.0, 0.0])


def test_every_model_gives_a_typed_response():
    """simulate_response: the same numbers as each model's own simulate, in one shape."""
    from contactlab.simulation import Response, SimulatedResponse, simulate_response

    t = np.linspace(0.0, 2 * np.pi, 400)
    p = 0.4e6 * np.sin(t)
    kv = KelvinVoigt(k=1.3e12, psi=0.2, omega=1.0)
    nl = NonlinearContact([1.32596e12, 1.59811e18, 2.92127e24, 2.87416e30], psi=0.2, omega=1.0)
    for model in (kv, nl):
        r = simulate_response(model, t, p)
        assert isinstance(r, SimulatedResponse) and r.success and r.status == 0
        np.testing.assert_array_equal(r.response, model.simulate(t, p).delta)
        np.testing.assert_array_equal(r.t, t)
    s = Structure(M=[[1.0]], C=[[0.5]], K=[[100.0]])
    f = np.sin(3.0 * t)
    r = simulate_response(s, t, force=f)
    assert isinstance(r, SimulatedResponse) and r.success
    np.testing.assert_array_equal(r.response, s.simulate(t, force=f).x)

    class Gain:  # a model whose simulate returns a bare array, as the diagnosis's does
        def simulate(self, t, u):
            return 2.0 * np.asarray(u)

    r = simulate_response(Gain(), t, f)
    assert isinstance(r, Response) and isinstance(r, SimulatedResponse) and r.success
    np.testing.assert_array_equal(r.response, 2.0 * f)
    np.testing.assert_array_equal(r.t, t)


def test_a_bare_array_is_no_typed_response():
    from contactlab.simulation import Response, SimulatedResponse

    r = Response(np.arange(3.0), np.zeros(3))
    assert isinstance(r, SimulatedResponse) and r.success and r.message == ""
    assert not isinstance(np.zeros(3), SimulatedResponse)
