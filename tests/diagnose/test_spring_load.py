"""A parallel spring against a normal load locked to the drive at 2f, in gross sliding
(helper spring_load): the load's quadrature part, times the friction's sign, tilts the loop
as ``k_p x`` does, and where the input is noisy the spring's prediction carries the sensor's
noise (``k_p`` times it, and its steeper branch at the turns) while the load, a function of
time, carries none. The load yields to the spring where the spring does as well away from
the turns and the load's lead in the misfit locked to the cycle (the noise averaged out) is
small; a genuine 2f load, even at the phase most like a spring, keeps its name.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from contactlab.diagnose._family import Prepared
from contactlab.diagnose.effects.tangential.normal_load import cycle_locked_parts
from contactlab.diagnose.search import _yield_to_tried
from contactlab.diagnose.select import Verdict
from contactlab.masing import Masing

H0, AC, N_C, CYCLES = 10.0, 1e4, 200, 24
FS = 10_000.0  # 50 Hz drive
ACA = 4.0
A = ACA / AC
W = 2 * np.pi * FS / N_C


def _t() -> np.ndarray:
    return np.arange(CYCLES * N_C) / FS


def test_cycle_locked_parts_split_strokes_and_drop_noise():
    """A function of x alone shows in the half-sum of the strokes, one of ẋ in the
    half-difference; white noise in neither."""
    t = _t()
    x = A * np.cos(W * t)
    d = Prepared.build(t, x, np.zeros_like(x), errors_in_input=False)
    rng = np.random.default_rng(5)
    s, dd = cycle_locked_parts(d, 2.0 * x / A)
    assert abs(s - 2.0) < 0.1 and abs(dd) < 0.02
    s, dd = cycle_locked_parts(d, np.sin(W * t))
    assert abs(dd - 0.5) < 0.03 and abs(s) < 0.01
    s, dd = cycle_locked_parts(d, rng.normal(0.0, 3.0, t.size))
    assert abs(s) < 0.05 and abs(dd) < 0.05


def _trial(pred: np.ndarray, **p: float) -> SimpleNamespace:
    return SimpleNamespace(
        prediction=pred, heldout=np.ones(pred.size, bool), fitted=pred,
        full=SimpleNamespace(params={"h0": H0, "ac": AC, **p}),
    )  # fmt: skip


def _v(name: str, gain: float) -> Verdict:
    return Verdict(name, 1.0, gain, 10.0, -50.0, True, "accepted")


def _judge(truth: str) -> tuple[list, list]:
    """The record with a spring (``truth`` "spring") or a 2f load at the phase most like
    one ("load"), x noise 1.5 % of the range; each rival fitted by least squares on the
    base's residual, the load given the larger held-out gain as on the rig."""
    t = _t()
    x = A * np.sin(W * t)
    rng = np.random.default_rng(11)
    m = Masing(H0, AC)
    h = m.force(x)
    if truth == "spring":
        y = h + 0.5 * H0 / A * x
    else:
        y = h * (1.0 + 0.25 * np.sin(2 * W * t))
    y = y + rng.normal(0.0, 0.01 * H0, t.size)
    d = Prepared.build(t, x + rng.normal(0.0, 0.03 * A, t.size), y)
    hb = m.force(d.u)
    r = y - hb
    k_p = float(np.dot(r, d.u) / np.dot(d.u, d.u))
    cols = np.column_stack([hb * np.cos(2 * W * t), hb * np.sin(2 * W * t)])
    eps = np.linalg.lstsq(cols, r, rcond=None)[0]
    spring = _trial(hb + k_p * d.u, k_p=k_p)
    load = _trial(hb + cols @ eps, eps_c=eps[0], eps_s=eps[1], f_n=2 * W / (2 * np.pi))
    accepted = [(_v("normal_load", 6.0), load), (_v("parallel_stiffness", 5.0), spring)]
    verdicts = [v for v, _ in accepted]
    tried = {v.name: (v, c) for v, c in accepted}
    return _yield_to_tried(
        SimpleNamespace(kind="tangential"), accepted, verdicts, tried, _trial(hb), d
    )


def test_load_yields_to_a_spring_on_a_noisy_input():
    keep, verdicts = _judge("spring")
    assert [v.name for v, _ in keep] == ["parallel_stiffness"]
    why = {v.name: v.reason for v in verdicts}["normal_load"]
    assert why.startswith("look-alike") and "turns" in why


def test_a_load_like_a_spring_keeps_its_name():
    """At the phase where the load's quadrature part is all (the spring's best look-alike)
    the spring does not draw it as well away from the turns: the load stands."""
    keep, verdicts = _judge("load")
    assert {v.name for v, _ in keep} == {"normal_load", "parallel_stiffness"}
    assert all(v.accepted for v in verdicts)
