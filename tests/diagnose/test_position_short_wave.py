"""Friction varying along the track in waves shorter than the stroke (issue 29, helper
posfric): an independent generator's wave of 40 µm on a long stroke was named
``power_law_microslip`` or nothing; the start's wavelength grid began at 0.6 half-widths."""

from __future__ import annotations

import tempfile
import warnings
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from contactlab.diagnose.effects import registry
from contactlab.diagnose.effects.tangential.position_friction import start_wavelengths
from contactlab.masing import Masing


def _record(wave_halves: float, cycles: int = 6, n: int = 400, a: float = 0.02):
    """A Masing loop whose friction varies along the track by ``a`` in a wave of
    ``wave_halves`` half-widths of the stroke: ``(d, residual of the base)``."""
    t = np.arange(cycles * n) / n
    A = 2.4 / 1e4
    x = A * np.sin(2 * np.pi * t)
    h = Masing(40.0, 1e4).force(x)
    L = wave_halves * A
    F = h * (1.0 + a * np.cos(2 * np.pi * x / L + 0.7))
    extra = {"x_mid": 0.0, "x_half": A, "u_noise": 0.0}
    cycles = SimpleNamespace(period_samples=float(n), cycle=np.floor(t).astype(int))
    d = SimpleNamespace(u=x, y=F, extra=extra, cycles=cycles)
    return d, F - h, L


@pytest.mark.parametrize("halves", [0.17, 0.3])
def test_start_finds_a_wave_shorter_than_the_stroke(halves):
    d, residual, L = _record(halves)
    p = registry("tangential")["position_friction"].start({}, d, residual)
    assert abs(p["L"] / L - 1.0) < 0.03
    assert np.hypot(p["a1"], p["b1"]) == pytest.approx(0.02, rel=0.15)


def test_start_takes_the_wave_that_repeats_across_cycles():
    """A wiggle that changes from cycle to cycle is not a track's wave: with the residual
    a short wave on the even cycles and its opposite on the odd ones, no short wave gains
    held out, and the start keeps to the long waves' grid."""
    d, residual, _ = _record(0.17)
    flip = np.where(d.cycles.cycle % 2 == 0, 1.0, -1.0)
    p = registry("tangential")["position_friction"].start({}, d, residual * flip)
    assert p["L"] >= 0.6 * d.extra["x_half"] * (1 - 1e-9)


def test_short_waves_stop_where_the_record_resolves_them():
    # 40 samples per period: a wave shorter than 5 samples at mid-stroke is not tried
    d, _, _ = _record(0.17, n=40)
    wl = start_wavelengths(d, d.extra["x_half"])
    A = d.extra["x_half"]
    assert wl.min() >= min(5.0 * np.pi * A / 40, 0.6 * A) * (1 - 1e-9)
    # the input's noise: waves shorter than 10 of its standard deviations are not tried
    d.extra["u_noise"] = 0.05 * A
    assert start_wavelengths(d, A).min() >= 0.5 * A * (1 - 1e-9)
    assert start_wavelengths(d, A).min() < 0.6 * A
    # the grid's step turns the phase over the stroke by at most π/4
    d, _, _ = _record(0.17)
    k = np.sort(2 * np.pi / start_wavelengths(d, A))
    assert np.max(np.diff(k)) * 2 * A <= np.pi / 4 * (1 + 1e-9)


@pytest.mark.slow
def test_rig_wave_of_a_sixth_of_the_stroke_is_named():
    """The lead's miss (conditions of the independent generator): fs 1 kHz, 8.1 Hz, 20 cycles,
    ac·A 2.4, a = 2.3 %, L = 40 µm on a 240 µm amplitude; named stribeck before."""
    import contactlab
    from contactlab.synthetic.rig import rig_recording

    warnings.simplefilter("ignore")
    rec = rig_recording(
        {"position_friction": {"eps": 0.023, "L": 40e-6, "phi": 0.7}}, "tangential",
        seed=49400000, fs=1000.0, f=8.1, cycles=20, acA=2.4, h0=40.0, ac=1e4, x_noise=0.016,
        F_noise=0.006, ramp_cycles=0.5,
    )  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp:
        r = contactlab.read_recording(str(rec.to_csv(Path(tmp) / "r.csv")))
    rep = contactlab.diagnose(r, model="tangential")
    assert rep.effect_names == ["position_friction"]
