"""The Gauss-Newton polish of least_squares_fit when its steps zigzag (issue 9): a residual
far from zero makes Gauss-Newton's curvature too small (it omits Σ r ∇²r), the full steps
overshoot and turn back; the polish then takes the step length from the parabola of the
cost along the step and reaches the minimum in a few steps."""

from __future__ import annotations

import numpy as np

from contactlab import _lsq

T = np.linspace(0.0, 3.0, 200)
# an exponential decay with a misfit of the same sign as its curvature (r·r'' > 0): the true
# curvature at the minimum is 1.9 times Gauss-Newton's
Y = np.exp(-T) - 0.9 * T**2 * np.exp(-T)


def _fun(z: np.ndarray) -> np.ndarray:
    return np.exp(-z[0] * T) - Y


def _jac(z: np.ndarray) -> np.ndarray:
    return (-T * np.exp(-z[0] * T))[:, None]


def _minimum() -> float:
    """Where Σ r r' = 0, by bisection (the cost is unimodal on 1..4)."""
    lo, hi = 1.0, 4.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if float(_fun(np.array([mid])) @ _jac(np.array([mid]))[:, 0]) > 0:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


def _polish(z0: float) -> tuple[float, int, bool]:
    calls = [0]

    def fun(z: np.ndarray) -> np.ndarray:
        calls[0] += 1
        return _fun(z)

    z = np.array([z0])
    out = _lsq.polish(fun, _jac, z, _fun(z), _jac(z), np.array([0.0]), np.array([10.0]), ["k"])
    return float(out[0][0]), calls[0], bool(out[3])


def test_polish_zigzag_takes_the_parabola_step(monkeypatch):
    zmin = _minimum()
    r, J = _fun(np.array([zmin])), _jac(np.array([zmin]))[:, 0]
    gn = float(J @ J)
    assert 1.8 < (gn + float(r @ (T**2 * np.exp(-zmin * T)))) / gn < 2.0  # the setting
    z, calls, ok = _polish(1.003 * zmin)
    assert ok and calls <= 12
    assert abs(z - zmin) < 1e-6 * zmin
    # without the parabola step the same polish spends all its 30 steps, short of the minimum
    monkeypatch.setattr(_lsq, "LINE_SEARCH_OFF", np.inf)
    z_old, calls_old, _ = _polish(1.003 * zmin)
    assert calls_old >= 30 and abs(z_old - zmin) > abs(z - zmin)
