"""The λ-scaled element from rest on a noisy displacement record (docs/effects.md:
only the first loading tells a branch scale from a force offset): the turning points ignore
the sensor's wiggles at rest, and the fit starts at the λ the data show."""

from __future__ import annotations

import numpy as np

from contactlab.diagnose._family import Prepared
from contactlab.diagnose.candidates_tangential import TangentialFamily
from contactlab.diagnose.effects import registry
from contactlab.diagnose.effects.tangential._common import from_rest, record_turns
from contactlab.diagnose.effects.tangential.non_masing_scaling import (
    turning_point_force,
    turning_points,
)
from contactlab.masing import Masing


def _record(lam=1.45, noise=0.01, seed=3, first=6.0):
    """A λ-scaled element driven from rest by a ramped sine; the displacement sensor reads
    noise and a first sample ``first`` noise RMS off (a filter's start-up transient)."""
    rng = np.random.default_rng(seed)
    A, h0, ac = 5e-5, 40.0, 4e4
    t = np.arange(0.0, 12.0, 1.0 / 400.0)
    ramp = np.clip(t, 0.0, 1.0)
    x = A * (0.5 - 0.5 * np.cos(np.pi * ramp)) * np.sin(2 * np.pi * t)
    F = turning_point_force(Masing(h0, ac).virgin, lam, x, turning_points(x, 1e-12))
    xn = x + noise * A * rng.normal(size=x.size)
    xn[0] += first * noise * A
    return t, xn, F + 0.01 * h0 * rng.normal(size=x.size), (A, h0, ac)


def test_a_wiggle_at_rest_is_no_turning_point():
    _, x, _, (A, _, _) = _record()
    band = 6 * 0.01 * A
    raw = turning_points(x, band)
    assert x[raw[0]] < 0.05 * A  # the noise at rest read as a turn...
    kept = from_rest(x, raw, band)
    assert abs(x[kept[0]]) > 0.1 * A  # ...is not one of the contact's
    assert np.array_equal(record_turns(x, 0.01 * A), kept)
    # a record whose first turn is real keeps it
    clean = turning_points(np.sin(np.linspace(0, 20, 2001)), 1e-9)
    assert np.array_equal(from_rest(np.sin(np.linspace(0, 20, 2001)), clean, 1e-9), clean)


def test_branch_scale_starts_where_the_data_put_it():
    """From the base fit's equivalent Masing loop (λ h0/2, 2 ac/λ), the start scan finds λ
    near the truth (the gradient from λ = 2 ran to the range's edge, λ = 0.2, on such a
    record, and a force offset took the gain)."""
    t, x, F, (A, h0, ac) = _record()
    d = Prepared.build(t, x, F)
    d.extra["u_noise"] = 0.01 * A
    lam = 1.45
    base = {"h0": lam * h0 / 2, "ac": 2 * ac / lam}  # what the base model fits
    resid = F - Masing(base["h0"], base["ac"]).force(d.u)
    TangentialFamily().prepare(d)
    got = registry("tangential")["non_masing_scaling"].start(base, d, resid)
    assert abs(got["lam"] - lam) <= 0.16
    assert abs(got["h0"] / h0 - 1) < 0.15 and abs(got["ac"] / ac - 1) < 0.15
