"""The λ-scaled element from rest on a noisy displacement record (docs/effects.md:
only the first loading tells a branch scale from a force offset): the turning points ignore
the sensor's wiggles at rest, and the fit starts at the λ the data show."""

from __future__ import annotations

import numpy as np
import pytest

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


def _doc_breakaway(x, rev, b, dc, h0):
    """docs/effects.md, plain Python: b h0 sgn(ẋ) (s/d_c) e^(1 - s/d_c), s the travel since
    the last turning point; before the first, the travel from the origin (the first loading
    from rest breaks away as after a turn)."""
    out = []
    last = None
    for i, xi in enumerate(x):
        if last is None or (rev.size and i >= rev[0] and last != rev[rev <= i][-1]):
            last = rev[rev <= i][-1] if rev.size and i >= rev[0] else None
        anchor = 0.0 if last is None else x[last]
        s = abs(xi - anchor)
        sgn = 1.0 if xi >= anchor else -1.0
        out.append(b * h0 * sgn * (s / dc) * np.exp(1 - s / dc))
    return np.array(out)


def test_stick_slip_is_the_documents_breakaway():
    """The candidate adds docs/effects.md's breakaway to the branches (against a plain
    loop); its peak b h0 sits a travel d_c after each reversal; the full-branch breakaway
    force is h0 (1 + b) once the branch has saturated before d_c."""
    from contactlab.diagnose.effects.tangential.stick_slip import (
        breakaway_force,
        breakaway_term,
    )

    t = np.linspace(0.0, 3.0, 3001)
    x = 1e-4 * np.sin(2 * np.pi * t)
    rev = turning_points(x, 1e-9)
    h = Masing(40.0, 4e4).force(x)
    b, dc = 0.2, 2.5e-5
    got = breakaway_term(h, x, rev, b, dc, 40.0) - h
    np.testing.assert_allclose(got, _doc_breakaway(x, rev, b, dc, 40.0), atol=1e-12)
    after = slice(rev[0], rev[1])
    k = int(np.argmax(np.abs(got[after])))
    assert abs(got[after][k]) == pytest.approx(b * 40.0, rel=1e-3)
    assert abs(x[after][k] - x[rev[0]]) == pytest.approx(dc, rel=0.02)
    assert breakaway_force(40.0, 1e7, b, dc) == pytest.approx(40.0 * (1 + b), rel=1e-3)


def test_a_base_biased_by_the_missing_effect_may_move_as_far_as_the_effect_explains():
    """The base parameters may move by 30 % when an effect is added; by 50 % when the
    effect leaves at most a fifth of the current model's excess held-out error, and by 100 %
    when it leaves at most a tenth (a breakaway at ac·A = 0.8 biases the base's h0 by -40 %);
    a model that takes h0 from 29 N to 6330 N is refused whatever it explains."""
    from contactlab.diagnose.search import _takes_over

    fam = TangentialFamily()
    base = {"h0": 24.3, "ac": 4e4}
    for h0, share, refused in [
        (33.0, 1.0, True), (30.0, 1.0, False), (33.0, 0.15, False), (40.5, 0.15, True),
        (40.5, 0.05, False), (6330.0, 0.0, True), (8.9, 0.05, False), (8.9, 0.5, True),
    ]:  # fmt: skip
        why = _takes_over(fam, base, {"h0": h0, "ac": 4e4}, (), share)
        assert (why is not None) == refused, (h0, share, why)


@pytest.mark.parametrize(("waves", "phi"), [(1.28, 1.0), (1.5, 2.0), (1.77, 4.8)])
def test_position_friction_follows_a_wave_of_any_length_along_the_stroke(waves, phi):
    """docs/effects.md: h0(x) = h0 (1 + ε cos(2π x / L + φ)), L between A and 2A. The
    candidate is that wave with its length fitted (started by the wavelength grid of
    :meth:`PositionFriction.start`): it leaves under 2 % of the effect's RMS and finds L within
    2 % (two harmonics of the stroke and a gradient left up to 15 % here, 28 % at worst)."""
    from contactlab.diagnose.select import fit

    fam = TangentialFamily()
    t = np.arange(0.0, 10.0, 1.0 / 500.0)
    A = 1e-5
    x = A * np.sin(2 * np.pi * t)
    h = Masing(40.0, 4e4).force(x)
    F = h * (1.0 + 0.1 * np.cos(2 * np.pi * x / (waves * A) + phi))
    d = Prepared.build(t, x, F)
    fam.prepare(d)
    start = {"h0": 40.0, "ac": 4e4}
    start.update(fam.start_effect("position_friction", start, d, F - h))
    out = fit(fam, ("position_friction",), d, np.ones(F.size, bool), start, fam.scales(d))
    left = F - fam.predict(out.params, ("position_friction",), d)
    assert np.sqrt(np.mean(left**2)) < 0.02 * np.sqrt(np.mean((F - h) ** 2))
    assert out.params["h0"] == pytest.approx(40.0, rel=0.02)
    assert out.params["L"] == pytest.approx(waves * A, rel=0.02)


def test_breakaway_read_off_the_model_covers_a_series_springs_stretch():
    """A friction damper's model (h0 17 kN behind a series spring of 2 MN/m, 4 cm stroke):
    its breakaway force is read where the branch has crossed the spring's stretch, not
    within the slip distance of the reversal (there it read 1.0 kN)."""
    fam = TangentialFamily()
    t = np.arange(0.0, 6.0, 1.0 / 1024.0)
    x = 0.04 * np.sin(2 * np.pi * t)
    d = Prepared.build(t, x, np.zeros_like(x))
    fam.prepare(d)
    p = {"h0": 1.7e4, "ac": 5e6, "C_s": 5e-7, "s_b": 0.3, "ell": 2.4e-3}
    fb = fam.model_breakaway(p, ("series_compliance", "stick_slip"), d)
    assert 1.7e4 < fb < 1.7e4 * 1.3
