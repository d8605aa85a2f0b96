"""The rig's electrodynamic shaker (``rig_recording(shaker=...)``): the armature's motion
from rest carries a start-up transient and odd drive harmonics, its steady stroke is the
asked one, and bad figures are refused by name."""

from __future__ import annotations

import math

import numpy as np
import pytest

from contactlab.errors import InputError
from contactlab.synthetic.rig import rig_recording

KW = {"fs": 2000.0, "f": 10.0, "cycles": 8, "x_noise": 0.0, "F_noise": 0.0, "bits": None}
SHAKER = {"mass": 0.5, "fn": 6.0, "zeta": 0.05}


def _harmonics(t, x, f, K=15, start=0.0):
    """Amplitudes of the first ``K`` harmonics of ``x`` over ``t >= start`` and what a fit
    by them leaves per cycle (RMS, over the whole record)."""
    w = 2 * math.pi * f
    B = np.column_stack(
        [np.ones_like(t)] + [g(k * w * t) for k in range(1, K + 1) for g in (np.cos, np.sin)]
    )
    keep = t >= start
    c, *_ = np.linalg.lstsq(B[keep], x[keep], rcond=None)
    amp = np.hypot(c[1::2], c[2::2])
    r = x - B @ c
    per = t < 1.0 / f
    return amp, float(np.sqrt(np.mean(r[per] ** 2))), float(np.sqrt(np.mean(r[keep] ** 2)))


def test_shaker_motion_has_a_startup_transient_and_odd_harmonics():
    rec = rig_recording({}, seed=2, acA=3.0, ramp_cycles=0.0, shaker=SHAKER, **KW)
    A = rec.truth["base"]["A"]
    amp, first, steady = _harmonics(rec.t, rec.x, 10.0, start=0.4)
    assert abs(amp[0] / A - 1.0) < 0.03  # the steady stroke is the asked one
    assert amp[2] > 0.01 * amp[0]  # the friction's back-action: a 3rd harmonic
    assert amp[1] < 1e-3 * amp[0]  # ... and no even one (the friction is odd)
    assert first > 0.02 * A and steady < 0.1 * first  # a start-up transient that dies out
    assert rec.truth["base"]["shaker"]["F0"] > 0.5 * 40.0  # the drive overcomes h0


def test_a_fixture_mass_is_carried_by_the_armature_and_read_by_the_cell():
    kw = {**KW, "acA": 1.0, "ramp_cycles": 1.0, "shaker": SHAKER}
    plain = rig_recording({}, seed=4, **kw)
    heavy = rig_recording({"inertia": {"m": 2.0}}, seed=4, **kw)
    # the steady stroke is held, but the command must push the heavier armature harder
    assert heavy.truth["base"]["shaker"]["F0"] != pytest.approx(
        plain.truth["base"]["shaker"]["F0"], rel=1e-3
    )
    dt = 1.0 / KW["fs"]
    acc = np.gradient(np.gradient(heavy.x, dt), dt)
    steady = heavy.t > 0.3
    # the cell reads m·ẍ beside the contact: the force's part along ẍ is about 2 kg
    B = np.column_stack([heavy.x, np.ones_like(heavy.x), acc])[steady]
    servo = rig_recording({"inertia": {"m": 2.0}}, seed=4, **{**kw, "shaker": None})
    assert servo.truth["base"].get("shaker") is None
    c, *_ = np.linalg.lstsq(B, heavy.F[steady], rcond=None)
    assert c[2] > 0.5


@pytest.mark.parametrize(
    "kw",
    [
        {"shaker": {"mass": 0.0}},
        {"shaker": {"fn": -1.0}},
        {"shaker": {"zeta": float("nan")}},
        {"shaker": {"stroke": 1.0}},
        {"shaker": 3.0},
        {"shaker": SHAKER, "effects": {"backlash": {"b": 1e-6}}},
        {"shaker": SHAKER, "drive_harmonics": (0.1,)},
        {"shaker": SHAKER, "kind": "normal"},
    ],
)
def test_bad_shaker_figures_are_refused_by_name(kw):
    kw = dict(kw)
    effects = kw.pop("effects", {})
    with pytest.raises(InputError, match=r"shaker|backlash|drive_harmonics"):
        rig_recording(effects, seed=1, **{**KW, "cycles": 2}, **kw)
