"""A mass read along ẍ of a noisy x (issue 29: clean records named ``inertia``).

The base model runs on the measured input, so its error at a sample is ``-k·n`` (the loop's
stiffness times the input's noise there); any ``ẍ`` read over that same sample carries the
noise twice differentiated, whose weight at the centre is negative: a clean record's mass
came out positive. The mass now reads ``ẍ`` without the samples the base model's input at
that sample holds (``inertia.mass_acceleration``).
"""

from __future__ import annotations

import types

import numpy as np

import contactlab
from contactlab.diagnose.effects.tangential import inertia
from contactlab.masing import Masing
from contactlab.synthetic._common import block_excitation


def _clean_three_blocks():
    """The package generator's clean record 482111 of ``benches/eval_false_alarm.py``:
    three blocks (amplitudes 0.4, 0.7, 1.0; frequencies 1, 1.7, 0.6 times 11.55 Hz) from rest,
    50 cycles at 1 kHz, ac·A 0.3, x noise 2 % and F noise 0.77 % of each channel's range.
    It was named ``inertia`` (5.7 kg, held-out gain 0.39 σ², t 3.3) + ``parameter_drift``."""
    rng = np.random.default_rng(482111)
    A, f0, fs, cycles = 1e-5, 11.550461086533751, 1000.0, 50
    xfun, total, _ = block_excitation(
        A * np.array([0.4, 0.7, 1.0]), f0 * np.array([1.0, 1.7, 0.6]), (cycles + 2) / 3.0
    )
    t = np.arange(round(total * fs) + 1) / fs
    x = xfun(t)
    F = Masing(50.0, 0.3 / A).force(x)
    xm = x + rng.normal(0.0, 0.02 * float(np.ptp(x)), x.size)
    Fm = F + rng.normal(0.0, 0.0077 * float(np.ptp(F)), F.size)
    return t, xm, Fm


def test_a_clean_record_with_a_noisy_input_names_no_mass():
    rep = contactlab.diagnose(_clean_three_blocks(), model="tangential")
    assert "inertia" not in rep.effect_names
    tried = [v for st in rep.steps for v in st.candidates if v.name == "inertia"]
    assert tried and not any(v.accepted for v in tried)
    # and a bound is stated for it (none was, with the mass named)
    nd = {x.effect: x for x in rep.not_detected}["inertia"]
    assert nd.detectable_above is not None or nd.reason.strip()


def _prepared(u: np.ndarray, dt: float, period: float, u_filter: int):
    return types.SimpleNamespace(
        u=u, udd=np.zeros(u.size), dt=dt, t=np.arange(u.size) * dt,
        extra={"u_noise": 1e-9, "u_raw": u, "u_filter": u_filter},
        cycles=types.SimpleNamespace(
            period_samples=period, reversals=np.arange(0, u.size, period / 2).astype(int)
        ),
    )  # fmt: skip


def test_the_mass_acceleration_is_exact_on_a_cubic_up_to_the_ends():
    dt = 1e-3
    t = np.arange(400) * dt
    acc = inertia.mass_acceleration(_prepared(3 + 2 * t - 5 * t**2 + 7 * t**3, dt, 100.0, 9))
    np.testing.assert_allclose(acc, -10 + 42 * t, atol=1e-6)


def test_the_mass_acceleration_reads_no_sample_the_base_input_holds():
    """Its weight on the samples within the input filter's half window is zero: a unit
    impulse there leaves ``ẍ`` at that sample untouched."""
    n, period, wf = 600, 100.0, 9
    for k in (0, 2, 4):
        u = np.zeros(n)
        u[300 + k] = 1.0
        acc = inertia.mass_acceleration(_prepared(u, 1.0, period, wf))
        assert acc[300] == 0.0
    u = np.zeros(n)
    u[300 + 12] = 1.0  # and reads the samples further out (a 20-sample half window)
    assert inertia.mass_acceleration(_prepared(u, 1.0, period, wf))[300] != 0.0
